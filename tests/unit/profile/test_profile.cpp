// Robot profiles and pose files: the shipped profiles, errors with file and line, poses both ways.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/board/rom_image.hpp>
#include <rcb4/robot/profile.hpp>

#include <catch2/catch.hpp>

#include "profile_error.hpp"

#include <unistd.h>
#include <cstdio>
#include <filesystem>
#include <fstream>

using namespace rcb4;
using namespace rcb4::robot;

namespace {
std::string error_of(const std::string& text) { return rcb4::test::profile_error_of(text); }
const char* two_joints =
    "robot: test\n"
    "joints:\n"
    "  left_knee: {ics: 16, lower: -10, upper: 125}\n"
    "  right_knee: {id: 8, bus: 2, direction: -1, offset: 2.5, lower: -125, upper: 10}\n";
std::filesystem::path temp_path(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("rcb4-profile-test-" + std::to_string(::getpid()) + "-" + name);
}
}  // namespace

TEST_CASE("profile: the built-in KHR-3HV has its 20 joints on the virtual board's slots", "[profile]") {
  const auto m = open_profile("khr-3hv");
  CHECK(m.name() == "KHR-3HV");
  REQUIRE(m.joints().size() == 20);
  CHECK(m.find("head_yaw")->ics.value() == 0);
  CHECK(m.find("left_knee")->ics.value() == 16);  // ID 8 on SIO1-4
  CHECK(m.find("right_ankle_roll")->ics.value() == 21);
  CHECK(m.mask() == board::khr3hv_servos);  // the board serves exactly this robot
  CHECK(std::get<std::vector<const joint*>>(m.select("legs")).size() == 10);
  CHECK(m.motion(2) == "wave");
  const auto kxr = open_profile("kxr-l2");
  CHECK(kxr.joints().size() == 17);
  CHECK(kxr.find("right_knee")->ics.value() == 17);
}

TEST_CASE("profile: the shipped files are the built-ins", "[profile]") {
  for (auto name : builtin_profiles()) {
    const auto path = std::filesystem::path(RCB4_PROFILES_DIR) / (std::string(name) + ".yaml");
    std::ifstream in(path);
    REQUIRE(in);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    CHECK(text == *builtin_profile_text(name));
    CHECK(load_profile(path).joints().size() == open_profile(name).joints().size());
  }
}

TEST_CASE("profile: ICS or servo ID and bus, direction and offset", "[profile]") {
  const auto m = parse_profile(two_joints, "t.yaml");
  REQUIRE(m.joints().size() == 2);
  const auto* r = m.find("right_knee");
  CHECK(r->ics.value() == 17);
  CHECK(r->servo_id() == 8);
  CHECK(r->bus() == 2);
  CHECK(r->direction == -1);
  CHECK(r->offset == 2.5);
  CHECK(r->lower == -125);
}

TEST_CASE("profile: a bad profile names the file, the line and what is wrong", "[profile]") {
  std::string base = "robot: t\njoints:\n  a: {ics: 1, lower: -10, upper: 10}\n";
  CHECK(error_of(base + "  b: {ics: 2, lower: -10, upper: 10, speed: 3}\n") ==
        "bad.yaml:4:38: b: unknown key 'speed' (known: ics, id, bus, direction, offset, lower, upper)");
  CHECK(error_of(base + "  b: {ics: 1, lower: -10, upper: 10}\n") == "bad.yaml:4:3: b: ICS 1 is already a's");
  CHECK(error_of(base + "  b: {ics: 2, lower: 10, upper: -10}\n") ==
        "bad.yaml:4:3: b: limits reversed or empty (lower 10, upper -10)");
  CHECK(error_of(base + "  b: {ics: 35, lower: -10, upper: 10}\n").find("bad.yaml:4:3: b: ICS 35 is the receiver's") ==
        0);
  CHECK(error_of(base + "  b: {ics: 36, lower: -10, upper: 10}\n") ==
        "bad.yaml:4:12: b: ics: expected a whole number in 0..35, not 36");
  CHECK(error_of(base + "  b: {ics: 2, lower: low, upper: 10}\n") ==
        "bad.yaml:4:22: b: lower: expected a number, not 'low'");
  CHECK(error_of(base + "  b: {ics: 2, upper: 10}\n") ==
        "bad.yaml:4:6: b: needs its limits, lower and upper (degrees)");
  CHECK(error_of(base + "  b: {lower: -1, upper: 10}\n").find("bad.yaml:4:6: b: needs its slot") == 0);
  CHECK(error_of(base + "  b: {ics: 2, direction: 0, lower: -1, upper: 1}\n") ==
        "bad.yaml:4:3: b: direction is 1 or -1");
  CHECK(error_of(base + "groups:\n  legs: [a, z]\n") == "bad.yaml:5:3: group 'legs': no joint is called 'z'");
  CHECK(error_of(base + "motions:\n  0: stand\n") ==
        "bad.yaml:5:3: motion slot: expected a whole number in 1..120, not 0");
  CHECK(error_of(base + "colour: red\n") ==
        "bad.yaml:4:1: profile: unknown key 'colour' (known: robot, joints, groups, motions, mimic, kinematics, "
        "dynamics)");
  CHECK(error_of(base + "  a: {ics: 2, lower: -10, upper: 10}\n") == "bad.yaml:4:3: joint 'a' is given twice");
  CHECK(error_of("robot: t\njoints: [\n").find("bad.yaml:") == 0);  // YAML syntax: yaml-cpp's words, with the place
  CHECK(error_of("robot: t\n") == "bad.yaml:1:1: joints: expected a mapping of joint names");
  try {
    load_profile("/no/such/profile.yaml");
    FAIL("no error");
  } catch (const profile_error& e) {
    CHECK(std::string(e.what()) == "/no/such/profile.yaml: cannot be read (No such file or directory)");
  }
  try {
    open_profile("khr3");
    FAIL("no error");
  } catch (const profile_error& e) {
    CHECK(std::string(e.what()) == "khr3: no such file, and not a built-in profile (khr-3hv, kxr-l2)");
  }
}

