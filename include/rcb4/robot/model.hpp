// rcb4 — the robot model: joints by name in degrees, with limits, on ICS slots (std only).
// SPDX-License-Identifier: BSL-1.0
//
// A joint is one servo seen as a robot user sees it: "left_knee", in degrees from the robot's
// own zero, within limits. Its servo position follows (protocol.md §7: 7500 is the centre,
// 4000 counts per 135°, KRS servos turn over 3500..11500):
//
//   servo degrees = direction × joint degrees + offset
//   position      = 7500 + servo degrees × 4000 / 135
//
// Nothing here does I/O; the operations on a model are in <rcb4/robot/ops.hpp>, the profile
// file that fills one in <rcb4/robot/profile.hpp> (a separate target).
#pragma once

#include <rcb4/ops/servos.hpp>
#include <rcb4/robot/dynamics.hpp>
#include <rcb4/robot/kinematics.hpp>
#include <rcb4/values.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace rcb4::robot {

/** A servo family's travel: the positions it reaches and their angle (ICS servos, §7). */
struct servo_kind {
  std::string_view name;       ///< "KRS"
  std::uint16_t low = 3500;    ///< position at -half_turn
  std::uint16_t high = 11500;  ///< position at +half_turn
  double half_turn = 135.0;    ///< degrees from centre to either end
};

/** KONDO's KRS ICS servos (KRS-2552, -3304, -4034 …): ±135° over 3500..11500. */
inline constexpr servo_kind krs{"KRS", 3500, 11500, 135.0};

/** What went wrong, in words that name the joint, the value and the limit. */
struct problem {
  std::string message;  ///< e.g. "left_knee: 140 degrees is beyond its upper limit 125"
};

/** A value or a problem. */
template <class T>
using outcome = std::variant<T, problem>;

/** True when @p o holds a value. */
template <class T>
bool ok(const outcome<T>& o) noexcept {
  return o.index() == 0;
}

/** One joint: a name, its servo slot, how the servo's angle maps to the joint's, its limits. */
struct joint {
  std::string name;                  ///< [A-Za-z0-9_], as URDF names them: "left_knee", "LARM_JOINT0"
  ics_number ics{};                  ///< the slot: 2 × servo ID + bus (0: SIO1-4, 1: SIO5-8)
  int direction = 1;                 ///< +1 or -1: which way the servo turns for + joint degrees
  double offset = 0;                 ///< servo degrees at joint 0
  double lower = -135, upper = 135;  ///< joint limits, degrees
  servo_kind kind = krs;             ///< the servo's travel

  /** The servo ID on its bus (ICS ÷ 2). */
  unsigned servo_id() const noexcept { return ics.value() / 2u; }
  /** The bus: 1 for SIO1–SIO4, 2 for SIO5–SIO8 (ICS parity). */
  unsigned bus() const noexcept { return ics.value() % 2u + 1u; }
};

