// rcb4 — operations on a robot model: read joints, move joints, trims (std only, sans-I/O).
// SPDX-License-Identifier: BSL-1.0
//
// Each class is an rcb4::ops::Operation (next / on_reply / error / value): it never does I/O, so
// it runs on rcb4::transport's client, on the virtual board, or in a microcontroller's UART loop.
// Joints are found through the ICS allocation table (RAM 0x0044, protocol.md §6), never by
// assuming HeartToHeart4's 0x0090 + 20·k. A servo block's fields (§7):
//
//   +2 trim (int16)   +4 measured position (servo value − trim)   +6 output position (target)
//
// so joint angles are read from +4 and +6 and are trim-independent, as HTH4 shows them.
// Free/hold of joints and groups is ops::set_servo_power on select()'s mask; the motion list is
// <rcb4/robot/motions.hpp>.
#pragma once

#include <rcb4/ops/servos.hpp>
#include <rcb4/ops/system.hpp>
#include <rcb4/robot/model.hpp>

#include <chrono>
#include <cmath>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace rcb4::robot {

namespace detail {
/** The slot of joint @p j among @p slots (from the allocation table), or nullptr: no block. */
inline const ops::servo_slot* slot_of(std::span<const ops::servo_slot> slots, const joint& j) noexcept {
  for (const auto& s : slots)
    if (s.ics == j.ics) return &s;
  return nullptr;
}
}  // namespace detail

/** A joint and its servo block's RAM address (nothing when the board allocates no block to it). */
struct located {
  const joint* j = nullptr;            ///< the model's joint
  std::optional<std::uint16_t> block;  ///< its 20-byte block, or nothing
};

/** Where each joint of a model lives on a board, from one read of the allocation table. */
class joint_map {
 public:
  joint_map() = default;
  /** Maps every joint of @p m through @p slots (the allocated slots, ops::scan_servos). */
  joint_map(const model& m, std::span<const ops::servo_slot> slots) {
    for (const auto& j : m.joints()) {
      const auto* s = detail::slot_of(slots, j);
      entries_.push_back({&j, s ? std::optional<std::uint16_t>(s->address) : std::nullopt});
    }
  }
  /** One entry per joint, in the model's order. */
  const std::vector<located>& entries() const noexcept { return entries_; }
  /** The joints without a block, in the model's order. */
  std::vector<const joint*> missing() const {
    std::vector<const joint*> out;
    for (const auto& e : entries_)
      if (!e.block) out.push_back(e.j);
    return out;
  }
  /** The block of @p j, or nothing. */
  std::optional<std::uint16_t> block_of(const joint& j) const noexcept {
    for (const auto& e : entries_)
      if (e.j == &j || e.j->name == j.name) return e.block;
    return std::nullopt;
  }

 private:
  std::vector<located> entries_;
};

/** Reads the allocation table once; value(): the joint_map of the model. */
class locate_joints {
 public:
  /** Locates @p m's joints (the model must outlive the map). */
  explicit locate_joints(const model& m) : model_(&m) {}
  /** The table read. */
  std::optional<command> next() { return scan_.next(); }
  /** Takes its reply. */
  void on_reply(const reply& r) {
    scan_.on_reply(r);
    if (scan_.error() == errc{}) map_ = joint_map(*model_, scan_.value());
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return scan_.error(); }
  /** Where the joints are. */
  const joint_map& value() const noexcept { return map_; }
  /** Every allocated slot the table lists (joints or not). */
  const std::vector<ops::servo_slot>& slots() const noexcept { return scan_.value(); }

 private:
  const model* model_;
  ops::scan_servos scan_;
  joint_map map_;
};

/** What a joint read fetches from each block. */
enum class fields : std::uint8_t {
  positions,  ///< the measured position (+4) only: the least bytes, for control loops
  state,      ///< trim, measured position and target (+2..+7)
};

