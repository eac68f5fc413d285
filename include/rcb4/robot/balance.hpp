// rcb4 — balance without physics: where each link is in a pose (forward kinematics), the centre
// of mass, the support polygon of the soles on the floor, and how far inside it the centre of mass
// lies (static stability: a robot standing still falls when its centre of mass leaves the
// polygon). std only, no I/O; every build tests it. physics.md §7.
// SPDX-License-Identifier: BSL-1.0
//
// The robot rests on the floor as a rigid body: on the face of the convex hull of its sole corners
// that tilts it least from upright (a pose that lifts a foot stands on the other; feet spread
// apart stand on their inner edges). A corner within `contact_mm` (1 mm) of that face touches.
// Margin: the signed distance in mm from the centre of mass (projected on the floor) to the
// nearest edge of the convex hull of the touching corners; positive inside, negative outside.
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
        for (int k = 0; k < 3; ++k)
          s += r[static_cast<std::size_t>(3 * i + k)] * b.r[static_cast<std::size_t>(3 * k + j)];
        out.r[static_cast<std::size_t>(3 * i + j)] = s;
      }
    out.p = apply(b.p);
    return out;
  }
};

namespace detail {
constexpr double degrees = std::numbers::pi / 180;

/** A joint's origin (URDF's xyz in mm, rpy in degrees) as a frame. */
inline frame from_rpy(const vec3& xyz, const vec3& rpy) noexcept {
  const mat3 m = rpy_matrix(rpy);
  frame f;
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = 0; j < 3; ++j) f.r[3 * i + j] = m[i][j];
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

/**
 * The balance of one pose, in the floor's frame: its origin the point of the floor under the
 * root link's origin, x the root's forward direction along the floor, y to its left, z up.
 */
struct balance {
  vec3 com{};                         ///< centre of mass: x, y over the floor, z its height, mm
  double mass = 0;                    ///< grams
  std::string standing_on;            ///< the sole with the most corners on the floor
  std::vector<point2> support;        ///< the support polygon, counter-clockwise
  std::vector<std::string> touching;  ///< the soles with a corner on the floor
  double margin = 0;                  ///< mm from the centre of mass to the polygon's nearest edge; < 0: outside
  double tilt = 0;                    ///< degrees between the root link's z axis and the floor's normal
  double lean_forward = 0;            ///< the root's z axis leaning forward (+) or back (−), degrees
  double lean_left = 0;               ///< the root's z axis leaning left (+) or right (−), degrees
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

}  // namespace detail

/**
 * The balance of the body @p k with masses @p d at joint angles @p degrees (body joint names,
 * degrees), standing still. The robot rests on the floor as a rigid body would: the floor is a
 * plane through three sole corners with every sole corner on or above it (a face of their convex
 * hull), the least tilted. When the centre of mass lies outside it, the robot tips onto the next
 * face that holds it if that is at most @p settle_deg further from upright (a lunge with one heel
 * a few mm up), else it falls (the margin negative). So a pose that lifts a foot stands on the
 * other, a pose that leans both legs tilts the torso, feet spread apart stand on their inner
 * edges. A corner within @p contact_mm of the floor touches it.
 */
inline balance balance_of(const kinematics& k, const dynamics& d, const std::map<std::string, double>& degrees,
                          double contact_mm = 1.0, double settle_deg = 5.0) {
  const auto frames = link_frames(k, degrees);
  const auto index_of = [&](const std::string& name) {
    for (std::size_t i = 0; i < k.links.size(); ++i)
      if (k.links[i].name == name) return i;
    return k.links.size();
  };
  const auto dot = [](const vec3& a, const vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  const auto sub = [](const vec3& a, const vec3& b) { return vec3{a[0] - b[0], a[1] - b[1], a[2] - b[2]}; };
  const auto crossv = [](const vec3& a, const vec3& b) {
    return vec3{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
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
  // Every sole's four bottom corners in the root's frame.
  std::vector<std::pair<const sole*, vec3>> corners;
  for (const auto& s : d.soles) {
    const auto i = index_of(s.link);
    if (i >= frames.size()) continue;
    for (int c = 0; c < 4; ++c)
      corners.emplace_back(&s,
                           frames[i].apply({s.xyz[0] + ((c & 1) ? 0.5 : -0.5) * s.size[0],
                                            s.xyz[1] + ((c & 2) ? 0.5 : -0.5) * s.size[1], s.xyz[2] - s.size[2] / 2}));
  }
  // The robot on the floor plane with normal n (pointing up) through the point on.
  const vec3 up{0, 0, 1};  // the root's z axis
  const auto resting_on = [&](const vec3& n, const vec3& on) {
    balance r;
    r.mass = b.mass;
    // The floor's frame: its origin under the root's, x the root's forward along it, z its normal.
    const vec3 origin{n[0] * dot(n, on), n[1] * dot(n, on), n[2] * dot(n, on)};
    vec3 x = sub(vec3{1, 0, 0}, vec3{n[0] * n[0], n[0] * n[1], n[0] * n[2]});  // root x minus its normal part
    if (dot(x, x) < 1e-12) x = crossv(vec3{0, 1, 0}, n);
    const double xl = std::sqrt(dot(x, x));
    for (auto& v : x) v /= xl;
    const vec3 y = crossv(n, x);
    const auto floor_of = [&](const vec3& p) {
      const auto q = sub(p, origin);
      return vec3{dot(x, q), dot(y, q), dot(n, q)};
    };
    r.com = floor_of(com);
    r.tilt = std::acos(std::clamp(dot(n, up), -1.0, 1.0)) / detail::degrees;
    r.lean_forward = std::atan2(dot(x, up), dot(n, up)) / detail::degrees;
    r.lean_left = std::atan2(dot(y, up), dot(n, up)) / detail::degrees;
    std::vector<point2> on_floor;
    std::map<std::string, int> count;
    for (const auto& [s, c] : corners) {
      const auto q = floor_of(c);
      if (q[2] > contact_mm) continue;
      on_floor.push_back({q[0], q[1]});
      if (count[s->link]++ == 0) r.touching.push_back(s->link);
    }
    for (const auto& t : r.touching)
      if (r.standing_on.empty() || count[t] > count[r.standing_on]) r.standing_on = t;
    r.support = detail::hull(on_floor);
    const point2 g{r.com[0], r.com[1]};
    double dist = std::numeric_limits<double>::infinity();
    bool inside = r.support.size() >= 3;
    for (std::size_t i = 0; i < r.support.size(); ++i) {
      const auto& p = r.support[i];
      const auto& q = r.support[(i + 1) % r.support.size()];
      inside = inside && detail::cross(p, q, g) > 0;
      dist = std::min(dist, detail::to_segment(g, p, q));
    }
    r.margin = inside ? dist : -dist;
    return r;
  };
  // The floors it could rest on: planes through three corners with none below (faces of their
  // convex hull), each with its tilt from upright.
  struct face {
    double tilt;
    vec3 n, on;
  };
  std::vector<face> faces;
  const double eps = 1e-6;
  for (std::size_t i = 0; i < corners.size(); ++i)
    for (std::size_t j = i + 1; j < corners.size(); ++j)
      for (std::size_t m = j + 1; m < corners.size(); ++m) {
        const auto& p = corners[i].second;
        auto n = crossv(sub(corners[j].second, p), sub(corners[m].second, p));
        const double len = std::sqrt(dot(n, n));
        if (len < 1e-9) continue;  // three corners in a line
        for (auto& v : n) v /= len;
        bool above = true, below = true;
        for (const auto& c : corners) {
          const double h = dot(n, sub(c.second, p));
          above = above && h >= -eps;
          below = below && h <= eps;
        }
        if (!above && !below) continue;  // corners on both sides: not a face the robot rests on
        // The normal points up, towards the corners; when they all lie in the plane (soles flat
        // together), towards the body's centre of mass.
        if (!above || (below && dot(n, sub(com, p)) < 0))
          for (auto& v : n) v = -v;
        faces.push_back({std::acos(std::clamp(dot(n, up), -1.0, 1.0)) / detail::degrees, n, p});
      }
  if (faces.empty()) {
    b.margin = -std::numeric_limits<double>::infinity();  // no sole, or nothing to stand on
    return b;
  }
  // Set down on the least tilted face. When its centre of mass is outside, it tips: onto the
  // least tilted face within settle_deg more that holds it (a heel a few mm up), else it falls.
  std::sort(faces.begin(), faces.end(), [](const face& a, const face& c) { return a.tilt < c.tilt; });
  auto first = resting_on(faces.front().n, faces.front().on);
  if (first.stable()) return first;
  for (std::size_t i = 1; i < faces.size() && faces[i].tilt <= faces.front().tilt + settle_deg; ++i) {
    auto r = resting_on(faces[i].n, faces[i].on);
    if (r.stable()) return r;
  }
  return first;
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
