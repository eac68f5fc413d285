// libFuzzer harness: the decoder of a PARMRK-marked serial line (rcb4/link/line_marks.hpp),
// which reads whatever a serial port hands over. The first input byte chooses where the stream is
// cut into reads; the rest is the raw stream. Properties:
//   - never more data bytes than raw bytes, in every read;
//   - split invariance: any cutting gives the same data bytes and the same damage count as one read;
//   - no FF or 00-after-FF of a mark ever reaches the data: the data is exactly what a reference
//     reading of termios(3)'s rules (FF FF = FF, FF 00 X = damaged X, FF Y = damaged) gives;
//   - first_damaged <= clean_from <= size, and both 0 when nothing was damaged.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/link/line_marks.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace {
void check(bool ok) {
  if (!ok) __builtin_trap();
}

/** termios(3)'s rules read the simplest way: the data and the damage of a whole stream. */
std::vector<std::uint8_t> reference(const std::uint8_t* p, std::size_t n, std::size_t& damaged) {
  std::vector<std::uint8_t> out;
  damaged = 0;
  for (std::size_t i = 0; i < n;) {
    if (p[i] != 0xFF) {
      out.push_back(p[i++]);
    } else if (i + 1 == n) {
      break;  // an escape the stream ends inside
    } else if (p[i + 1] == 0xFF) {
      out.push_back(0xFF);
      i += 2;
    } else if (p[i + 1] == 0x00) {
      if (i + 2 == n) break;  // a mark the stream ends inside
      ++damaged;
      i += 3;
    } else {
      ++damaged;
      i += 2;
    }
  }
  return out;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t cut = data[0];
  const std::uint8_t* raw = data + 1;
  const std::size_t n = size - 1;

  std::size_t want_damaged = 0;
  const auto want = reference(raw, n, want_damaged);

  for (const std::size_t step : {n > 0 ? n : std::size_t{1}, std::size_t{1}, std::size_t{cut % 7u + 1u}}) {
    rcb4::link::line_marks m;
    std::vector<std::uint8_t> got;
    std::size_t damaged = 0;
    for (std::size_t at = 0; at < n; at += step) {
      const std::size_t len = at + step <= n ? step : n - at;
      std::vector<std::uint8_t> chunk(raw + at, raw + at + len);
      const auto d = m.decode(chunk);
      check(d.size <= len);
      check(d.first_damaged <= d.clean_from && d.clean_from <= d.size);
      if (d.damaged == 0) check(d.first_damaged == 0 && d.clean_from == 0);
      got.insert(got.end(), chunk.begin(), chunk.begin() + static_cast<std::ptrdiff_t>(d.size));
      damaged += d.damaged;
    }
    check(got == want);
    check(damaged == want_damaged);
  }
  return 0;
}
