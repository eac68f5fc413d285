// rcb4 — a profile's `kinematics:` (the robot's body, rcb4/robot/kinematics.hpp) read from YAML,
// and the body written as URDF (rcb4/robot/urdf.hpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/profile.hpp>
#include <rcb4/robot/urdf.hpp>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cctype>
#include <cmath>
#include <numbers>
#include <utility>

#include "yaml_helpers.hpp"

namespace rcb4::robot {
namespace detail {

namespace {

vec3 triple(const std::string& source, const YAML::Node& n, const std::string& what) {
  if (!n.IsSequence() || n.size() != 3) fail(source, n, what + ": expected three numbers [x, y, z]");
  return {number(source, n[0], what), number(source, n[1], what), number(source, n[2], what)};
}

shape parse_shape(const std::string& source, const YAML::Node& n, const std::string& link) {
  if (!n.IsMap()) fail(source, n, link + ": a shape is {box: [x, y, z]}, {cylinder: [radius, length]} or {sphere: r}");
  check_keys(source, n, {"box", "cylinder", "sphere", "xyz", "rpy"}, link + ": shape");
  shape s;
  const int kinds = (n["box"] ? 1 : 0) + (n["cylinder"] ? 1 : 0) + (n["sphere"] ? 1 : 0);
  if (kinds != 1) fail(source, n, link + ": a shape is exactly one of box, cylinder, sphere");
  if (n["box"]) {
    s.type = shape::kind::box;
    s.size = triple(source, n["box"], link + ": box");
  } else if (n["cylinder"]) {
    s.type = shape::kind::cylinder;
    const auto c = n["cylinder"];
    if (!c.IsSequence() || c.size() != 2) fail(source, c, link + ": cylinder: expected [radius, length]");
    s.size = {number(source, c[0], link + ": cylinder"), number(source, c[1], link + ": cylinder"), 0};
  } else {
    s.type = shape::kind::sphere;
    s.size = {number(source, n["sphere"], link + ": sphere"), 0, 0};
  }
  if (n["xyz"]) s.xyz = triple(source, n["xyz"], link + ": xyz");
  if (n["rpy"]) s.rpy = triple(source, n["rpy"], link + ": rpy");
  return s;
}

}  // namespace

kinematics parse_body(const std::string& source, const YAML::Node& n, const std::vector<std::string>& profile_joints) {
  if (!n.IsMap()) fail(source, n, "kinematics: expected a mapping with links and joints");
  check_keys(source, n, {"source", "links", "joints"}, "kinematics");
  kinematics k;
  if (n["source"]) k.source = scalar(source, n["source"], "kinematics: source");
  const auto ls = n["links"];
  if (!ls || !ls.IsMap()) fail(source, ls ? ls : n, "kinematics: links: expected a mapping of link names to shapes");
  std::vector<YAML::Node> link_nodes, joint_nodes;
  for (const auto& kv : ls) {
    link l;
    l.name = scalar(source, kv.first, "link name");
    if (kv.second.IsSequence()) {
      for (const auto& s : kv.second) l.shapes.push_back(parse_shape(source, s, l.name));
    } else if (!kv.second.IsNull()) {
      l.shapes.push_back(parse_shape(source, kv.second, l.name));
    }
    k.links.push_back(std::move(l));
    link_nodes.push_back(kv.first);
  }
  const auto js = n["joints"];
  if (!js || !js.IsMap()) fail(source, js ? js : n, "kinematics: joints: expected a mapping of joint names");
  for (const auto& kv : js) {
    body_joint j;
    j.name = scalar(source, kv.first, "joint name");
    const auto& v = kv.second;
    if (!v.IsMap()) fail(source, v, j.name + ": expected {parent, child, xyz, rpy, axis}");
    check_keys(source, v, {"parent", "child", "xyz", "rpy", "axis", "fixed"}, j.name);
    if (!v["parent"] || !v["child"]) fail(source, v, j.name + ": parent and child are required");
    j.parent = scalar(source, v["parent"], j.name + ": parent");
    j.child = scalar(source, v["child"], j.name + ": child");
    if (v["xyz"]) j.xyz = triple(source, v["xyz"], j.name + ": xyz");
    if (v["rpy"]) j.rpy = triple(source, v["rpy"], j.name + ": rpy");
    if (v["axis"]) j.axis = triple(source, v["axis"], j.name + ": axis");
    if (v["fixed"]) {
      const auto f = scalar(source, v["fixed"], j.name + ": fixed");
      if (f != "true" && f != "false") fail(source, v["fixed"], j.name + ": fixed: true or false");
      j.fixed = f == "true";
    }
    k.joints.push_back(std::move(j));
    joint_nodes.push_back(kv.first);
  }
  if (const auto p = check_body(k, profile_joints)) {
    switch (p->where) {
      case body_problem::at::joint: fail(source, joint_nodes[p->index], p->message);
      case body_problem::at::link: fail(source, link_nodes[p->index], p->message);
      case body_problem::at::whole: fail(source, n, "kinematics: " + p->message);
    }
  }
  return k;
}

}  // namespace detail

namespace {

constexpr double pi = std::numbers::pi;

/** Metres from millimetres, as URDF wants them. */
std::string metres(const vec3& v) { return fmt::format("{:g} {:g} {:g}", v[0] / 1000, v[1] / 1000, v[2] / 1000); }
/** Radians from degrees. */
std::string radians(const vec3& v) {
  return fmt::format("{:g} {:g} {:g}", v[0] * pi / 180, v[1] * pi / 180, v[2] * pi / 180);
}

std::string geometry(const shape& s) {
  switch (s.type) {
    case shape::kind::box: return fmt::format("<box size=\"{}\"/>", metres(s.size));
    case shape::kind::cylinder:
      return fmt::format("<cylinder radius=\"{:g}\" length=\"{:g}\"/>", s.size[0] / 1000, s.size[1] / 1000);
    case shape::kind::sphere: return fmt::format("<sphere radius=\"{:g}\"/>", s.size[0] / 1000);
  }
  return {};
}

/** @p text with XML's five special characters escaped. */
std::string xml(std::string_view text) {
  std::string out;
  for (const char c : text) switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  return out;
}

}  // namespace

/** The robot's name as an XML name and a comment's text allow it. */
std::string robot_name_of(const model& m) {
  std::string out;
  for (const char c : m.name()) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

std::string to_urdf(const model& m, const urdf_options& o) {
  const auto* k = m.body();
  if (!k) throw profile_error(m.name(), "the profile has no kinematics: section, so no body to write as URDF");
  std::string out = "<?xml version=\"1.0\"?>\n";
  out += fmt::format("<!-- the robot {} as rcb4's profile describes it: simple shapes, not its meshes. -->\n",
                     robot_name_of(m));
  if (!k->source.empty()) {
    // A comment holds any text but "--" (XML 1.0 §2.5); entities are not read there.
    auto source = k->source;
    for (auto at = source.find("--"); at != std::string::npos; at = source.find("--", at)) source.replace(at, 2, "- -");
    out += fmt::format("<!-- Figures: {} -->\n", source);
  }
  out += fmt::format("<robot name=\"{}\">\n", robot_name_of(m));
  out += "  <material name=\"rcb4_body\"><color rgba=\"0.8 0.8 0.82 1\"/></material>\n";
  const auto* dyn = m.dynamics();
  for (const auto& l : k->links) {
    out += fmt::format("  <link name=\"{}{}\">\n", xml(o.prefix), xml(l.name));
    // The mass model's figures in URDF's units: kg, m, kg*m^2 (the profile's g, mm, kg*mm^2).
    if (const auto* lm = dyn ? dyn->find(l.name) : nullptr) {
      const auto& w = lm->whole;
      const auto& i = w.inertia;
      out += fmt::format(
          "    <inertial><origin xyz=\"{}\" rpy=\"0 0 0\"/><mass value=\"{:g}\"/>"
          "<inertia ixx=\"{:g}\" ixy=\"{:g}\" ixz=\"{:g}\" iyy=\"{:g}\" iyz=\"{:g}\" izz=\"{:g}\"/></inertial>\n",
          metres(w.com), w.mass / 1000, i[0] * 1e-6, i[3] * 1e-6, i[4] * 1e-6, i[1] * 1e-6, i[5] * 1e-6, i[2] * 1e-6);
    }
    for (const auto& s : l.shapes)
      out += fmt::format(
          "    <visual><origin xyz=\"{}\" rpy=\"{}\"/><geometry>{}</geometry><material name=\"rcb4_body\"/></visual>\n"
          "    <collision><origin xyz=\"{}\" rpy=\"{}\"/><geometry>{}</geometry></collision>\n",
          metres(s.xyz), radians(s.rpy), geometry(s), metres(s.xyz), radians(s.rpy), geometry(s));
    out += "  </link>\n";
  }
  for (const auto& j : k->joints) {
    out += fmt::format("  <joint name=\"{}{}\" type=\"{}\">\n", xml(o.prefix), xml(j.name),
                       j.fixed ? "fixed" : "revolute");
    out += fmt::format("    <parent link=\"{}{}\"/>\n    <child link=\"{}{}\"/>\n", xml(o.prefix), xml(j.parent),
                       xml(o.prefix), xml(j.child));
    out += fmt::format("    <origin xyz=\"{}\" rpy=\"{}\"/>\n", metres(j.xyz), radians(j.rpy));
    if (!j.fixed) {
      // A profile joint's limits; a mimic joint's are those of the joint it follows, carried over.
      const auto* mj = m.find_mimic(j.name);
      const auto* pj = m.find(mj ? mj->joint : j.name);
      double lower = mj ? mj->angle(pj->lower) : pj->lower, upper = mj ? mj->angle(pj->upper) : pj->upper;
      if (lower > upper) std::swap(lower, upper);
      const double len = std::sqrt(j.axis[0] * j.axis[0] + j.axis[1] * j.axis[1] + j.axis[2] * j.axis[2]);
      out += fmt::format("    <axis xyz=\"{:g} {:g} {:g}\"/>\n", j.axis[0] / len, j.axis[1] / len, j.axis[2] / len);
      out += fmt::format("    <limit lower=\"{:g}\" upper=\"{:g}\" effort=\"{:g}\" velocity=\"{:g}\"/>\n",
                         lower * pi / 180, upper * pi / 180, o.effort, o.velocity);
      if (mj)
        out += fmt::format("    <mimic joint=\"{}{}\" multiplier=\"{:g}\" offset=\"{:g}\"/>\n", xml(o.prefix),
                           xml(mj->joint), mj->multiplier, mj->offset * pi / 180);
    }
    out += "  </joint>\n";
  }
  out += "</robot>\n";
  return out;
}

}  // namespace rcb4::robot
