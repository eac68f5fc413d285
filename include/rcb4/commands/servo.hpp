// rcb4 — servo commands: SINGLE (0x0F), CONST (0x10), SERIES (0x11), SPEED/STRETCH (0x12).
// SPDX-License-Identifier: BSL-1.0
//
// Wire layouts (protocol.md §4.6–§4.9), positions and values in ascending ICS order:
//   SINGLE: [07][0F][ICS|U<<7][frames][posL][posH][SUM]          e.g. ICS 0 → 7500 in 10 frames:
//                                                                      07 0F 00 0A 4C 1D 89
//   CONST:  [9+2n][10][M0 M1 M2 M3 M4|U<<7][frames][pos0L pos0H]...[SUM]
//   SERIES: [8+3n][11][M0 M1 M2 M3 M4|U<<7][frames0][pos0L pos0H]...[SUM]
//   PARAM:  [9+n][12][M0 M1 M2 M3 M4][SUB 01 stretch | 02 speed][v0]...[SUM]
// U = update-flag control (rcb4::update_flags). Reply: ACK [04][CMD][06][SUM].
#pragma once

#include <rcb4/commands/common.hpp>
#include <rcb4/servo_set.hpp>
#include <rcb4/values.hpp>

namespace rcb4 {

/** SINGLE: move one servo to a position over a number of frames. */
class single_servo {
 public:
  static constexpr std::uint8_t command_code = 0x0F;  ///< CMD byte
  /** ICS @p n to @p pos in @p speed frames. */
  constexpr single_servo(ics_number n, servo_position pos, frames speed,
                         update_flags flags = update_flags::replace) noexcept
      : ics_(n), pos_(pos), speed_(speed), flags_(flags) {}
  /** No default: a SINGLE acts (it would move ICS 0), so every field is the caller's. */
  single_servo() = delete;

  /** The servo slot. */
  constexpr ics_number ics() const noexcept { return ics_; }
  /** Target position. */
  constexpr servo_position position() const noexcept { return pos_; }
  /** Interpolation frames. */
  constexpr frames speed() const noexcept { return speed_; }
  /** Update-flag control. */
  constexpr update_flags flags() const noexcept { return flags_; }

  /** CMD byte. */
  constexpr std::uint8_t code() const noexcept { return command_code; }
  /** Always 7. */
  constexpr std::size_t wire_size() const noexcept { return 7; }
  /** Writes ICS|flag, frames, position. */
  constexpr void write_body(detail::writer& w) const noexcept {
    w.u8(static_cast<std::uint8_t>(ics_.value() | (static_cast<unsigned>(flags_) << 7)));
    w.u8(speed_.value());
    w.u16(pos_.value());
  }
  /** ACK. */
  constexpr reply_shape expected_reply() const noexcept { return {command_code, false, 0}; }
  /** Reads SINGLE from a checked frame; ICS byte bit 6 must be zero. */
  static constexpr result<single_servo> parse(std::span<const std::uint8_t> f, const codec_options&) noexcept {
    if (f.size() != 7) return errc::bad_frame_size;
    if ((f[2] & 0x40u) != 0) return errc::reserved_bits_set;
    auto n = ics_number::make(f[2] & 0x3Fu);
    if (!n) return n.error();
    auto p = servo_position::make(f[4] | (f[5] << 8));
    if (!p) return p.error();
    return single_servo(*n, *p, frames::make(f[3]).value(),
                        (f[2] & 0x80u) ? update_flags::leave : update_flags::replace);
  }
  friend constexpr bool operator==(const single_servo&, const single_servo&) noexcept = default;

