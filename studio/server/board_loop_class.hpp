// rcb4 ui: the board loop's class, shared by its three files (board_loop.hpp says what it does):
//   board_loop.cpp     the loop: takes the pages' actions, paces the reads, notices other programs
//   board_reading.cpp  reading the robot: the state every page gets, the pose and motion lists
//   board_actions.cpp  the pages' actions carried out on the board (move, free/hold, stop, poses, ROM motions)
// Private to the studio's server: not installed.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include "board_loop.hpp"
#include "studio_ops.hpp"

#include <rcb4/robot/services/moves.hpp>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cli::ui {

namespace t = rcb4::transport;

/** An angle for the page: rounded to hundredths, null when unknown. */
json angle_json(std::optional<double> d);
/** An error for a page: the words of the failure, and its hint. */
std::string words_of(std::error_code ec, std::string_view what);

/** A failure while carrying out an action, with words for the page. */
struct refusal {
  std::string what;
};

/** The loop that owns the board, for one run_board_loop() (one thread). */
class board_loop {
 public:
  board_loop(session& s, const rcb4::robot::model& m, hub& h, const loop_options& o);
  /** Until the hub stops. */
  void run();

 private:
  using joint_target = rcb4::robot::joint_target;
  using joint = rcb4::robot::joint;

  // board_loop.cpp: the loop
  void notice_outside_writes();
  void carry_out(const action& a);
  void located();
  void refuse_during_motion();
  /** Runs @p op; its value, or a default one with @p ec set. */
  template <class Op>
  auto run_ec(Op op, t::error_code& ec) {
    t::run(s_.c(), op, ec);
    return op.value();
  }

  // board_reading.cpp: reading the robot
  /** Reads the robot and sends the state; @p joints_only (the read after a slider move) keeps the rest as last read. */
  void poll(bool joints_only = false);
  void locate(t::error_code& ec);
  std::string state_text();
  std::vector<std::string> pose_names() const;
  void refresh_lists();

  // board_actions.cpp: the pages' actions
  /** Runs @p op on the board; a failure is a refusal in the page's words. */
  template <class Op>
  auto must(Op op, std::string_view what) {
    t::error_code ec;
    auto v = run_ec(std::move(op), ec);
    if (ec) {
      if (std::error_code(ec).category() != rcb4::codec_category()) answering_ = false;
      throw refusal{words_of(ec, what)};
    }
    return v;
  }

  /** Runs @p make()'s operation up to three times (a stop must get through a lossy line). */
  template <class Make>
  void insist(Make make, std::string_view what) {
    for (int attempt = 1;; ++attempt) {
      try {
        must(make(), what);
        return;
      } catch (const refusal&) {
        if (attempt == 3) throw;
      }
    }
  }

  /** The longest move the board makes: 255 frames of its output period (protocol.md §5). */
  std::chrono::milliseconds slowest() const { return std::chrono::milliseconds(255 * rcb4::milliseconds(period_)); }

  json act(const move_action& a) { return move(a.targets); }
  json act(const studio_action&) { return nullptr; }  // carried out by carry_out, which knows the page
  /** Moves @p targets (checked here again: nothing from a page is trusted). */
  json move(std::vector<joint_target> targets);
  rcb4::servo_mask mask_of(const std::vector<const joint*>& joints, std::vector<std::string>* missing);
  std::filesystem::path pose_path(const std::string& name, bool for_reading) const;
  json act(const power_action& a);
  /**
   * Stops a motion playing from the host, and with @p rom_motion one of the ROM's if one runs:
   * what a stop, a free or a hold needs first. Says which it stopped (play_stopped, motion_stopped).
   */
  json stop_motions_first(bool rom_motion);
  /** Every joint of the robot holds where it is (insisted on); returns how many joints. */
  std::size_t hold_all();
  json act(const stop_action& a);
  json act(const capture_action& a);
  json act(const play_pose_action& a);
  json act(const motion_play_action& a);
  json act(const motion_stop_action&);
  json act(const refresh_action&);
  /** The slot read back as `rcb4 motion pull` writes it. */
  json act(const motion_file_action& a);

  session& s_;
  const rcb4::robot::model& m_;
  hub& h_;
  const loop_options& o_;
  rcb4::robot::joint_map map_;
  std::optional<rcb4::robot::read_joints> reader_;
  std::vector<std::optional<double>> angles_, targets_;
  std::vector<std::string> modes_;
  rcb4::ops::analog_inputs analog_{};
  rcb4::ops::motion_state motion_{};
  bool rom_program_ = false;
  rcb4::output_period period_ = rcb4::output_period::ms10;
  std::optional<double> move_at_ms_;  // when the board acknowledged the last move (system clock, ms)
  std::vector<rcb4::ops::motion_slot> motions_;
  bool answering_ = false;
  std::string error_;
  std::uint64_t seq_ = 0;
  studio_ops studio_;
  std::uint64_t last_exchanges_ = 0;
  double rate_ = 0;
  clock::time_point last_rate_at_;
  std::uint64_t outside_seen_ = 0;    // o_.outside_writes when last looked at
  std::uint64_t outside_unseen_ = 0;  // writes not yet told to the pages
  clock::time_point outside_at_;      // when the last of them was seen
};

}  // namespace cli::ui
