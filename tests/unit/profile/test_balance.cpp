// A profile's mass model (dynamics:) and the balance check without physics: the built-in KHR-3HV's
// figures, parts combined by hand-worked numbers, each mistake refused with its place, and poses
// that stand, lean out of their feet, or stand on one foot.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/balance.hpp>
#include <rcb4/robot/profile.hpp>

#include <catch2/catch.hpp>

#include "profile_error.hpp"

#include <cmath>
#include <map>
#include <string>

using namespace rcb4::robot;
using Catch::Matchers::Contains;

namespace {
std::string error_of(const std::string& text) { return rcb4::test::profile_error_of(text); }

// One joint: a leg under a body, a foot box 100 x 60 mm under the leg.
const std::string body =
    "robot: t\n"
    "joints:\n"
    "  hip: {ics: 1, lower: -90, upper: 90}\n"
    "kinematics:\n"
    "  links:\n"
    "    body: {box: [50, 80, 100], xyz: [0, 0, 50]}\n"
    "    leg: {box: [100, 60, 10], xyz: [0, 0, -5]}\n"
    "  joints:\n"
    "    hip: {parent: body, child: leg, axis: [0, 1, 0]}\n";
}  // namespace

TEST_CASE("dynamics: two parts combine by the parallel-axis theorem", "[profile][dynamics]") {
  // Two 100 g points 20 mm apart on x: 200 g at the middle; each 10 mm away adds
  // 0.1 kg x 100 mm^2 = 10 kg*mm^2 to iyy and izz, nothing to ixx.
  const inertial a{100, {-10, 0, 0}, {1, 1, 1, 0, 0, 0}};
  const inertial b{100, {10, 0, 0}, {1, 1, 1, 0, 0, 0}};
  const auto c = combine(a, b);
  CHECK(c.mass == 200);
  CHECK(c.com[0] == Approx(0).margin(1e-12));
  CHECK(c.inertia[0] == Approx(2));
  CHECK(c.inertia[1] == Approx(22));
  CHECK(c.inertia[2] == Approx(22));
  // Off the axes the products of inertia appear: d = (10, 10, 0) for a part of 100 g and its twin.
  const auto d =
      combine(inertial{100, {10, 10, 0}, {1, 1, 1, 0, 0, 0}}, inertial{100, {-10, -10, 0}, {1, 1, 1, 0, 0, 0}});
  CHECK(d.inertia[3] == Approx(-2 * 0.1 * 100));  // ixy = -sum m x y
  CHECK(d.inertia[2] == Approx(2 + 2 * 0.1 * 200));
}

TEST_CASE("dynamics: impossible inertials are named", "[profile][dynamics]") {
  CHECK(inertial_problem({-1, {}, {1, 1, 1, 0, 0, 0}}).value() == "a mass must be more than 0 g");
  CHECK_THAT(inertial_problem({10, {}, {1, 1, -1, 0, 0, 0}}).value(), Contains("not positive definite"));
  CHECK_THAT(inertial_problem({10, {}, {1, 1, 1, 2, 0, 0}}).value(), Contains("not positive definite"));
  CHECK_THAT(inertial_problem({10, {}, {1, 1, 5, 0, 0, 0}}).value(), Contains("triangle inequality"));
  CHECK_FALSE(inertial_problem({10, {}, {1, 1, 2, 0, 0, 0}}));
}

TEST_CASE("dynamics: the built-in KHR-3HV weighs what its source says", "[profile][dynamics]") {
  const auto m = open_profile("khr-3hv");
  REQUIRE(m.dynamics());
  const auto& d = *m.dynamics();
  CHECK(d.total_mass() == Approx(1458).margin(1));  // MasutaniLab's URDF: 1.458 kg
  CHECK(d.soles.size() == 2);
  CHECK(d.find("pelvis")->parts == 3);
  CHECK(d.find("chest")->parts == 3);
  CHECK(d.find("left_thigh")->whole.mass == Approx(90.97));
  for (const auto& l : m.body()->links) CHECK(d.find(l.name));  // every link has its mass
  CHECK_FALSE(d.source.empty());
}

