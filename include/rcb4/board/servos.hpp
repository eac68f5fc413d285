// rcb4 — the virtual board's servos: interpolation of the outputs and the EEPROM update flags.
// SPDX-License-Identifier: BSL-1.0
//
// Model (protocol.md §5, §7; motions.md §2): a servo command sets a slot's end point and frames;
// each output period moves the output one step ((end − output) / steps remaining) and, when the
// steps run out, clears the slot's update flag (RAM 0x0007–0x000B). The measured position (+4)
// follows the output at once (ideal servos) unless the slot is one that never answers.
#pragma once

#include <rcb4/board/memory.hpp>
#include <rcb4/rcb4.hpp>

#include <array>
#include <cstdint>
#include <utility>

namespace rcb4::board {

/** The servos behind the ICS slots of a board's memory. */
class servo_bank {
 public:
  /** Slots in @p unanswered have a block but their servo never answers (+4 stays 0). */
  explicit servo_bank(servo_mask unanswered = {}) : unanswered_(unanswered) { reset(); }

  /** Power-on: speed and stretch back to 127. */
  void reset() noexcept {
    for (auto& p : params_) p = {127, 127};
  }

  /** Starts moving ICS @p n's output to @p pos over @p speed frames; false when the slot has no block. */
  bool command(memory& m, ics_number n, servo_position pos, frames speed) const {
    const auto block = m.block_of(n);
    if (!block || n.value() == 35) return false;
    const std::uint32_t b = *block;
    m.put16(b + servo_block::interp_end.offset, pos.value());
    m.ram[b + servo_block::interp_speed.offset] = speed.value();
    // A free or held servo is where it was measured (moved by hand, perhaps): a move starts there.
    const auto out = servo_position::make(m.ram16(b + servo_block::target.offset));
    if (!out || out->is_free() || out->is_hold())
      m.put16(b + servo_block::target.offset, m.ram16(b + servo_block::position.offset));
    const bool immediate = speed.value() == 0 || pos.is_free() || pos.is_hold();
    if (immediate) {
      m.put16(b + servo_block::target.offset, pos.value());
      m.ram[b + servo_block::interp_steps.offset] = 0;
      m.put16(b + servo_block::interp_width.offset, 0);
      follow(m, n, b);
    } else {
      m.ram[b + servo_block::interp_steps.offset] = speed.value();
      const int width = int{pos.value()} - int{m.ram16(b + servo_block::target.offset)};
      m.put16(b + servo_block::interp_width.offset, static_cast<std::uint16_t>(width));
    }
    return true;
  }

  /**
   * The update flags of a servo command: set for the commanded servos that have a slot, 0 for the
   * others (DOC-CMD p18; motions.md §5): a flag no interpolation will clear would stop the program
   * for ever, as a motion listing an unallocated ICS did on a board with fewer servos.
   */
  static void set_update_flags(memory& m, servo_mask commanded, update_flags mode) noexcept {
    if (mode == update_flags::leave) return;
    servo_mask allocated;
    for (auto n : commanded)
      if (m.block_of(n) && n.value() != 35) allocated.insert(n);
    for (unsigned i = 0; i < 5; ++i)
      m.ram[ram::update_flags.value() + i] = static_cast<std::uint8_t>((allocated.bits() >> (8 * i)) & 0xFFu);
  }
  /** True while any update flag is set: the ROM program fetches nothing (motions.md §2). */
  static bool flags_pending(const memory& m) noexcept {
    for (unsigned i = 0; i < 5; ++i)
      if (m.ram[ram::update_flags.value() + i] != 0) return true;
    return false;
  }

  /** One output period: every interpolating servo one step on; a finished one's flag cleared. */
  void step(memory& m) const {
    for (unsigned k = 0; k < 35; ++k) {
      const auto n = ics_number::make(k).value();
      const auto block = m.block_of(n);
      if (!block) continue;
      const std::uint32_t b = *block;
      std::uint8_t steps = m.ram[b + servo_block::interp_steps.offset];
      if (steps > 0) {
        const int out = static_cast<std::int16_t>(m.ram16(b + servo_block::target.offset));
        const int end = static_cast<std::int16_t>(m.ram16(b + servo_block::interp_end.offset));
        const int next = steps == 1 ? end : out + (end - out) / steps;
        m.put16(b + servo_block::target.offset, static_cast<std::uint16_t>(next));
        m.ram[b + servo_block::interp_steps.offset] = --steps;
        follow(m, n, b);
      }
      if (steps == 0) m.ram[ram::update_flags.value() + k / 8] &= static_cast<std::uint8_t>(~(1u << (k % 8)));
    }
  }

  /** Stores speed (output limit) or stretch values of 0x12 for the allocated slots (DOC-CMD: others skipped). */
  void set_params(const memory& m, const servo_params& p) noexcept {
    for (auto e : p.values()) {
      if (!m.block_of(e.ics)) continue;
      auto& s = params_[e.ics.value()];
      (p.kind() == param_kind::speed ? s.first : s.second) = e.value.value();
    }
  }
  /** The speed and stretch of ICS @p n, as last set by 0x12. */
  std::pair<std::uint8_t, std::uint8_t> params_of(ics_number n) const noexcept { return params_[n.value()]; }
  /** True when ICS @p n's servo answers. */
  bool answers(ics_number n) const noexcept { return !unanswered_.contains(n); }

 private:
  /** The measured position follows the output (ideal servo); FREE and HOLD leave it where it is. */
  void follow(memory& m, ics_number n, std::uint32_t b) const noexcept {
    if (unanswered_.contains(n)) return;  // a servo that never answers: +4 stays 0
    const std::uint16_t out = m.ram16(b + servo_block::target.offset);
    if (out != servo_position::free_value && out != servo_position::hold_value)
      m.put16(b + servo_block::position.offset, out);
  }

  servo_mask unanswered_;
  std::array<std::pair<std::uint8_t, std::uint8_t>, ics_slots> params_{};
};

}  // namespace rcb4::board
