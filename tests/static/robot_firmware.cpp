// The robot model and its operations build for a Cortex-M4 (arm-none-eabi, -fno-exceptions
// -fno-rtti), as the codec does: a model made, a move checked and its first command produced.
// Compiled by cmake/cross_compile.cmake. So are the motion assembler and disassembler (below).
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

// The motion assembler and disassembler build there too (issue 23: "building where the codec builds").
#include <rcb4/motion/disassemble.hpp>

unsigned motion_probe(std::uint8_t count) {
  rcb4::servo_set<rcb4::servo_position> s;
  s.insert(rcb4::ics_number{0}, rcb4::servo_position{8000});
  const rcb4::motion::program p{{rcb4::motion::set_counter{rcb4::motion::hth4_counter, count}, rcb4::motion::label{"a"},
                                 rcb4::motion::pose{s, rcb4::frames{5}},
                                 rcb4::motion::count_down{rcb4::motion::hth4_counter, "a"}, rcb4::motion::end{}}};
  const auto where = rcb4::motion::slot_of(rcb4::hth4_2_2, 3);
  if (!where) return 0;
  const auto bytes = rcb4::motion::assemble(p, *where);
  if (!rcb4::motion::ok(bytes)) return 0;
  const auto& b = std::get<std::vector<std::uint8_t>>(bytes);
  return static_cast<unsigned>(rcb4::motion::disassemble(b, *where).code.size());
}
