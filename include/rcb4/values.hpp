// rcb4 — range-checked value types of the protocol (ICS numbers, addresses, sizes, positions).
// SPDX-License-Identifier: BSL-1.0
//
// Every type here can only hold a value the board accepts. Integer literals are checked at
// compile time by consteval constructors (a bad literal does not compile, and the compiler
// names the `..._literal_out_of_range` function it could not call); run-time values go through
// `T::make(v)`, which returns rcb4::result<T> with the matching errc.
#pragma once

#include <rcb4/result.hpp>

#include <compare>
#include <concepts>
#include <cstdint>
#include <utility>

namespace rcb4 {

namespace detail {
// Each bounded type's tag. fail() is declared, never defined, never constexpr: a consteval
// constructor that calls it cannot be evaluated, so the build fails and the diagnostic names
// the tag ("ics_number_literal_out_of_range::fail").
struct ics_number_literal_out_of_range {
  static void fail();
};
struct ram_address_literal_out_of_range {
  static void fail();
};
struct rom_address_literal_out_of_range {
  static void fail();
};
struct transfer_size_literal_out_of_range {
  static void fail();
};
struct frames_literal_out_of_range {
  static void fail();
};
struct servo_param_literal_out_of_range {
  static void fail();
};
/// False for every type: a static_assert that fails only when its template is used.
template <class>
inline constexpr bool always_false = false;
struct servo_position_literal_out_of_range {
  static void fail();
};
struct shift_count_literal_out_of_range {
  static void fail();
};

/**
 * An integer restricted to [Min, Max], stored as Rep. Tag makes each use a distinct type and
 * names the compile-time failure; Err is the run-time error.
 */
template <class Tag, class Rep, long long Min, long long Max, errc Err>
class bounded {
 public:
  using rep = Rep;
  static constexpr Rep min = static_cast<Rep>(Min);  ///< smallest valid value
  static constexpr Rep max = static_cast<Rep>(Max);  ///< largest valid value

  /** The smallest valid value. */
  constexpr bounded() noexcept = default;
  /** From an integer constant; an out-of-range constant does not compile. */
  consteval bounded(long long v) : v_(static_cast<Rep>(v)) {  // NOLINT(google-explicit-constructor)
    if (v < Min || v > Max) Tag::fail();
  }
  /** A floating-point constant does not compile: the value is a whole number (no silent 2.5 → 2). */
  template <std::floating_point F>
  consteval bounded(F) {  // NOLINT(google-explicit-constructor)
    static_assert(detail::always_false<F>,
                  "rcb4: this value is a whole number: write an integer literal (10, not 10.0 or 2.5)");
  }
  /** From a run-time integer: the value, or Err when outside [Min, Max]. */
  template <std::integral I>
  static constexpr result<bounded> make(I v) noexcept {
    if (std::cmp_less(v, Min) || std::cmp_greater(v, Max)) return Err;
    bounded t;
    t.v_ = static_cast<Rep>(v);
    return t;
  }
  /** The raw value. */
  constexpr Rep value() const noexcept { return v_; }
  friend constexpr bool operator==(bounded, bounded) noexcept = default;
  friend constexpr auto operator<=>(bounded, bounded) noexcept = default;

 private:
  Rep v_ = static_cast<Rep>(Min);
};
}  // namespace detail

/** ICS number (servo slot) 0–35; slot 35 is the KRI-3/KRR receiver (protocol.md §5). */
using ics_number =
    detail::bounded<detail::ics_number_literal_out_of_range, std::uint8_t, 0, 35, errc::ics_out_of_range>;

/** A RAM address 0x0000–0x048F (protocol.md §6). */
using ram_address = detail::bounded<detail::ram_address_literal_out_of_range, std::uint16_t, 0x0000, 0x048F,
                                    errc::ram_address_out_of_range>;

/** Bytes of RAM: addresses 0x0000–0x048F. */
inline constexpr std::uint32_t ram_size = 0x0490;

/** An EEPROM (ROM) address 0x000000–0x03FFFF, 256 KiB (protocol.md §8). */
using rom_address = detail::bounded<detail::rom_address_literal_out_of_range, std::uint32_t, 0x000000, 0x03FFFF,
                                    errc::rom_address_out_of_range>;

/** Bytes of ROM: addresses 0x000000–0x03FFFF. */
inline constexpr std::uint32_t rom_size = 0x040000;

/** Size of a MOV / logic transfer: 1–128 bytes (DOC-CMD). */
using transfer_size =
    detail::bounded<detail::transfer_size_literal_out_of_range, std::uint8_t, 1, 128, errc::transfer_size_out_of_range>;

/**
 * The SPEED byte of SINGLE/CONST/SERIES: the number of interpolation frames, 0–255; larger is
 * slower, 0 moves at once; one frame is the output period (10–25 ms) (protocol.md §5, DOC-FW
 * 補間動作). This is KONDO's meaning; the 2015 C library inverted it (256 − speed).
 */
using frames = detail::bounded<detail::frames_literal_out_of_range, std::uint8_t, 0, 255, errc::frames_out_of_range>;

/**
 * An ICS servo parameter (speed = output limit, stretch = softness) sent by command 0x12:
 * 1–127 (protocol.md §4.9, §11.4).
 */
using servo_param =
    detail::bounded<detail::servo_param_literal_out_of_range, std::uint8_t, 1, 127, errc::param_out_of_range>;

/**
 * A servo output position: 0–16383 (ICS 14-bit range; KRS centre 7500, travel ≈ 3500–11500),
 * or one of the two special values FREE (0x8000) and HOLD (0x7FFF) (protocol.md §5, §11.9).
 */
class servo_position {
 public:
  static constexpr std::uint16_t max_angle_value = 16383;  ///< largest ordinary position
  static constexpr std::uint16_t free_value = 0x8000;      ///< servo limp (output off)
  static constexpr std::uint16_t hold_value = 0x7FFF;      ///< servo holds where it is
  static constexpr std::uint16_t centre_value = 7500;      ///< KRS neutral

