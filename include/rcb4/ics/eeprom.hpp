// rcb4 — the ICS servo's 64-byte EEPROM image as a typed value (ics.md §4).
// SPDX-License-Identifier: BSL-1.0
//
// Layout (1-based byte numbers as in ICSSW; every byte carries 4 bits in its low nibble, a field of
// n bytes is a 4n-bit number, most significant nibble first; ics.md §4.1-§4.3):
//   1-2 check mark 0x5A | 3-4 stretch ×2 | 5-6 speed | 7-8 punch | 9-10 dead band | 11-12 damping
//   13-14 safe timer | 15 flags: slave(3) rotation(0) | 16 flags: PWMINH(3) fixed(2) FREE(1) reverse(0)
//   17-20 maximum limit | 21-24 minimum limit | 25-26 factory | 27-28 baud code (byte 28) | 29-30
//   temperature limit | 31-32 current limit | 33-50 factory | 51-52 response | 53-54 user offset
//   (signed byte) | 55-56 factory | 57-58 ID | 59-64 stretch sets 1-3 (×2)
// e.g. a maximum limit of 11500 = 0x2CEC is stored as 02 0C 0E 0C in bytes 17-20.
// Fields are read and set in the units of the ICS commands and KONDO's manager (stretch 1-127,
// not the stored 2-254). The factory-correction bytes are kept exactly as read.
#pragma once

#include <rcb4/ics/values.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace rcb4::ics {

/** A field of the EEPROM image (ics.md §4.2, §4.3). */
enum class field : std::uint8_t {
  stretch,            ///< bytes 3-4, 1-127 (stored ×2)
  speed,              ///< bytes 5-6, 1-127
  punch,              ///< bytes 7-8, 0-10
  dead_band,          ///< bytes 9-10, 0-10 (ICSSW p22 says 0-5, p4 and ICSMGR 0-10: ics.md §7.2)
  damping,            ///< bytes 11-12, 1-255
  safe_timer,         ///< bytes 13-14, 10-255 (about 0.056 s a unit)
  slave,              ///< byte 15 bit 3: never replies (the second of a back-to-back pair)
  rotation,           ///< byte 15 bit 0: endless rotation
  pwm_inhibit,        ///< byte 16 bit 3: serial only, never PWM after a power glitch
  free,               ///< byte 16 bit 1: free status (read only)
  reverse,            ///< byte 16 bit 0: turns the other way
  max_limit,          ///< bytes 17-20, 8000-11500
  min_limit,          ///< bytes 21-24, 3500-7500
  baud,               ///< byte 28: 115200, 625000 or 1250000 (as the rate, not the code)
  temperature_limit,  ///< bytes 29-30, 1-127 (smaller is hotter)
  current_limit,      ///< bytes 31-32, 1-63 (about 0.1 A a unit)
  response,           ///< bytes 51-52, 1-5
  user_offset,        ///< bytes 53-54, −127…127 (a signed byte)
  id,                 ///< bytes 57-58, 0-31 (read only here: the ID command changes it)
  stretch_1,          ///< bytes 59-60, 1-127 (stored ×2)
  stretch_2,          ///< bytes 61-62, 1-127 (stored ×2)
  stretch_3,          ///< bytes 63-64, 1-127 (stored ×2)
};

/** How a field sits in the image and what it may hold. */
struct field_info {
  field f;                ///< the field
  std::string_view name;  ///< its name in the tool, JSON and pyrcb4 ("stretch", "max_limit")
  std::uint8_t first;     ///< its first byte, 1-based as in ICSSW
  std::uint8_t nibbles;   ///< bytes it spans (one nibble each); 0 for a flag bit
  std::uint8_t bit;       ///< for a flag: its bit in byte `first`'s nibble
  long min;               ///< lowest value (command units)
  long max;               ///< highest value
  bool writable;          ///< `set` may change it
  std::string_view what;  ///< one line for people
};

