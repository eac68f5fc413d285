// rcb4 command-line tool: motion check FILE|N: does the motion stand? Each pose's centre of mass
// against the soles on the floor (rcb4/robot/motion_balance.hpp), from a motion file or a slot of
// the board (pulled as `motion pull` reads it). No physics: each pose held still.
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/robot/motion_balance.hpp>
#include <rcb4/robot/services/motion_slots.hpp>

#include <fmt/format.h>

#include <charconv>
#include <cmath>

namespace cli {
namespace {

namespace ro = rcb4::robot;
namespace sv = rcb4::robot::services;

/** Exit code of a check that found a pose off its feet. */
constexpr int exit_falls = 5;

struct check_options {
  motion_options m;
  std::string what;  ///< a motion file, or a slot number
};

/** The slot number @p s names, if it is one (1..120). */
std::optional<unsigned> slot_of(const std::string& s) {
  unsigned n = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), n);
  if (ec != std::errc{} || end != s.data() + s.size() || n < 1 || n > 120) return std::nullopt;
  return n;
}

std::string feet_text(const ro::balance& b) {
  if (b.touching.empty()) return "-";
  std::string out;
  for (const auto& t : b.touching) out += (out.empty() ? "" : "+") + t;
  return out;
}

/** Which way the torso leans: "upright", "12.0° forward", "5.0° back, 3.0° left". */
std::string lean_text(const ro::balance& b) {
  std::string out;
  if (std::abs(b.lean_forward) >= 0.05)
    out = fmt::format("{:.1f}° {}", std::abs(b.lean_forward), b.lean_forward > 0 ? "forward" : "back");
  if (std::abs(b.lean_left) >= 0.05)
    out +=
        fmt::format("{}{:.1f}° {}", out.empty() ? "" : ", ", std::abs(b.lean_left), b.lean_left > 0 ? "left" : "right");
  return out.empty() ? "upright" : out;
}

int report(const ro::motion_balance& r, const std::string& what, const ro::model& robot, const globals& g) {
  const auto* worst = r.worst();
  if (g.json) {
    json poses = json::array();
    for (const auto& p : r.poses)
      poses.push_back(
          {{"step", p.step + 1},
           {"name", p.name.empty() ? json(nullptr) : json(p.name)},
           {"margin_mm", std::round(p.at.margin * 10) / 10},
           {"stable", p.at.stable()},
           {"tilt_deg", std::round(p.at.tilt * 10) / 10},
           {"lean_forward_deg", std::round(p.at.lean_forward * 10) / 10},
           {"lean_left_deg", std::round(p.at.lean_left * 10) / 10},
           {"com_mm",
            {std::round(p.at.com[0] * 10) / 10, std::round(p.at.com[1] * 10) / 10, std::round(p.at.com[2] * 10) / 10}},
           {"touching", p.at.touching}});
    emit(json{{"motion", what},
              {"robot", robot.name()},
              {"mass_g", std::round(r.mass)},
              {"physics", false},
              {"stands", r.stands()},
              {"worst_step", worst ? json(worst->step + 1) : json(nullptr)},
              {"worst_margin_mm", worst ? json(std::round(worst->at.margin * 10) / 10) : json(nullptr)},
              {"assumed_at_zero", r.assumed},
              {"poses", poses}});
  } else {
    fmt::print("{} on {} ({:.0f} g): {} pose{}, each held still (no physics)\n", what, robot.name(), r.mass,
               r.poses.size(), r.poses.size() == 1 ? "" : "s");
    if (!r.assumed.empty())
      fmt::print("note: the first pose leaves {} joint{} unnamed: taken at 0 (home)\n", r.assumed.size(),
                 r.assumed.size() == 1 ? "" : "s");
    fmt::print("{:>5}  {:<16} {:>10}  {:<16}  {}\n", "step", "name", "margin", "torso leans", "on the floor");
    for (const auto& p : r.poses)
      fmt::print("{:>5}  {:<16} {:>+7.1f} mm  {:<16}  {}{}\n", p.step + 1, p.name.empty() ? "-" : p.name.substr(0, 16),
                 p.at.margin, lean_text(p.at), feet_text(p.at), p.at.stable() ? "" : "   OUTSIDE its feet: falls");
    if (!worst)
      fmt::print("no pose to check: the motion has none\n");
    else if (r.stands())
      fmt::print("stands: every pose's centre of mass lies over its feet (smallest margin {:.1f} mm, step {})\n",
                 worst->at.margin, worst->step + 1);
    else {
      std::size_t falls = 0;
      for (const auto& p : r.poses) falls += p.at.stable() ? 0U : 1U;
      fmt::print("falls: {} of {} poses off their feet; the worst, step {}'s centre of mass, {:.1f} mm outside\n",
                 falls, r.poses.size(), worst->step + 1, -worst->at.margin);
    }
  }
  return r.stands() ? exit_ok : exit_falls;
}

}  // namespace

void add_motion_check_command(CLI::App* motion, context& ctx) {
  auto o = std::make_shared<check_options>();
  auto* cmd = motion->add_subcommand(
      "check",
      "does it stand? each pose of a motion file (or of slot N on the board) held still: its centre of mass "
      "against the soles on the floor, the margin in mm (exit 5 when a pose's lies outside)");
  cmd->add_option("FILE|N", o->what, "a motion file (.yaml), or the number of a motion on the board")->required();
  add_layout(cmd, o->m);
  cmd->callback([&ctx, o] {
    const auto n = slot_of(o->what);
    if (!n && !o->what.empty() && o->what.find_first_not_of("0123456789") == std::string::npos)
      throw usage_error(fmt::format("N: {} is not a motion's number (1..120)", o->what));
    const auto& robot = robot_of(ctx.g);
    if (!robot.dynamics())
      throw usage_error(
          fmt::format("the profile of {} has no mass model (dynamics:): nothing to check balance with "
                      "(docs/robot-profiles.md shows how to add one)",
                      robot.name()));
    if (!n) {
      ctx.action = [&ctx, o] {
        const auto& r = robot_of(ctx.g);
        ro::motion_document d;
        try {
          d = ro::load_motion(o->what, r);
        } catch (const ro::profile_error& e) {
          throw usage_error(e.what());
        }
        return report(ro::check_balance(d, r), o->what, r, ctx.g);
      };
      return;
    }
    ctx.action = [&ctx, o, n] {
      session s(ctx.g);
      const auto& r = robot_of(ctx.g);
      session_link link(s, ctx.g.json);
      const auto pulled = sv::pull_motion(link, r, layout_for(s, o->m), *n);
      return report(ro::check_balance(pulled.document, r), fmt::format("motion {}", *n), r, ctx.g);
    };
  });
}

}  // namespace cli