/** One joint as read from its block. */
struct joint_reading {
  const joint* j = nullptr;    ///< the joint
  bool allocated = false;      ///< false: the board has no block for it (nothing else is valid)
  std::int16_t trim = 0;       ///< +2 (fields::state only)
  std::uint16_t position = 0;  ///< +4: measured position
  std::uint16_t target = 0;    ///< +6: output position, FREE 0x8000, HOLD 0x7FFF (fields::state only)

  /** False for a measured position of 0: the servo never answered (a KRS reads 3500..11500). */
  bool answered() const noexcept { return allocated && position != 0; }
  /** The joint's angle, from the measured position; nothing when unallocated, silent or not an angle. */
  std::optional<double> degrees() const { return answered() ? to_degrees(*j, position) : std::nullopt; }
  /**
   * The target's angle; nothing when free, held, unallocated, not read, or 0 (a block the board
   * never drove: no servo position is 0, so it is not an angle of -253 degrees).
   */
  std::optional<double> target_degrees() const {
    return allocated && target != 0 ? to_degrees(*j, target) : std::nullopt;
  }
  /** True when the output is FREE (no torque). */
  bool is_free() const noexcept { return allocated && target == servo_position::free_value; }
  /** True when the output is HOLD. */
  bool is_hold() const noexcept { return allocated && target == servo_position::hold_value; }
};

/**
 * Reads the located joints' blocks in the reads the planner chooses for @p cost (few long reads
 * on a slow-turnaround adapter, one short read per joint on a fast one). restart() runs the same
 * plan again, without allocating: the read half of a control loop.
 */
class read_joints {
 public:
  /** Plans the reads of @p what for every located joint of @p map. */
  read_joints(const joint_map& map, fields what = fields::state, ops::link_cost cost = {}) : what_(what) {
    std::vector<ops::byte_range> wanted;
    for (const auto& e : map.entries()) {
      readings_.push_back({e.j, e.block.has_value(), 0, 0, 0});
      blocks_.push_back(e.block.value_or(0));
      if (e.block)
        wanted.push_back(what == fields::state ? ops::byte_range{*e.block + 2u, 6u}
                                               : ops::byte_range{*e.block + 4u, 2u});
    }
    reads_ = ops::detail::planned_reads(std::move(wanted), cost);
  }
  /** The next read. */
  std::optional<command> next() const {
    if (error_ != errc{}) return std::nullopt;
    return reads_.next();
  }
  /** Takes a reply. */
  void on_reply(const reply& r) {
    if ((error_ = reads_.on_reply(r)) == errc{} && reads_.done()) decode();
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return error_; }
  /** One reading per joint, in the model's order (valid once finished). */
  const std::vector<joint_reading>& value() const noexcept { return readings_; }
  /** The reads chosen. */
  const std::vector<ops::byte_range>& plan() const noexcept { return reads_.plan(); }
  /** Starts the same reads again (the next control-loop cycle). */
  void restart() noexcept {
    reads_.restart();
    error_ = errc{};
  }

 private:
  void decode() {
    for (std::size_t i = 0; i < readings_.size(); ++i) {
      auto& r = readings_[i];
      if (!r.allocated) continue;
      r.position = reads_.word(blocks_[i] + 4u);
      if (what_ == fields::state) {
        r.trim = static_cast<std::int16_t>(reads_.word(blocks_[i] + 2u));
        r.target = reads_.word(blocks_[i] + 6u);
      }
    }
  }
  fields what_;
  std::vector<joint_reading> readings_;
  std::vector<std::uint16_t> blocks_;
  ops::detail::planned_reads reads_;
  errc error_{};
};

// --- moves -------------------------------------------------------------------------------------

/** "Joint NAME to DEGREES", optionally over its own time (else the move's). */
struct joint_target {
  std::string joint;                              ///< a joint's name
  double degrees = 0;                             ///< the angle
  std::optional<std::chrono::milliseconds> time;  ///< this joint's duration, or the move's
};

