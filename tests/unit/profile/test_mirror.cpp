// A pose mirrored left ↔ right (rcb4/robot/mirror.hpp): images and signs from the built-in robots'
// bodies, worked out by hand from their profiles' axes, and what a profile without a body gets.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/mirror.hpp>
#include <rcb4/robot/profile.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <string>

using namespace rcb4::robot;

namespace {
struct images_of {
  std::vector<std::string> names;
  std::vector<std::optional<mirror_image>> images;
  explicit images_of(const model& m) {
    for (const auto& j : m.joints()) names.push_back(j.name);
    images = mirror_images(*m.body(), names);
  }
  std::size_t at(const std::string& n) const {
    return static_cast<std::size_t>(std::find(names.begin(), names.end(), n) - names.begin());
  }
  /** "right_knee +" : the image of @p n and its sign. */
  std::string of(const std::string& n) const {
    const auto& i = images[at(n)];
    if (!i) return "none";
    return names[i->joint] + (i->sign > 0 ? " +" : " -");
  }
};
}  // namespace

TEST_CASE("mirror: KHR-3HV's images (its right roll and yaw axes drawn flipped)", "[profile][mirror]") {
  const auto m = open_profile("khr-3hv");
  const images_of k(m);
  // yaw on the middle plane about z: its own image, negated
  CHECK(k.of("head_yaw") == "head_yaw -");
  CHECK(k.of("waist_yaw") == "waist_yaw -");
  // pitch about y on both sides: the same angle
  CHECK(k.of("left_knee") == "right_knee +");
  CHECK(k.of("right_knee") == "left_knee +");
  CHECK(k.of("left_shoulder_pitch") == "right_shoulder_pitch +");
  CHECK(k.of("left_ankle_pitch") == "right_ankle_pitch +");
  // roll about x, the right side's axis -x (profile): M·x = x = -(-x), so the same angle
  CHECK(k.of("left_shoulder_roll") == "right_shoulder_roll +");
  CHECK(k.of("left_hip_roll") == "right_hip_roll +");
  CHECK(k.of("right_ankle_roll") == "left_ankle_roll +");
  // yaw about z, the right side's axis -z: the same angle
  CHECK(k.of("left_elbow_yaw") == "right_elbow_yaw +");
  CHECK(k.images[k.at("left_knee")]->left);
  CHECK(k.images[k.at("right_knee")]->right);
  CHECK_FALSE(k.images[k.at("head_yaw")]->left);
  CHECK_FALSE(k.images[k.at("head_yaw")]->right);
}

TEST_CASE("mirror: KXR-L2's images (both roll axes +x: a roll is negated)", "[profile][mirror]") {
  const auto m = open_profile("kxr-l2");
  const images_of k(m);
  CHECK(k.of("head_yaw") == "head_yaw -");
  CHECK(k.of("left_shoulder_roll") == "right_shoulder_roll -");
  CHECK(k.of("left_hip_roll") == "right_hip_roll -");
  CHECK(k.of("left_ankle_roll") == "right_ankle_roll -");
  CHECK(k.of("left_knee") == "right_knee +");
  for (std::size_t n = 0; n < k.names.size(); ++n) {
    INFO(k.names[n]);
    CHECK(k.images[n].has_value());
  }
}

TEST_CASE("mirror: a pose swapped with its signs, a joint not in the pose stays out", "[profile][mirror]") {
  const auto m = open_profile("khr-3hv");
  const images_of k(m);
  std::vector<std::optional<double>> pose(k.names.size());
  pose[k.at("head_yaw")] = 20;
  pose[k.at("left_knee")] = 45;
  pose[k.at("right_knee")] = 10;
  pose[k.at("left_shoulder_roll")] = 30;  // right_shoulder_roll not in the pose
  const auto out = mirrored(k.images, pose);
  CHECK(out[k.at("head_yaw")] == -20.0);
  CHECK(out[k.at("left_knee")] == 10.0);
  CHECK(out[k.at("right_knee")] == 45.0);
  CHECK(out[k.at("right_shoulder_roll")] == 30.0);
  CHECK_FALSE(out[k.at("left_shoulder_roll")].has_value());
  CHECK(mirrored(k.images, out) == pose);  // twice: the pose as it was
}

TEST_CASE("mirror: a body without a partner or with a crooked axis gives no image", "[profile][mirror]") {
  kinematics b;
  b.links = {{"body", {}}, {"l", {}}, {"r", {}}, {"x", {}}};
  b.joints = {{"left", false, "body", "l", {0, 30, 0}, {}, {0, 1, 0}},
              {"right", false, "body", "r", {0, -30, 0}, {}, {1, 0, 0}},  // the partner's axis is not a mirror
              {"alone", false, "body", "x", {0, 50, 0}, {}, {0, 1, 0}}};
  const auto i = mirror_images(b, {"left", "right", "alone", "absent"});
  CHECK_FALSE(i[0].has_value());
  CHECK_FALSE(i[1].has_value());
  CHECK_FALSE(i[2].has_value());
  CHECK_FALSE(i[3].has_value());
  const std::vector<std::optional<double>> pose{1.0, 2.0, 3.0, std::nullopt};
  CHECK(mirrored(i, pose) == pose);  // nothing guessed
}
