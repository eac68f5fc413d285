// rcb4 — a robot profile's body written as URDF, for rviz, MoveIt and robot_state_publisher: the
// profile's joint names and limits, the kinematics' origins and axes, its boxes and cylinders as
// the links' visual and collision geometry (metres and radians, as URDF wants them).
// SPDX-License-Identifier: BSL-1.0
//
//   std::cout << rcb4::robot::to_urdf(rcb4::robot::open_profile("khr-3hv"));
#pragma once

#include <rcb4/robot/model.hpp>

#include <string>

namespace rcb4::robot {

/** What URDF needs that a profile does not say. */
struct urdf_options {
  std::string prefix;     ///< put before every link and joint name (a ROS node's ~joint_prefix)
  double effort = 2.5;    ///< N·m each joint's limit states (a KRS-2500-class servo's stall torque, nominal)
  double velocity = 5.8;  ///< rad/s each joint's limit states (0.18 s per 60°, nominal)
};

/** @p m's body as URDF text; a profile_error when the profile has no kinematics. */
std::string to_urdf(const model& m, const urdf_options& o = {});

}  // namespace rcb4::robot
