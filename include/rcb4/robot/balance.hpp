// rcb4 — balance without physics: where each link is in a pose (forward kinematics), the centre
// of mass, the support polygon of the soles on the floor, and how far inside it the centre of mass
// lies (static stability: a robot standing still falls when its centre of mass leaves the
// polygon). std only, no I/O; every build tests it. physics.md §7.
// SPDX-License-Identifier: BSL-1.0
//
// The robot is set down flat on a sole: the floor is the bottom of a sole no other reaches below,
// so a pose that lifts a foot stands on the other and a pose that leans the legs tilts the torso.
// A sole touches when one of its bottom corners is within `contact_mm` of the floor. Margin: the
// signed distance in mm from the centre of mass (projected on the floor) to the nearest edge of
// the convex hull of the touching corners; positive inside, negative outside.
#pragma once

#include <rcb4/robot/dynamics.hpp>
#include <rcb4/robot/kinematics.hpp>
#include <rcb4/robot/model.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

namespace rcb4::robot {

/** A rotation (row-major 3×3) and a translation in mm: a link's frame in the root's. */
struct frame {
  std::array<double, 9> r{1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< rotation
  vec3 p{};                                            ///< origin, mm

  /** @p v (a point in this frame) in the parent frame. */
  vec3 apply(const vec3& v) const noexcept {
    return {r[0] * v[0] + r[1] * v[1] + r[2] * v[2] + p[0], r[3] * v[0] + r[4] * v[1] + r[5] * v[2] + p[1],
            r[6] * v[0] + r[7] * v[1] + r[8] * v[2] + p[2]};
  }
  /** This frame followed by @p b (b given in this frame). */
  frame then(const frame& b) const noexcept {
    frame out;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double s = 0;
        for (int k = 0; k < 3; ++k) s += r[static_cast<std::size_t>(3 * i + k)] * b.r[static_cast<std::size_t>(3 * k + j)];
        out.r[static_cast<std::size_t>(3 * i + j)] = s;
      }
    out.p = apply(b.p);
    return out;
  }
};

namespace detail {
constexpr double degrees = std::numbers::pi / 180;

/** URDF's rpy (degrees): roll about x, then pitch about y, then yaw about z, fixed axes. */
inline frame from_rpy(const vec3& xyz, const vec3& rpy) noexcept {
  const double cr = std::cos(rpy[0] * degrees), sr = std::sin(rpy[0] * degrees);
  const double cp = std::cos(rpy[1] * degrees), sp = std::sin(rpy[1] * degrees);
  const double cy = std::cos(rpy[2] * degrees), sy = std::sin(rpy[2] * degrees);
  frame f;
  f.r = {cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,  //
         sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,  //
         -sp,     cp * sr,                cp * cr};
  f.p = xyz;
  return f;
}

/** A turn of @p deg degrees about @p axis (any length but 0; Rodrigues). */
inline frame about(const vec3& axis, double deg) noexcept {
  const double n = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  const double x = axis[0] / n, y = axis[1] / n, z = axis[2] / n;
  const double c = std::cos(deg * degrees), s = std::sin(deg * degrees), t = 1 - c;
  frame f;
  f.r = {t * x * x + c,     t * x * y - s * z, t * x * z + s * y,  //
         t * x * y + s * z, t * y * y + c,     t * y * z - s * x,  //
         t * x * z - s * y, t * y * z + s * x, t * z * z + c};
  return f;
}
}  // namespace detail

/**
 * Each link's frame in the root link's frame for the body joints' angles @p degrees (by body
 * joint name; a joint not named is at 0), in the order of k.links.
 */
inline std::vector<frame> link_frames(const kinematics& k, const std::map<std::string, double>& degrees) {
  std::vector<frame> out(k.links.size());
  std::vector<bool> done(k.links.size(), false);
  const auto index_of = [&](const std::string& name) -> std::size_t {
    for (std::size_t i = 0; i < k.links.size(); ++i)
      if (k.links[i].name == name) return i;
    return k.links.size();
  };
  if (const auto* root = k.root()) done[index_of(root->name)] = true;
  // Joints may be listed in any order: place children whose parent is placed until none is left.
  for (bool more = true; more;) {
    more = false;
    for (const auto& j : k.joints) {
      const auto pi = index_of(j.parent), ci = index_of(j.child);
      if (pi >= out.size() || ci >= out.size() || !done[pi] || done[ci]) continue;
      frame f = out[pi].then(detail::from_rpy(j.xyz, j.rpy));
      if (!j.fixed) {
        const auto a = degrees.find(j.name);
        if (a != degrees.end() && std::isfinite(a->second)) f = f.then(detail::about(j.axis, a->second));
      }
      out[ci] = f;
      done[ci] = true;
      more = true;
    }
  }
  return out;
}

/** A point on the floor plane, mm. */
using point2 = std::array<double, 2>;

/** The balance of one pose, in the floor's frame (x forward, y left along the sole it stands on; z up from the floor). */
struct balance {
  vec3 com{};                         ///< centre of mass: x, y over the floor, z its height, mm
  double mass = 0;                    ///< grams
  std::string standing_on;            ///< the sole whose bottom is the floor
  std::vector<point2> support;        ///< the support polygon, counter-clockwise
  std::vector<std::string> touching;  ///< the soles on the floor
  double margin = 0;                  ///< mm from the centre of mass to the polygon's nearest edge; < 0: outside
  double tilt = 0;                    ///< degrees between the root link's z axis and the floor's normal
  /** True when the centre of mass lies over the support polygon. */
  bool stable() const noexcept { return margin > 0; }
};

namespace detail {
inline double cross(const point2& o, const point2& a, const point2& b) noexcept {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

/** The convex hull of @p pts, counter-clockwise (Andrew's monotone chain). */
inline std::vector<point2> hull(std::vector<point2> pts) {
  std::sort(pts.begin(), pts.end());
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return pts;
  std::vector<point2> h(2 * pts.size());
  std::size_t k = 0;
  for (const auto& p : pts) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p) <= 0) --k;
    h[k++] = p;
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  h.resize(k - 1);
  return h;
}

/** Distance from @p p to the segment a–b. */
inline double to_segment(const point2& p, const point2& a, const point2& b) noexcept {
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  const double len2 = dx * dx + dy * dy;
  double t = len2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2 : 0;
  t = std::clamp(t, 0.0, 1.0);
  const double ex = a[0] + t * dx - p[0], ey = a[1] + t * dy - p[1];
  return std::sqrt(ex * ex + ey * ey);
}

/** @p p (in the root's frame) in the frame @p f: f's rotation transposed applied to p − f's origin. */
inline vec3 into(const frame& f, const vec3& p) noexcept {
  const vec3 d{p[0] - f.p[0], p[1] - f.p[1], p[2] - f.p[2]};
  return {f.r[0] * d[0] + f.r[3] * d[1] + f.r[6] * d[2], f.r[1] * d[0] + f.r[4] * d[1] + f.r[7] * d[2],
          f.r[2] * d[0] + f.r[5] * d[1] + f.r[8] * d[2]};
}
}  // namespace detail

