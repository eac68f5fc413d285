// The robot model builds for a Cortex-M4 (arm-none-eabi, -fno-exceptions -fno-rtti), as the codec
// does: a model made, a joint angle turned into a position. Compiled by cmake/cross_compile.cmake.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/model.hpp>

int robot_probe(double degrees) {
  rcb4::robot::joint knee;
  knee.name = "left_knee";
  knee.ics = rcb4::ics_number{16};
  auto m = rcb4::robot::model::make("probe", {knee});
  if (!rcb4::robot::ok(m)) return -1;
  const auto p = rcb4::robot::to_position(std::get<rcb4::robot::model>(m).joints().front(), degrees);
  return rcb4::robot::ok(p) ? std::get<rcb4::servo_position>(p).value() : -1;
}
