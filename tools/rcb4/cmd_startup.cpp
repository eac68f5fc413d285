// rcb4 command-line tool: motion startup [N|none]: the motion HTH4's boot code plays at power-on
// (the CALL at 0x0444, hth4-files.md §3), shown or set. The work is in the robot services
// (rcb4/robot/services/boot.hpp).
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/robot/services/boot.hpp>
#include <rcb4/robot/services/slot_names.hpp>

namespace cli {
namespace {

namespace sv = rcb4::robot::services;

int startup(session& s, const motion_options& m, const std::string& which, const globals& g) {
  std::optional<unsigned> n;
  const bool set = !which.empty();
  if (set && which != "none") n = static_cast<unsigned>(parse_int(which, "N", 1, 120));
  const auto& layout = layout_for(s, m);
  session_link link(s, g.json);
  const auto r = set ? sv::set_startup(link, layout, n) : sv::read_startup(link, layout);
  // the profile's name only: a name of the names file is shown where the slot's code is read (motion list)
  const auto name = r.motion ? sv::slot_name(robot_of(g), *r.motion, {}) : std::string();
  if (g.json) {
    emit(json{{"call", r.has_call},
              {"target", r.has_call ? json(r.target) : json(nullptr)},
              {"motion", r.motion ? json(*r.motion) : json(nullptr)},
              {"name", name},
              {"default_startup", r.default_startup},
              {"set", set}});
    return exit_ok;
  }
  if (!r.has_call)
    fmt::print("no start-up CALL at 0x{:06X}: the board's boot code is not HTH4 2.x's (it plays no start-up motion)\n",
               layout.startup.value());
  else if (r.motion)
    fmt::print("{}motion {}{} (0x{:06X}) plays at power-on\n", set ? "now " : "", *r.motion,
               name.empty() ? std::string() : fmt::format(" \"{}\"", name), r.target);
  else if (r.default_startup)
    fmt::print("{}no start-up motion (the boot code calls DefaultStartup, a RETURN, at 0x{:06X})\n", set ? "now " : "",
               r.target);
  else
    fmt::print("the boot code calls 0x{:06X}, not the start of a motion slot\n", r.target);
  return exit_ok;
}

}  // namespace

void add_startup_command(CLI::App* motion, context& ctx) {
  struct options {
    motion_options m;
    std::string which;
  };
  auto o = std::make_shared<options>();
  auto* cmd = motion->add_subcommand(
      "startup",
      "the motion the board plays at power-on (HTH4's start-up CALL at 0x000444): shown, or set to N "
      "or none");
  cmd->add_option("N", o->which, "a motion number, or none (no argument: show it)");
  add_layout(cmd, o->m);
  on_device(cmd, ctx, [&ctx, o](session& s) { return startup(s, o->m, o->which, ctx.g); });
}

}  // namespace cli
