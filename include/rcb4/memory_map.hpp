// rcb4 — the board's memory: RAM map, config register, servo data block, KRR buttons, HTH4 ROM layouts.
// SPDX-License-Identifier: BSL-1.0
//
// RAM (protocol.md §6, DOC-FW p3-4):
//   0x0000 config word | 0x0002 PC (3) | 0x0005 SP | 0x0007 EEPROM update flags (5)
//   0x000C+2k AD k reference | 0x0022+2k AD k value | 0x0038 PIO dir | 0x003A PIO value
//   0x003C.. timers 0-3 | 0x0044+2k ICS k allocation | 0x008C vector table | 0x0090–0x048F user area
#pragma once

#include <rcb4/values.hpp>

#include <array>
#include <cstdint>

namespace rcb4 {

/** Named RAM addresses (protocol.md §6). */
namespace ram {
inline constexpr ram_address config{0x0000};           ///< system/config register (2 bytes)
inline constexpr ram_address program_counter{0x0002};  ///< ROM program counter (3 bytes, LE)
inline constexpr ram_address stack_pointer{0x0005};    ///< call-stack counter (1 byte, do not write)
inline constexpr ram_address update_flags{0x0007};     ///< EEPROM update flags (5 bytes)
inline constexpr ram_address ad_reference{0x000C};     ///< AD k reference at +2k, k = 0..10
inline constexpr ram_address ad_value{0x0022};         ///< AD k measured value at +2k (raw − reference)
inline constexpr ram_address pio_direction{0x0038};    ///< bit n = PIO n+1 is an output (power-on 0x03FF)
inline constexpr ram_address pio_value{0x003A};        ///< PIO levels, 10 bits
inline constexpr ram_address timer{0x003C};            ///< down-timer k at +2k, k = 0..3 (100 ms ticks)
inline constexpr ram_address ics_allocation{0x0044};   ///< ICS k servo block address at +2k (0xFFFF none)
inline constexpr ram_address vector_table{0x008C};     ///< jump-vector table address
inline constexpr ram_address user_area{0x0090};        ///< first byte of the user area

inline constexpr std::uint8_t ad_channels = 11;         ///< AD0 (supply/5) … AD10
inline constexpr std::uint8_t timers = 4;               ///< down-timers 0–3
inline constexpr std::uint16_t timer_stopped = 0x8000;  ///< bit 15 of a timer: stopped (power-on value)
inline constexpr std::uint16_t no_allocation = 0xFFFF;  ///< allocation entry of an unused ICS slot

/** AD channel @p k's measured value (k 0..10). */
constexpr result<ram_address> ad(unsigned k) noexcept {
  if (k >= ad_channels) return errc::ram_address_out_of_range;
  return ram_address::make(ad_value.value() + 2 * k);
}
/** ICS slot @p n's allocation-table entry. */
constexpr ram_address allocation_entry(ics_number n) noexcept {
  return ram_address::make(ics_allocation.value() + 2 * n.value()).value();
}
/** Down-timer @p k (0..3). */
constexpr result<ram_address> timer_at(unsigned k) noexcept {
  if (k >= timers) return errc::ram_address_out_of_range;
  return ram_address::make(timer.value() + 2 * k);
}
}  // namespace ram

/** Output period of the servo loop: config bits 4-5 (DOC-FW p5, §11.8). */
enum class output_period : std::uint8_t { ms10 = 0, ms15 = 1, ms20 = 2, ms25 = 3 };

/** Milliseconds of @p p. */
constexpr unsigned milliseconds(output_period p) noexcept { return 10u + 5u * static_cast<unsigned>(p); }

/** A COM or ICS baud code: config bits 6-7 / 13-14. Code 3 is a second encoding of 115200. */
enum class baud_code : std::uint8_t { b115200 = 0, b625000 = 1, b1250000 = 2, b115200_alt = 3 };

/** Bits per second of @p b. */
constexpr std::uint32_t bits_per_second(baud_code b) noexcept {
  switch (b) {
    case baud_code::b625000: return 625000;
    case baud_code::b1250000: return 1250000;
    default: return 115200;
  }
}
/** The code of @p bps: 115200, 625000 or 1250000; other rates are errc::unsupported_baud. */
constexpr result<baud_code> baud_code_of(std::uint32_t bps) noexcept {
  switch (bps) {
    case 115200: return baud_code::b115200;
    case 625000: return baud_code::b625000;
    case 1250000: return baud_code::b1250000;
    default: return errc::unsupported_baud;
  }
}

/**
 * The system/config register at RAM 0x0000 (DOC-FW p5-6; protocol.md §6), typed.
 * decode(encode()) and encode(decode(w)) are identities for every 16-bit word.
 */
struct config_word {
  bool ics_enabled = false;                    ///< bit 0: SIO/ICS switch, servos driven
  bool rom_program = false;                    ///< bit 1: run the EEPROM program
  bool interpolation_message = false;          ///< bit 2: message on COM when interpolation ends
  bool vector_jump = false;                    ///< bit 3: vector-jump switch
  output_period period = output_period::ms10;  ///< bits 4-5
  baud_code com_baud = baud_code::b115200;     ///< bits 6-7
  bool zero_flag = false;                      ///< bit 8: Z
  bool carry_flag = false;                     ///< bit 9: C
  bool program_error = false;                  ///< bit 10: program checksum error
  std::uint8_t unused = 0;                     ///< bits 11-12, kept as read
  baud_code ics_baud = baud_code::b115200;     ///< bits 13-14
  bool led = false;                            ///< bit 15: green LED

