// rcb4 — does a motion stand? Each pose of a motion file, in the order the file lists them, with
// the joints the poses before it left where they were, checked for static balance (the centre of
// mass over the soles on the floor, <rcb4/robot/balance.hpp>). Without physics: a pose held
// still. The first pose starts from the home pose (every joint at 0) for the joints it does not
// name, and the report says which.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/robot/balance.hpp>
#include <rcb4/robot/motion_file.hpp>

#include <cstddef>
#include <string>
#include <vector>

namespace rcb4::robot {

/** One pose of a motion and its balance. */
struct pose_balance {
  std::size_t step = 0;  ///< the step's place in the file, 0-based
  std::string name;      ///< the step's name (step_view), or empty
  std::string where;     ///< "FILE:LINE", or empty
  balance at;            ///< its balance, held still
};

/** A motion's poses checked for balance. */
struct motion_balance {
  std::vector<pose_balance> poses;   ///< every pose step, in file order
  std::vector<std::string> assumed;  ///< joints no pose names before the first that is checked: at 0
  double mass = 0;                   ///< the robot's mass, grams
  /** The pose with the smallest margin, or nullptr when there is none. */
  const pose_balance* worst() const noexcept {
    const pose_balance* w = nullptr;
    for (const auto& p : poses)
      if (!w || p.at.margin < w->at.margin) w = &p;
    return w;
  }
  /** True when every pose's centre of mass lies over its soles. */
  bool stands() const noexcept {
    for (const auto& p : poses)
      if (!p.at.stable()) return false;
    return true;
  }
};

/**
 * Checks every pose of @p d on @p m. A profile_error when @p m has no body or no mass model
 * (`kinematics:` and `dynamics:`), naming what to add.
 */
motion_balance check_balance(const motion_document& d, const model& m);

}  // namespace rcb4::robot
