// libFuzzer harness: the vector-jump table and button names (rcb4/vector_entry.hpp,
// rcb4/motion/buttons.hpp, rcb4/ops/layout.hpp), whatever the board's RAM or ROM holds or a user
// types. Properties:
//   - an entry that decodes encodes back to the same 8 bytes;
//   - a decoded table encodes to bytes that decode to the same entries, ending with EOF;
//   - parse_buttons either fails or gives defined bits only, and their names parse back to them;
//   - judge_layout never names a layout without a frame where that layout puts motion 1.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/motion/buttons.hpp>
#include <rcb4/ops/layout.hpp>

#include <string_view>

namespace {
void check(bool ok) {
  if (!ok) __builtin_trap();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace mo = rcb4::motion;
  const std::span<const std::uint8_t> bytes(data, size);
  if (size >= rcb4::vector_entry::size)
    if (const auto e = rcb4::vector_entry::decode(bytes.first<rcb4::vector_entry::size>()))
      check(std::equal(bytes.begin(), bytes.begin() + 8, e->encode().begin()));
  const auto t = mo::decode_vector_table(bytes);
  const auto again = mo::encode_vector_table(t.entries);
  check(mo::ok(again));
  const auto& b = std::get<std::vector<std::uint8_t>>(again);
  const auto back = mo::decode_vector_table(b);
  check(back.ended && back.problem.empty());
  check(back.entries.size() == t.entries.size());
  for (std::size_t j = 0; j < t.entries.size(); ++j) {
    auto want = t.entries[j];
    want.last = j + 1 == t.entries.size();
    check(back.entries[j] == want);
  }
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto w = mo::parse_buttons(text);
  if (mo::ok(w)) {
    const auto word = std::get<std::uint16_t>(w);
    check(word != 0 && (word & ~rcb4::krr::valid_buttons) == 0);
    const auto named = mo::parse_buttons(mo::buttons_text(word));
    check(mo::ok(named) && std::get<std::uint16_t>(named) == word);
  }
  if (size >= 64) {
    const auto q = size / 4;
    const auto g =
        rcb4::ops::judge_layout(bytes.first(q), bytes.subspan(q, q), bytes.subspan(2 * q, q), bytes.subspan(3 * q, q));
    if (g.layout == &rcb4::hth4_2_2) check(rcb4::ops::detail::holds_frame(bytes.first(q)));
    if (g.layout == &rcb4::hth4_2_0 || g.layout == &rcb4::hth4_1_3)
      check(rcb4::ops::detail::holds_frame(bytes.subspan(q, q)));
  }
  return 0;
}