/** @p v as a person writes it: "90", "-12.5", "0.25" (no trailing zeros). */
inline std::string number_text(double v) {
  std::string s = std::to_string(std::round(v * 1e4) / 1e4);
  while (s.size() > 1 && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  if (s == "-0") s = "0";
  return s;
}

/** The position that puts @p j at @p degrees; a problem beyond the joint's limits or the servo's travel. */
inline outcome<servo_position> to_position(const joint& j, double degrees) {
  if (!std::isfinite(degrees)) return problem{j.name + ": not a number of degrees"};
  // A hair of tolerance: a limit typed as 30 must accept the 30.0000001 a round trip gives.
  constexpr double eps = 1e-6;
  if (degrees < j.lower - eps)
    return problem{j.name + ": " + number_text(degrees) + " degrees is beyond its lower limit " + number_text(j.lower)};
  if (degrees > j.upper + eps)
    return problem{j.name + ": " + number_text(degrees) + " degrees is beyond its upper limit " + number_text(j.upper)};
  const double servo_deg = j.direction * degrees + j.offset;
  const double counts_per_degree = (j.kind.high - j.kind.low) / (2 * j.kind.half_turn);
  const double centre = (j.kind.high + j.kind.low) / 2.0;
  const double p = std::round(centre + servo_deg * counts_per_degree);
  if (p < j.kind.low || p > j.kind.high)
    return problem{j.name + ": " + number_text(degrees) + " degrees needs the servo at " +
                   std::to_string(static_cast<long>(p)) + ", beyond its travel " + std::to_string(j.kind.low) + ".." +
                   std::to_string(j.kind.high)};
  return servo_position::make(static_cast<int>(p)).value();
}

/** The joint angle of servo position @p p; nothing for FREE, HOLD or a value outside 0..16383. */
inline std::optional<double> to_degrees(const joint& j, std::uint16_t p) {
  const auto v = servo_position::make(p);
  if (!v || v->is_free() || v->is_hold()) return std::nullopt;
  const double counts_per_degree = (j.kind.high - j.kind.low) / (2 * j.kind.half_turn);
  const double centre = (j.kind.high + j.kind.low) / 2.0;
  const double servo_deg = (p - centre) / counts_per_degree;
  return (servo_deg - j.offset) / j.direction;
}

/**
 * A joint with no servo of its own that follows another (URDF's mimic: two joints on one servo,
 * such as a gripper's fingers): its angle is multiplier × the joint's + offset (degrees).
 */
struct mimic_joint {
  std::string name;       ///< its own name, as a joint's
  std::string joint;      ///< the profile joint it follows
  double multiplier = 1;  ///< non-zero
  double offset = 0;      ///< degrees
  /** Its angle when the joint it follows is at @p degrees. */
  double angle(double degrees) const noexcept { return multiplier * degrees + offset; }
};

/** True when @p name is a joint's name as profiles and URDF take it: A-Z, a-z, 0-9 and _. */
inline bool valid_joint_name(std::string_view name) noexcept {
  if (name.empty()) return false;
  for (char c : name)
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_')) return false;
  return true;
}

/** A named set of joints ("left_arm", "legs"). */
struct group {
  std::string name;                 ///< the group's name
  std::vector<std::string> joints;  ///< its joints' names
};

/** A motion slot with a name a person gave it (a HeartToHeart4 project). */
struct motion_name {
  unsigned slot = 0;  ///< 1-based
  std::string name;   ///< "walk forward"
};

/** A robot: its joints, groups and motion names, checked when made. */
class model {
 public:
  model() = default;
  /**
   * The model of @p joints, @p groups and @p motions; a problem for a duplicate name or ICS,
   * ICS 35 (the receiver's slot), a direction other than ±1, reversed limits, limits the servo
   * cannot reach, a group naming an unknown joint, or a name that is also a joint's.
   */
  static outcome<model> make(std::string name, std::vector<joint> joints, std::vector<group> groups = {},
                             std::vector<motion_name> motions = {});

  /** The robot's name ("KHR-3HV"). */
  const std::string& name() const noexcept { return name_; }
  /** Every joint, in the order given. */
  const std::vector<joint>& joints() const noexcept { return joints_; }
  /** Every group; "all" is implicit. */
  const std::vector<group>& groups() const noexcept { return groups_; }
  /** Named motion slots. */
  const std::vector<motion_name>& motions() const noexcept { return motions_; }
  /** The joint called @p name, or nullptr. */
  const joint* find(std::string_view name) const noexcept;
  /** The joint on slot @p ics, or nullptr. */
  const joint* on(ics_number ics) const noexcept;
  /** The joints a word names: a joint, a group, or "all"; a problem for an unknown word. */
  outcome<std::vector<const joint*>> select(std::string_view word) const;
  /** The name of motion @p slot, or empty. */
  std::string_view motion(unsigned slot) const noexcept;
  /** Every joint's slot. */
  servo_mask mask() const noexcept;
  /** The joints that follow another (mimic), in the order given. */
  const std::vector<mimic_joint>& mimics() const noexcept { return mimics_; }
  /** The mimic joint called @p name, or nullptr. */
  const mimic_joint* find_mimic(std::string_view name) const noexcept {
    for (const auto& m : mimics_)
      if (m.name == name) return &m;
    return nullptr;
  }
  /**
   * Adds @p m as a joint that follows another; a problem (and nothing added) for a name that is
   * not valid or already a joint's, group's or mimic's, a joint that is not the profile's (a
   * mimic does not follow a mimic), or a multiplier that is 0 or not finite.
   */
  std::optional<problem> add_mimic(mimic_joint m) {
    if (!valid_joint_name(m.name)) return problem{"mimic '" + m.name + "': names use A-Z, a-z, 0-9 and _"};
    if (m.name == "all" || find(m.name) || find_mimic(m.name))
      return problem{"mimic '" + m.name + "': the name is already a joint's"};
    for (const auto& g : groups_)
      if (g.name == m.name) return problem{"mimic '" + m.name + "': the name is already a group's"};
    if (!find(m.joint))
      return problem{m.name + ": it follows '" + m.joint + "', which is no joint of the profile (a mimic follows a " +
                     "joint with a servo)"};
    if (!std::isfinite(m.multiplier) || m.multiplier == 0 || !std::isfinite(m.offset))
      return problem{m.name + ": multiplier is a number other than 0, offset a number"};
    mimics_.push_back(std::move(m));
    return std::nullopt;
  }
  /** The robot's body (links, where each joint sits), when the profile describes it; else nullptr. */
  const kinematics* body() const noexcept { return body_ ? &*body_ : nullptr; }
  /**
   * Gives the robot the body @p k, checked against its joints and mimic joints (check_body); its
   * problem, and no body, if unsound.
   */
  std::optional<body_problem> attach_body(kinematics k) {
    std::vector<std::string> names;
    for (const auto& j : joints_) names.push_back(j.name);
    for (const auto& m : mimics_) names.push_back(m.name);
    if (auto p = check_body(k, names)) return p;
    body_ = std::move(k);
    return std::nullopt;
  }
  /** The robot's mass model, when the profile gives one (it needs a body); else nullptr. */
  const robot::dynamics* dynamics() const noexcept { return dynamics_ ? &*dynamics_ : nullptr; }
  /** Gives the robot the mass model @p d, checked against its body (check_dynamics); its problem if unsound. */
  std::optional<std::string> attach_dynamics(robot::dynamics d) {
    if (!body_) return std::string("a mass model (dynamics:) needs the body (kinematics:)");
    if (auto p = check_dynamics(d, *body_)) return p;
    dynamics_ = std::move(d);
    return std::nullopt;
  }

 private:
  std::string name_;
  std::vector<joint> joints_;
  std::vector<group> groups_;
  std::vector<motion_name> motions_;
  std::vector<mimic_joint> mimics_;
  std::optional<kinematics> body_;
  std::optional<robot::dynamics> dynamics_;
};

// ---------------------------------------------------------------------------------------------

inline outcome<model> model::make(std::string name, std::vector<joint> joints, std::vector<group> groups,
                                  std::vector<motion_name> motions) {
  const auto num = number_text;
  servo_mask seen;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const auto& j = joints[i];
    if (j.name.empty()) return problem{"joint " + std::to_string(i + 1) + ": no name"};
    if (!valid_joint_name(j.name)) return problem{"joint '" + j.name + "': names use A-Z, a-z, 0-9 and _"};
    if (j.name == "all") return problem{"joint 'all': the name is reserved for every joint"};
    for (std::size_t k = 0; k < i; ++k)
      if (joints[k].name == j.name) return problem{"joint '" + j.name + "' is given twice"};
    if (j.ics.value() == 35) return problem{j.name + ": ICS 35 is the receiver's slot (KRR), not a servo"};
    if (seen.contains(j.ics)) {
      for (std::size_t k = 0; k < i; ++k)
        if (joints[k].ics == j.ics)
          return problem{j.name + ": ICS " + std::to_string(j.ics.value()) + " is already " + joints[k].name + "'s"};
    }
    seen.insert(j.ics);
    if (j.direction != 1 && j.direction != -1) return problem{j.name + ": direction is 1 or -1"};
    if (!(j.lower < j.upper))
      return problem{j.name + ": limits reversed or empty (lower " + num(j.lower) + ", upper " + num(j.upper) + ")"};
    // Both limits must be positions the servo reaches.
    for (double limit : {j.lower, j.upper})
      if (const double s = j.direction * limit + j.offset; std::abs(s) > j.kind.half_turn + 1e-9)
        return problem{j.name + ": the limit " + num(limit) + " degrees puts the servo at " + num(s) +
                       " degrees, beyond its ±" + num(j.kind.half_turn)};
  }
  for (const auto& g : groups) {
    if (g.name.empty() || g.name == "all") return problem{"group '" + g.name + "': a group needs its own name"};
    for (const auto& j : joints)
      if (j.name == g.name) return problem{"group '" + g.name + "': a joint has that name"};
    for (const auto& n : g.joints)
      if (std::none_of(joints.begin(), joints.end(), [&](const joint& j) { return j.name == n; }))
        return problem{"group '" + g.name + "': no joint is called '" + n + "'"};
  }
  for (const auto& m : motions)
    if (m.slot < 1 || m.slot > 120)
      return problem{"motion '" + m.name + "': slot " + std::to_string(m.slot) + " is outside 1..120"};
  model out;
  out.name_ = std::move(name);
  out.joints_ = std::move(joints);
  out.groups_ = std::move(groups);
  out.motions_ = std::move(motions);
  return out;
}

inline const joint* model::find(std::string_view n) const noexcept {
  for (const auto& j : joints_)
    if (j.name == n) return &j;
  return nullptr;
}

inline const joint* model::on(ics_number ics) const noexcept {
  for (const auto& j : joints_)
    if (j.ics == ics) return &j;
  return nullptr;
}

inline outcome<std::vector<const joint*>> model::select(std::string_view word) const {
  std::vector<const joint*> out;
  if (word == "all") {
    for (const auto& j : joints_) out.push_back(&j);
    return out;
  }
  if (const auto* j = find(word)) return std::vector<const joint*>{j};
  for (const auto& g : groups_)
    if (g.name == word) {
      for (const auto& n : g.joints) out.push_back(find(n));
      return out;
    }
  return problem{"no joint or group is called '" + std::string(word) + "'"};
}

inline std::string_view model::motion(unsigned slot) const noexcept {
  for (const auto& m : motions_)
    if (m.slot == slot) return m.name;
  return {};
}

inline servo_mask model::mask() const noexcept {
  servo_mask m;
  for (const auto& j : joints_) m.insert(j.ics);
  return m;
}

}  // namespace rcb4::robot