/** Every field, in the image's order. */
inline constexpr field_info fields[] = {
    {field::stretch, "stretch", 3, 2, 0, 1, 127, true, "holding stiffness, soft to hard"},
    {field::speed, "speed", 5, 2, 0, 1, 127, true, "maximum speed, slow to fast (lock protection only at 127)"},
    {field::punch, "punch", 7, 2, 0, 0, 10, true, "torque offset at the start of a move"},
    {field::dead_band, "dead_band", 9, 2, 0, 0, 10, true, "neutral band"},
    {field::damping, "damping", 11, 2, 0, 1, 255, true, "braking at the stop"},
    {field::safe_timer, "safe_timer", 13, 2, 0, 10, 255, true, "delay before a locked servo drops to 50 % power"},
    {field::slave, "slave", 15, 0, 3, 0, 1, true, "never replies (second servo of a back-to-back pair)"},
    {field::rotation, "rotation", 15, 0, 0, 0, 1, true, "endless rotation (wheel) mode"},
    {field::pwm_inhibit, "pwm_inhibit", 16, 0, 3, 0, 1, true, "serial only: never falls into PWM mode"},
    {field::free, "free", 16, 0, 1, 0, 1, false, "free status (read only)"},
    {field::reverse, "reverse", 16, 0, 0, 0, 1, true, "turns the other way"},
    {field::max_limit, "max_limit", 17, 4, 0, 8000, 11500, true, "maximum position"},
    {field::min_limit, "min_limit", 21, 4, 0, 3500, 7500, true, "minimum position"},
    {field::baud, "baud", 28, 1, 0, 115200, 1250000, true, "line rate: 115200, 625000 or 1250000"},
    {field::temperature_limit, "temperature_limit", 29, 2, 0, 1, 127, true, "temperature limit (smaller is hotter)"},
    {field::current_limit, "current_limit", 31, 2, 0, 1, 63, true, "current limit, about 0.1 A a unit"},
    {field::response, "response", 51, 2, 0, 1, 5, true, "sharpness of the start"},
    {field::user_offset, "user_offset", 53, 2, 0, -127, 127, true, "neutral shift (factory-adjusted)"},
    {field::id, "id", 57, 2, 0, 0, 31, false, "servo ID (changed with `ics id set`)"},
    {field::stretch_1, "stretch_1", 59, 2, 0, 1, 127, true, "stretch set 1 (HTH3 characteristic change)"},
    {field::stretch_2, "stretch_2", 61, 2, 0, 1, 127, true, "stretch set 2"},
    {field::stretch_3, "stretch_3", 63, 2, 0, 1, 127, true, "stretch set 3"},
};

/** The entry of @p f in `fields`. */
constexpr const field_info& info(field f) noexcept { return fields[static_cast<std::size_t>(f)]; }
/** The field called @p name, or nullptr. */
constexpr const field_info* find_field(std::string_view name) noexcept {
  for (const auto& i : fields)
    if (i.name == name) return &i;
  return nullptr;
}

/** True for the bytes (1-based) that hold the servo's factory correction: 25-26, 33-50, 55-56 (ics.md §4.2). */
constexpr bool factory_byte(std::size_t n) noexcept {
  return (n >= 25 && n <= 26) || (n >= 33 && n <= 50) || (n >= 55 && n <= 56);
}

/** The 64-byte image: raw bytes kept as read, fields decoded and set in command units. */
class eeprom_image {
 public:
  /** Bytes in the image. */
  static constexpr std::size_t size = 64;
  using bytes_type = std::array<std::uint8_t, size>;  ///< the raw image

  /** An all-zero image (not valid: no check mark); for building one in tests. */
  constexpr eeprom_image() noexcept = default;

  /** @p raw checked (ics.md §4.1): 64 bytes, each ≤ 0x0F, starting 05 0A; else errc::ics_bad_eeprom. */
  static constexpr result<eeprom_image> parse(std::span<const std::uint8_t> raw) noexcept {
    if (raw.size() != size) return errc::ics_bad_eeprom;
    eeprom_image e;
    for (std::size_t i = 0; i < size; ++i) {
      if (raw[i] > 0x0F) return errc::ics_bad_eeprom;
      e.raw_[i] = raw[i];
    }
    if (e.number(1, 2) != 0x5A) return errc::ics_bad_eeprom;
    return e;
  }

  /** The raw bytes. */
  constexpr const bytes_type& bytes() const noexcept { return raw_; }

