// libFuzzer harness: board-side command parsing (what the virtual board does with any bytes).
// Properties, not just "no crash":
//   - consumed never exceeds the input; need_more asks for at least one byte and only when the
//     input is shorter than the frame's SIZE;
//   - a complete parse re-serializes to exactly the consumed bytes (serialize(parse(x)) == x);
//   - split invariance: every proper prefix of an accepted frame is need_more, with prefix +
//     needed == frame length once the SIZE byte is in.
// The first input byte picks the codec options (the disputed encodings), the rest is the stream.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/rcb4.hpp>

#include <cstdlib>

namespace {
void check(bool ok) {
  if (!ok) __builtin_trap();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  rcb4::codec_options opt;
  opt.shift = (data[0] & 1) ? rcb4::shift_encoding::kondo_manual : rcb4::shift_encoding::measured_2015;
  opt.allow_arith_to_com = (data[0] & 2) != 0;
  std::span<const std::uint8_t> in(data + 1, size - 1);

  // Walk the stream frame by frame, as a board would.
  while (true) {
    const auto r = rcb4::parse_command(in, opt);
    check(r.consumed <= in.size());
    if (r.status == rcb4::parse_status::need_more) {
      check(r.needed >= 1);
      if (!in.empty()) check(in[0] > in.size());
      break;
    }
    check(r.consumed >= 1);
    if (r.status == rcb4::parse_status::complete) {
      const auto frame = in.first(r.consumed);
      const auto again = rcb4::encode(r.value());
      check(again.size() == frame.size());
      check(std::equal(again.begin(), again.end(), frame.begin()));
      check(rcb4::wire_size(r.value()) == frame.size());
      for (std::size_t k = 0; k < frame.size(); ++k) {
        const auto p = rcb4::parse_command(frame.first(k), opt);
        check(p.status == rcb4::parse_status::need_more);
        if (k >= 1) check(k + p.needed == frame.size());
      }
    } else {
      check(r.error != rcb4::errc{});
    }
    in = in.subspan(r.consumed);
  }
  return 0;
}
