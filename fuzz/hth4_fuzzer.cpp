// libFuzzer harness: HTH4 project (.h4p) and trim (.h4t) files (rcb4/robot/hth4, pugixml
// underneath). The input is read as both. Properties:
//   - the only way out is a value or a profile_error whose text starts with the source name;
//   - an accepted project passes check_project again, is written and reads back to the same
//     value, and its motions relocate to the other layout and back unchanged;
//   - an accepted trim file is written and reads back to the same entries;
//   - an accepted flowchart compiles or is refused with a profile_error; compiled, its frames
//     all pass their SIZE and SUM, fit the slot and end in 03 0D 10 FF.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/hth4/flowchart.hpp>
#include <rcb4/robot/hth4/project.hpp>
#include <rcb4/robot/hth4/trim_file.hpp>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string_view>

namespace {
void check(bool ok, const char* what, int line) {
  if (ok) return;
  std::fprintf(stderr, "hth4_fuzzer.cpp:%d: property failed: %s\n", line, what);
  __builtin_trap();
}
#define CHECK(x) check((x), #x, __LINE__)
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace rcb4::robot;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto p = hth4::parse_project(text, "fuzz.h4p");
    hth4::check_project(p, "value");
    CHECK(hth4::parse_project(hth4::project_xml(p), "back.h4p") == p);
    const auto from = p.layout().motion_base.value();
    const auto to = from == 0x0B80 ? 0x0BB8u : 0x0B80u;
    for (const auto& m : p.motions) CHECK(hth4::relocate(hth4::relocate(m.frames, from, to), to, from) == m.frames);
  } catch (const profile_error& e) {
    CHECK(std::string_view(e.what()).substr(0, 8) == "fuzz.h4p");  // what is written reads back
  } catch (const std::exception& e) {
    check(false, e.what(), __LINE__);
  }
  try {
    const auto t = hth4::parse_trim_file(text, "fuzz.h4t");
    CHECK(hth4::parse_trim_file(hth4::trim_file_xml(t), "back.h4t") == t);
  } catch (const profile_error& e) {
    CHECK(std::string_view(e.what()).substr(0, 8) == "fuzz.h4t");
  } catch (const std::exception& e) {
    check(false, e.what(), __LINE__);
  }
  try {
    const auto f = hth4::parse_flowchart(text, "fuzz.xml");
    const auto c = hth4::compile_flowchart(f, 0x0B80, rcb4::hth4_2_2, "fuzz.xml");
    std::size_t n = 0;
    for (std::size_t i = 0; i < c.frames.size(); ++i) {
      const auto& fr = c.frames[i];
      n += fr.size();
      if (i + 1 < c.frames.size()) CHECK(fr.size() >= 3 && fr[0] == fr.size() && rcb4::checksum_ok(fr));
    }
    CHECK(!c.frames.empty() && c.frames.back() == std::vector<std::uint8_t>({0x03, 0x0D, 0x10, 0xFF}));
    CHECK(n <= 2048);
  } catch (const profile_error& e) {
    CHECK(std::string_view(e.what()).substr(0, 8) == "fuzz.xml");
  } catch (const std::exception& e) {
    check(false, e.what(), __LINE__);
  }
  return 0;
}
