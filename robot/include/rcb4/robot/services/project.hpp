// rcb4 — robot services: HeartToHeart4 projects on the board. An import writes what HTH4's
// "write to robot" writes as far as its bytes are known (hth4::plan_import, hth4-files.md §10),
// as one ROM restore: the ROM saved first, only the pieces that differ written, each read back,
// the button table the board compares loaded from the new ROM; then the trims also in RAM, and
// the motions' names as slot names. An export reads the ROM back as a project.
// SPDX-License-Identifier: BSL-1.0
//
//   auto r = import_project(link, layout, project, {}, save);   // r.plan.areas: what changed
//   auto e = export_project(link, layout, robot);               // e.value: a project
#pragma once

#include <rcb4/robot/hth4/rom_image.hpp>
#include <rcb4/robot/profile.hpp>
#include <rcb4/robot/services/link.hpp>
#include <rcb4/robot/services/rom.hpp>

namespace rcb4::robot::services {

/** How an import treats the board. */
struct project_import_options {
  bool dry_run = false;   ///< read and compare only: nothing is written
  bool keep_baud = true;  ///< keep the board's COM baud in the config word
};

/** What an import did (or, dry, would do). */
struct project_import_report {
  hth4::import_plan plan;     ///< the areas (with changes), what is not written, the trims
  restore_report written;     ///< the ROM restore (empty when dry)
  std::size_t ram_trims = 0;  ///< trims also written to RAM
  bool relocated = false;     ///< the project's layout differs from the board's (§4)
  std::size_t names = 0;      ///< slot names set from the motions' names
  bool period_set = false;    ///< the board's output period (RAM) set to the project's
};

/**
 * Imports @p p into the board of layout @p layout: refused (nothing written) on an HTH4 1.3
 * board, when the project does not fit (hth4::plan_import), or as a ROM restore is refused (a
 * motion running or stopped part way). The ROM it replaces goes to @p save first; the used
 * motions' names become @p robot's slot names (report: names).
 */
project_import_report import_project(link& l, const rom_layout& layout, const model& robot, const hth4::project& p,
                                     const project_import_options& opt, const rom_sink& save);

/**
 * The board as a project: its ROM read whole (progress under "reading ROM"), the servos named by
 * @p robot's joints, the slots by the slot names kept for @p robot (`name:` of a pushed file).
 */
hth4::export_result export_project(link& l, const rom_layout& layout, const model& robot);

}  // namespace rcb4::robot::services
