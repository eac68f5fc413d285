// rcb4 — servo operations: scan the allocated slots, read every servo's state in few exchanges.
// SPDX-License-Identifier: BSL-1.0
//
// Servo blocks are found through the ICS allocation table at RAM 0x0044 (protocol.md §6, §7),
// not by assuming HTH4's 0x0090 + 20·k. Moving a set of servos at one speed is the codec's
// const_servo; move_servos adds per-servo speeds without SERIES (one CONST frame per distinct
// speed). Free/hold and the ICS speed/stretch parameters apply to a given set or to every
// allocated servo (the operation reads the allocation table first).
#pragma once

#include <rcb4/ops/fixed_vector.hpp>
#include <rcb4/ops/memory.hpp>
#include <rcb4/ops/planner.hpp>

#include <algorithm>
#include <array>
#include <functional>
#include <limits>
#include <span>
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
/**
 * Degrees from centre of @p p (FREE and HOLD have no angle: NaN). For a word read from a servo
 * block use degrees_of(), which also knows that 0 is no angle.
 */
inline double to_degrees(servo_position p) noexcept {
  if (p.is_free() || p.is_hold()) return std::numeric_limits<double>::quiet_NaN();
  return (p.value() - double{servo_position::centre_value}) / counts_per_degree;
}
/**
 * The angle of a position word read from a servo block (+4 measured or +6 target, protocol.md §7),
 * or nothing when it holds none: FREE, HOLD, a word that is no position, and 0. The board writes
 * +4 from the servo's answers and +6 from its moves; 0 is what a block holds before either
 * (the servo never answered, or was never driven), not an angle of -253 degrees: a KRS servo's
 * positions are 3500-11500 (§10).
 */
inline std::optional<double> degrees_of(std::uint16_t word) noexcept {
  const auto p = servo_position::make(word);
  if (word == 0 || !p || p->is_free() || p->is_hold()) return std::nullopt;
  return to_degrees(*p);
}

/** An allocated ICS slot and its servo data block's RAM address. */
struct servo_slot {
  ics_number ics{};           ///< the slot
  std::uint16_t address = 0;  ///< its 20-byte block
  friend bool operator==(const servo_slot&, const servo_slot&) = default;
};

/**
 * The allocated slots of an ICS allocation table (@p table: its 70 bytes from RAM 0x0044, ICS 0–34,
 * little-endian words, protocol.md §6), ascending; errc::bad_allocation_table when an entry cannot
 * be a servo block. 0xFFFF is no servo, and so is 0x0000 (a table of zeros, as on a board without
 * a project). Any other entry must be a whole 20-byte block inside the user area (0x0090–0x048F,
 * §6) at an even address (its fields are 16-bit words, §7), and no two blocks may overlap. Blocks
 * need not sit at HeartToHeart4's 0x0090 + 20·k (§7: read the table, do not assume it), but a
 * table that breaks these rules would make every reader show made-up angles and every trim write
 * land in another servo's block, so it is refused whole. No heap: firmware can call it.
 */
inline result<fixed_vector<servo_slot, 35>> parse_allocation_table_fixed(std::span<const std::uint8_t> table) noexcept {
  if (table.size() < 70) return errc::bad_allocation_table;
  fixed_vector<servo_slot, 35> slots;
  std::array<std::uint16_t, 35> at{};
  std::size_t n = 0;
  for (unsigned k = 0; k < 35; ++k) {
    const auto a = static_cast<std::uint16_t>(table[2 * k] | (table[2 * k + 1] << 8));
    if (a == ram::no_allocation || a == 0) continue;
    if (a < ram::user_area.value() || std::uint32_t{a} + servo_block::size > ram_size || a % 2 != 0)
      return errc::bad_allocation_table;
    slots.push_back({ics_number::make(k).value(), a});
    at[n++] = a;
  }
  for (std::size_t i = 1; i < n; ++i)  // insertion sort: 35 words at most, no recursion
    for (std::size_t j = i; j > 0 && at[j] < at[j - 1]; --j) std::swap(at[j], at[j - 1]);
  for (std::size_t i = 1; i < n; ++i)
    if (at[i] < at[i - 1] + servo_block::size) return errc::bad_allocation_table;
  return slots;
}
/** parse_allocation_table_fixed's slots in a std::vector. */
inline result<std::vector<servo_slot>> parse_allocation_table(std::span<const std::uint8_t> table) {
  const auto slots = parse_allocation_table_fixed(table);
  if (!slots) return slots.error();
  return std::vector<servo_slot>(slots->begin(), slots->end());
}