 private:
  ics_number ics_{};
  servo_position pos_{};
  frames speed_{};
  update_flags flags_ = update_flags::replace;
};

namespace detail {
/** Reads the 5 mask bytes at frame[2..6] and checks the frame length against the count. */
constexpr result<servo_mask::decoded> read_mask(std::span<const std::uint8_t> f, std::size_t fixed,
                                                std::size_t per_servo) noexcept {
  if (f.size() < fixed) return errc::bad_frame_size;
  auto m = servo_mask::decode(f.subspan<2, 5>());
  if (!m) return m.error();
  if (m->mask.empty()) return errc::empty_servo_set;
  if (f.size() != fixed + per_servo * m->mask.size()) return errc::bad_frame_size;
  return m;
}
}  // namespace detail

/** CONST: move several servos, each to its own position, all over the same number of frames. */
class const_servo {
 public:
  static constexpr std::uint8_t command_code = 0x10;  ///< CMD byte
  /** @p targets (at least one) over @p speed frames. */
  static constexpr result<const_servo> make(const servo_set<servo_position>& targets, frames speed,
                                            update_flags flags = update_flags::replace) noexcept {
    if (targets.empty()) return errc::empty_servo_set;
    return result<const_servo>(std::in_place, targets, speed, flags);
  }
  /** Servo targets. */
  constexpr const servo_set<servo_position>& targets() const noexcept { return targets_; }
  /** Interpolation frames. */
  constexpr frames speed() const noexcept { return speed_; }
  /** Update-flag control. */
  constexpr update_flags flags() const noexcept { return flags_; }

  /** CMD byte. */
  constexpr std::uint8_t code() const noexcept { return command_code; }
  /** 9 + 2 per servo. */
  constexpr std::size_t wire_size() const noexcept { return 9 + 2 * targets_.size(); }
  /** Writes mask, frames, positions. */
  constexpr void write_body(detail::writer& w) const noexcept {
    w.bytes(targets_.mask().encode(flags_));
    w.u8(speed_.value());
    for (auto p : targets_.values()) w.u16(p.value());
  }
  /** ACK. */
  constexpr reply_shape expected_reply() const noexcept { return {command_code, false, 0}; }
  /** Reads CONST from a checked frame. */
  static constexpr result<const_servo> parse(std::span<const std::uint8_t> f, const codec_options&) noexcept {
    auto m = detail::read_mask(f, 9, 2);
    if (!m) return m.error();
    servo_set<servo_position> set;
    std::size_t i = 8;
    for (auto n : m->mask) {
      auto p = servo_position::make(f[i] | (f[i + 1] << 8));
      if (!p) return p.error();
      set.insert(n, *p);
      i += 2;
    }
    return make(set, frames::make(f[7]).value(), m->flags);
  }
  friend constexpr bool operator==(const const_servo&, const const_servo&) noexcept = default;
  /** No default: a CONST acts, so it comes from make() with at least one target. */
  const_servo() = delete;

 private:
  friend class result<const_servo>;
  constexpr const_servo(const servo_set<servo_position>& t, frames s, update_flags f) noexcept
      : targets_(t), speed_(s), flags_(f) {}
  servo_set<servo_position> targets_{};
  frames speed_{};
  update_flags flags_ = update_flags::replace;
};

/** A SERIES target: position and the frames to reach it. */
struct timed_position {
  servo_position position{};  ///< target
  frames speed{};             ///< interpolation frames for this servo
  friend constexpr bool operator==(const timed_position&, const timed_position&) noexcept = default;
};

/** Tag: the caller accepts that SERIES (0x11) is unverified on the RCB-4HV (protocol.md §11.2). */
struct series_opt_in_t {
  explicit constexpr series_opt_in_t() noexcept = default;
};
/** Passed to series_servo::make to opt in. */
inline constexpr series_opt_in_t series_opt_in{};

/**
 * SERIES: several servos, each with its own frames. The 2015 report found that it reboots a
 * real RCB-4HV; a later library sends it (protocol.md §4.8, §11.2). Opt in explicitly.
 */
class series_servo {
 public:
  static constexpr std::uint8_t command_code = 0x11;  ///< CMD byte
  /** @p targets (at least one); needs rcb4::series_opt_in. */
  static constexpr result<series_servo> make(series_opt_in_t, const servo_set<timed_position>& targets,
                                             update_flags flags = update_flags::replace) noexcept {
    if (targets.empty()) return errc::empty_servo_set;
    return series_servo(targets, flags);
  }
  /** Servo targets with their frames. */
  constexpr const servo_set<timed_position>& targets() const noexcept { return targets_; }
  /** Update-flag control. */
  constexpr update_flags flags() const noexcept { return flags_; }

