// rcb4 — each pose of a motion file checked for static balance (rcb4/robot/motion_balance.hpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/motion_balance.hpp>

#include <algorithm>
#include <map>
#include <variant>

namespace rcb4::robot {

motion_balance check_balance(const motion_document& d, const model& m) {
  if (!m.body()) throw profile_error(m.name(), "the profile has no body (kinematics:), so no balance to check");
  if (!m.dynamics())
    throw profile_error(m.name(),
                        "the profile has no mass model (dynamics:), so no balance to check: "
                        "docs/robot-profiles.md shows how to add one");
  motion_balance out;
  out.mass = m.dynamics()->total_mass();
  std::map<std::string, double> angles;  // every profile joint, as the poses so far left it
  std::vector<std::string> named;
  for (std::size_t i = 0; i < d.steps.size(); ++i) {
    const auto* pose = std::get_if<motion_pose>(&d.steps[i]);
    if (!pose) continue;
    for (const auto& t : pose->targets)
      if (t.degrees && m.find(t.key)) {
        angles[t.key] = *t.degrees;
        if (std::find(named.begin(), named.end(), t.key) == named.end()) named.push_back(t.key);
      }
    if (out.poses.empty())
      for (const auto& j : m.joints())
        if (std::find(named.begin(), named.end(), j.name) == named.end()) out.assumed.push_back(j.name);
    pose_balance p;
    p.step = i;
    if (i < d.views.size()) p.name = d.views[i].name;
    if (i < d.where.size()) p.where = d.where[i];
    p.at = *balance_of(m, angles);
    out.poses.push_back(std::move(p));
  }
  return out;
}

}  // namespace rcb4::robot