  /** The 16-bit register value. */
  constexpr std::uint16_t encode() const noexcept {
    unsigned w = 0;
    w |= ics_enabled ? 1u : 0u;
    w |= rom_program ? 1u << 1 : 0u;
    w |= interpolation_message ? 1u << 2 : 0u;
    w |= vector_jump ? 1u << 3 : 0u;
    w |= static_cast<unsigned>(period) << 4;
    w |= static_cast<unsigned>(com_baud) << 6;
    w |= zero_flag ? 1u << 8 : 0u;
    w |= carry_flag ? 1u << 9 : 0u;
    w |= program_error ? 1u << 10 : 0u;
    w |= (unused & 3u) << 11;
    w |= static_cast<unsigned>(ics_baud) << 13;
    w |= led ? 1u << 15 : 0u;
    return static_cast<std::uint16_t>(w);
  }
  /** The fields of register value @p w. */
  static constexpr config_word decode(std::uint16_t w) noexcept {
    config_word c;
    c.ics_enabled = (w & 1u) != 0;
    c.rom_program = (w & (1u << 1)) != 0;
    c.interpolation_message = (w & (1u << 2)) != 0;
    c.vector_jump = (w & (1u << 3)) != 0;
    c.period = static_cast<output_period>((w >> 4) & 3u);
    c.com_baud = static_cast<baud_code>((w >> 6) & 3u);
    c.zero_flag = (w & (1u << 8)) != 0;
    c.carry_flag = (w & (1u << 9)) != 0;
    c.program_error = (w & (1u << 10)) != 0;
    c.unused = static_cast<std::uint8_t>((w >> 11) & 3u);
    c.ics_baud = static_cast<baud_code>((w >> 13) & 3u);
    c.led = (w & (1u << 15)) != 0;
    return c;
  }
  friend constexpr bool operator==(const config_word&, const config_word&) noexcept = default;
};

/** A field of the 20-byte servo data block (protocol.md §7, DOC-FW p16-19). */
struct servo_field {
  std::uint8_t offset;  ///< byte offset in the block
  std::uint8_t size;    ///< 1 or 2 bytes (2 = little-endian word)
};

/** The servo data block's fields. */
namespace servo_block {
inline constexpr std::uint8_t size = 20;           ///< bytes per ICS slot
inline constexpr servo_field category{0, 1};       ///< 0 = servo block
inline constexpr servo_field id{1, 1};             ///< servo ID
inline constexpr servo_field trim{2, 2};           ///< reference / trim (基準値)
inline constexpr servo_field position{4, 2};       ///< measured position = servo value − trim
inline constexpr servo_field target{6, 2};         ///< output position written by 0x0F/0x10
inline constexpr servo_field interp_speed{8, 1};   ///< interpolation frames
inline constexpr servo_field interp_end{9, 2};     ///< interpolation end position
inline constexpr servo_field interp_steps{11, 1};  ///< interpolation steps remaining
inline constexpr servo_field interp_width{12, 2};  ///< interpolation width
inline constexpr servo_field mix1_source{14, 2};   ///< mixing-1 source word
inline constexpr servo_field mix1_gain{16, 1};     ///< mixing-1 gain: bit 7 sign, low bits ratio
inline constexpr servo_field mix2_source{17, 2};   ///< mixing-2 source word
inline constexpr servo_field mix2_gain{19, 1};     ///< mixing-2 gain
/** HTH4's RAM address of ICS @p n's block, 0x0090 + 20·n (read the allocation table to be sure). */
constexpr ram_address hth4_address(ics_number n) noexcept {
  return ram_address::make(ram::user_area.value() + size * n.value()).value();
}
}  // namespace servo_block

/** KRR/KRC receiver buttons, as bits of the button word (protocol.md §6). */
enum class krr_button : std::uint16_t {
  up = 0x0001,
  down = 0x0002,
  right = 0x0004,
  left = 0x0008,
  triangle = 0x0010,
  cross = 0x0020,
  circle = 0x0040,
  square = 0x0100,
  s1 = 0x0200,
  s2 = 0x0400,
  s3 = 0x0800,
  s4 = 0x1000,
};

/** The KRI-3 receiver area of HTH4 (slot 35's block, DOC-PRG). */
namespace krr {
inline constexpr ram_address block{0x034C};    ///< start of the receiver block
inline constexpr ram_address id{0x034D};       ///< receiver ID
inline constexpr ram_address buttons{0x0350};  ///< button word, high byte first (§11.11)
inline constexpr ram_address analog{0x0352};   ///< PA1–PA4, one byte each (7-bit)
inline constexpr std::uint8_t analog_channels = 4;
inline constexpr std::uint16_t valid_buttons = 0x1F7F;  ///< all defined bits (bit 7 unused)
/** The 2 bytes stored at 0x0350 for button word @p w: high byte first (KPY, KARD, GMU). */
constexpr std::array<std::uint8_t, 2> encode_buttons(std::uint16_t w) noexcept {
  return {static_cast<std::uint8_t>(w >> 8), static_cast<std::uint8_t>(w & 0xFFu)};
}
/** The button word of the 2 bytes at 0x0350. */
constexpr std::uint16_t decode_buttons(std::uint8_t first, std::uint8_t second) noexcept {
  return static_cast<std::uint16_t>((first << 8) | second);
}
}  // namespace krr

/** HTH4 user-area items (DOC-PRG p2-5). */
namespace hth4_ram {
inline constexpr ram_address vector_entries{0x0357};  ///< 8-byte vector-jump entries
inline constexpr ram_address counters{0x0457};        ///< 1 byte each; DOC-PRG/GMU: 11 counters 0–10
inline constexpr std::uint8_t counter_count = 11;
inline constexpr ram_address user_params{0x0462};  ///< int16 each, 20 parameters
inline constexpr std::uint8_t user_param_count = 20;
inline constexpr ram_address tmp1{0x048A};
inline constexpr ram_address tmp2{0x048C};
/** Counter @p k (0..10). */
constexpr result<ram_address> counter(unsigned k) noexcept {
  if (k >= counter_count) return errc::ram_address_out_of_range;
  return ram_address::make(counters.value() + k);
}
/** User parameter @p k (0..19). */
constexpr result<ram_address> user_param(unsigned k) noexcept {
  if (k >= user_param_count) return errc::ram_address_out_of_range;
  return ram_address::make(user_params.value() + 2 * k);
}
}  // namespace hth4_ram

/** Supply voltage from AD0: AD0 is the supply / 5 on 10 bits, V = raw × 25 / 1024 (DOC-FW, §11.17). */
constexpr double battery_volts(std::uint16_t ad0) noexcept { return ad0 * 25.0 / 1024.0; }

/** Where an HTH4 version puts the main loop and the motions in ROM (protocol.md §8, §11.13). */
struct rom_layout {
  const char* name;           ///< "HTH4 1.3", ...
  rom_address startup;        ///< StartupCmd
  rom_address main_loop;      ///< MainLoopCmd: the PC to reset to before a CALL
  rom_address config;         ///< ConfigDataRom (persistent config word)
  rom_address motion_base;    ///< motion 1
  std::uint32_t slot_size;    ///< bytes per motion
  std::uint8_t motion_count;  ///< motions 1..count
};

/** HTH4 1.3 (DOC-PRG). */
inline constexpr rom_layout hth4_1_3{"HTH4 1.3", 0x003F6, 0x003FD, 0x005DC, 0x00BB8, 4864, 50};
/** HTH4 2.0 and 2.1 (DOC-PRG). */
inline constexpr rom_layout hth4_2_0{"HTH4 2.0-2.1", 0x00444, 0x0044B, 0x005DC, 0x00BB8, 2048, 120};
/** HTH4 2.2 and later: what KONDO's own libraries use. */
inline constexpr rom_layout hth4_2_2{"HTH4 2.2+", 0x00444, 0x0044B, 0x005DC, 0x00B80, 2048, 120};

/**
 * HTH4's images in ROM of what the board loads into RAM at power-on (protocol.md §8, every
 * layout): the ICS allocation table (72 bytes, RAM 0x0044) and the servo data blocks (RAM 0x0090
 * onwards, 20 bytes per block). A trim written at image + (block − 0x0090) + 2 survives a power cycle.
 */
namespace hth4_rom {
inline constexpr rom_address allocation_image{0x005DE};  ///< image of RAM 0x0044..0x008B
inline constexpr rom_address servo_image{0x00626};       ///< image of RAM 0x0090 onwards
/** The ROM image address of RAM byte @p a of the servo area (a ≥ 0x0090). */
constexpr rom_address servo_image_of(std::uint16_t a) noexcept {
  return rom_address::make(servo_image.value() + (a - ram::user_area.value())).value();
}
}  // namespace hth4_rom

/** ROM address of motion @p n (1-based) under @p layout. */
constexpr result<rom_address> motion_address(const rom_layout& layout, unsigned n) noexcept {
  if (n < 1 || n > layout.motion_count) return errc::motion_out_of_range;
  return rom_address::make(layout.motion_base.value() + (n - 1) * layout.slot_size);
}

}  // namespace rcb4