  /** True when @p v is an ordinary position or FREE/HOLD. */
  template <std::integral I>
  static constexpr bool valid(I v) noexcept {
    return (std::cmp_greater_equal(v, 0) && std::cmp_less_equal(v, max_angle_value)) || std::cmp_equal(v, free_value) ||
           std::cmp_equal(v, hold_value);
  }
  /** The KRS centre, 7500. */
  constexpr servo_position() noexcept = default;
  /** From an integer constant; an invalid constant does not compile. */
  consteval servo_position(long long v) : v_(static_cast<std::uint16_t>(v)) {  // NOLINT
    if (!valid(v)) detail::servo_position_literal_out_of_range::fail();
  }
  /** A floating-point constant does not compile: positions are whole units (no silent 7999.99 → 7999). */
  template <std::floating_point F>
  consteval servo_position(F) {  // NOLINT(google-explicit-constructor)
    static_assert(detail::always_false<F>,
                  "rcb4: a servo position is a whole number: write an integer literal (7500, not 7500.0)");
  }
  /** From a run-time integer; errc::position_out_of_range unless valid. */
  template <std::integral I>
  static constexpr result<servo_position> make(I v) noexcept {
    if (!valid(v)) return errc::position_out_of_range;
    servo_position p;
    p.v_ = static_cast<std::uint16_t>(v);
    return p;
  }
  /** FREE: the servo goes limp. */
  static constexpr servo_position free() noexcept { return servo_position(free_value); }
  /** HOLD: the servo keeps its current angle. */
  static constexpr servo_position hold() noexcept { return servo_position(hold_value); }
  /** True for FREE. */
  constexpr bool is_free() const noexcept { return v_ == free_value; }
  /** True for HOLD. */
  constexpr bool is_hold() const noexcept { return v_ == hold_value; }
  /** The raw 16-bit value as sent on the wire. */
  constexpr std::uint16_t value() const noexcept { return v_; }
  friend constexpr bool operator==(servo_position, servo_position) noexcept = default;

 private:
  std::uint16_t v_ = centre_value;
};

/**
 * A shift count: positive shifts left, negative shifts right, −127…127 (protocol.md §4.2).
 * How it is put on the wire is disputed (§11.5); see rcb4::shift_encoding.
 */
using shift_count =
    detail::bounded<detail::shift_count_literal_out_of_range, std::int8_t, -127, 127, errc::shift_count_out_of_range>;

/** The two halves of the RCB-4's servo connectors (protocol.md §5). */
enum class sio_side : std::uint8_t {
  sio1_4 = 0,  ///< SIO1–SIO4: even ICS numbers
  sio5_8 = 1,  ///< SIO5–SIO8: odd ICS numbers
};

/** A servo as HeartToHeart4 names it: the servo's own ID and the connector side it is on. */
struct servo_address {
  std::uint8_t id = 0;               ///< the ID stored in the ICS servo, 0–17
  sio_side side = sio_side::sio1_4;  ///< connector side
  friend constexpr bool operator==(servo_address, servo_address) noexcept = default;
};

/** ICS number of @p a: 2 × ID + (0 for SIO1–4, 1 for SIO5–8) (DOC-GEN p3). */
constexpr result<ics_number> to_ics(servo_address a) noexcept {
  return ics_number::make(2 * int{a.id} + static_cast<int>(a.side));
}

/** The servo ID and side of ICS number @p n (inverse of to_ics). */
constexpr servo_address to_servo_address(ics_number n) noexcept {
  return {static_cast<std::uint8_t>(n.value() / 2), static_cast<sio_side>(n.value() % 2)};
}

}  // namespace rcb4
