// rcb4 — a robot's body: which link each joint turns, where, about which axis, and the simple
// shapes (boxes, cylinders, spheres) that draw each link. Optional in a profile (`kinematics:`);
// rcb4 ui draws the robot from it and `rcb4 urdf` writes it as URDF (std only, no I/O).
// SPDX-License-Identifier: BSL-1.0
//
// Frames as URDF's: a joint's origin (xyz in mm, rpy in degrees: roll about x, then pitch about y,
// then yaw about z, fixed axes) places its frame in its parent link's frame; the child link's
// frame is the joint's frame turned by the joint's angle about its axis. x forward, y left, z up.
#pragma once

#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace rcb4::robot {

/** Three numbers: a position in mm, angles in degrees, an axis, or a shape's size. */
using vec3 = std::array<double, 3>;
/** A rotation, row by row. */
using mat3 = std::array<vec3, 3>;

/**
 * The rotation URDF's rpy (degrees) names: roll about x, then pitch about y, then yaw about z,
 * about fixed axes, R = Rz(yaw) · Ry(pitch) · Rx(roll). The mirror and the balance check share it.
 */
inline mat3 rpy_matrix(const vec3& rpy_deg) noexcept {
  constexpr double rad = 3.14159265358979323846 / 180.0;
  const double cr = std::cos(rpy_deg[0] * rad), sr = std::sin(rpy_deg[0] * rad);
  const double cp = std::cos(rpy_deg[1] * rad), sp = std::sin(rpy_deg[1] * rad);
  const double cy = std::cos(rpy_deg[2] * rad), sy = std::sin(rpy_deg[2] * rad);
  return {vec3{cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr},
          vec3{sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr}, vec3{-sp, cp * sr, cp * cr}};
}

/** A simple solid that draws part of a link. */
struct shape {
  enum class kind { box, cylinder, sphere };
  kind type = kind::box;  ///< what it is
  vec3 size{};            ///< box: x, y, z mm; cylinder: radius, length (along its z), 0; sphere: radius, 0, 0
  vec3 xyz{};             ///< its centre in the link's frame, mm
  vec3 rpy{};             ///< its orientation in the link's frame, degrees
};

/** A rigid part of the robot. */
struct link {
  std::string name;           ///< "left_thigh"
  std::vector<shape> shapes;  ///< what draws it (none: an invisible frame)
};

/** Where a joint sits and how it turns: a profile joint, or a fixed one that only places a link. */
struct body_joint {
  std::string name;    ///< the profile joint's name, or a fixed joint's own
  bool fixed = false;  ///< true: it does not turn (no servo)
  std::string parent;  ///< the link it sits on
  std::string child;   ///< the link it turns
  vec3 xyz{};          ///< its origin in the parent's frame, mm
  vec3 rpy{};          ///< its orientation in the parent's frame, degrees
  vec3 axis{0, 0, 1};  ///< the axis it turns about, in its own frame (any length but 0)
};

/** The robot's body: one root link, every other link the child of exactly one joint. */
struct kinematics {
  std::vector<link> links;         ///< every link
  std::vector<body_joint> joints;  ///< every joint, in the order given
  std::string source;              ///< where the figures come from (cited in the profile)

  /** The link no joint turns (the body the robot is held by). */
  const link* root() const noexcept {
    for (const auto& l : links) {
      bool child = false;
      for (const auto& j : joints) child = child || j.child == l.name;
      if (!child) return &l;
    }
    return nullptr;
  }
  /** The link called @p name, or nullptr. */
  const link* find_link(const std::string& name) const noexcept {
    for (const auto& l : links)
      if (l.name == name) return &l;
    return nullptr;
  }
  /** The joint called @p name, or nullptr. */
  const body_joint* find_joint(const std::string& name) const noexcept {
    for (const auto& j : joints)
      if (j.name == name) return &j;
    return nullptr;
  }
};

/** What is wrong with a body, and where: the joint or link it is about (an index into joints or links). */
struct body_problem {
  enum class at { joint, link, whole };
  at where = at::whole;   ///< which list @ref index is of
  std::size_t index = 0;  ///< the joint's or link's place in its list
  std::string message;    ///< "left_knee: its parent 'left_thih' is no link"
};

/**
 * Checks @p k against the profile's joint names @p profile_joints: names unique and valid, every
 * parent and child a link, no link the child of two joints, exactly one root, no cycle, every
 * axis of a turning joint non-zero, every profile joint placed and every turning joint a profile
 * joint, every size positive. Nothing when it is sound.
 */
