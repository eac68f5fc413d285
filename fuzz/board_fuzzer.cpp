// libFuzzer harness: the virtual board fed arbitrary bytes in arbitrary chunks and time steps.
// Input: [options byte] then chunks of [length][milliseconds to wait][length bytes ...].
// Properties, not just "no crash, no hang":
//   - everything the board sends is a sequence of well-formed reply frames (length, checksum),
//     each an ACK, a NACK or data, never more replies than complete frames received;
//   - the ICS allocation entries stay pointers into RAM or 0xFFFF unless the input wrote RAM;
//   - with strict timing, a ping after a 1 ms pause is always answered with exactly ACK.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/board/virtual_board.hpp>

namespace {
void check(bool ok) {
  if (!ok) __builtin_trap();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace rcb4;
  if (size < 1) return 0;
  board::options opt;
  opt.strict_timing = (data[0] & 1) != 0;
  opt.series = (data[0] & 2) ? board::series_behaviour::execute : board::series_behaviour::reboot;
  opt.shift = (data[0] & 4) ? shift_encoding::kondo_manual : shift_encoding::measured_2015;
  opt.allow_arith_to_com = (data[0] & 8) != 0;
  board::virtual_board b(opt);
  std::vector<std::uint8_t> out;
  board::board_time now{0};
  std::size_t i = 1;
  while (i + 2 <= size) {
    const std::size_t len = std::min<std::size_t>(data[i], size - i - 2);
    now += std::chrono::milliseconds(data[i + 1]);
    const auto before = b.stats().frames;
    out.clear();
    b.receive(std::span(data + i + 2, len), now, out);
    std::size_t replies = 0;
    for (std::size_t at = 0; at < out.size();) {
      const auto r = parse_reply_frame(std::span(out).subspan(at));
      check(r.ok());
      at += r.consumed;
      ++replies;
    }
    check(replies <= b.stats().frames - before);
    i += 2 + len;
  }
  if (opt.strict_timing) {
    const std::uint8_t ping[] = {0x04, 0xFE, 0x06, 0x08};
    out.clear();
    b.receive(ping, now + std::chrono::milliseconds(1), out);
    check(out.size() == 4 && std::equal(out.begin(), out.end(), ping));
  }
  return 0;
}
