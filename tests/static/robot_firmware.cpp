// The robot model and its operations build for a Cortex-M4 (arm-none-eabi, -fno-exceptions
// -fno-rtti), as the codec does: a model made, a move checked and its first command produced.
// Compiled by cmake/cross_compile.cmake.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/ops/survey.hpp>
#include <rcb4/robot/ops.hpp>

int robot_probe(double degrees) {
  rcb4::robot::joint knee;
  knee.name = "left_knee";
  knee.ics = rcb4::ics_number{16};
  auto m = rcb4::robot::model::make("probe", {knee});
  if (!rcb4::robot::ok(m)) return -1;
  const auto& model = std::get<rcb4::robot::model>(m);
  const rcb4::robot::joint_target t[] = {{"left_knee", degrees, {}}};
  auto moves = rcb4::robot::check_targets(model, t, std::chrono::milliseconds(300));
  if (!rcb4::robot::ok(moves)) return -1;
  rcb4::robot::move_joints op(std::get<std::vector<rcb4::robot::joint_move>>(moves));
  rcb4::ops::list_motions motions;
  if (!op.next() || !motions.next()) return -1;
  return std::get<std::vector<rcb4::robot::joint_move>>(moves).front().position.value();
}
