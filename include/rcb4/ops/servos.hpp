// rcb4 — servo operations: scan the allocated slots, read every servo's state in few exchanges.
// SPDX-License-Identifier: BSL-1.0
//
// Servo blocks are found through the ICS allocation table at RAM 0x0044 (protocol.md §6, §7),
// not by assuming HTH4's 0x0090 + 20·k. Moving servos needs no operation: send the codec's
// single_servo / const_servo (FREE and HOLD are servo_position::free() / hold()).
#pragma once

#include <rcb4/ops/memory.hpp>
#include <rcb4/ops/planner.hpp>

#include <limits>
#include <vector>

namespace rcb4::ops {

/** Position units: 4000 counts per 135° around the 7500 centre (≈ 29.63 counts/degree, KRS). */
inline constexpr double counts_per_degree = 4000.0 / 135.0;
/** The position for @p degrees from centre; errc::position_out_of_range outside 0–16383. */
inline result<servo_position> from_degrees(double degrees) noexcept {
  const double v = servo_position::centre_value + degrees * counts_per_degree;
  if (!(v >= 0.0 && v <= servo_position::max_angle_value)) return errc::position_out_of_range;
  return servo_position::make(static_cast<int>(v + 0.5));
}
/** Degrees from centre of @p p (FREE and HOLD have no angle: NaN). */
inline double to_degrees(servo_position p) noexcept {
  if (p.is_free() || p.is_hold()) return std::numeric_limits<double>::quiet_NaN();
  return (p.value() - double{servo_position::centre_value}) / counts_per_degree;
}

/** One servo's state from its data block. */
struct servo_state {
  ics_number ics{};            ///< the slot
  std::int16_t trim = 0;       ///< +2 reference (trim)
  std::uint16_t position = 0;  ///< +4 measured position (servo value − trim)
  std::uint16_t target = 0;    ///< +6 output position (FREE 0x8000, HOLD 0x7FFF)
  friend bool operator==(const servo_state&, const servo_state&) = default;
};

/** Reads the allocation table, then trim/position/target of every allocated servo slot (0–34). */
class read_servo_states {
 public:
  /** Plans its reads for @p cost (the link's byte time and per-exchange overhead). */
  explicit read_servo_states(link_cost cost = {}) : cost_(cost) {}
  /** The next read. */
  std::optional<command> next() {
    if (error_ != errc{}) return std::nullopt;
    if (!table_read_) return command{move::read_ram(ram::ics_allocation, 70).value()};  // ICS 0–34
    if (step_ >= plan_.size()) return std::nullopt;
    return command{
        move::read_ram(ram_address::make(plan_[step_].address).value(), transfer_size::make(plan_[step_].size).value())
            .value()};
  }
  /** Takes a reply. */
  void on_reply(const reply& r) {
    if (!table_read_) {
      if ((error_ = detail::check_reply(r, true, 70)) != errc{}) return;
      std::vector<byte_range> wanted;
      for (unsigned k = 0; k < 35; ++k) {
        const std::uint16_t a = r.u16(2 * k);
        if (a == ram::no_allocation || std::uint32_t{a} + servo_block::size > ram_size) continue;
        blocks_.push_back({ics_number::make(k).value(), a});
        wanted.push_back({a + 2u, 6u});  // trim, position, target
      }
      plan_ = plan_reads(wanted, cost_);
      memory_.assign(ram_size, 0);
      table_read_ = true;
      return;
    }
    if ((error_ = detail::check_reply(r, true, plan_[step_].size)) != errc{}) return;
    std::copy(r.bytes().begin(), r.bytes().end(), memory_.begin() + plan_[step_].address);
    if (++step_ == plan_.size()) decode();
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return error_; }
  /** One state per allocated servo slot, ascending. */
  const std::vector<servo_state>& value() const noexcept { return states_; }
  /** The reads chosen after the table (for inspection and benchmarks). */
  const std::vector<byte_range>& plan() const noexcept { return plan_; }

 private:
  struct block {
    ics_number ics;
    std::uint16_t address;
  };
  std::uint16_t word(std::uint32_t a) const { return static_cast<std::uint16_t>(memory_[a] | (memory_[a + 1] << 8)); }
  void decode() {
    for (const auto& b : blocks_)
      states_.push_back(
          {b.ics, static_cast<std::int16_t>(word(b.address + 2u)), word(b.address + 4u), word(b.address + 6u)});
  }
  link_cost cost_;
  bool table_read_ = false;
  std::vector<block> blocks_;
  std::vector<byte_range> plan_;
  std::size_t step_ = 0;
  std::vector<std::uint8_t> memory_;
  std::vector<servo_state> states_;
  errc error_{};
};

}  // namespace rcb4::ops
