// rcb4 — robot services: the one rule for a move while the board's ROM program plays a motion.
// A motion that runs writes the servo outputs every output period (protocol.md §8.2), so a move
// sent from the host now would be overwritten at once, the robot jerking between the two. Only a
// motion counts: the program counter in a motion slot with a CALL pending and the ROM program on
// (a host move's own interpolation sets the update flags too; a stopped motion leaves its program
// counter behind). The tool, rcb4 ui, pyrcb4 and the ROS node all refuse with these words.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/ops/motion.hpp>
#include <rcb4/robot/services/link.hpp>

#include <optional>
#include <string>

namespace rcb4::robot::services {

/** Why a move must not be sent in @p state, or nothing when it may. */
inline std::optional<std::string> move_refusal(const ops::motion_state& state) {
  if (!(state.running && state.motion)) return std::nullopt;
  return "motion " + std::to_string(*state.motion) +
         " is running on the board: it would overwrite the move, so nothing was sent";
}

/** Reads the board's state and refuses a move (refusal_kind::board) while a motion runs; returns the state read. */
inline ops::motion_state require_no_motion(link& l, const rom_layout& layout = hth4_2_2) {
  const auto st = run(l, ops::read_motion_state(layout));
  if (auto why = move_refusal(st)) throw refused(refusal_kind::board, std::move(*why));
  return st;
}

}  // namespace rcb4::robot::services
