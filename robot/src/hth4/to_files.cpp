// rcb4 — an HTH4 project as rcb4's own files (see rcb4/robot/hth4/to_files.hpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/motion/buttons.hpp>
#include <rcb4/motion/disassemble.hpp>
#include <rcb4/robot/hth4/to_files.hpp>
#include <rcb4/robot/hth4/trim_file.hpp>
#include <rcb4/robot/motion_file.hpp>

#include <fmt/format.h>

#include <map>
#include <set>

namespace rcb4::robot::hth4 {

std::string identifier(std::string_view name) {
  std::string out;
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (std::isalnum(u) && u < 0x80)
      out += static_cast<char>(std::tolower(u));
    else if (!out.empty() && out.back() != '_')
      out += '_';
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  if (!out.empty() && std::isdigit(static_cast<unsigned char>(out[0]))) out = "j_" + out;
  return out;
}

project_files project_as_files(const project& p, const std::string& robot) {
  project_files out;
  const std::string name = !robot.empty() ? robot : !p.name.empty() ? p.name : "HTH4 project";
  // The profile: one joint per allocated servo.
  std::string prof = fmt::format(
      "# {}: made by rcb4 from the HeartToHeart4 project '{}' (its servo table). Limits are a servo's\n"
      "# travel (±135°) and directions +1: set them for your robot (docs/robot-profiles.md).\n"
      "robot: \"{}\"\n\njoints:\n",
      name, p.file_name.empty() ? p.name : p.file_name, name);
  std::set<std::string> used;
  unsigned joints = 0;
  for (const auto& s : p.servos) {
    if (s.mode != servo_mode::normal) continue;
    auto j = identifier(s.name);
    if (j.empty()) j = "ics_" + std::to_string(s.device_number);
    if (!used.insert(j).second) {
      j += "_" + std::to_string(s.device_number);
      used.insert(j);
    }
    prof += fmt::format("  {}: {{ics: {}, lower: -135, upper: 135}}  # HTH4: \"{}\", ID {} on {}\n", j, s.device_number,
                        s.name, s.id, s.port == servo_port::sio2 ? "SIO2" : "SIO1");
    ++joints;
  }
  if (!joints)
    throw profile_error("the project", "allocates no servo (every Mode is None): there is no robot to describe");
  out.files.push_back({"profile.yaml", prof, {}});
  const auto m = parse_profile(prof, "profile.yaml");
  // The motions, in the 2.2 layout.
  const auto& layout = hth4_2_2;
  const auto from = p.layout().motion_base.value();
  const auto period = config_word::decode(p.config).period;
  struct item {
    unsigned n;
    std::string file;
    std::vector<std::uint32_t> calls;
  };
  std::vector<item> items;
  for (const auto& mo : p.motions) {
    if (mo.frames.empty()) continue;
    const unsigned n = mo.number + 1;
    const auto where = motion::slot_of(layout, n).value();
    std::vector<std::uint8_t> code;
    for (const auto& f :
         from == layout.motion_base.value() ? mo.frames : relocate(mo.frames, from, layout.motion_base.value()))
      code.insert(code.end(), f.begin(), f.end());
    const auto listing = motion::disassemble(code, where);
    const auto stem = fmt::format("{:03d}-{}", n, identifier(mo.name).empty() ? "motion" : identifier(mo.name));
    const auto prog = motion::lift(listing);
    std::string file;
    if (motion::ok(prog)) {
      auto d = from_program(std::get<motion::program>(prog), m, layout, period);
      d.name = mo.name;
      file = stem + ".yaml";
      out.files.push_back({file,
                           motion_yaml(d, fmt::format("motion {} of the HTH4 project '{}' (slot 0x{:06X})", n, p.name,
                                                      where.address.value())),
                           {}});
    } else {
      file = stem + ".bin";
      out.files.push_back({file, {}, code});
      out.notes.push_back(fmt::format("motion {} '{}' is kept as its code ({}): {}", n, mo.name, file,
                                      std::get<motion::failure>(prog).message));
    }
    items.push_back({n, file, listing.calls});
  }
  // push.sh: callees before callers (a push refuses a call of an empty slot).
  std::string sh = fmt::format(
      "#!/bin/sh\n# Puts the HTH4 project '{}' on a board of the HTH4 2.2+ layout with the rcb4 tool: its motions\n"
      "# (each slot's old bytes backed up beside this script), buttons and trims. rcb4 project import\n"
      "# --to wrote it; the board: RCB4_DEVICE, or --device in RCB4 (RCB4=\"rcb4 --device /dev/ttyUSB0\" sh push.sh).\n"
      "set -e\ncd \"$(dirname \"$0\")\"\nRCB4=${{RCB4:-rcb4}}\n"
      "# The project's output period, which its motions' frames were made for (RAM and power-on).\n"
      "$RCB4 config set period={} --persist\n",
      p.name, milliseconds(period));
  std::set<unsigned> pushed;
  const auto slot_of_address = [&](std::uint32_t a) -> unsigned {
    return (a - layout.motion_base.value()) / layout.slot_size + 1;
  };
  for (std::size_t round = 0; pushed.size() < items.size() && round <= items.size(); ++round)
    for (const auto& it : items) {
      if (pushed.count(it.n)) continue;
      const bool ready = std::all_of(it.calls.begin(), it.calls.end(), [&](std::uint32_t a) {
        const auto c = slot_of_address(a);
        return c == it.n || pushed.count(c);
      });
      if (!ready && round < items.size()) continue;
      sh +=
          fmt::format("$RCB4 --robot profile.yaml motion push {} {} --backup {:03d}-before.bin\n", it.file, it.n, it.n);
      pushed.insert(it.n);
    }
  for (const auto& mo : p.motions) {
    if (mo.frames.empty() || mo.buttons == 0) continue;
    if (mo.compare != compare_type::equals) {
      out.notes.push_back(fmt::format("motion {}'s button {} compares with {}: not in push.sh (hth4-files.md §9)",
                                      mo.number + 1, motion::buttons_text(mo.buttons), compare_name(mo.compare)));
      continue;
    }
    sh += fmt::format("$RCB4 motion buttons set {} {}\n", motion::buttons_text(mo.buttons), mo.number + 1);
  }
  sh += "$RCB4 trim import trims.h4t --persist\n";
  out.files.push_back({"trims.h4t", trim_file_xml(trims_of(p)), {}});
  out.files.push_back({"push.sh", sh, {}});
  return out;
}

}  // namespace rcb4::robot::hth4
