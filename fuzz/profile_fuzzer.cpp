// libFuzzer harness: robot profiles and pose files (rcb4::profile, yaml-cpp underneath).
// The input is parsed as a profile and as a pose for the built-in KHR-3HV. Properties:
//   - the only way out is a model, a pose or a profile_error (any other exception traps);
//   - a profile_error's text starts with the source name;
//   - an accepted model passes model::make's checks again (its joints, groups and motions);
//   - an accepted pose names only joints of the model, each once, and written back as JSON it
//     reads back to the same joints.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/profile.hpp>

#include <cstddef>
#include <cstdint>
#include <exception>
#include <string_view>

namespace {
void check(bool ok) {
  if (!ok) __builtin_trap();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace rcb4::robot;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  static const model khr = open_profile("khr-3hv");
  try {
    const auto m = parse_profile(text, "fuzz.yaml");
    check(ok(model::make(m.name(), m.joints(), m.groups(), m.motions())));
  } catch (const profile_error& e) {
    check(std::string_view(e.what()).substr(0, 9) == "fuzz.yaml");
  } catch (...) {
    check(false);
  }
  try {
    const auto p = parse_pose(text, "fuzz.json", khr);
    for (std::size_t i = 0; i < p.joints.size(); ++i) {
      check(khr.find(p.joints[i].first) != nullptr);
      for (std::size_t k = 0; k < i; ++k) check(p.joints[k].first != p.joints[i].first);
    }
    const auto back = parse_pose(pose_json(p), "back.json", khr);
    check(back.joints.size() == p.joints.size());
    for (std::size_t i = 0; i < p.joints.size(); ++i) check(back.joints[i].first == p.joints[i].first);
  } catch (const profile_error& e) {
    check(std::string_view(e.what()).substr(0, 9) == "fuzz.json");
  } catch (...) {
    check(false);
  }
  return 0;
}
