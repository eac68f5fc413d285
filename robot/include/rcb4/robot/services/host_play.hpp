// rcb4 — robot services: a motion file played from the host, pose by pose with the board's timing
// (motions.md §2): each pose a CONST sent when the board has finished the one before, each branch
// decided from the RAM value the board holds, each call of a ROM motion played on the board and
// waited for. Checked first as a push is checked (limits, the servos' slots, the calls), nothing
// sent when it is refused.
// SPDX-License-Identifier: BSL-1.0
//
// The driver owns the clock, the waits and Ctrl-C:
//
//   host_play p(link, robot, layout, period, document, "wave.yaml");
//   for (auto next = p.advance(0ms); next; next = p.advance(elapsed()))
//     if (!sleep_until(*next)) { p.stop(); break; }      // interrupted: a called ROM motion stopped too
#pragma once

#include <rcb4/motion/player.hpp>
#include <rcb4/robot/motion_file.hpp>
#include <rcb4/robot/services/link.hpp>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace rcb4::robot::services {

/**
 * True when @p d calls a ROM motion (its slot's address depends on the board's HTH4 layout): only
 * then must a front end tell the layout from the ROM before a play from the host.
 */
inline bool needs_layout(const motion_document& d) {
  for (const auto& st : d.steps)
    if (std::holds_alternative<motion_call>(st)) return true;
  return false;
}

/** A motion file played from the host; see the file comment. */
class host_play {
 public:
  /**
   * Checks @p d for a board with @p period and @p layout (refused, nothing sent: it does not
   * compile, a motion runs on the board, a servo it moves has no slot, its calls reach an empty
   * or broken slot or nest too deep). @p file names it in messages; @p rescale keeps its times in
   * ms on another output period; a ROM motion it calls may run @p callee_limit before it is stopped.
   */
  host_play(link& l, const model& robot, const rom_layout& layout, output_period period, const motion_document& d,
            std::string file, bool rescale = false,
            std::chrono::milliseconds callee_limit = std::chrono::milliseconds(60000));

  /**
   * Does what is due at @p now (since the play began; never going back) and returns when to be
   * called next, or nothing once the motion has ended and its last pose is reached: the board's
   * output position of every servo it moved equals its last target (read from the board, one
   * output period apart, since the board starts a pose at its next frame after the command
   * arrived; a note when it has not after a second). Refused
   * (usage) when the program stops on an error, (timeout) when a called ROM motion outlives its
   * limit (stopped on the board first).
   */
  std::optional<std::chrono::milliseconds> advance(std::chrono::milliseconds now);
  /**
   * Interrupted: a ROM motion it called is stopped on the board, and every servo it moved holds
   * where it is now; once it has called a ROM motion, every servo the board has a slot for (the
   * called motion's pose under way would go on to its end).
   */
  void stop();

  /** Notes on the file (times rounded to frames, a rescale, steps that never run). */
  const std::vector<std::string>& notes() const noexcept { return compiled_.notes; }
  /** The step the next action comes from (0-based). */
  std::size_t step() const noexcept { return player_.step(); }
  /** Poses sent so far. */
  std::size_t poses() const noexcept { return player_.poses(); }
  /** ROM motions called so far. */
  std::size_t calls() const noexcept { return player_.calls(); }
  /** The board's output period. */
  output_period period() const noexcept { return period_; }

 private:
  std::optional<std::chrono::milliseconds> settled(std::chrono::milliseconds now);
  link& l_;
  const rom_layout& layout_;
  output_period period_;
  std::string file_;
  std::chrono::milliseconds callee_limit_;
  servo_mask slots_;  ///< the servos the board has a slot for (read when it is checked)
  compiled_motion compiled_;
  motion::player player_;
  std::chrono::milliseconds ready_{};                      ///< when the board has reached the last pose sent
  std::optional<std::chrono::milliseconds> callee_since_;  ///< a called ROM motion runs, since then
  std::optional<unsigned> callee_;
  servo_mask moved_;                ///< the servos its poses moved (held where they are when it is stopped)
  servo_set<servo_position> last_;  ///< each moved servo's last target sent
  std::optional<std::chrono::milliseconds> settle_since_;  ///< the program ended: waiting for the board to get there
  bool finished_ = false;
};

}  // namespace rcb4::robot::services
