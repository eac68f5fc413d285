// rcb4 — a pose mirrored left ↔ right, from the robot's body (kinematics.hpp): which joint is
// each joint's mirror image and whether its angle keeps or changes its sign. std only, no I/O.
// SPDX-License-Identifier: BSL-1.0
//
// How: every joint's origin and axis are placed in the robot's frame at the zero pose (x forward,
// y left, z up). Mirroring is the reflection M = diag(1, -1, 1) (y → -y). Joint j's mirror image
// is the joint whose origin is M · origin_j (within 2 mm) and whose axis is ±M · axis_j; a joint on
// the middle plane is its own image (head and waist yaw). A reflection turns a rotation by θ about
// an axis a into a rotation by -θ about M·a, so the image's angle is
//   -θ when its axis is  M · axis_j   (sign -1: yaw on the middle plane, axes drawn mirrored)
//   +θ when its axis is -M · axis_j   (sign +1: pitch about y on both sides; roll and yaw with
//                                      the right side's axes flipped, as KHR-3HV's profile has them).
// A joint with no such image (no body in the profile, or an arm without a partner) has none, and
// a mirror leaves it as it is: nothing is guessed from names.
#pragma once

#include <rcb4/robot/kinematics.hpp>

#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace rcb4::robot {

/** Where a joint's angle goes in the mirrored pose. */
struct mirror_image {
  std::size_t joint = 0;  ///< the image joint's index in the joint list given to mirror_images()
  int sign = 1;           ///< +1: the same angle; -1: the angle negated
  bool left = false;      ///< this joint is on the robot's left (its origin at y > 1 mm)
  bool right = false;     ///< this joint is on the robot's right (y < -1 mm); neither: the middle
};

namespace detail {
inline vec3 times(const mat3& m, const vec3& v) {
  return {m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2], m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
          m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2]};
}
inline mat3 times(const mat3& a, const mat3& b) {
  mat3 out{};
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t c = 0; c < 3; ++c) out[r][c] = a[r][0] * b[0][c] + a[r][1] * b[1][c] + a[r][2] * b[2][c];
  return out;
}
inline vec3 unit(const vec3& v) {
  const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return n > 0 ? vec3{v[0] / n, v[1] / n, v[2] / n} : v;
}
inline bool near(const vec3& a, const vec3& b, double tolerance) {
  return std::abs(a[0] - b[0]) <= tolerance && std::abs(a[1] - b[1]) <= tolerance && std::abs(a[2] - b[2]) <= tolerance;
}

/** A joint's frame in the robot's frame at the zero pose. */
struct placed {
  vec3 origin{};
  mat3 turn{vec3{1, 0, 0}, vec3{0, 1, 0}, vec3{0, 0, 1}};
};

/** Places body joint @p i (following its parents up to the root; @p depth guards a loop). */
inline std::optional<placed> place(const kinematics& k, std::size_t i, int depth = 0) {
  if (depth > 64) return std::nullopt;
  const auto& j = k.joints[i];
  placed parent;
  for (std::size_t p = 0; p < k.joints.size(); ++p)
    if (k.joints[p].child == j.parent) {
      auto up = place(k, p, depth + 1);
      if (!up) return std::nullopt;
      parent = *up;
      break;
    }
  placed out;
  const auto moved = times(parent.turn, j.xyz);
  out.origin = {parent.origin[0] + moved[0], parent.origin[1] + moved[1], parent.origin[2] + moved[2]};
  out.turn = times(parent.turn, rpy_matrix(j.rpy));
  return out;
}
}  // namespace detail

/**
 * The mirror image of each of @p joints (the profile's joint names, in order) in @p body: one
 * entry per joint, nullopt where there is none (a joint the body does not have, or one whose
 * image is not in @p joints).
 */
inline std::vector<std::optional<mirror_image>> mirror_images(const kinematics& body,
                                                              const std::vector<std::string>& joints) {
  struct where {
    vec3 origin, axis;
    bool known = false;
  };
  std::vector<where> at(joints.size());
  for (std::size_t n = 0; n < joints.size(); ++n)
    for (std::size_t i = 0; i < body.joints.size(); ++i)
      if (!body.joints[i].fixed && body.joints[i].name == joints[n])
        if (const auto p = detail::place(body, i))
          at[n] = {p->origin, detail::unit(detail::times(p->turn, body.joints[i].axis)), true};
  constexpr double mm = 2.0, axis_tolerance = 0.02;
  std::vector<std::optional<mirror_image>> out(joints.size());
  for (std::size_t n = 0; n < joints.size(); ++n) {
    if (!at[n].known) continue;
    const vec3 origin{at[n].origin[0], -at[n].origin[1], at[n].origin[2]};
    const vec3 axis{at[n].axis[0], -at[n].axis[1], at[n].axis[2]};
    const vec3 flipped{-axis[0], -axis[1], -axis[2]};
    for (std::size_t m = 0; m < joints.size(); ++m) {
      if (!at[m].known || !detail::near(at[m].origin, origin, mm)) continue;
      int sign = 0;
      if (detail::near(at[m].axis, axis, axis_tolerance))
        sign = -1;
      else if (detail::near(at[m].axis, flipped, axis_tolerance))
        sign = 1;
      if (sign == 0) continue;
      out[n] = mirror_image{m, sign, at[n].origin[1] > 1.0, at[n].origin[1] < -1.0};
      break;
    }
  }
  return out;
}

/**
 * @p angles (degrees, one per joint, nullopt: not in the pose) mirrored left ↔ right: each joint
 * takes its image's angle, sign applied (not in the pose when its image is not); a joint without
 * an image keeps its own.
 */
inline std::vector<std::optional<double>> mirrored(const std::vector<std::optional<mirror_image>>& images,
                                                   const std::vector<std::optional<double>>& angles) {
  std::vector<std::optional<double>> out = angles;  // a joint without an image keeps its angle
  for (std::size_t n = 0; n < images.size() && n < angles.size(); ++n)
    if (images[n] && images[n]->joint < out.size())
      out[images[n]->joint] = angles[n] ? std::optional<double>(*angles[n] * images[n]->sign) : std::nullopt;
  return out;
}

}  // namespace rcb4::robot