namespace detail {
/** The allocation table read: ICS 0–34, 2 bytes each at 0x0044 (ICS 35 has no entry, §6). */
inline command read_allocation() { return command{move::read_ram(ram::ics_allocation, 70).value()}; }
/**
 * The allocated slots in a reply to read_allocation(), ascending, or errc::bad_allocation_table.
 * See parse_allocation_table() for what an entry may hold.
 */
inline result<std::vector<servo_slot>> allocated_slots(const reply& r) {
  if (const auto e = check_reply(r, true, 70); e != errc{}) return e;
  return parse_allocation_table(r.bytes());
}
/** allocated_slots without the heap. */
inline result<fixed_vector<servo_slot, 35>> allocated_slots_fixed(const reply& r) noexcept {
  if (const auto e = check_reply(r, true, 70); e != errc{}) return e;
  return parse_allocation_table_fixed(r.bytes());
}
/**
 * RAM reads of byte ranges, as plan_reads chooses them for a link, into a RAM image: the read
 * half of every servo-block reader (read_servo_states, scan_slots, robot::read_joints).
 * restart() runs the same plan again without allocating. Plan: a std::vector of byte_range, or
 * a fixed_vector (no heap).
 */
template <class Plan>
class basic_planned_reads {
 public:
  basic_planned_reads() = default;
  /** Runs the reads @p plan (each inside RAM, at most 128 bytes). */
  explicit basic_planned_reads(Plan plan) : plan_(std::move(plan)) {}
  /** The next read, or nothing when every read is done. */
  std::optional<command> next() const {
    if (done()) return std::nullopt;
    return command{
        move::read_ram(ram_address::make(plan_[step_].address).value(), transfer_size::make(plan_[step_].size).value())
            .value()};
  }
  /** Takes the reply to next()'s read: errc{} and its bytes stored, or what was wrong with it. */
  errc on_reply(const reply& r) {
    if (const auto e = check_reply(r, true, plan_[step_].size); e != errc{}) return e;
    std::copy(r.bytes().begin(), r.bytes().end(), memory_.begin() + plan_[step_].address);
    ++step_;
    return errc{};
  }
  /** True when every read has its reply. */
  bool done() const noexcept { return step_ >= plan_.size(); }
  /** The 16-bit little-endian word read at RAM @p a. */
  std::uint16_t word(std::uint32_t a) const { return static_cast<std::uint16_t>(memory_[a] | (memory_[a + 1] << 8)); }
  /** The reads chosen. */
  const Plan& plan() const noexcept { return plan_; }
  /** Starts the same reads again. */
  void restart() noexcept { step_ = 0; }

