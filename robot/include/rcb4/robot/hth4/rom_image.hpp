// rcb4 — an HTH4 project and a board's ROM image, both ways, without I/O: what HTH4's "write to
// robot" puts in ROM as far as its bytes are known (hth4-files.md §3, §10), and a project read
// back from a ROM (for `rcb4 project export`).
// SPDX-License-Identifier: BSL-1.0
//
//   auto rom = services::backup_rom(link);                // the board's ROM, whole
//   auto plan = hth4::plan_import(rom, project, {});      // the ROM after the import, and each area
//   for (const auto& a : plan.areas) ... a.changes ...    // --dry-run lists these
//   services::restore_rom(link, plan.image, save, false); // writes only what differs, read back
//
// Areas written (§10): every used motion at its slot (relocated to the board's layout, §4); the
// button table (ROM 0x091B, its RAM address at 0x0919) with one CALL entry per ButtonData, left as
// it is when it already plays the same buttons; the allocation image (0x05DE) and each allocated
// servo's trim in its block image (0x0626 + 20k + 2); the config word (0x05DC, keeping the
// board's COM baud unless asked); the AD references (0x08F6); the start-up CALL (0x0444). Left as
// the board has them, and listed with the reason: priority motions, the KRI-3 block, the title
// and the low-power motion (their bytes are [U], §11), mixing (its rate encoding is [U], §2.3),
// the blocks' category and ID bytes ([I]),
// compare types other than Equals (§9), slots the project leaves empty.
#pragma once

#include <rcb4/robot/hth4/project.hpp>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace rcb4::robot::hth4 {

/** How an import treats the board. */
struct import_options {
  /** The board's layout (motions relocated to it); null: the project's own. */
  const rom_layout* layout = nullptr;
  /** Keep the board's COM baud in the config word (the link survives a power cycle). */
  bool keep_baud = true;
  /** The board runs HTH4 2.x boot code (32 button entries); else at most 25 (hth4-files.md §9). */
  bool boot_2x = true;
};

/** One area an import writes. */
struct rom_area {
  std::string what;           ///< "motion 3 'bow' (27 bytes)", "button table", "config word 0x801B"
  std::uint32_t address = 0;  ///< first ROM byte
  std::size_t size = 0;       ///< bytes
  bool changes = false;       ///< the board holds other bytes there now
};

/** What an import does to a ROM. */
struct import_plan {
  std::vector<std::uint8_t> image;       ///< the ROM after the import
  std::vector<rom_area> areas;           ///< every area written, in the order above
  std::vector<std::string> not_written;  ///< what the project holds that is left as the board has it, and why
  /** The trims (ICS number, counts) of the allocated servos, for RAM too (they act at once). */
  std::vector<std::pair<unsigned, std::int16_t>> trims;
};

/**
 * The ROM @p rom (rom_size bytes, as read) with @p p written into it. Throws profile_error when the
 * project cannot go on this board: more button entries than the table takes, a ROM that is not
 * rom_size bytes.
 */
import_plan plan_import(std::span<const std::uint8_t> rom, const project& p, const import_options& opt);

/** What export leaves out of a project read from a ROM. */
struct export_result {
  project value;                      ///< the project
  std::vector<std::string> left_out;  ///< what the ROM holds that the project cannot, and why
};

/**
 * A project from a ROM image in @p layout: the config word, AD references, allocation and servo
 * blocks (named by @p names: ICS number → name, else "ICSk"), every slot whose code reads (its
 * reachable frames from the slot's start, in a row, ending in `03 0D 10 FF`), slot names from
 * @p slot_names (empty: "motion N"), button entries, the start-up motion.
 */
export_result project_from_rom(std::span<const std::uint8_t> rom, const rom_layout& layout,
                               const std::vector<std::string>& names, const std::vector<std::string>& slot_names,
                               const std::string& date);

}  // namespace rcb4::robot::hth4
