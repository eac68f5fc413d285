// rcb4 — the virtual board's options, clock and counters.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/board/rom_image.hpp>
#include <rcb4/rcb4.hpp>

#include <chrono>
#include <cstdint>
#include <optional>

namespace rcb4::board {

/** What the emulator does with SERIES (0x11), disputed in protocol.md §11.2. */
enum class series_behaviour : std::uint8_t {
  reboot,   ///< what the 2015 report saw on a real RCB-4HV: the board resets, no reply
  execute,  ///< move the servos, each with its own frames, and ACK
};

/** Emulator choices. */
struct options {
  shift_encoding shift = shift_encoding::measured_2015;  ///< §11.5
  bool allow_arith_to_com = false;                       ///< §11.6
  series_behaviour series = series_behaviour::reboot;    ///< §11.2
  bool strict_timing = false;                            ///< drop a partial frame after a 150 µs gap (DOC-FW "COM")
  std::uint32_t seed = 1;                                ///< AD noise
  servo_mask servos = khr3hv_servos;                     ///< the allocated slots (default: a KHR-3HV's)
  servo_mask unanswered{};                               ///< allocated slots whose servo never answers (+4 stays 0)
  std::optional<output_period>
      period{};  ///< boot with this output period, not the ROM config's (15 ms: HTH4's samples)
};

/** ICS 0..@p n−1 (at most 0..34): a board with @p n anonymous servo slots. */
constexpr servo_mask first_slots(unsigned n) noexcept {
  servo_mask m;
  for (unsigned k = 0; k < n && k < 35; ++k) m.insert(ics_number::make(k).value());
  return m;
}

/** Board time: microseconds since an epoch of the caller's choosing. */
using board_time = std::chrono::microseconds;

/** Counters of what the board saw. */
struct statistics {
  std::uint64_t frames = 0;     ///< complete frames received
  std::uint64_t acks = 0;       ///< ACK replies sent
  std::uint64_t nacks = 0;      ///< NACK replies sent
  std::uint64_t data = 0;       ///< data replies sent
  std::uint64_t dropped = 0;    ///< bytes discarded (bad size byte, timing gaps)
  std::uint64_t reboots = 0;    ///< resets (SERIES with series_behaviour::reboot)
  std::uint64_t rom_steps = 0;  ///< commands executed from ROM
  std::uint64_t vectors = 0;    ///< vector-jump entries that fired
};

}  // namespace rcb4::board