 private:
  Plan plan_{};
  std::array<std::uint8_t, ram_size> memory_{};
  std::size_t step_ = 0;
};

/** Planned reads of any number of ranges (robot::read_joints). */
class planned_reads : public basic_planned_reads<std::vector<byte_range>> {
 public:
  planned_reads() = default;
  /** Plans the reads of @p wanted for @p cost. */
  planned_reads(std::vector<byte_range> wanted, link_cost cost)
      : basic_planned_reads(plan_reads(std::move(wanted), cost)) {}
};

/**
 * Reads the allocation table, then @p size bytes (at most max_field) at @p offset of every
 * allocated block, in the reads plan_reads chooses for the link: the shape of read_servo_states
 * and scan_slots. No heap, and no RAM mirror: it keeps only the bytes asked for (max_field a
 * block), taken from each reply as it comes; the plan is made in place.
 */
class table_then_reads {
 public:
  static constexpr std::uint32_t max_field = 8;  ///< the most bytes of each block a reader keeps
  /** The fields [offset, offset + size) of each block, planned for @p cost. */
  table_then_reads(std::uint32_t offset, std::uint32_t size, link_cost cost)
      : offset_(offset), size_(size), cost_(cost) {}
  /** The next read. */
  std::optional<command> next() const {
    if (error_ != errc{}) return std::nullopt;
    if (!table_read_) return read_allocation();
    if (step_ >= plan_.size()) return std::nullopt;
    return command{
        move::read_ram(ram_address::make(plan_[step_].address).value(), transfer_size::make(plan_[step_].size).value())
            .value()};
  }
  /** Takes a reply; true when the last read is in (slots() and word() are then ready). */
  bool on_reply(const reply& r) {
    if (!table_read_) {
      const auto slots = allocated_slots_fixed(r);
      if ((error_ = slots.error()) != errc{}) return false;
      if (size_ == 0 || size_ > max_field) {
        error_ = errc::transfer_size_out_of_range;  // a field wider than a reader keeps: a caller's mistake
        return false;
      }
      slots_ = *slots;
      // The wanted ranges are built where the plan goes, then planned in place: 35 ranges of at
      // most 8 bytes never need more than 35 parts.
      plan_.resize(slots_.size());
      for (std::size_t i = 0; i < slots_.size(); ++i) plan_[i] = {slots_[i].address + offset_, size_};
      // (plan_parts reads them into its parts before choose_reads writes the plan over them.)
      plan_reads_into<35>({plan_.data(), slots_.size()}, cost_, plan_);
      table_read_ = true;
      return step_ >= plan_.size();
    }
    if (const auto e = check_reply(r, true, plan_[step_].size); e != errc{}) {
      error_ = e;
      return false;
    }
    // Each kept byte the read covers (a field may span two reads: kept byte by byte).
    const std::uint32_t from = plan_[step_].address, to = from + plan_[step_].size;
    for (std::size_t i = 0; i < slots_.size(); ++i)
      for (std::uint32_t k = 0; k < size_; ++k) {
        const std::uint32_t a = slots_[i].address + offset_ + k;
        if (a >= from && a < to) fields_[i * max_field + k] = r.bytes()[a - from];
      }
    ++step_;
    return step_ >= plan_.size();
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return error_; }
  /** The allocated slots, ascending by ICS. */
  std::span<const servo_slot> slots() const noexcept { return slots_.view(); }
  /** The 16-bit word read at RAM @p a (inside a block's kept field; 0 elsewhere). */
  std::uint16_t word(std::uint32_t a) const noexcept {
    for (std::size_t i = 0; i < slots_.size(); ++i) {
      const std::uint32_t f = slots_[i].address + offset_;
      if (a >= f && a + 2 <= f + size_) {
        const auto k = i * max_field + (a - f);
        return static_cast<std::uint16_t>(fields_[k] | (fields_[k + 1] << 8));
      }
    }
    return 0;
  }
  /** The reads chosen after the table. */
  const fixed_vector<byte_range, 35>& plan() const noexcept { return plan_; }

 private:
  std::uint32_t offset_;
  std::uint32_t size_;
  link_cost cost_;
  bool table_read_ = false;
  std::size_t step_ = 0;
  fixed_vector<servo_slot, 35> slots_;
  fixed_vector<byte_range, 35> plan_;
  std::array<std::uint8_t, 35 * max_field> fields_{};
  errc error_{};
};
}  // namespace detail