/**
 * The balance of the body @p k with masses @p d at joint angles @p degrees (body joint names,
 * degrees), standing still. The floor is the bottom face of a sole that no other sole reaches
 * below (the robot is set down flat on it); a sole touches when a bottom corner is within
 * @p contact_mm of the floor. Poses with no such sole (every foot tilted against the others)
 * stand on the root link held upright, the floor under the lowest corner.
 */
inline balance balance_of(const kinematics& k, const dynamics& d, const std::map<std::string, double>& degrees,
                          double contact_mm = 2.0) {
  const auto frames = link_frames(k, degrees);
  const auto index_of = [&](const std::string& name) {
    for (std::size_t i = 0; i < k.links.size(); ++i)
      if (k.links[i].name == name) return i;
    return k.links.size();
  };
  balance b;
  vec3 com{};
  for (const auto& l : d.links) {
    const auto i = index_of(l.link);
    if (i >= frames.size()) continue;
    const auto c = frames[i].apply(l.whole.com);
    for (std::size_t a = 0; a < 3; ++a) com[a] += l.whole.mass * c[a];
    b.mass += l.whole.mass;
  }
  if (b.mass > 0)
    for (auto& v : com) v /= b.mass;
  // Every sole's bottom corners in the root's frame, and the frame of each sole's bottom face.
  struct sole_at {
    const sole* s;
    frame bottom;
    std::array<vec3, 4> corners;
  };
  std::vector<sole_at> soles;
  for (const auto& s : d.soles) {
    const auto i = index_of(s.link);
    if (i >= frames.size()) continue;
    sole_at a{&s, frames[i], {}};
    a.bottom.p = frames[i].apply({s.xyz[0], s.xyz[1], s.xyz[2] - s.size[2] / 2});
    for (int c = 0; c < 4; ++c)
      a.corners[static_cast<std::size_t>(c)] = frames[i].apply({s.xyz[0] + ((c & 1) ? 0.5 : -0.5) * s.size[0],
                                                                s.xyz[1] + ((c & 2) ? 0.5 : -0.5) * s.size[1],
                                                                s.xyz[2] - s.size[2] / 2});
    soles.push_back(a);
  }
  if (soles.empty()) {
    b.margin = -std::numeric_limits<double>::infinity();
    return b;
  }
  // The floor: the first sole no corner of another sole reaches below; else the root upright.
  std::optional<frame> floor;
  for (const auto& a : soles) {
    bool lowest = true;
    for (const auto& o : soles)
      for (const auto& c : o.corners) lowest = lowest && detail::into(a.bottom, c)[2] >= -contact_mm;
    if (lowest) {
      floor = a.bottom;
      b.standing_on = a.s->link;
      break;
    }
  }
  if (!floor) {
    frame f;
    f.p[2] = std::numeric_limits<double>::infinity();
    for (const auto& a : soles)
      for (const auto& c : a.corners) f.p[2] = std::min(f.p[2], c[2]);
    floor = f;
  }
  b.com = detail::into(*floor, com);
  b.tilt = std::acos(std::clamp(floor->r[8], -1.0, 1.0)) / detail::degrees;  // root z · floor normal
  std::vector<point2> on_floor;
  for (const auto& a : soles)
    for (const auto& c : a.corners) {
      const auto q = detail::into(*floor, c);
      if (q[2] > contact_mm) continue;
      on_floor.push_back({q[0], q[1]});
      if (std::find(b.touching.begin(), b.touching.end(), a.s->link) == b.touching.end())
        b.touching.push_back(a.s->link);
    }
  b.support = detail::hull(on_floor);
  const point2 g{b.com[0], b.com[1]};
  double dist = std::numeric_limits<double>::infinity();
  bool inside = b.support.size() >= 3;
  for (std::size_t i = 0; i < b.support.size(); ++i) {
    const auto& p = b.support[i];
    const auto& q = b.support[(i + 1) % b.support.size()];
    inside = inside && detail::cross(p, q, g) > 0;
    dist = std::min(dist, detail::to_segment(g, p, q));
  }
  b.margin = inside ? dist : -dist;
  return b;
}

/**
 * The body joints' angles for the profile joints at @p joint_degrees (by joint name; a joint not
 * named is at 0): each joint's own, and each mimic joint's from the joint it follows.
 */
inline std::map<std::string, double> body_angles(const model& m, const std::map<std::string, double>& joint_degrees) {
  std::map<std::string, double> out;
  for (const auto& j : m.joints()) {
    const auto a = joint_degrees.find(j.name);
    out[j.name] = a == joint_degrees.end() ? 0.0 : a->second;
  }
  for (const auto& mj : m.mimics()) out[mj.name] = mj.angle(out[mj.joint]);
  return out;
}

/** The balance of @p m at @p joint_degrees (profile joints); nothing when the profile has no body or masses. */
inline std::optional<balance> balance_of(const model& m, const std::map<std::string, double>& joint_degrees) {
  if (!m.body() || !m.dynamics()) return std::nullopt;
  return balance_of(*m.body(), *m.dynamics(), body_angles(m, joint_degrees));
}

}  // namespace rcb4::robot
