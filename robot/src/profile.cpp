// rcb4 — robot profiles and pose files (yaml-cpp; nlohmann::json writes JSON poses).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/profile.hpp>

#include <yaml-cpp/yaml.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>

#include "builtin_profiles.hpp"  // generated: rcb4::robot::detail::builtin_texts
#include "yaml_helpers.hpp"

namespace rcb4::robot {
namespace {
using namespace detail;

joint parse_joint(const std::string& source, const std::string& name, const YAML::Node& n) {
  if (!n.IsMap()) fail(source, n, name + ": expected a mapping such as {ics: 16, lower: -10, upper: 125}");
  check_keys(source, n, {"ics", "id", "bus", "direction", "offset", "lower", "upper"}, name);
  joint j;
  j.name = name;
  if (n["ics"]) {
    if (n["id"] || n["bus"]) fail(source, n["ics"], name + ": give ics, or id and bus, not both");
    j.ics = ics_number::make(static_cast<unsigned>(integer(source, n["ics"], name + ": ics", 0, 35))).value();
  } else if (n["id"] && n["bus"]) {
    const long id = integer(source, n["id"], name + ": id", 0, 17);
    const long bus = integer(source, n["bus"], name + ": bus (1: SIO1-4, 2: SIO5-8)", 1, 2);
    j.ics = ics_number::make(static_cast<unsigned>(2 * id + bus - 1)).value();
  } else {
    fail(source, n, name + ": needs its slot: ics (0..34), or id (0..17) and bus (1 or 2)");
  }
  if (n["direction"]) j.direction = static_cast<int>(integer(source, n["direction"], name + ": direction", -1, 1));
  if (n["offset"]) j.offset = number(source, n["offset"], name + ": offset");
  if (!n["lower"] || !n["upper"]) fail(source, n, name + ": needs its limits, lower and upper (degrees)");
  j.lower = number(source, n["lower"], name + ": lower");
  j.upper = number(source, n["upper"], name + ": upper");
  return j;
}

}  // namespace

model parse_profile_nodes(std::string_view text, const std::string& source);
pose parse_pose_nodes(std::string_view text, const std::string& source, const model& m);

model parse_profile(std::string_view text, const std::string& source) {
  try {
    return parse_profile_nodes(text, source);
  } catch (const YAML::Exception& e) {
    throw profile_error(where(source, e.mark), e.msg);
  }
}

pose parse_pose(std::string_view text, const std::string& source, const model& m) {
  try {
    return parse_pose_nodes(text, source, m);
  } catch (const YAML::Exception& e) {
    throw profile_error(where(source, e.mark), e.msg);
  }
}

model parse_profile_nodes(std::string_view text, const std::string& source) {
  const YAML::Node root = parse_yaml(text, source);
  if (!root.IsMap()) throw profile_error(source, "a profile is a mapping with robot, joints, groups, motions");
  check_keys(source, root, {"robot", "joints", "groups", "motions", "mimic", "kinematics", "dynamics"}, "profile");
  const std::string name = root["robot"] ? scalar(source, root["robot"], "robot") : std::string("robot");
  const YAML::Node js = root["joints"];
  if (!js || !js.IsMap() || js.size() == 0)
    throw profile_error(where(source, js ? js.Mark() : root.Mark()), "joints: expected a mapping of joint names");

  // Each joint, group and motion is added to a model in turn: model::make's problem then
  // belongs to the entry just added, whose line the message carries.
  std::vector<joint> joints;
  for (const auto& kv : js) {
    const std::string jn = scalar(source, kv.first, "joint name");
    joints.push_back(parse_joint(source, jn, kv.second));
    if (auto m = model::make(name, joints); !ok(m)) fail(source, kv.first, std::get<problem>(m).message);
  }
  std::vector<group> groups;
  if (const YAML::Node gs = root["groups"]) {
    if (!gs.IsMap()) fail(source, gs, "groups: expected a mapping of group names to joint lists");
    for (const auto& kv : gs) {
      group g;
      g.name = scalar(source, kv.first, "group name");
      if (!kv.second.IsSequence()) fail(source, kv.second, g.name + ": expected a list of joint names");
      for (const auto& e : kv.second) g.joints.push_back(scalar(source, e, g.name));
      for (const auto& other : groups)
        if (other.name == g.name) fail(source, kv.first, "group '" + g.name + "' is given twice");
      groups.push_back(g);
      if (auto m = model::make(name, joints, groups); !ok(m)) fail(source, kv.first, std::get<problem>(m).message);
    }
  }
  std::vector<motion_name> motions;
  if (const YAML::Node ms = root["motions"]) {
    if (!ms.IsMap()) fail(source, ms, "motions: expected a mapping of slot numbers (1..120) to names");
    for (const auto& kv : ms) {
      const auto slot = static_cast<unsigned>(integer(source, kv.first, "motion slot", 1, 120));
      for (const auto& other : motions)
        if (other.slot == slot) fail(source, kv.first, "motion slot " + std::to_string(slot) + " is named twice");
      motions.push_back({slot, scalar(source, kv.second, "motion name")});
    }
  }
  std::vector<std::string> names;
  for (const auto& j : joints) names.push_back(j.name);
  auto m = model::make(name, std::move(joints), std::move(groups), std::move(motions));
  if (!ok(m)) throw profile_error(source, std::get<problem>(m).message);
  auto out = std::get<model>(std::move(m));
  // mimic: NAME: {joint: J, multiplier: M, offset: DEG}: joints on another's servo (URDF's mimic).
  if (const YAML::Node ms = root["mimic"]) {
    if (!ms.IsMap()) fail(source, ms, "mimic: expected a mapping of joint names to {joint, multiplier, offset}");
    for (const auto& kv : ms) {
      mimic_joint mj;
      mj.name = scalar(source, kv.first, "mimic joint name");
      const auto& v = kv.second;
      if (!v.IsMap() || !v["joint"]) fail(source, v, mj.name + ": expected {joint, multiplier, offset}");
      check_keys(source, v, {"joint", "multiplier", "offset"}, mj.name);
      mj.joint = scalar(source, v["joint"], mj.name + ": joint");
      if (v["multiplier"]) mj.multiplier = number(source, v["multiplier"], mj.name + ": multiplier");
      if (v["offset"]) mj.offset = number(source, v["offset"], mj.name + ": offset");
      if (const auto p = out.add_mimic(mj)) fail(source, kv.first, p->message);
      names.push_back(mj.name);
    }
  }
  if (const YAML::Node k = root["kinematics"]) {
    if (const auto p = out.attach_body(parse_body(source, k, names)))  // parse_body has checked it: never
      throw profile_error(source, "kinematics: " + p->message);
  }
  if (const YAML::Node d = root["dynamics"]) {
    if (!out.body()) fail(source, d, "dynamics: the mass model needs the body: give kinematics: too");
    if (const auto p = out.attach_dynamics(parse_dynamics(source, d, *out.body())))  // checked: never
      throw profile_error(source, "dynamics: " + *p);
  }
  return out;
}

model load_profile(const std::filesystem::path& path) { return parse_profile(read_file(path), path.string()); }

std::vector<std::string_view> builtin_profiles() {
  std::vector<std::string_view> out;
  for (const auto& b : detail::builtin_texts) out.push_back(b.name);
  return out;
}

std::optional<std::string_view> builtin_profile_text(std::string_view name) {
  for (const auto& b : detail::builtin_texts)
    if (b.name == name) return b.text;
  return std::nullopt;
}

model open_profile(std::string_view what) {
  if (const auto text = builtin_profile_text(what)) return parse_profile(*text, "built-in " + std::string(what));
  std::error_code ec;
  if (!std::filesystem::exists(std::filesystem::path(what), ec)) {
    std::string names;
    for (auto n : builtin_profiles()) names += (names.empty() ? "" : ", ") + std::string(n);
    throw profile_error(std::string(what), "no such file, and not a built-in profile (" + names + ")");
  }
  return load_profile(std::filesystem::path(what));
}

pose parse_pose_nodes(std::string_view text, const std::string& source, const model& m) {
  const YAML::Node root = parse_yaml(text, source);
  if (!root.IsMap()) throw profile_error(source, "a pose is a mapping with robot, joints and optionally time_ms");
  check_keys(source, root, {"robot", "joints", "time_ms"}, "pose");
  pose p;
  p.robot = m.name();  // a pose that names no robot is the profile's (and is written back so)
  if (root["robot"]) {
    p.robot = scalar(source, root["robot"], "robot");
    if (p.robot.empty()) fail(source, root["robot"], "robot: an empty name (name " + m.name() + " or leave it out)");
    // Another robot's pose may name the same joints with other zeros, directions and limits.
    // Names compare without case: "khr-3hv" (the built-in's name) is KHR-3HV.
    const auto same = [](std::string_view a, std::string_view b) {
      return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
               return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
             });
    };
    if (!same(p.robot, m.name()))
      fail(source, root["robot"],
           "this pose is " + p.robot + "'s, not " + m.name() + "'s (--robot names the profile it was captured with)");
  }
  if (root["time_ms"]) p.time = std::chrono::milliseconds(integer(source, root["time_ms"], "time_ms", 0, 6375));
  const YAML::Node js = root["joints"];
  if (!js || !js.IsMap() || js.size() == 0)
    throw profile_error(where(source, js ? js.Mark() : root.Mark()),
                        "joints: expected a mapping of joint names to degrees");
  for (const auto& kv : js) {
    const std::string n = scalar(source, kv.first, "joint name");
    if (!m.find(n)) fail(source, kv.first, "no joint of " + m.name() + " is called '" + n + "'");
    for (const auto& e : p.joints)
      if (e.first == n) fail(source, kv.first, n + " is given twice");
    p.joints.emplace_back(n, number(source, kv.second, n));
  }
  return p;
}

