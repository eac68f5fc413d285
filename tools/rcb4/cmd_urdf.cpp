// rcb4 command-line tool: urdf: the robot (--robot) as URDF on standard output, for rviz, MoveIt and
// robot_state_publisher (rcb4/robot/urdf.hpp): the profile's joints, limits and kinematics.
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/robot/urdf.hpp>

namespace cli {

void add_urdf_command(CLI::App& app, context& ctx) {
  auto* cmd = app.add_subcommand(
      "urdf", "the robot (--robot) as URDF on standard output: joints, limits, axes, simple shapes (rviz, MoveIt)");
  auto prefix = std::make_shared<std::string>();
  cmd->add_option("--prefix", *prefix, "put before every link and joint name (a ROS node's ~joint_prefix)");
  on_run(cmd, ctx, [&ctx, prefix] {
    const auto& m = robot_of(ctx.g);
    rcb4::robot::urdf_options o;
    o.prefix = *prefix;
    std::string text;
    try {
      text = rcb4::robot::to_urdf(m, o);
    } catch (const rcb4::robot::profile_error& e) {
      throw failure(exit_usage, e.what(),
                    "a profile's kinematics: section describes its body (docs/robot-profiles.md)");
    }
    if (ctx.g.json) {  // one JSON object as every command's --json: the URDF text in it, not XML bare
      emit(json{{"robot", m.name()}, {"prefix", *prefix}, {"urdf", text}});
      return exit_ok;
    }
    fmt::print("{}", text);
    return exit_ok;
  });
}

}  // namespace cli
