// A profile's body (kinematics:): the built-in robots', the mistakes refused with their place, URDF.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/profile.hpp>
#include <rcb4/robot/urdf.hpp>

#include <catch2/catch.hpp>

#include "profile_error.hpp"

#include <string>

using namespace rcb4::robot;

namespace {
std::string error_of(const std::string& text) { return rcb4::test::profile_error_of(text); }
// Two joints: a knee on a thigh on a body.
const std::string head =
    "robot: t\n"
    "joints:\n"
    "  hip: {ics: 1, lower: -90, upper: 90}\n"
    "  knee: {ics: 2, lower: -90, upper: 90}\n"
    "kinematics:\n"
    "  links:\n"
    "    body: {box: [50, 80, 100]}\n"
    "    thigh: {box: [30, 30, 80], xyz: [0, 0, -40]}\n"
    "    shin: [{cylinder: [15, 80], xyz: [0, 0, -40]}, {sphere: 10}]\n"
    "  joints:\n";
}  // namespace

TEST_CASE("body: the built-in robots place every joint, from one root", "[profile][body]") {
  for (const char* name : {"khr-3hv", "kxr-l2"}) {
    const auto m = open_profile(name);
    REQUIRE(m.body());
    CHECK(m.body()->root()->name == (std::string(name) == "khr-3hv" ? "pelvis" : "torso"));
    for (const auto& j : m.joints()) CHECK(m.body()->find_joint(j.name));
    CHECK_FALSE(m.body()->source.empty());
  }
}

TEST_CASE("body: a sound body, and each mistake with its line", "[profile][body]") {
  const auto ok = parse_profile(head +
                                    "    hip: {parent: body, child: thigh, xyz: [0, 20, -50], axis: [0, 1, 0]}\n"
                                    "    knee: {parent: thigh, child: shin, xyz: [0, 0, -80], axis: [0, 1, 0]}\n",
                                "ok.yaml");
  REQUIRE(ok.body());
  CHECK(ok.body()->links.at(2).shapes.size() == 2);
  CHECK(ok.body()->find_joint("knee")->xyz[2] == -80);
  // An unknown parent.
  CHECK(error_of(head + "    hip: {parent: bdy, child: thigh}\n    knee: {parent: thigh, child: shin}\n") ==
        "bad.yaml:11:5: hip: its parent 'bdy' is no link");
  // A cycle: the body's parent is the shin, whose parent is the thigh, whose parent is the body.
  CHECK(error_of(head + "    hip: {parent: body, child: thigh}\n    knee: {parent: thigh, child: shin}\n"
                        "    loop: {fixed: true, parent: shin, child: body}\n")
            .find("its parents come back round to it (a cycle)") != std::string::npos);
  // A zero axis.
  CHECK(error_of(head +
                 "    hip: {parent: body, child: thigh, axis: [0, 0, 0]}\n    knee: {parent: thigh, child: shin}\n") ==
        "bad.yaml:11:5: hip: its axis is 0 0 0: it turns about nothing");
  // A profile joint without a place, a placed joint without a servo, a link turned twice.
  CHECK(error_of(head + "    hip: {parent: body, child: thigh}\n") ==
        "bad.yaml:6:3: kinematics: knee: the profile's joint has no place in the body");
  CHECK(error_of(head + "    hip: {parent: body, child: thigh}\n    knee: {parent: thigh, child: shin}\n"
                        "    ankle: {parent: shin, child: body}\n")
            .find("ankle: no joint of the profile is called so") != std::string::npos);
  CHECK(error_of(head + "    hip: {parent: body, child: thigh}\n    knee: {parent: body, child: thigh}\n") ==
        "bad.yaml:12:5: knee: the link 'thigh' is already turned by hip");
  // Two roots: a link no joint turns besides the body.
  CHECK(error_of("robot: t\njoints:\n  a: {ics: 1, lower: -1, upper: 1}\nkinematics:\n  links:\n    b: {sphere: 1}\n"
                 "    c: {sphere: 1}\n    spare: {sphere: 1}\n  joints:\n    a: {parent: b, child: c}\n")
            .find("2 links are no joint's child: the body is in pieces") != std::string::npos);
  // Shapes: a bad size, two kinds at once, an unknown key.
  CHECK(
      error_of("robot: t\njoints:\n  a: {ics: 1, lower: -1, upper: 1}\nkinematics:\n  links:\n    b: {box: [1, 0, 1]}\n"
               "    c: []\n  joints:\n    a: {parent: b, child: c}\n") ==
      "bad.yaml:6:5: b: a shape's sizes must be more than 0 mm");
  CHECK(
      error_of("robot: t\njoints:\n  a: {ics: 1, lower: -1, upper: 1}\nkinematics:\n  links:\n    b: {box: [1, 1, 1], "
               "sphere: 2}\n  joints:\n    a: {parent: b, child: b}\n") ==
      "bad.yaml:6:8: b: a shape is exactly one of box, cylinder, sphere");
  CHECK(error_of(head + "    hip: {parent: body, child: thigh, twist: 3}\n").find("unknown key 'twist'") !=
        std::string::npos);
}