TEST_CASE("profile: poses in JSON and YAML, written and read back", "[profile]") {
  const auto m = parse_profile(two_joints, "t.yaml");
  pose p{"test", {{"left_knee", 30.25}, {"right_knee", -12.5}}, std::chrono::milliseconds(800)};
  CHECK(pose_json(p) ==
        "{\n  \"robot\": \"test\",\n  \"time_ms\": 800,\n  \"joints\": {\n    \"left_knee\": 30.25,\n"
        "    \"right_knee\": -12.5\n  }\n}\n");
  for (const char* ext : {".json", ".yaml"}) {
    const auto path = temp_path(std::string("pose") + ext);
    save_pose(path, p);
    const auto back = load_pose(path, m);
    std::filesystem::remove(path);
    CHECK(back.robot == "test");
    CHECK(back.time == std::chrono::milliseconds(800));
    REQUIRE(back.joints.size() == 2);
    CHECK(back.joints[0] == std::pair<std::string, double>{"left_knee", 30.25});
    CHECK(back.joints[1] == std::pair<std::string, double>{"right_knee", -12.5});
  }
  CHECK_THROWS_WITH(save_pose(temp_path("pose.txt"), p), Catch::Contains("ends in .json, .yaml or .yml"));
  CHECK_THROWS_WITH(parse_pose("{\"joints\": {\"tail\": 3}}", "p.json", m),
                    "p.json:1:13: no joint of test is called 'tail'");
  CHECK_THROWS_WITH(parse_pose("{\"joints\": {\"left_knee\": \"up\"}}", "p.json", m),
                    "p.json:1:26: left_knee: expected a number, not the string \"up\"");
  CHECK_THROWS_WITH(parse_pose("joints: {left_knee: up}", "p.yaml", m),
                    "p.yaml:1:21: left_knee: expected a number, not 'up'");
  CHECK_THROWS_WITH(parse_pose("{\"joints\": {}}", "p.json", m), Catch::Contains("joints: expected a mapping"));
  // A quoted number is a string, in JSON and in YAML.
  CHECK_THROWS_WITH(parse_pose("{\"joints\": {\"left_knee\": \"10\"}}", "p.json", m),
                    "p.json:1:26: left_knee: expected a number, not the string \"10\"");
  CHECK_THROWS_WITH(parse_pose("joints:\n  left_knee: '10'\n", "p.yaml", m),
                    Catch::Contains("expected a number, not the string"));
  // Another robot's pose is refused, naming both.
  CHECK_THROWS_WITH(parse_pose("robot: KXR-L2\njoints: {left_knee: 10}\n", "p.yaml", m),
                    "p.yaml:1:8: this pose is KXR-L2's, not test's (--robot names the profile it was captured with)");
  // The same robot in other letters is the same robot.
  CHECK(parse_pose("robot: TEST\njoints: {left_knee: 10}\n", "p.yaml", m).joints.size() == 1);
  // A pose that names no robot is the profile's, and is written back naming it (found by fuzzing:
  // it was written back as "robot": "", which did not read). An empty name is refused, saying so.
  const auto unnamed = parse_pose("{\"joints\": {\"left_knee\": 10}}", "p.json", m);
  CHECK(unnamed.robot == "test");
  CHECK(pose_json(unnamed) == "{\n  \"robot\": \"test\",\n  \"joints\": {\n    \"left_knee\": 10.0\n  }\n}\n");
  CHECK(parse_pose(pose_json(unnamed), "back.json", m).joints.size() == 1);
  CHECK(parse_pose(pose_yaml(unnamed), "back.yaml", m).joints.size() == 1);
  CHECK_THROWS_WITH(parse_pose("robot: ''\njoints: {left_knee: 10}\n", "p.yaml", m),
                    "p.yaml:1:8: robot: an empty name (name test or leave it out)");
  // A pose built in code without a robot is written without one, and reads back.
  const pose anonymous{"", {{"left_knee", 5}}, std::nullopt};
  CHECK(pose_json(anonymous).find("robot") == std::string::npos);
  CHECK(pose_yaml(anonymous).find("robot") == std::string::npos);
  CHECK(parse_pose(pose_yaml(anonymous), "back.yaml", m).joints.size() == 1);
}

TEST_CASE("profile: YAML poses carry hundredths, not float noise", "[profile]") {
  pose p{"test", {{"left_knee", 39.99}, {"right_knee", -0.001}, {"head", 129.995}}, std::nullopt};
  CHECK(pose_yaml(p) == "robot: test\njoints:\n  left_knee: 39.99\n  right_knee: 0\n  head: 130\n");
  CHECK(pose_json(p).find("\"right_knee\": 0.0") != std::string::npos);
}
