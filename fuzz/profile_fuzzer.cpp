// libFuzzer harness: robot profiles and pose files (rcb4::profile, yaml-cpp underneath).
// The input is parsed as a profile and as a pose for the built-in KHR-3HV. Properties:
//   - the only way out is a model, a pose or a profile_error (any other exception traps);
//   - a profile_error's text starts with the source name;
//   - an accepted model passes model::make's checks again (its joints, groups and motions);
//   - an accepted pose names only joints of the model, each once, and written back as JSON it
//     reads back to the same joints;
//   - an accepted motion file, written back as YAML, reads back to the same steps (when the input
//     is valid UTF-8: the writer replaces invalid bytes); to_program gives a program or a problem,
//     and a program that assembles reads back (disassemble, lift, from_program) to the same bytes
//     (when its code reaches every byte; else what reads back reads back to itself).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/motion/disassemble.hpp>
#include <rcb4/robot/motion_file.hpp>
#include <rcb4/robot/profile.hpp>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string_view>

namespace {
std::string_view current_input;  // printed when a property fails (a CI log then holds the input)

/** Traps when a property does not hold, after naming it and printing the input escaped. */
void check(bool ok, const char* what, int line) {
  if (ok) return;
  std::fprintf(stderr, "profile_fuzzer.cpp:%d: property failed: %s\ninput (%zu bytes): \"", line, what,
               current_input.size());
  for (const char c : current_input) {
    const auto u = static_cast<unsigned char>(c);
    if (u == '\\' || u == '"')
      std::fprintf(stderr, "\\%c", c);
    else if (u >= 0x20 && u < 0x7F)
      std::fputc(c, stderr);
    else
      std::fprintf(stderr, "\\x%02X", u);
  }
  std::fprintf(stderr, "\"\n");
  __builtin_trap();
}
#define CHECK(x) check((x), #x, __LINE__)

bool valid_utf8(std::string_view s) {
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    const std::size_t n = c < 0x80 ? 1 : (c >> 5) == 6 ? 2 : (c >> 4) == 14 ? 3 : (c >> 3) == 30 ? 4 : 0;
    if (n == 0 || i + n > s.size()) return false;
    for (std::size_t k = 1; k < n; ++k)
      if ((static_cast<unsigned char>(s[i + k]) >> 6) != 2) return false;
    i += n;
  }
  return true;
}

/** How many bytes of the slot @p listing's code reaches, following it from the slot's start. */
std::size_t reached(const rcb4::motion::listing& listing) {
  std::size_t n = 0;
  for (const auto& i : listing.code) n += i.bytes.size();
  return n;
}

void motion_file(std::string_view text, const rcb4::robot::model& khr) {
  using namespace rcb4::robot;
  motion_document d;
  try {
    // Pose files resolve under a folder that does not exist: the input reaches no real file by a relative path.
    d = parse_motion(text, "fuzz-motion.yaml", khr, "/nonexistent-rcb4-fuzz");
  } catch (const profile_error&) {
    return;
  }
  CHECK(d.where.size() == d.steps.size() && !d.steps.empty());
  if (valid_utf8(text)) {
    try {
      const auto again = parse_motion(motion_yaml(d, "c"), "back.yaml", khr, "/nonexistent-rcb4-fuzz");
      CHECK(again.steps == d.steps && again.period == d.period);
    } catch (const profile_error& e) {
      check(false, e.what(), __LINE__);  // the file written back does not read
    }
  }
  const auto c = to_program(d, khr, rcb4::hth4_2_2, d.period);
  if (!ok(c)) return;
  const rcb4::motion::slot where{rcb4::rom_address::make(0x0B80).value(), 2048};
  const auto b = rcb4::motion::assemble(std::get<compiled_motion>(c).program, where);
  if (!rcb4::motion::ok(b)) return;
  const auto& bytes = std::get<std::vector<std::uint8_t>>(b);
  // Read back as pull does (disassemble, lift, from_program) and assembled again. A pose of a joint
  // beyond its limit cannot come out of to_program: the same limits pass again.
  const auto read_back = [&](const rcb4::motion::listing& x) {
    const auto p = rcb4::motion::lift(x);
    CHECK(rcb4::motion::ok(p));
    const auto c2 = to_program(from_program(std::get<rcb4::motion::program>(p), khr, rcb4::hth4_2_2, d.period), khr,
                               rcb4::hth4_2_2, d.period);
    CHECK(ok(c2));
    const auto b2 = rcb4::motion::assemble(std::get<compiled_motion>(c2).program, where);
    CHECK(rcb4::motion::ok(b2));
    return std::get<std::vector<std::uint8_t>>(b2);
  };
  const auto listing = rcb4::motion::disassemble(bytes, where);
  const auto bytes2 = read_back(listing);
  // The same bytes when the code reaches all of them; a step no code reaches (after an end or a
  // goto) is not read back, so then the bytes read back must read back to themselves.
  if (reached(listing) == bytes.size())
    CHECK(bytes2 == bytes);
  else
    CHECK(read_back(rcb4::motion::disassemble(bytes2, where)) == bytes2);
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace rcb4::robot;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  current_input = text;
  static const model khr = open_profile("khr-3hv");
  try {
    const auto m = parse_profile(text, "fuzz.yaml");
    CHECK(ok(model::make(m.name(), m.joints(), m.groups(), m.motions())));
  } catch (const profile_error& e) {
    CHECK(std::string_view(e.what()).substr(0, 9) == "fuzz.yaml");
  } catch (const std::exception& e) {
    check(false, e.what(), __LINE__);  // only a profile_error may leave
  } catch (...) {
    CHECK(false);
  }
  try {
    const auto p = parse_pose(text, "fuzz.json", khr);
    for (std::size_t i = 0; i < p.joints.size(); ++i) {
      CHECK(khr.find(p.joints[i].first) != nullptr);
      for (std::size_t k = 0; k < i; ++k) CHECK(p.joints[k].first != p.joints[i].first);
    }
    const auto back = parse_pose(pose_json(p), "back.json", khr);
    CHECK(back.joints.size() == p.joints.size());
    for (std::size_t i = 0; i < p.joints.size(); ++i) CHECK(back.joints[i].first == p.joints[i].first);
  } catch (const profile_error& e) {
    CHECK(std::string_view(e.what()).substr(0, 9) == "fuzz.json");
  } catch (const std::exception& e) {
    check(false, e.what(), __LINE__);  // only a profile_error may leave
  } catch (...) {
    CHECK(false);
  }
  try {
    motion_file(text, khr);
  } catch (const std::exception& e) {
    check(false, e.what(), __LINE__);  // only a profile_error may leave
  } catch (...) {
    CHECK(false);
  }
  return 0;
}