  /** CMD byte. */
  constexpr std::uint8_t code() const noexcept { return command_code; }
  /** 8 + 3 per servo. */
  constexpr std::size_t wire_size() const noexcept { return 8 + 3 * targets_.size(); }
  /** Writes mask, then frames and position per servo. */
  constexpr void write_body(detail::writer& w) const noexcept {
    w.bytes(targets_.mask().encode(flags_));
    for (const auto& t : targets_.values()) {
      w.u8(t.speed.value());
      w.u16(t.position.value());
    }
  }
  /** ACK. */
  constexpr reply_shape expected_reply() const noexcept { return {command_code, false, 0}; }
  /** Reads SERIES from a checked frame (the board side sees it whether or not it is wise). */
  static constexpr result<series_servo> parse(std::span<const std::uint8_t> f, const codec_options&) noexcept {
    auto m = detail::read_mask(f, 8, 3);
    if (!m) return m.error();
    servo_set<timed_position> set;
    std::size_t i = 7;
    for (auto n : m->mask) {
      auto p = servo_position::make(f[i + 1] | (f[i + 2] << 8));
      if (!p) return p.error();
      set.insert(n, {*p, frames::make(f[i]).value()});
      i += 3;
    }
    return make(series_opt_in, set, m->flags);
  }
  friend constexpr bool operator==(const series_servo&, const series_servo&) noexcept = default;
  /** No default: a SERIES acts, so it comes from make() with at least one target. */
  series_servo() = delete;

 private:
  constexpr series_servo(const servo_set<timed_position>& t, update_flags f) noexcept : targets_(t), flags_(f) {}
  servo_set<timed_position> targets_{};
  update_flags flags_ = update_flags::replace;
};

/** The ICS parameter command 0x12 sets (its SUB byte). */
enum class param_kind : std::uint8_t {
  stretch = 0x01,  ///< softness (ICS "stretch")
  speed = 0x02,    ///< output limit (ICS "speed"); not the interpolation frames of 0x0F/0x10
};

/**
 * SPEED/STRETCH: forwards an ICS parameter to several servos (protocol.md §4.9). DOC-CMD prints
 * the CMD as 11h; every implementation and KONDO's DLL use 0x12 (§11.3).
 */
class servo_params {
 public:
  static constexpr std::uint8_t command_code = 0x12;  ///< CMD byte
  /** Sets @p kind to the values of @p values (at least one servo). */
  static constexpr result<servo_params> make(param_kind kind, const servo_set<servo_param>& values) noexcept {
    if (values.empty()) return errc::empty_servo_set;
    return servo_params(kind, values);
  }
  /** Which parameter. */
  constexpr param_kind kind() const noexcept { return kind_; }
  /** Per-servo values. */
  constexpr const servo_set<servo_param>& values() const noexcept { return values_; }

  /** CMD byte. */
  constexpr std::uint8_t code() const noexcept { return command_code; }
  /** 9 + 1 per servo. */
  constexpr std::size_t wire_size() const noexcept { return 9 + values_.size(); }
  /** Writes mask, SUB, values. */
  constexpr void write_body(detail::writer& w) const noexcept {
    w.bytes(values_.mask().encode(update_flags::replace));
    w.u8(static_cast<std::uint8_t>(kind_));
    for (auto v : values_.values()) w.u8(v.value());
  }
  /** ACK. */
  constexpr reply_shape expected_reply() const noexcept { return {command_code, false, 0}; }
  /** Reads SPEED/STRETCH from a checked frame; M4 bit 7 must be zero here. */
  static constexpr result<servo_params> parse(std::span<const std::uint8_t> f, const codec_options&) noexcept {
    auto m = detail::read_mask(f, 9, 1);
    if (!m) return m.error();
    if (m->flags != update_flags::replace) return errc::reserved_bits_set;
    if (f[7] != 0x01 && f[7] != 0x02) return errc::unknown_parameter_kind;
    servo_set<servo_param> set;
    std::size_t i = 8;
    for (auto n : m->mask) {
      auto v = servo_param::make(f[i++]);
      if (!v) return v.error();
      set.insert(n, *v);
    }
    return make(static_cast<param_kind>(f[7]), set);
  }
  friend constexpr bool operator==(const servo_params&, const servo_params&) noexcept = default;
  /** No default: a SPEED/STRETCH acts, so it comes from make() with at least one servo. */
  servo_params() = delete;

 private:
  constexpr servo_params(param_kind k, const servo_set<servo_param>& v) noexcept : kind_(k), values_(v) {}
  param_kind kind_ = param_kind::stretch;
  servo_set<servo_param> values_{};
};

}  // namespace rcb4
