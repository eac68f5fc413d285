// rcb4 — robot services: the remote's buttons. HTH4's vector-jump table (motions.md §4: 32
// entries, the image in ROM at 0x091B with its RAM address at 0x0919, the copy the board compares
// in RAM at 0x0357) read, set, cleared and reset, and buttons pressed as a KRR receiver presses
// them (the button word at RAM 0x0350, protocol.md §6).
// SPDX-License-Identifier: BSL-1.0
//
//   auto t = read_buttons(link);                  // both copies, decoded
//   set_button(link, rcb4::hth4_2_2, 0x0201, 3);  // s1+up plays motion 3, in ROM and RAM
//   press(link, rcb4::hth4_2_2, 0x0201, false);   // pressed until a motion starts, then released
#pragma once

#include <rcb4/motion/buttons.hpp>
#include <rcb4/ops/motion.hpp>
#include <rcb4/robot/services/link.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace rcb4::robot::services {

/** Both copies of the table: RAM (what the board compares now) and ROM (what it loads at power-on). */
struct button_tables {
  std::uint16_t ram_at = 0;                        ///< RAM 0x008C: where the board looks
  std::uint16_t rom_at = 0;                        ///< ROM 0x0919: what power-on writes to 0x008C
  motion::vector_table ram;                        ///< the entries the board compares now
  motion::vector_table rom;                        ///< the entries power-on loads
  std::vector<std::uint8_t> ram_bytes, rom_bytes;  ///< as read
  /** True when RAM and ROM hold the same entries. */
  bool same() const { return ram.entries == rom.entries && ram.problem.empty() == rom.problem.empty(); }
};

/** Reads both copies of the table. */
button_tables read_buttons(link& l);

/** The buttons (or other vector entries) of either table that go to ROM @p address, in words ("s1+up"). */
std::vector<std::string> entries_playing(const button_tables& t, std::uint32_t address);

/** A table written: what was done, and the entries read back (RAM and ROM, the same). */
struct table_report {
  std::string done;                   ///< "s1+up plays motion 3"
  std::vector<vector_entry> entries;  ///< the table now
  bool ram_followed_rom = false;      ///< RAM held other entries than ROM; it now holds ROM's
};

/** @p buttons play motion @p n from now on (ROM and RAM); refused for an empty or broken slot. */
table_report set_button(link& l, const rom_layout& layout, std::uint16_t buttons, unsigned n);
/** @p buttons play nothing any more: their entry removed from ROM and RAM, whichever lists it. */
table_report clear_button(link& l, std::uint16_t buttons);
/** An empty table: no button plays anything (ROM and RAM). */
table_report reset_buttons(link& l);
/** Writes @p entries as the table (ROM, its address word, RAM), read back; @p done names it. */
table_report write_buttons(link& l, const button_tables& before, std::vector<vector_entry> entries, std::string done);
/** Loads ROM's table into RAM, as the board does at power-on (after a ROM restore); false when ROM's does not read. */
bool load_buttons_from_rom(link& l);

/** What a press did. */
struct press_report {
  std::uint16_t buttons = 0;  ///< the button word pressed
  bool entry = false;         ///< an entry of the table plays something for them
  bool held = false;          ///< still pressed (released: false)
  ops::motion_state state;    ///< the board's state after the press
};

/**
 * Presses @p buttons as a receiver would: refused when an entry would play an empty or broken
 * slot; without an entry, only with @p hold (a motion's button test sees them). With an entry,
 * waits (at most 1 s, reading the board) until a motion starts, refused when none does; released
 * afterwards unless @p hold.
 */
press_report press(link& l, const rom_layout& layout, std::uint16_t buttons, bool hold);
/** Releases every button (the button word to 0). */
void release(link& l);

}  // namespace rcb4::robot::services
