// rcb4 — a profile's `dynamics:` (the robot's mass model, rcb4/robot/dynamics.hpp) read from
// YAML and checked, each problem at its line.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/dynamics.hpp>
#include <rcb4/robot/profile.hpp>

#include <yaml-cpp/yaml.h>

#include "yaml_helpers.hpp"

namespace rcb4::robot::detail {
namespace {

vec3 three(const std::string& source, const YAML::Node& n, const std::string& what) {
  if (!n || !n.IsSequence() || n.size() != 3) fail(source, n, what + ": expected three numbers [x, y, z]");
  return {number(source, n[0], what), number(source, n[1], what), number(source, n[2], what)};
}

inertial parse_part(const std::string& source, const YAML::Node& n, const std::string& link) {
  const std::string what = link + ": a part";
  if (!n.IsMap()) fail(source, n, what + " is {mass: grams, com: [x, y, z] mm, inertia: [ixx, iyy, izz] kg*mm^2}");
  check_keys(source, n, {"mass", "com", "inertia", "from"}, what);
  if (!n["mass"] || !n["com"] || !n["inertia"]) fail(source, n, what + ": mass, com and inertia are required");
  inertial p;
  p.mass = number(source, n["mass"], link + ": mass");
  p.com = three(source, n["com"], link + ": com");
  const auto in = n["inertia"];
  if (!in.IsSequence() || (in.size() != 3 && in.size() != 6))
    fail(source, in, link + ": inertia: expected [ixx, iyy, izz] or [ixx, iyy, izz, ixy, ixz, iyz] in kg*mm^2");
  for (std::size_t i = 0; i < in.size(); ++i) p.inertia[i] = number(source, in[i], link + ": inertia");
  if (const auto problem = inertial_problem(p)) fail(source, n, link + ": " + *problem);
  return p;
}

}  // namespace

dynamics parse_dynamics(const std::string& source, const YAML::Node& n, const kinematics& body) {
  if (!n.IsMap()) fail(source, n, "dynamics: expected a mapping with links, soles and joints");
  check_keys(source, n, {"source", "links", "soles", "joints"}, "dynamics");
  dynamics d;
  if (n["source"]) d.source = scalar(source, n["source"], "dynamics: source");
  const auto ls = n["links"];
  if (!ls || !ls.IsMap()) fail(source, ls ? ls : n, "dynamics: links: expected a mapping of link names to masses");
  for (const auto& kv : ls) {
    link_mass l;
    l.link = scalar(source, kv.first, "dynamics: link name");
    if (!body.find_link(l.link)) fail(source, kv.first, l.link + ": no link of the kinematics is called so");
    if (d.find(l.link)) fail(source, kv.first, l.link + ": its mass is given twice");
    if (kv.second.IsSequence()) {
      if (kv.second.size() == 0) fail(source, kv.second, l.link + ": at least one part");
      l.whole = parse_part(source, kv.second[0], l.link);
      for (std::size_t i = 1; i < kv.second.size(); ++i)
        l.whole = combine(l.whole, parse_part(source, kv.second[i], l.link));
      l.parts = kv.second.size();
    } else {
      l.whole = parse_part(source, kv.second, l.link);
    }
    if (const auto problem = inertial_problem(l.whole))
      fail(source, kv.first, l.link + ": its parts together: " + *problem);
    d.links.push_back(std::move(l));
  }
  const auto ss = n["soles"];
  if (!ss || !ss.IsMap() || ss.size() == 0)
    fail(source, ss ? ss : n,
         "dynamics: soles: the boxes the robot stands on are required, e.g. left_foot: {box: [x, y, z], xyz: [x, y, "
         "z]}");
  for (const auto& kv : ss) {
    sole s;
    s.link = scalar(source, kv.first, "dynamics: sole");
    const auto& v = kv.second;
    if (!body.find_link(s.link))
      fail(source, kv.first, "soles: " + s.link + ": no link of the kinematics is called so");
    if (!v.IsMap()) fail(source, v, "soles: " + s.link + ": expected {box: [x, y, z], xyz: [x, y, z], friction: mu}");
    check_keys(source, v, {"box", "xyz", "friction"}, "soles: " + s.link);
    s.size = three(source, v["box"], "soles: " + s.link + ": box");
    if (v["xyz"]) s.xyz = three(source, v["xyz"], "soles: " + s.link + ": xyz");
    if (v["friction"]) s.friction = number(source, v["friction"], "soles: " + s.link + ": friction");
    for (double x : s.size)
      if (!(x > 0)) fail(source, v["box"], "soles: " + s.link + ": a box's sizes must be more than 0 mm");
    if (!(s.friction > 0)) fail(source, v["friction"], "soles: " + s.link + ": friction must be more than 0");
    d.soles.push_back(std::move(s));
  }
  if (const auto js = n["joints"]) {
    if (!js.IsMap()) fail(source, js, "dynamics: joints: expected {damping, armature, friction}");
    check_keys(source, js, {"damping", "armature", "friction"}, "dynamics: joints");
    const auto at_least_0 = [&](const char* key, double& out) {
      if (!js[key]) return;
      out = number(source, js[key], std::string("dynamics: joints: ") + key);
      if (!(out >= 0)) fail(source, js[key], std::string("dynamics: joints: ") + key + " is 0 or more");
    };
    at_least_0("damping", d.joints.damping);
    at_least_0("armature", d.joints.armature);
    at_least_0("friction", d.joints.friction);
  }
  // Every link of the body weighs something: one left out would be massless, silently.
  for (const auto& l : body.links)
    if (!d.find(l.name))
      fail(source, ls,
           "dynamics: links: " + l.name +
               ": no mass given (every link of the body needs its mass, centre of mass and inertia)");
  if (const auto problem = check_dynamics(d, body)) fail(source, n, "dynamics: " + *problem);
  return d;
}

}  // namespace rcb4::robot::detail