  /** The value of @p f in command units (stretch 1-127, baud as the rate, flags 0 or 1, offset signed). */
  constexpr long get(field f) const noexcept {
    const auto& i = info(f);
    if (i.nibbles == 0) return (raw_[i.first - 1u] >> i.bit) & 1u;
    switch (f) {
      case field::stretch:
      case field::stretch_1:
      case field::stretch_2:
      case field::stretch_3: return static_cast<long>(number(i.first, 2) / 2);
      case field::baud: {
        const auto b = baud_of_code(raw_[27]);
        return b ? static_cast<long>(*b) : -static_cast<long>(raw_[27]);  // an unknown code: its negation
      }
      case field::user_offset: return static_cast<std::int8_t>(static_cast<std::uint8_t>(number(i.first, 2)));
      default: return static_cast<long>(number(i.first, i.nibbles));
    }
  }

  /**
   * True when @p f is a stretch field stored odd: no ICS command writes that (stretch is stored
   * doubled, ics.md §4.2), but another tool can; get() shows the value halved, rounded down.
   */
  constexpr bool stored_odd(field f) const noexcept {
    const bool stretch = f == field::stretch || f == field::stretch_1 || f == field::stretch_2 || f == field::stretch_3;
    return stretch && (number(info(f).first, 2) & 1u) != 0;
  }

  /**
   * Sets @p f to @p v (command units), only the field's own bits: errc::ics_value_out_of_range
   * outside the field's range, or for a field that cannot be set (free, id: use set_id()).
   */
  constexpr result<void> set(field f, long v) noexcept {
    const auto& i = info(f);
    if (!i.writable || v < i.min || v > i.max) return errc::ics_value_out_of_range;
    if (i.nibbles == 0) {
      auto& b = raw_[i.first - 1u];
      b = static_cast<std::uint8_t>(v ? (b | (1u << i.bit)) : (b & ~(1u << i.bit)));
      return {};
    }
    switch (f) {
      case field::stretch:
      case field::stretch_1:
      case field::stretch_2:
      case field::stretch_3: put(i.first, 2, static_cast<std::uint32_t>(v * 2)); return {};
      case field::baud: {
        const auto code = baud_code(static_cast<std::uint32_t>(v));
        if (!code) return errc::ics_value_out_of_range;
        raw_[27] = *code;  // byte 28; byte 27 (its high nibble) stays as read (ics.md §4.2)
        return {};
      }
      case field::user_offset: put(i.first, 2, static_cast<std::uint8_t>(static_cast<std::int8_t>(v))); return {};
      default: put(i.first, i.nibbles, static_cast<std::uint32_t>(v)); return {};
    }
  }

  /** Sets the ID field (bytes 57-58); a servo takes a new ID through the ID command, not this (ics.md §4.2). */
  constexpr void set_id(servo_id id) noexcept { put(57, 2, id.value()); }
  /** Sets raw byte @p n (1-based) to @p nibble (≤ 0x0F), as a servo's own factory correction would be. */
  constexpr result<void> set_raw(std::size_t n, std::uint8_t nibble) noexcept {
    if (n < 1 || n > size || nibble > 0x0F) return errc::ics_value_out_of_range;
    raw_[n - 1] = nibble;
    return {};
  }
  /** True when @p other holds the same factory-correction bytes: it comes from the same servo (ics.md §5.2). */
  constexpr bool same_unit(const eeprom_image& other) const noexcept {
    for (std::size_t n = 1; n <= size; ++n)
      if (factory_byte(n) && raw_[n - 1] != other.raw_[n - 1]) return false;
    return true;
  }
  /** This image with the factory bytes of @p unit (so that writing it never changes a servo's calibration). */
  constexpr eeprom_image with_factory_of(const eeprom_image& unit) const noexcept {
    eeprom_image e = *this;
    for (std::size_t n = 1; n <= size; ++n)
      if (factory_byte(n)) e.raw_[n - 1] = unit.raw_[n - 1];
    return e;
  }
  friend constexpr bool operator==(const eeprom_image&, const eeprom_image&) noexcept = default;

 private:
  constexpr std::uint32_t number(std::size_t first, std::size_t nibbles) const noexcept {
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < nibbles; ++k) v = (v << 4) | raw_[first - 1 + k];
    return v;
  }
  constexpr void put(std::size_t first, std::size_t nibbles, std::uint32_t v) noexcept {
    for (std::size_t k = nibbles; k-- > 0; v >>= 4) raw_[first - 1 + k] = static_cast<std::uint8_t>(v & 0x0F);
  }
  bytes_type raw_{};
};

}  // namespace rcb4::ics
