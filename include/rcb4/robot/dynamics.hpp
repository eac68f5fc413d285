// rcb4 — a robot's mass model: each link's mass, centre of mass and inertia, the soles it stands
// on, and its joints' damping. Optional in a profile (`dynamics:`, next to `kinematics:`); the
// balance check (<rcb4/robot/balance.hpp>), `rcb4 urdf`'s inertials and the physics-backed
// virtual board read it. std only, no I/O.
// SPDX-License-Identifier: BSL-1.0
//
// Units, as the profile writes them: mass in grams, lengths in mm (in the link's frame, the frame
// of <rcb4/robot/kinematics.hpp>), inertia in kg·mm² (1 kg·mm² = 1e-6 kg·m²) about the part's own
// centre of mass along the link's axes, as [ixx, iyy, izz] or [ixx, iyy, izz, ixy, ixz, iyz].
// A link may be given as several parts (a source model that splits it, a part folded in from a
// joint the robot lacks): they are combined here (parallel-axis theorem).
#pragma once

#include <rcb4/robot/kinematics.hpp>

#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace rcb4::robot {

/** The inertia tensor's six numbers in kg·mm²: ixx, iyy, izz, ixy, ixz, iyz. */
using inertia6 = std::array<double, 6>;

/** A rigid part's mass properties in its link's frame. */
struct inertial {
  double mass = 0;     ///< grams
  vec3 com{};          ///< centre of mass, mm
  inertia6 inertia{};  ///< about com, link axes, kg·mm²
};

/** A box under a link that touches the floor: the support polygon's corners and its friction. */
struct sole {
  std::string link;       ///< "left_foot"
  vec3 size{};            ///< box x, y, z in mm
  vec3 xyz{};             ///< the box's centre in the link's frame, mm
  double friction = 1.0;  ///< sliding friction coefficient against the floor
};

/** What damps every joint's motion (a servo's gear train): MuJoCo's joint damping and armature. */
struct joint_damping {
  double damping = 0.0;   ///< N·m·s/rad
  double armature = 0.0;  ///< kg·m², the rotor's inertia seen through the gears
  double friction = 0.0;  ///< N·m, dry friction (MuJoCo's frictionloss)
};

/** A link's parts, combined into one inertial when read. */
struct link_mass {
  std::string link;       ///< the kinematics' link
  inertial whole;         ///< its parts combined
  std::size_t parts = 1;  ///< how many parts the profile gave
};

/** The robot's mass model. */
struct dynamics {
  std::vector<link_mass> links;  ///< links with mass (a link not listed is massless)
  std::vector<sole> soles;       ///< at least one
  joint_damping joints;          ///< the same for every joint
  std::string source;            ///< where the figures come from (cited in the profile)

  /** The mass of the link called @p name, or nullptr. */
  const link_mass* find(const std::string& name) const noexcept {
    for (const auto& l : links)
      if (l.link == name) return &l;
    return nullptr;
  }
  /** The whole robot's mass, grams. */
  double total_mass() const noexcept {
    double m = 0;
    for (const auto& l : links) m += l.whole.mass;
    return m;
  }
};

/**
 * @p a and @p b as one part: masses added, the centre of mass weighted, each inertia moved to
 * the new centre (parallel axis: I + m(|d|²E − d dᵀ), grams × mm² = 1e-3 kg·mm²).
 */
inline inertial combine(const inertial& a, const inertial& b) noexcept {
  inertial out;
  out.mass = a.mass + b.mass;
  if (!(out.mass > 0)) return out;
  for (std::size_t i = 0; i < 3; ++i) out.com[i] = (a.mass * a.com[i] + b.mass * b.com[i]) / out.mass;
  for (const auto* p : {&a, &b}) {
    const vec3 d{p->com[0] - out.com[0], p->com[1] - out.com[1], p->com[2] - out.com[2]};
    const double m = p->mass * 1e-3;  // g·mm² → kg·mm²
    const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    out.inertia[0] += p->inertia[0] + m * (dd - d[0] * d[0]);
    out.inertia[1] += p->inertia[1] + m * (dd - d[1] * d[1]);
    out.inertia[2] += p->inertia[2] + m * (dd - d[2] * d[2]);
    out.inertia[3] += p->inertia[3] - m * d[0] * d[1];
    out.inertia[4] += p->inertia[4] - m * d[0] * d[2];
    out.inertia[5] += p->inertia[5] - m * d[1] * d[2];
  }
  return out;
}

/**
 * What is wrong with @p p's numbers, or nothing: a mass not above 0, a centre of mass or inertia
 * not finite, an inertia that is not positive definite or breaks the triangle inequality
 * (ixx + iyy ≥ izz and its turns, which every real body keeps; MuJoCo refuses the rest).
 */
inline std::optional<std::string> inertial_problem(const inertial& p) {
  if (!(p.mass > 0) || !std::isfinite(p.mass)) return "a mass must be more than 0 g";
  for (double v : p.com)
    if (!std::isfinite(v)) return "a centre of mass that is not finite";
  for (double v : p.inertia)
    if (!std::isfinite(v)) return "an inertia that is not finite";
  const auto& i = p.inertia;
  // Sylvester: the leading minors of [[ixx ixy ixz][ixy iyy iyz][ixz iyz izz]] all positive.
  const double m1 = i[0];
  const double m2 = i[0] * i[1] - i[3] * i[3];
  const double m3 =
      i[0] * (i[1] * i[2] - i[5] * i[5]) - i[3] * (i[3] * i[2] - i[5] * i[4]) + i[4] * (i[3] * i[5] - i[1] * i[4]);
  if (!(m1 > 0 && m2 > 0 && m3 > 0)) return "an inertia that is not positive definite";
  const double slack = 1e-9 * (i[0] + i[1] + i[2]);
  if (i[0] + i[1] + slack < i[2] || i[1] + i[2] + slack < i[0] || i[0] + i[2] + slack < i[1])
    return "an inertia whose diagonal breaks the triangle inequality (ixx + iyy >= izz, and so on)";
  return std::nullopt;
}

/** What is wrong with @p d against the body @p k, and where (a link or sole name first), or nothing. */
inline std::optional<std::string> check_dynamics(const dynamics& d, const kinematics& k) {
  for (const auto& l : d.links) {
    if (!k.find_link(l.link)) return l.link + ": no link of the kinematics is called so";
    if (auto p = inertial_problem(l.whole)) return l.link + ": " + *p;
  }
  // A link left out would weigh nothing, silently: balance and physics would be wrong without a word.
  for (const auto& l : k.links)
    if (!d.find(l.name))
      return l.name + ": no mass given (every link of the body needs its mass, centre of mass and inertia)";
  if (d.soles.empty()) return "soles: at least one sole is needed (the boxes the robot stands on)";
  for (const auto& s : d.soles) {
    if (!k.find_link(s.link)) return "soles: " + s.link + ": no link of the kinematics is called so";
    for (double v : s.size)
      if (!(v > 0) || !std::isfinite(v)) return "soles: " + s.link + ": a box's sizes must be more than 0 mm";
    for (double v : s.xyz)
      if (!std::isfinite(v)) return "soles: " + s.link + ": a number that is not finite";
    if (!(s.friction > 0) || !std::isfinite(s.friction)) return "soles: " + s.link + ": friction must be more than 0";
  }
  const auto& j = d.joints;
  for (double v : {j.damping, j.armature, j.friction})
    if (!(v >= 0) || !std::isfinite(v)) return "joints: damping, armature and friction are 0 or more";
  return std::nullopt;
}

}  // namespace rcb4::robot
