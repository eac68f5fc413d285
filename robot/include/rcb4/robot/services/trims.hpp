// rcb4 — robot services: trims, the per-joint corrections of a servo horn's mounting. A trim is
// +2 of the joint's servo block in RAM (added to every output, protocol.md §7) and, for the board
// to load it at power-on, HTH4's servo image in ROM (hth4_rom::servo_image, protocol.md §8).
// SPDX-License-Identifier: BSL-1.0
//
//   for (const auto& t : read_trims(link, robot, robot_joints)) ...   // RAM and ROM, counts and degrees
//   auto r = set_trims(link, robot, {{"left_knee", 1.5}}, true);      // RAM and ROM, read back
#pragma once

#include <rcb4/robot/ops.hpp>
#include <rcb4/robot/services/link.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace rcb4::robot::services {

/** One joint's trim as the board holds it. */
struct trim_entry {
  const joint* j = nullptr;         ///< the joint
  bool allocated = false;           ///< the board has a servo block for it (else nothing below is read)
  std::int16_t ram = 0;             ///< counts in RAM: what the board adds now
  std::optional<std::int16_t> rom;  ///< counts in ROM's servo image: what power-on loads
  /** The RAM trim in degrees, in the joint's direction. */
  double degrees() const { return trim_degrees(*j, ram); }
  /** The ROM trim in degrees, if read. */
  std::optional<double> rom_degrees() const {
    return rom ? std::optional<double>(trim_degrees(*j, *rom)) : std::nullopt;
  }
};

/** The trims of @p joints (empty: every joint of @p robot), in the model's order; RAM and ROM. */
std::vector<trim_entry> read_trims(link& l, const model& robot, const std::vector<const joint*>& joints);

/** What set_trims wrote. */
struct trims_report {
  std::vector<joint_trim> written;  ///< each trim, in counts
  bool persistent = false;          ///< also in ROM
};

/**
 * Writes trims (joint name → degrees, within ±30) to RAM, and with @p persistent to ROM's servo
 * image, then reads them back. Refused before anything is written for an unknown joint, one named
 * twice, a trim out of range (usage) or a joint the board has no servo block for (board); a line
 * that fails part way is refused naming the trims already written.
 */
trims_report set_trims(link& l, const model& robot, const std::vector<std::pair<std::string, double>>& trims,
                       bool persistent);

/** What set_ics_trims wrote. */
struct ics_trims_report {
  std::vector<std::pair<unsigned, std::int16_t>> written;  ///< ICS number, counts: RAM (and ROM), read back
  std::vector<std::pair<unsigned, std::int16_t>> skipped;  ///< servos the board has no block for
  bool persistent = false;                                 ///< also in ROM
};

/**
 * Writes trims by ICS number in counts (an HTH4 trim file's entries, hth4-files.md §6) to the
 * blocks the board's allocation table names: RAM, and with @p persistent ROM's servo image (for
 * blocks in the user area); each read back. An ICS number the board does not allocate is
 * skipped and listed, nothing written for it. Refused (usage) for an ICS number given twice or
 * beyond 35; a line that fails part way names what was written.
 */
ics_trims_report set_ics_trims(link& l, const std::vector<std::pair<unsigned, std::int16_t>>& trims, bool persistent);

}  // namespace rcb4::robot::services