/** Scans the allocation table: the ICS slots that have a servo block, ascending. */
class scan_servos {
 public:
  /** The table read, once. */
  std::optional<command> next() {
    if (done_) return std::nullopt;
    return detail::read_allocation();
  }
  /** Takes its reply. */
  void on_reply(const reply& r) {
    done_ = true;
    auto slots = detail::allocated_slots(r);
    if ((error_ = slots.error()) == errc{}) slots_ = std::move(slots).value();
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return error_; }
  /** The allocated slots. */
  const std::vector<servo_slot>& value() const noexcept { return slots_; }

 private:
  bool done_ = false;
  std::vector<servo_slot> slots_;
  errc error_{};
};

/** One servo's state from its data block. */
struct servo_state {
  ics_number ics{};            ///< the slot
  std::int16_t trim = 0;       ///< +2 reference (trim)
  std::uint16_t position = 0;  ///< +4 measured position (servo value − trim); 0: never answered
  std::uint16_t target = 0;    ///< +6 output position (FREE 0x8000, HOLD 0x7FFF); 0: never driven
  /** True when the board has heard from the servo (a measured position other than 0). */
  bool answered() const noexcept { return position != 0; }
  /** The measured angle; nothing when the servo never answered (see degrees_of()). */
  std::optional<double> degrees() const noexcept { return degrees_of(position); }
  /** The target's angle; nothing when FREE, HOLD or never driven. */
  std::optional<double> target_degrees() const noexcept { return degrees_of(target); }
  friend bool operator==(const servo_state&, const servo_state&) = default;
};

/**
 * Reads the allocation table, then trim/position/target of every allocated servo slot (0–34),
 * without the heap (firmware can run it): value() is a span over the states held inline.
 */
class read_servo_states_fixed {
 public:
  /** Plans its reads for @p cost (the link's byte time and per-exchange overhead). */
  explicit read_servo_states_fixed(link_cost cost = {}) : reads_(2, 6, cost) {}  // trim, position, target
  /** The next read. */
  std::optional<command> next() const { return reads_.next(); }
  /** Takes a reply. */
  void on_reply(const reply& r) {
    if (!reads_.on_reply(r)) return;
    for (const auto& b : reads_.slots())
      states_.push_back({b.ics, static_cast<std::int16_t>(reads_.word(b.address + 2u)), reads_.word(b.address + 4u),
                         reads_.word(b.address + 6u)});
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return reads_.error(); }
  /** One state per allocated servo slot, ascending (a copy of it owns its values). */
  const fixed_vector<servo_state, 35>& value() const noexcept { return states_; }
  /** The reads chosen after the table (for inspection and benchmarks). */
  const fixed_vector<byte_range, 35>& plan() const noexcept { return reads_.plan(); }

 private:
  detail::table_then_reads reads_;
  fixed_vector<servo_state, 35> states_;
};

/** Reads the allocation table, then trim/position/target of every allocated servo slot (0–34). */
class read_servo_states {
 public:
  /** Plans its reads for @p cost (the link's byte time and per-exchange overhead). */
  explicit read_servo_states(link_cost cost = {}) : op_(cost) {}
  /** The next read. */
  std::optional<command> next() const { return op_.next(); }
  /** Takes a reply. */
  void on_reply(const reply& r) {
    op_.on_reply(r);
    if (states_.empty()) states_.assign(op_.value().begin(), op_.value().end());  // once, when finished
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return op_.error(); }
  /** One state per allocated servo slot, ascending. */
  const std::vector<servo_state>& value() const noexcept { return states_; }
  /** The reads chosen after the table (for inspection and benchmarks). */
  const fixed_vector<byte_range, 35>& plan() const noexcept { return op_.plan(); }

 private:
  read_servo_states_fixed op_;
  std::vector<servo_state> states_;
};