pose load_pose(const std::filesystem::path& path, const model& m) {
  return parse_pose(read_file(path), path.string(), m);
}

namespace {
/** @p d rounded to hundredths of a degree, with no negative zero. */
double hundredths(double d) {
  const double r = std::round(d * 100) / 100;
  return r == 0 ? 0.0 : r;
}
}  // namespace

std::string pose_json(const pose& p) {
  nlohmann::ordered_json j;
  if (!p.robot.empty()) j["robot"] = p.robot;  // a pose built without one names no robot
  if (p.time) j["time_ms"] = p.time->count();
  nlohmann::ordered_json joints = nlohmann::ordered_json::object();
  for (const auto& [n, d] : p.joints) joints[n] = hundredths(d);
  j["joints"] = joints;
  // A robot name read from a file may be any bytes: invalid UTF-8 becomes U+FFFD (found by fuzzing).
  return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

std::string pose_yaml(const pose& p) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  if (!p.robot.empty()) out << YAML::Key << "robot" << YAML::Value << p.robot;
  if (p.time) out << YAML::Key << "time_ms" << YAML::Value << p.time->count();
  out << YAML::Key << "joints" << YAML::Value << YAML::BeginMap;
  // Six significant digits: ±360.00 at most, written as 39.99, not 39.990000000000002.
  out.SetDoublePrecision(6);
  for (const auto& [n, d] : p.joints) out << YAML::Key << n << YAML::Value << hundredths(d);
  out << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

void save_pose(const std::filesystem::path& path, const pose& p) {
  const auto ext = path.extension().string();
  std::string text;
  if (ext == ".json")
    text = pose_json(p);
  else if (ext == ".yaml" || ext == ".yml")
    text = pose_yaml(p);
  else
    throw profile_error(path.string(), "a pose file ends in .json, .yaml or .yml");
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw profile_error(path.string(), "cannot be written (" + std::string(std::strerror(errno)) + ")");
  out << text;
  out.flush();
  if (!out) throw profile_error(path.string(), "writing failed (" + std::string(std::strerror(errno)) + ")");
}

}  // namespace rcb4::robot
