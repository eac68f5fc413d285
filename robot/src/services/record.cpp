// rcb4 — robot services: teach by demonstration (see rcb4/robot/services/record.hpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/ops/servos.hpp>
#include <rcb4/ops/system.hpp>
#include <rcb4/robot/services/moves.hpp>
#include <rcb4/robot/services/record.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace rcb4::robot::services {
namespace {

/** The joints, located; refused naming those without a block. */
joint_map located(link& l, const model& robot, const std::vector<const joint*>& joints) {
  auto map = run(l, locate_joints(robot));
  std::vector<std::string> missing;
  for (const auto* j : joints)
    if (!map.block_of(*j)) missing.push_back(fmt::format("{} (ICS {})", j->name, j->ics.value()));
  if (!missing.empty())
    throw refused(refusal_kind::board,
                  fmt::format("the board has no servo allocated for {}: nothing recorded", fmt::join(missing, ", ")),
                  fmt::format("is this a {}? rcb4 scan shows the board's slots", robot.name()));
  return map;
}

output_period period_of(link& l) { return run(l, rcb4::ops::read_config{}).period; }

}  // namespace

recording::recording(link& l, const model& robot, std::vector<const joint*> joints, const record_options& options)
    : l_(l),
      robot_(robot),
      joints_(joints.empty() ? [&] {
        std::vector<const joint*> all;
        for (const auto& j : robot.joints()) all.push_back(&j);
        return all;
      }()
                             : std::move(joints)),
      o_(options),
      map_(located(l, robot, joints_)),
      period_(period_of(l)),
      rec_(joints_, options.threshold, period_, options.lead_in) {
  if (const auto st = run(l, rcb4::ops::read_motion_state{}); st.running && st.motion)
    throw refused(
        refusal_kind::board,
        fmt::format("motion {} is running: the robot is not yours to move, so nothing was recorded", *st.motion),
        "rcb4 motion wait, or rcb4 motion stop");
  // Every joint must answer before anything is freed: a silent servo would record as nothing.
  read_angles();
  for (const auto* j : joints_) mask_.insert(j->ics);
  if (o_.free) {
    run(l, rcb4::ops::set_servo_power(rcb4::ops::power_state::free, mask_));
    freed_ = true;
  }
}

recording::~recording() {
  if (!freed_) return;
  try {
    run(l_, rcb4::ops::set_servo_power(rcb4::ops::power_state::hold, mask_));
  } catch (...) {  // the failure that brought us here is the one to report
  }
}

std::vector<double> recording::read_angles() {
  const auto rs = run(l_, read_joints(map_, fields::positions, o_.cost));
  std::vector<double> out;
  for (const auto* j : joints_)
    for (const auto& r : rs)
      if (r.j == j) {
        const auto d = r.degrees();
        if (!d)
          throw refused(refusal_kind::board,
                        fmt::format("{} reads position {}: its servo does not answer", j->name, r.position),
                        "rcb4 scan shows which servos answer; --joints leaves it out");
        out.push_back(*d);
      }
  return out;
}

void recording::sample(std::chrono::milliseconds t) {
  const auto a = read_angles();
  rec_.sample(t, a);
  last_ = std::max(last_, t);
}

record_report recording::finish(bool board_lost) {
  rec_.finish();
  record_report r;
  if (freed_ && !board_lost) {
    run(l_, rcb4::ops::set_servo_power(rcb4::ops::power_state::hold, mask_));
    r.held = true;
  }
  freed_ = false;  // a lost board: nothing more is tried
  r.samples = rec_.samples();
  r.clamped = rec_.clamped();
  r.span = last_;
  r.document.robot = robot_.name();
  r.document.period = period_;
  for (const auto& p : rec_.poses()) {
    motion_pose mp;
    for (std::size_t i = 0; i < joints_.size(); ++i)
      mp.targets.push_back({joints_[i]->name, p.degrees[i], std::nullopt});
    mp.time = p.time;
    r.document.steps.emplace_back(std::move(mp));
  }
  r.document.steps.emplace_back(rcb4::motion::end{});
  return r;
}

}  // namespace rcb4::robot::services