inline std::optional<body_problem> check_body(const kinematics& k, const std::vector<std::string>& profile_joints) {
  const auto link_at = [&](const std::string& n) -> std::optional<std::size_t> {
    for (std::size_t i = 0; i < k.links.size(); ++i)
      if (k.links[i].name == n) return i;
    return std::nullopt;
  };
  if (k.links.empty()) return body_problem{body_problem::at::whole, 0, "no links"};
  for (std::size_t i = 0; i < k.links.size(); ++i) {
    const auto& l = k.links[i];
    if (l.name.empty()) return body_problem{body_problem::at::link, i, "a link needs a name"};
    for (std::size_t p = 0; p < i; ++p)
      if (k.links[p].name == l.name)
        return body_problem{body_problem::at::link, i, "the link '" + l.name + "' is given twice"};
    for (const auto& s : l.shapes) {
      const int n = s.type == shape::kind::box ? 3 : s.type == shape::kind::cylinder ? 2 : 1;
      for (int d = 0; d < n; ++d)
        if (!(s.size[static_cast<std::size_t>(d)] > 0) || !std::isfinite(s.size[static_cast<std::size_t>(d)]))
          return body_problem{body_problem::at::link, i, l.name + ": a shape's sizes must be more than 0 mm"};
    }
  }
  for (std::size_t i = 0; i < k.joints.size(); ++i) {
    const auto& j = k.joints[i];
    const auto at = body_problem::at::joint;
    if (j.name.empty()) return body_problem{at, i, "a joint needs a name"};
    for (std::size_t p = 0; p < i; ++p)
      if (k.joints[p].name == j.name) return body_problem{at, i, "the joint '" + j.name + "' is placed twice"};
    bool in_profile = false;
    for (const auto& n : profile_joints) in_profile = in_profile || n == j.name;
    if (!j.fixed && !in_profile)
      return body_problem{at, i,
                          j.name + ": no joint of the profile is called so (a joint without a servo is fixed: true)"};
    if (j.fixed && in_profile)
      return body_problem{at, i, j.name + ": a joint of the profile turns: it cannot be fixed"};
    if (!link_at(j.parent)) return body_problem{at, i, j.name + ": its parent '" + j.parent + "' is no link"};
    if (!link_at(j.child)) return body_problem{at, i, j.name + ": its child '" + j.child + "' is no link"};
    if (j.parent == j.child) return body_problem{at, i, j.name + ": its parent and child are the same link"};
    for (std::size_t p = 0; p < i; ++p)
      if (k.joints[p].child == j.child)
        return body_problem{at, i, j.name + ": the link '" + j.child + "' is already turned by " + k.joints[p].name};
    const double len = std::sqrt(j.axis[0] * j.axis[0] + j.axis[1] * j.axis[1] + j.axis[2] * j.axis[2]);
    if (!j.fixed && !(len > 1e-9)) return body_problem{at, i, j.name + ": its axis is 0 0 0: it turns about nothing"};
    for (const auto& v : {j.xyz, j.rpy, j.axis})
      for (double x : v)
        if (!std::isfinite(x)) return body_problem{at, i, j.name + ": a number that is not finite"};
  }
  for (std::size_t n = 0; n < profile_joints.size(); ++n)
    if (!k.find_joint(profile_joints[n]))
      return body_problem{body_problem::at::whole, 0,
                          profile_joints[n] + ": the profile's joint has no place in the body"};
  // One root, and from every link up through its parents to it, without coming back round.
  std::size_t roots = 0;
  for (const auto& l : k.links) {
    bool child = false;
    for (const auto& j : k.joints) child = child || j.child == l.name;
    roots += child ? 0 : 1;
  }
  for (std::size_t i = 0; i < k.links.size(); ++i) {
    std::string at = k.links[i].name;
    for (std::size_t steps = 0;; ++steps) {
      const body_joint* up = nullptr;
      for (const auto& j : k.joints)
        if (j.child == at) up = &j;
      if (!up) break;
      if (steps > k.joints.size())
        return body_problem{body_problem::at::link, i,
                            k.links[i].name + ": its parents come back round to it (a cycle)"};
      at = up->parent;
    }
  }
  if (roots != 1)
    return body_problem{body_problem::at::whole, 0,
                        roots == 0
                            ? "every link is some joint's child: there is no root"
                            : std::to_string(roots) + " links are no joint's child: the body is in pieces (one root)"};
  return std::nullopt;
}

}  // namespace rcb4::robot
