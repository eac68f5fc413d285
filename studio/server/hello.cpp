// rcb4 ui: the hello every page gets first (see board_loop.hpp): the robot, its joints with their
// limits and mirror images, groups, body, and the link.
// SPDX-License-Identifier: BSL-1.0
#include "board_loop.hpp"
#include "studio_ops.hpp"

#include <rcb4/robot/mirror.hpp>

#include <cmath>

namespace cli::ui {
namespace robot = rcb4::robot;

std::string hello_text(const robot::model& m, const session& s, const loop_options& o, const settings& limits) {
  json j;
  j["type"] = "hello";
  j["robot"] = m.name();
  // Each joint's mirror image (robot/mirror.hpp), from the body: the page mirrors a pose and
  // copies a limb with it; null where the body gives none (nothing is guessed from names).
  std::vector<std::string> names;
  for (const auto& jt : m.joints()) names.push_back(jt.name);
  const auto images =
      m.body() ? robot::mirror_images(*m.body(), names) : std::vector<std::optional<robot::mirror_image>>(names.size());
  json joints = json::array();
  for (std::size_t n = 0; n < names.size(); ++n) {
    const auto& jt = m.joints()[n];
    json mirror = nullptr;
    if (const auto& i = images[n])
      mirror = {{"joint", names[i->joint]},
                {"sign", i->sign},
                {"side", i->left    ? "left"
                         : i->right ? "right"
                                    : "middle"}};
    joints.push_back({{"name", jt.name},
                      {"ics", jt.ics.value()},
                      {"lower", jt.lower},
                      {"upper", jt.upper},
                      {"mirror", std::move(mirror)}});
  }
  j["joints"] = std::move(joints);
  json groups = json::array();
  for (const auto& g : m.groups()) groups.push_back({{"name", g.name}, {"joints", g.joints}});
  j["groups"] = std::move(groups);
  json link;
  link["device"] = s.where();
  link["baud"] = s.rate_known() ? json(s.baud()) : json(nullptr);
  link["virtual"] = s.is_virtual();
  j["link"] = std::move(link);
  j["max_speed"] = limits.max_speed;
  j["max_move_ms"] = max_move_ms;
  j["period_ms"] = o.period.count();
  j["version"] = RCB4_VERSION;
  j["body"] = body_json(m);
  return text_of(j);
}

}  // namespace cli::ui
