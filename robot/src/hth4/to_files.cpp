// rcb4 — an HTH4 project as rcb4's own files (see rcb4/robot/hth4/to_files.hpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/motion/buttons.hpp>
#include <rcb4/motion/disassemble.hpp>
#include <rcb4/robot/hth4/to_files.hpp>
#include <rcb4/robot/hth4/trim_file.hpp>
#include <rcb4/robot/motion_file.hpp>

#include <fmt/format.h>

#include <fstream>
#include <iterator>

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
      "# (each slot's old bytes backed up beside this script as motion-N-DATE.bin), buttons (the board's\n"
      "# others cleared, as a project holds the whole table) and trims. Not the start-up motion, the AD\n"
      "# references, HTH4's trailing 03 0D 10 FF or the allocation: `rcb4 project export P.h4p --from\n"
      "# DIR` then `rcb4 project import P.h4p` writes all of that. rcb4 project import --to wrote this;\n"
      "# the board: RCB4_DEVICE, or --device in RCB4 (RCB4=\"rcb4 --device /dev/ttyUSB0\" sh push.sh).\n"
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
      sh += fmt::format("$RCB4 --robot profile.yaml motion push {} {}\n", it.file, it.n);
      pushed.insert(it.n);
    }
  sh += "$RCB4 motion buttons reset\n";
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
  std::string buttons = "# which KRR buttons play which motion (rcb4 project export --from reads it)\n";
  for (const auto& mo : p.motions)
    if (!mo.frames.empty() && mo.buttons != 0 && mo.compare == compare_type::equals)
      buttons += fmt::format("{}: {}\n", motion::buttons_text(mo.buttons), mo.number + 1);
  out.files.push_back({"buttons.yaml", buttons, {}});
  out.files.push_back({"trims.h4t", trim_file_xml(trims_of(p)), {}});
  out.files.push_back({"push.sh", sh, {}});
  return out;
}

project load_project_dir(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  const auto m = load_profile(dir / "profile.yaml");
  project p = empty_project(hth4_2_2);
  p.name = m.name();
  for (const auto& j : m.joints()) {
    const auto k = j.ics.value();
    if (k >= servo_count) continue;
    p.servos[k].name = j.name;
    p.servos[k].mode = servo_mode::normal;
  }
  std::optional<output_period> period;
  std::error_code ec;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir, ec)) files.push_back(e.path());
  if (ec) throw profile_error(dir.string(), "cannot read: " + ec.message());
  std::sort(files.begin(), files.end());
  static constexpr std::uint8_t tail[] = {0x03, 0x0D, 0x10, 0xFF};
  const std::vector<std::uint8_t> ret = {0x03, 0x0D, 0x10};
  for (const auto& f : files) {
    const auto stem = f.stem().string();
    if (stem.size() < 5 || !std::isdigit(static_cast<unsigned char>(stem[0])) ||
        !std::isdigit(static_cast<unsigned char>(stem[1])) || !std::isdigit(static_cast<unsigned char>(stem[2])) ||
        stem[3] != '-' || (f.extension() != ".yaml" && f.extension() != ".bin"))
      continue;
    const auto n = static_cast<unsigned>(std::stoul(stem.substr(0, 3)));
    if (n < 1 || n > motion_count) throw profile_error(f.string(), "names slot " + std::to_string(n) + " (1..120)");
    auto& mo = p.motions[n - 1];
    if (!mo.frames.empty()) throw profile_error(f.string(), "a second file for slot " + std::to_string(n));
    const auto where = motion::slot_of(hth4_2_2, n).value();
    std::vector<std::uint8_t> code;
    if (f.extension() == ".yaml") {
      const auto d = load_motion(f, m);
      if (period && *period != d.period)
        throw profile_error(f.string(), "is made for another output period than the other motion files");
      period = d.period;
      const auto c = to_program(d, m, hth4_2_2, d.period);
      if (!ok(c)) throw profile_error(f.string(), std::get<problem>(c).message);
      const auto b = motion::assemble(std::get<compiled_motion>(c).program, where);
      if (!motion::ok(b)) throw profile_error(f.string(), std::get<motion::failure>(b).message);
      code = std::get<std::vector<std::uint8_t>>(b);
      mo.name = d.name.empty() ? stem.substr(4) : d.name;
    } else {
      std::ifstream in(f, std::ios::binary);
      code.assign(std::istreambuf_iterator<char>(in), {});
      if (code.size() > where.size) throw profile_error(f.string(), "is longer than a slot");
      mo.name = stem.substr(4);
    }
    // The frames in a row, then HTH4's tail after them (hth4-files.md §5.6 step 3); a .bin that
    // ends in a RETURN and one FF already has it (§2.2).
    bool return_ff = false;
    for (std::size_t at = 0; at < code.size();) {
      const std::size_t size = code[at];
      if (size < min_frame_size || at + size > code.size()) {
        const auto rest = code.size() - at;
        if (rest == 4 && std::equal(code.begin() + static_cast<std::ptrdiff_t>(at), code.end(), tail)) break;
        if (rest == 1 && code[at] == 0xFF && !mo.frames.empty() && mo.frames.back() == ret) {
          return_ff = true;
          break;
        }
        throw profile_error(f.string(), "byte " + std::to_string(at) + " does not start a frame");
      }
      mo.frames.emplace_back(code.begin() + static_cast<std::ptrdiff_t>(at),
                             code.begin() + static_cast<std::ptrdiff_t>(at + size));
      at += size;
    }
    if (return_ff) mo.frames.pop_back();
    mo.frames.emplace_back(std::begin(tail), std::end(tail));
  }
  auto config = config_word::decode(0x801B);  // ICS, program and vector switch on (hth4-files.md §2.1's GSU word)
  if (period) config.period = *period;
  p.config = config.encode();
  if (const auto file = dir / "buttons.yaml"; fs::exists(file)) {
    std::ifstream in(file);
    std::string line;
    for (unsigned no = 1; std::getline(in, line); ++no) {
      if (line.empty() || line[0] == '#') continue;
      const auto where = file.string() + ":" + std::to_string(no);
      const auto colon = line.find(':');
      if (colon == std::string::npos) throw profile_error(where, "a line is BUTTONS: N");
      const auto word = motion::parse_buttons(line.substr(0, colon));
      if (!motion::ok(word)) throw profile_error(where, std::get<motion::failure>(word).message);
      unsigned n = 0;
      try {
        n = static_cast<unsigned>(std::stoul(line.substr(colon + 1)));
      } catch (const std::exception&) {
      }
      if (n < 1 || n > motion_count || p.motions[n - 1].frames.empty())
        throw profile_error(where, "names no motion of this directory");
      p.motions[n - 1].buttons = std::get<std::uint16_t>(word);
    }
  }
  if (fs::exists(dir / "trims.h4t"))
    for (const auto& t : load_trim_file(dir / "trims.h4t"))
      if (t.device_number < servo_count) p.servos[t.device_number].trim = t.trim;
  check_project(p, dir.string());
  return p;
}

}  // namespace rcb4::robot::hth4