/** A checked target: the joint, its servo position and its duration. */
struct joint_move {
  const joint* j = nullptr;           ///< the joint
  double degrees = 0;                 ///< the angle asked for
  servo_position position{};          ///< the servo position it needs
  std::chrono::milliseconds time{0};  ///< its duration
  unsigned frames = 0;                ///< output periods (set once the board's period is known)
};

/** The longest move: 255 frames of the slowest output period (25 ms, protocol.md §5). */
inline constexpr std::chrono::milliseconds longest_move{255 * 25};

/**
 * Checks @p targets against @p m: known joints, each once, angles within the limits and the
 * servo's travel, durations 0..6375 ms (@p time for targets without their own). Nothing is sent
 * for a set with a problem; the problem names the joint and the limit.
 */
inline outcome<std::vector<joint_move>> check_targets(const model& m, std::span<const joint_target> targets,
                                                      std::chrono::milliseconds time) {
  std::vector<joint_move> out;
  if (targets.empty()) return problem{"no joint to move"};
  for (const auto& t : targets) {
    const joint* j = m.find(t.joint);
    if (!j) return problem{"no joint is called '" + t.joint + "' (see joint list)"};
    for (const auto& o : out)
      if (o.j == j) return problem{t.joint + " is given twice"};
    auto p = to_position(*j, t.degrees);
    if (!ok(p)) return std::get<problem>(p);
    const auto d = t.time.value_or(time);
    if (d.count() < 0 || d > longest_move)
      return problem{t.joint + ": a move takes 0.." + std::to_string(longest_move.count()) + " ms, not " +
                     std::to_string(d.count())};
    out.push_back({j, t.degrees, std::get<servo_position>(p), d, 0});
  }
  return out;
}

/**
 * Output periods for @p time at @p period: rounded to the nearest frame, at least 1 for a
 * non-zero time; nothing beyond the 255 a CONST frame carries.
 */
inline std::optional<unsigned> frames_for(std::chrono::milliseconds time, output_period period) noexcept {
  const unsigned ms = milliseconds(period);
  auto f = static_cast<unsigned>((time.count() + ms / 2) / ms);
  if (f == 0 && time.count() > 0) f = 1;
  if (f > 255) return std::nullopt;
  return f;
}

/**
 * Moves joints: reads the allocation table (every joint must have a block: the board ignores a
 * servo it has none for, errc::servo_not_allocated) and the config word (the output period turns
 * milliseconds into frames), then one CONST frame per distinct frame count, slowest first. SERIES
 * is never used: boards differ on it (protocol.md §11.2). value(): the moves with their frames.
 */
class move_joints {
 public:
  /** Moves @p moves (from check_targets). */
  explicit move_joints(std::vector<joint_move> moves) : moves_(std::move(moves)) {
    if (moves_.empty()) error_ = errc::empty_servo_set;
  }
  /** The next step. */
  std::optional<command> next() const {
    if (error_ != errc{}) return std::nullopt;
    if (step_ == 0) return ops::detail::read_allocation();
    if (step_ == 1) return command{move::read_ram(ram::config, 2).value()};
    if (step_ - 2 < commands_.size()) return commands_[step_ - 2];
    return std::nullopt;
  }
  /** Takes a reply. */
  void on_reply(const reply& r) {
    if (step_ == 0) {
      const auto table = ops::detail::allocated_slots(r);
      if ((error_ = table.error()) != errc{}) return;
      const auto& slots = *table;
      for (const auto& m : moves_)
        if (!detail::slot_of(slots, *m.j)) {
          error_ = errc::servo_not_allocated;
          unallocated_ = m.j;
          return;
        }
    } else if (step_ == 1) {
      if ((error_ = ops::detail::check_reply(r, true, 2)) != errc{}) return;
      period_ = config_word::decode(r.u16()).period;
      if ((error_ = build()) != errc{}) return;
    } else if ((error_ = ops::detail::check_reply(r, false)) != errc{}) {
      return;
    }
    ++step_;
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return error_; }
  /** The moves, with their frames once the period is known. */
  const std::vector<joint_move>& value() const noexcept { return moves_; }
  /** The board's output period (valid after the config read). */
  output_period period() const noexcept { return period_; }
  /** The joint without a block when error() is errc::servo_not_allocated. */
  const joint* unallocated() const noexcept { return unallocated_; }

