// rcb4 — robot services: what the board does at power-on. The config word it loads (ROM 0x05DC,
// protocol.md §8) and HTH4's start-up motion, the CALL its boot code makes at 0x0444
// (hth4-files.md §3: `07 0C a0 a1 a2 00 SUM`; DOC-PRG's StartupCmd; with no start-up motion HTH4
// 2.2 calls DefaultStartup at 0x3CB80, a RETURN).
// SPDX-License-Identifier: BSL-1.0
//
//   auto s = read_startup(link, rcb4::hth4_2_2);   // s.motion: 3, or none
//   set_startup(link, rcb4::hth4_2_2, 3);          // motion 3 plays at power-on
//   persist_config(link, word);                    // power-on loads this config word
#pragma once

#include <rcb4/memory_map.hpp>
#include <rcb4/robot/services/link.hpp>

#include <cstdint>
#include <optional>

namespace rcb4::robot::services {

/** The start-up CALL as the board's ROM holds it. */
struct startup_info {
  bool has_call = false;           ///< a CALL at 0x0444 (HTH4 2.x boot code); else nothing is known
  std::uint32_t target = 0;        ///< what it calls
  std::optional<unsigned> motion;  ///< the slot it calls the start of, if one
  bool default_startup = false;    ///< it calls DefaultStartup (no start-up motion)
};

/** Reads the start-up CALL of a board of @p layout. */
startup_info read_startup(link& l, const rom_layout& layout);

/**
 * Makes motion @p n (nothing: none, DefaultStartup) play at power-on, read back. Refused when the
 * board has no start-up CALL at 0x0444 (not HTH4 2.x boot code), for an empty or broken slot, and
 * for "none" outside HTH4 2.2's layout (where DefaultStartup is is known only for it).
 */
startup_info set_startup(link& l, const rom_layout& layout, std::optional<unsigned> n);

/** The config word the board loads at power-on (ROM 0x05DC). */
config_word boot_config(link& l);
/** Writes @p word as the config word the board loads at power-on (ROM 0x05DC), flags cleared, read back. */
void persist_config(link& l, config_word word);

}  // namespace rcb4::robot::services