TEST_CASE("dynamics: each mistake with its line", "[profile][dynamics]") {
  const std::string ok_soles = "  soles:\n    leg: {box: [100, 60, 2], xyz: [0, 0, -9]}\n";
  const std::string good = body +
                           "dynamics:\n"
                           "  links:\n"
                           "    body: {mass: 500, com: [0, 0, 50], inertia: [400, 400, 200]}\n"
                           "    leg: {mass: 100, com: [0, 0, -5], inertia: [30, 80, 100]}\n" +
                           ok_soles;
  CHECK_NOTHROW(parse_profile(good, "good.yaml"));
  CHECK_THAT(
      error_of(body + "dynamics:\n  links:\n    body: {mass: -5, com: [0, 0, 0], inertia: [1, 1, 1]}\n" + ok_soles),
      Contains(":12:") && Contains("body: a mass must be more than 0 g"));
  CHECK_THAT(
      error_of(body + "dynamics:\n  links:\n    body: {mass: 5, com: [0, 0, 0], inertia: [1, 1, 9]}\n" + ok_soles),
      Contains(":12:") && Contains("triangle inequality"));
  CHECK_THAT(
      error_of(body + "dynamics:\n  links:\n    arm: {mass: 5, com: [0, 0, 0], inertia: [1, 1, 1]}\n" + ok_soles),
      Contains(":12:5") && Contains("arm: no link of the kinematics is called so"));
  CHECK_THAT(error_of(body + "dynamics:\n  links:\n    body: {mass: 5, com: [0, 0, 0], inertia: [1, 1, 1]}\n"),
             Contains("soles") && Contains("required"));
  CHECK_THAT(error_of(body + "dynamics:\n  links:\n    body: {mass: 5, com: [0, 0, 0], inertia: [1, 1, 1]}\n"
                             "  soles:\n    foot: {box: [1, 1, 1]}\n"),
             Contains(":14:5") && Contains("soles: foot: no link"));
  CHECK_THAT(error_of(body + "dynamics:\n  links:\n    body: {mass: 5, com: [0, 0, 0], inertia: [1, 1, 1]}\n"
                             "  soles:\n    leg: {box: [1, 0, 1]}\n"),
             Contains("more than 0 mm"));
  // A link of the body left out of links: named, never weighed as nothing.
  CHECK_THAT(
      error_of(body + "dynamics:\n  links:\n    body: {mass: 5, com: [0, 0, 0], inertia: [1, 1, 1]}\n" + ok_soles),
      Contains(":12:") && Contains("leg: no mass given"));
  CHECK_THAT(error_of("robot: t\njoints:\n  hip: {ics: 1, lower: -90, upper: 90}\n"
                      "dynamics:\n  links: {}\n"),
             Contains(":5:") && Contains("needs the body"));
}

TEST_CASE("balance: a body over its foot stands, leaned past the foot's edge it does not", "[balance]") {
  // The body (500 g, its centre 80 mm above the hip) on a leg whose foot, 21 mm below the hip,
  // is 100 mm long and 60 wide: the centre of mass is over the middle of the foot, 50 mm from
  // its ends and 30 from its sides.
  kinematics k;
  k.links = {{"body", {}}, {"leg", {}}};
  k.joints = {{"hip", false, "body", "leg", {0, 0, 0}, {0, 0, 0}, {0, 1, 0}}};
  dynamics d;
  d.links = {{"body", {500, {0, 0, 80}, {1, 1, 1, 0, 0, 0}}, 1}};
  d.soles = {{"leg", {100, 60, 2}, {0, 0, -20}, 1.0}};
  const auto upright = balance_of(k, d, {});
  CHECK(upright.standing_on == "leg");
  CHECK(upright.touching == std::vector<std::string>{"leg"});
  CHECK(upright.margin == Approx(30));  // the sides are nearer than the ends
  CHECK(upright.com[2] == Approx(101));
  CHECK(upright.tilt == Approx(0).margin(1e-9));
  CHECK(upright.stable());
  // The hip turned 30 degrees: the foot stays flat on the floor, so the body leans 30 degrees
  // over it and its centre of mass moves 80 x sin(30) = 40 mm along x: 10 mm from the foot's end.
  const auto leaning = balance_of(k, d, {{"hip", 30}});
  CHECK(leaning.tilt == Approx(30));
  CHECK(std::abs(leaning.com[0]) == Approx(40));
  CHECK(leaning.com[2] == Approx(21 + 80 * std::cos(30 * detail::degrees)));
  CHECK(leaning.margin == Approx(10));
  // At 60 degrees: 80 x sin(60) = 69.28 mm, 19.28 mm beyond the foot's end.
  const auto fallen = balance_of(k, d, {{"hip", 60}});
  CHECK_FALSE(fallen.stable());
  CHECK(fallen.margin == Approx(50 - 69.282).margin(0.001));
  // No sole, nothing to stand on.
  d.soles.clear();
  CHECK_FALSE(balance_of(k, d, {}).stable());
}