 private:
  errc build() {
    std::vector<unsigned> counts;
    for (auto& m : moves_) {
      const auto f = frames_for(m.time, period_);
      if (!f) return errc::frames_out_of_range;
      m.frames = *f;
      if (std::find(counts.begin(), counts.end(), *f) == counts.end()) counts.push_back(*f);
    }
    std::sort(counts.begin(), counts.end(), std::greater<>{});
    for (auto f : counts) {
      servo_set<servo_position> set;
      for (const auto& m : moves_)
        if (m.frames == f) set.insert(m.j->ics, m.position);
      auto c = const_servo::make(set, frames::make(f).value());
      if (!c) return c.error();
      commands_.emplace_back(*c);
    }
    return errc{};
  }
  std::vector<joint_move> moves_;
  std::vector<command> commands_;
  output_period period_ = output_period::ms10;
  const joint* unallocated_ = nullptr;
  std::size_t step_ = 0;
  errc error_{};
};

/**
 * The write half of a control loop: a target per located joint, set in degrees (checked against
 * the joint's limits) and sent as one CONST frame (protocol.md §5). Built once from a joint_map;
 * set() and frame() allocate nothing unless a target is refused. Every joint starts at HOLD
 * (stay where it is) until set. The joint_map must outlive it.
 */
class joint_targets {
 public:
  /** The located joints of @p map, each at HOLD. */
  explicit joint_targets(const joint_map& map) {
    for (const auto& e : map.entries())
      if (e.block) {
        joints_.push_back(e.j);
        targets_.insert(e.j->ics, servo_position::hold());
      }
  }
  /** The joints that take targets (the located ones), in the model's order. */
  std::span<const joint* const> joints() const noexcept { return joints_; }
  /**
   * Sets joint @p i (an index into joints()) to @p degrees. A problem naming the joint and the
   * limit when the angle is outside them; the previous target stays.
   */
  std::optional<problem> set(std::size_t i, double degrees) {
    if (i >= joints_.size()) return problem{"joint index " + std::to_string(i) + " is beyond the located joints"};
    auto p = to_position(*joints_[i], degrees);
    if (!ok(p)) return std::get<problem>(std::move(p));
    targets_.insert(joints_[i]->ics, std::get<servo_position>(p));
    return std::nullopt;
  }
  /** Sets joint @p j, as read_joints' readings name it (see set(std::size_t, double)). */
  std::optional<problem> set(const joint& j, double degrees) {
    for (std::size_t i = 0; i < joints_.size(); ++i)
      if (joints_[i] == &j) return set(i, degrees);
    return set(j.name, degrees);
  }
  /** Sets the joint called @p name (see set(std::size_t, double)). */
  std::optional<problem> set(std::string_view name, double degrees) {
    for (std::size_t i = 0; i < joints_.size(); ++i)
      if (joints_[i]->name == name) return set(i, degrees);
    return problem{"no located joint is called '" + std::string(name) + "'"};
  }
  /** The raw targets, by ICS slot. */
  const servo_set<servo_position>& targets() const noexcept { return targets_; }
  /** One CONST frame with every target, reached in @p f output periods; errc::empty_servo_set for no joint. */
  result<const_servo> frame(frames f) const noexcept { return const_servo::make(targets_, f); }

 private:
  std::vector<const joint*> joints_;
  servo_set<servo_position> targets_;
};

// --- trims -------------------------------------------------------------------------------------

/** A trim in servo counts (+2 of the block: added to every output, protocol.md §7). */
struct joint_trim {
  const joint* j = nullptr;  ///< the joint
  std::int16_t counts = 0;   ///< the trim
};

