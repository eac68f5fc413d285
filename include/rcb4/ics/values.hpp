// rcb4 — ICS 3.5/3.6 servos on their own line: IDs, positions, sub-commands, bauds (ics.md §1-§3).
// SPDX-License-Identifier: BSL-1.0
//
// The ICS side of rcb4 talks to one KONDO servo through a USB adapter in ICS mode, without an
// RCB-4 in between (ics.md §6). Its codec lives in rcb4::ics, std only, in the RCB-4 codec's
// style: constexpr value types, rcb4::result, no exceptions, no allocation.
#pragma once

#include <rcb4/result.hpp>

#include <cstddef>
#include <cstdint>
#include <optional>

namespace rcb4::ics {

/** An ICS servo ID, 0–31 (the header byte's low five bits, ics.md §2.1). */
class servo_id {
 public:
  /** The highest ID. */
  static constexpr unsigned max = 31;
  /** @p v checked: errc::ics_id_out_of_range unless 0–31. */
  static constexpr result<servo_id> make(long long v) noexcept {
    if (v < 0 || v > max) return errc::ics_id_out_of_range;
    return servo_id(static_cast<std::uint8_t>(v));
  }
  constexpr servo_id() noexcept = default;
  /** The ID. */
  constexpr std::uint8_t value() const noexcept { return v_; }
  friend constexpr bool operator==(servo_id, servo_id) noexcept = default;

 private:
  constexpr explicit servo_id(std::uint8_t v) noexcept : v_(v) {}
  std::uint8_t v_ = 0;
};

/** Header bytes: bits 7-5 the command, bits 4-0 the ID; replies clear bit 7 (ics.md §2.1). */
namespace header {
inline constexpr std::uint8_t position = 0x80;      ///< position (and free): 0x80 + id; reply 0x00 + id
inline constexpr std::uint8_t read = 0xA0;          ///< read a parameter: 0xA0 + id; reply 0x20 + id
inline constexpr std::uint8_t write = 0xC0;         ///< write a parameter: 0xC0 + id; reply 0x40 + id
inline constexpr std::uint8_t id = 0xE0;            ///< ID read (0xFF) and write (0xE0 + new); reply 0xE0 + id
inline constexpr std::uint8_t command_mask = 0xE0;  ///< the command bits
inline constexpr std::uint8_t id_mask = 0x1F;       ///< the ID bits
}  // namespace header

/** Sub-commands of the read (0xA0) and write (0xC0) commands (ics.md §2.2). */
enum class sub : std::uint8_t {
  eeprom = 0x00,       ///< the 64-byte EEPROM image
  stretch = 0x01,      ///< stretch 1-127 (read and write)
  speed = 0x02,        ///< speed 1-127 (read and write)
  current = 0x03,      ///< read: current 0-127 (bit 6 the direction); write: the current limit 1-63
  temperature = 0x04,  ///< read: temperature 1-127 (smaller is hotter); write: the temperature limit 1-127
  position = 0x05,     ///< read only, ICS 3.6: the current position, 14 bits (a 3.5 servo does not answer)
};

/** A parameter's range as a write sets it (ics.md §3): stretch and speed and the temperature limit 1-127, the current
 * limit 1-63. */
struct value_range {
  std::uint8_t min = 1;    ///< lowest value
  std::uint8_t max = 127;  ///< highest value
};

/** The range a write of @p s takes (sub::eeprom and sub::position are not one-byte writes: 0-0). */
constexpr value_range write_range(sub s) noexcept {
  switch (s) {
    case sub::stretch:
    case sub::speed:
    case sub::temperature: return {1, 127};
    case sub::current: return {1, 63};
    case sub::eeprom:
    case sub::position: break;
  }
  return {0, 0};
}

/** Positions (ics.md §3): 14 bits on the wire; 3500-11500 settable, 7500 neutral, 0 frees the servo. */
namespace position {
inline constexpr std::uint16_t min = 3500;      ///< −135°
inline constexpr std::uint16_t max = 11500;     ///< +135°
inline constexpr std::uint16_t neutral = 7500;  ///< 0°
inline constexpr std::uint16_t free = 0;        ///< sent: go limp and report the angle
inline constexpr std::uint16_t top = 16383;     ///< the largest 14-bit value a reply can carry
/** Counts per degree: 4000 counts per 135° (ICSMGR p4). */
inline constexpr double counts_per_degree = 4000.0 / 135.0;
/** The angle of @p counts, in degrees from neutral. */
constexpr double degrees(std::uint16_t counts) noexcept { return (counts - double(neutral)) / counts_per_degree; }
/** The counts of @p deg (rounded to the nearest count), or nothing outside ±135°. */
constexpr std::optional<std::uint16_t> counts(double deg) noexcept {
  if (!(deg >= -135.0 && deg <= 135.0)) return std::nullopt;  // NaN too
  const double c = neutral + deg * counts_per_degree;
  return static_cast<std::uint16_t>(c + 0.5);
}
/** 14 bits in two 7-bit bytes: high then low (ics.md §2.3). */
constexpr std::uint8_t high(std::uint16_t p) noexcept { return static_cast<std::uint8_t>((p >> 7) & 0x7F); }
/** The low 7 bits. */
constexpr std::uint8_t low(std::uint16_t p) noexcept { return static_cast<std::uint8_t>(p & 0x7F); }
/** Back from the two bytes. */
constexpr std::uint16_t join(std::uint8_t hi, std::uint8_t lo) noexcept {
  return static_cast<std::uint16_t>(((hi & 0x7Fu) << 7) | (lo & 0x7Fu));
}
}  // namespace position

/** The line's rates (ics.md §1) and their EEPROM codes (ics.md §3: 10 = 115200, 1 = 625000, 0 = 1.25 M). */
inline constexpr std::uint32_t bauds[] = {115200, 625000, 1250000};
/** The EEPROM code of @p baud, or nothing for another rate. */
constexpr std::optional<std::uint8_t> baud_code(std::uint32_t baud) noexcept {
  if (baud == 115200) return 10;
  if (baud == 625000) return 1;
  if (baud == 1250000) return 0;
  return std::nullopt;
}
/** The rate of an EEPROM baud code, or nothing for another code. */
constexpr std::optional<std::uint32_t> baud_of_code(std::uint8_t code) noexcept {
  if (code == 10) return 115200;
  if (code == 1) return 625000;
  if (code == 0) return 1250000;
  return std::nullopt;
}

/** Wire time of @p bytes at @p baud: 11 bits a byte (start, 8 data, parity, stop; ics.md §1), in microseconds. */
constexpr std::uint32_t wire_micros(std::size_t bytes, std::uint32_t baud) noexcept {
  return baud == 0 ? 0 : static_cast<std::uint32_t>((bytes * 11ull * 1000000ull + baud - 1) / baud);
}

}  // namespace rcb4::ics