TEST_CASE("balance: the KHR-3HV in its home pose stands on both feet, hips pitched far do not", "[balance]") {
  const auto m = open_profile("khr-3hv");
  const auto home = balance_of(m, {});
  REQUIRE(home);
  CHECK(home->mass == Approx(1458).margin(1));
  CHECK(home->touching.size() == 2);
  CHECK(home->stable());
  CHECK(home->margin > 20);  // well inside two 78 mm-wide feet 54 mm apart
  CHECK(home->tilt == Approx(0).margin(1e-6));
  CHECK(home->com[2] > 150);  // the centre of mass sits in the torso
  // Both hips pitched 80 degrees: the feet stay flat, the torso leans far out over their ends.
  const auto pitched = balance_of(m, {{"left_hip_pitch", -80}, {"right_hip_pitch", -80}});
  REQUIRE(pitched);
  CHECK(pitched->tilt == Approx(80).margin(0.5));
  CHECK_FALSE(pitched->stable());
  // The torso's lean has a direction: both hips pitched the same way lean it along x only.
  CHECK(std::abs(pitched->lean_forward) == Approx(80).margin(0.5));
  CHECK(pitched->lean_left == Approx(0).margin(1e-6));
  CHECK(home->com[1] == Approx(0).margin(0.5));  // the floor's origin is under the pelvis: y 0 when symmetric
  // One knee bent far: the robot stands on the other foot (the bent one's sole is lifted).
  const auto one = balance_of(m, {{"left_hip_pitch", -40}, {"left_knee", 80}, {"left_ankle_pitch", -40}});
  REQUIRE(one);
  CHECK(one->touching == std::vector<std::string>{"right_foot"});
}

TEST_CASE("balance: a lifted or tilted foot never becomes the floor the robot stands on", "[balance]") {
  // A newcomer's trial: a knee bent far alone tilts its foot and lifts it; either knee, the
  // robot stays upright on the other foot (and, its centre of mass between the feet, falls sideways).
  const auto m = open_profile("khr-3hv");
  for (const auto& [knee, other] : {std::pair{"left_knee", "right_foot"}, std::pair{"right_knee", "left_foot"}}) {
    const auto b = balance_of(m, {{knee, 90.0}});
    REQUIRE(b);
    INFO(knee);
    CHECK(b->touching == std::vector<std::string>{other});
    CHECK(b->tilt == Approx(0).margin(0.01));
    CHECK_FALSE(b->stable());
    // Bent 20 degrees, the foot's tilted edge reaches below the other sole: the robot rests on both,
    // a little tilted, never on the tilted sole alone.
    const auto little = balance_of(m, {{knee, 20.0}});
    REQUIRE(little);
    CHECK(little->touching.size() == 2);
    CHECK(little->tilt > 1);
    CHECK(little->tilt < 15);
  }
  // Legs spread 10 degrees (the hip rolls, mirrored): the feet tilt outwards and the robot stands
  // upright on their inner edges.
  const auto spread = balance_of(m, {{"left_hip_roll", 10}, {"right_hip_roll", 10}});
  REQUIRE(spread);
  CHECK(spread->touching == std::vector<std::string>{"left_foot", "right_foot"});
  CHECK(spread->tilt == Approx(0).margin(0.01));
  CHECK(spread->stable());
  // A lunge (one hip forward, the other back, the ankles keeping both feet flat): the rear foot's
  // heel a few mm up, the robot tips a little onto both and stands.
  const auto lunge = balance_of(
      m, {{"left_hip_pitch", -30}, {"right_hip_pitch", 30}, {"left_ankle_pitch", 30}, {"right_ankle_pitch", -30}});
  REQUIRE(lunge);
  CHECK(lunge->touching.size() == 2);
  CHECK(lunge->tilt < 5);
  CHECK(lunge->stable());
}