/** The trim of @p degrees of joint @p j in counts, in the joint's direction; a problem beyond ±30°. */
inline outcome<joint_trim> trim_of(const joint& j, double degrees) {
  if (!std::isfinite(degrees) || std::abs(degrees) > 30.0)
    return problem{j.name + ": a trim corrects a servo horn's mounting, within ±30 degrees, not " +
                   number_text(degrees)};
  const double cpd = (j.kind.high - j.kind.low) / (2 * j.kind.half_turn);
  return joint_trim{&j, static_cast<std::int16_t>(std::lround(j.direction * degrees * cpd))};
}

/** The degrees of a trim of @p counts on joint @p j. */
inline double trim_degrees(const joint& j, std::int16_t counts) {
  const double cpd = (j.kind.high - j.kind.low) / (2 * j.kind.half_turn);
  return counts / cpd / j.direction;
}

/**
 * Writes trims to the joints' blocks (RAM +2, effective at once); with @p persistent also to
 * HTH4's servo image in ROM (hth4_rom::servo_image), which the board loads at power-on. Reads the
 * allocation table first: a joint without a block is errc::servo_not_allocated, nothing written.
 */
class write_trims {
 public:
  /** Writes @p trims. */
  write_trims(std::vector<joint_trim> trims, bool persistent) : trims_(std::move(trims)), persistent_(persistent) {
    if (trims_.empty()) error_ = errc::empty_servo_set;
  }
  /** The next step. */
  std::optional<command> next() const {
    if (error_ != errc{}) return std::nullopt;
    if (step_ == 0) return ops::detail::read_allocation();
    if (step_ - 1 < commands_.size()) return commands_[step_ - 1];
    return std::nullopt;
  }
  /** Takes a reply. */
  void on_reply(const reply& r) {
    if (step_ == 0) {
      const auto table = ops::detail::allocated_slots(r);
      if ((error_ = table.error()) != errc{}) return;
      const auto& slots = *table;
      for (const auto& t : trims_) {
        const auto* s = detail::slot_of(slots, *t.j);
        if (!s) {
          error_ = errc::servo_not_allocated;
          unallocated_ = t.j;
          commands_.clear();
          return;
        }
        // The literal lives in the command (source::literal_u16): nothing refers to this scope.
        const auto v = source::literal_u16(static_cast<std::uint16_t>(t.counts));
        const auto trim_at = static_cast<std::uint16_t>(s->address + 2u);
        commands_.emplace_back(move::make(destination::ram(ram_address::make(trim_at).value()), v).value());
        if (persistent_)
          commands_.emplace_back(move::make(destination::rom(hth4_rom::servo_image_of(trim_at)), v).value());
      }
    } else if ((error_ = ops::detail::check_reply(r, false)) != errc{}) {
      return;
    }
    ++step_;
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return error_; }
  /** The trims written. */
  const std::vector<joint_trim>& value() const noexcept { return trims_; }
  /** How many of the trims, from the first, the board has in RAM so far (after a failure: changed). */
  std::size_t in_ram() const noexcept { return persistent_ ? (acknowledged() + 1) / 2 : acknowledged(); }
  /** How many of the trims, from the first, are written to ROM so far. */
  std::size_t in_rom() const noexcept { return persistent_ ? acknowledged() / 2 : 0; }
  /** The joint without a block when error() is errc::servo_not_allocated. */
  const joint* unallocated() const noexcept { return unallocated_; }

 private:
  /** Writes acknowledged: per trim its RAM write, then (persistent) its ROM write. */
  std::size_t acknowledged() const noexcept { return step_ > 0 ? step_ - 1 : 0; }
  std::vector<joint_trim> trims_;
  bool persistent_;
  std::vector<command> commands_;
  const joint* unallocated_ = nullptr;
  std::size_t step_ = 0;
  errc error_{};
};

}  // namespace rcb4::robot
