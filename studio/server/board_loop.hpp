// rcb4 ui: the loop that owns the board: it does what the pages asked and reads the robot ~30
// times a second (joints, battery and AD channels, motion, link counters) for every page.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include "app.hpp"
#include "hub.hpp"

#include <atomic>
#include <filesystem>
#include <string>

namespace cli::ui {

/** What the loop needs besides the session. */
struct loop_options {
  std::filesystem::path poses;                       ///< where poses are saved and read (NAME.yaml)
  const rcb4::rom_layout* layout = &rcb4::hth4_2_2;  ///< where the motions are in ROM
  std::chrono::milliseconds period{33};              ///< one reading per period at most (~30 a second)
  std::string device;                                ///< for the page: what is open
  /** Counts the writes other programs made through the studio's share of the port (or null). */
  const std::atomic<std::uint64_t>* outside_writes = nullptr;
};

/**
 * Runs until @p h stops: takes the pages' actions, carries them out on @p s, reads the robot
 * @p m and sends the state through @p h. A board that stops answering is shown as such and
 * tried again every half second; nothing here throws out of run().
 */
void run_board_loop(session& s, const rcb4::robot::model& m, hub& h, const loop_options& o);

/** The hello every page gets first: the robot (joints, limits, groups, motion names) and the link. */
std::string hello_text(const rcb4::robot::model& m, const session& s, const loop_options& o, const settings& limits);

}  // namespace cli::ui