TEST_CASE("body: URDF in metres and radians, every joint with its limits", "[profile][body]") {
  const auto m = open_profile("khr-3hv");
  const auto u = to_urdf(m, {.prefix = "khr_"});
  CHECK(u.find("<robot name=\"KHR_3HV\">") != std::string::npos);
  CHECK(u.find("<joint name=\"khr_left_knee\" type=\"revolute\">") != std::string::npos);
  // left_knee: -130..130 degrees, 65 mm below the hip pitch; the root is a link of its own.
  CHECK(u.find("<origin xyz=\"0 0 -0.065\" rpy=\"0 0 0\"/>") != std::string::npos);
  CHECK(u.find("<limit lower=\"-2.26893\" upper=\"2.26893\"") != std::string::npos);
  CHECK(u.find("<link name=\"khr_pelvis\">") != std::string::npos);
  std::size_t joints = 0;
  for (auto at = u.find("type=\"revolute\""); at != std::string::npos; at = u.find("type=\"revolute\"", at + 1))
    ++joints;
  CHECK(joints == m.joints().size());
  // The mass model in URDF's units: the left thigh's 90.97 g at (2.59, -16.50, -33.76) mm, its
  // inertia 59, 56, 13 kg*mm^2 with ixz 4 (MasutaniLab's l_upperreg), in kg, m and kg*m^2.
  CHECK(u.find("<link name=\"khr_left_thigh\">\n    <inertial><origin xyz=\"0.00259 -0.0165 -0.03376\" rpy=\"0 0 0\"/>"
               "<mass value=\"0.09097\"/><inertia ixx=\"5.9e-05\" ixy=\"0\" ixz=\"4e-06\" iyy=\"5.6e-05\" iyz=\"0\" "
               "izz=\"1.3e-05\"/></inertial>") != std::string::npos);
  std::size_t inertials = 0;
  for (auto at = u.find("<inertial>"); at != std::string::npos; at = u.find("<inertial>", at + 1)) ++inertials;
  CHECK(inertials == m.body()->links.size());
  const auto bare = parse_profile("robot: t\njoints:\n  a: {ics: 1, lower: -1, upper: 1}\n", "t.yaml");
  CHECK_THROWS_WITH(to_urdf(bare), Catch::Contains("has no kinematics"));
}

TEST_CASE("body: URDF's joint names and a joint that mimics another (a gripper on one servo)", "[profile][body]") {
  const std::string gripper =
      "robot: g\n"
      "joints:\n"
      "  LARM_JOINT0: {ics: 1, lower: -90, upper: 90}\n"
      "  L_FINGER: {ics: 2, lower: 0, upper: 60}\n"
      "mimic:\n"
      "  R_FINGER: {joint: L_FINGER, multiplier: -1, offset: 5}\n"
      "kinematics:\n"
      "  links:\n"
      "    body: {box: [50, 80, 100]}\n"
      "    arm: {box: [20, 20, 80]}\n"
      "    left: {box: [5, 5, 20]}\n"
      "    right: {box: [5, 5, 20]}\n"
      "  joints:\n"
      "    LARM_JOINT0: {parent: body, child: arm, axis: [0, 1, 0]}\n"
      "    L_FINGER: {parent: arm, child: left, xyz: [0, 10, -80]}\n"
      "    R_FINGER: {parent: arm, child: right, xyz: [0, -10, -80]}\n";
  const auto m = parse_profile(gripper, "g.yaml");
  REQUIRE(m.mimics().size() == 1);
  CHECK(m.find_mimic("R_FINGER")->angle(30) == -25);
  CHECK(m.find("LARM_JOINT0"));
  const auto u = to_urdf(m);
  // Its limits are the followed joint's, carried over: -1 × 0..60 + 5 = -55..5 degrees.
  CHECK(u.find("<mimic joint=\"L_FINGER\" multiplier=\"-1\" offset=\"0.0872665\"/>") != std::string::npos);
  CHECK(u.find("<limit lower=\"-0.959931\" upper=\"0.0872665\"") != std::string::npos);
  // Mistakes: a mimic of an unknown joint, of a mimic, a name taken, a zero multiplier, a bad name.
  const auto with = [&](const std::string& line) {
    auto t = gripper;
    t.replace(t.find("  R_FINGER: {joint"), t.find("kinematics:") - t.find("  R_FINGER: {joint"), line);
    return error_of(t);
  };
  CHECK(with("  R_FINGER: {joint: NO_SUCH}\n") ==
        "bad.yaml:6:3: R_FINGER: it follows 'NO_SUCH', which is no joint of the profile (a mimic follows a joint with "
        "a servo)");
  CHECK(with("  LARM_JOINT0: {joint: L_FINGER}\n") ==
        "bad.yaml:6:3: mimic 'LARM_JOINT0': the name is already a joint's");
  CHECK(with("  R_FINGER: {joint: L_FINGER, multiplier: 0}\n") ==
        "bad.yaml:6:3: R_FINGER: multiplier is a number other than 0, offset a number");
  CHECK(with("  R-FINGER: {joint: L_FINGER}\n") == "bad.yaml:6:3: mimic 'R-FINGER': names use A-Z, a-z, 0-9 and _");
  CHECK(with("  R_FINGER: {joint: L_FINGER, gain: 2}\n").find("gain") != std::string::npos);
}