namespace detail {
/**
 * Sends commands built for a set of servos, each answered by ACK. Without an explicit set it
 * first reads the allocation table and uses every allocated slot. value(): the slots addressed.
 */
template <class Build>
class on_servos {
 public:
  on_servos(std::optional<servo_mask> which, Build build) : build_(std::move(build)) {
    if (which) use(*which);
  }
  std::optional<command> next() {
    if (error_ != errc{}) return std::nullopt;
    if (!have_mask_) return read_allocation();
    if (sent_ >= commands_.size()) return std::nullopt;
    return commands_[sent_];
  }
  void on_reply(const reply& r) {
    if (!have_mask_) {
      const auto slots = allocated_slots_fixed(r);  // no heap (GCC 12 -O2 misread the vector's free here)
      if ((error_ = slots.error()) != errc{}) return;
      servo_mask all;
      for (const auto& s : *slots) all.insert(s.ics);
      use(all);
      return;
    }
    if ((error_ = check_reply(r, false)) == errc{}) ++sent_;
  }
  errc error() const noexcept { return error_; }
  servo_mask value() const noexcept { return mask_; }

 private:
  void use(servo_mask m) {
    have_mask_ = true;
    mask_ = m;
    if (m.empty()) {
      error_ = errc::empty_servo_set;
      return;
    }
    auto built = build_(m);
    if (!built)
      error_ = built.error();
    else
      commands_ = std::move(*built);
  }
  Build build_;
  bool have_mask_ = false;
  servo_mask mask_{};
  std::vector<command> commands_;
  std::size_t sent_ = 0;
  errc error_{};
};
template <class Build>
on_servos(std::optional<servo_mask>, Build) -> on_servos<Build>;
}  // namespace detail

/** What set_servo_power leaves the servos in. */
enum class power_state : std::uint8_t {
  free,  ///< no torque: the servo can be moved by hand (position 0x8000)
  hold,  ///< torque on at the current position (position 0x7FFF)
};

/** Frees or holds the servos of @p which, or every allocated servo when it is empty. */
inline auto set_servo_power(power_state state, std::optional<servo_mask> which = std::nullopt) {
  return detail::on_servos(which, [state](servo_mask m) -> result<std::vector<command>> {
    servo_set<servo_position> set;
    for (auto n : m) set.insert(n, state == power_state::free ? servo_position::free() : servo_position::hold());
    auto c = const_servo::make(set, frames{1});
    if (!c) return c.error();
    return std::vector<command>{command{*c}};
  });
}

/**
 * Sets the ICS speed (output limit) or stretch (softness) parameter to @p value (1–127) on the
 * servos of @p which, or on every allocated servo (protocol.md §4.9).
 */
inline auto set_servo_param(param_kind kind, servo_param value, std::optional<servo_mask> which = std::nullopt) {
  return detail::on_servos(which, [kind, value](servo_mask m) -> result<std::vector<command>> {
    servo_set<servo_param> set;
    for (auto n : m) set.insert(n, value);
    auto c = servo_params::make(kind, set);
    if (!c) return c.error();
    return std::vector<command>{command{*c}};
  });
}

/**
 * Moves servos with a speed (interpolation frames) per servo, without SERIES (§4.8, unverified
 * on the RCB-4HV): one CONST frame per distinct speed, sent back to back, slowest first so that
 * the group that finishes last starts first. value(): the servos moved.
 */
inline auto move_servos(const servo_set<timed_position>& targets) {
  std::optional<servo_mask> mask = targets.mask();
  return detail::on_servos(mask, [targets](servo_mask) -> result<std::vector<command>> {
    std::vector<command> out;
    std::array<bool, 256> seen{};
    std::vector<std::uint8_t> speeds;
    for (const auto& e : targets) {
      const auto f = e.value.speed.value();
      if (!seen[f]) speeds.push_back(f);
      seen[f] = true;
    }
    std::sort(speeds.begin(), speeds.end(), std::greater<>{});
    for (auto f : speeds) {
      servo_set<servo_position> group;
      for (const auto& e : targets)
        if (e.value.speed.value() == f) group.insert(e.ics, e.value.position);
      auto c = const_servo::make(group, frames::make(f).value());
      if (!c) return c.error();
      out.emplace_back(*c);
    }
    return out;
  });
}

}  // namespace rcb4::ops
