// libFuzzer harness: host-side reply parsing (what a client does with whatever the line gives).
// The first three input bytes choose the expected reply shape (CMD, data or ACK, data size);
// the rest is the stream. Properties:
//   - consumed never exceeds the input; need_more asks for ≥ 1 byte and never past the
//     declared frame length;
//   - a complete parse is a frame with a correct checksum, the expected echo and an allowed
//     length, and re-encodes to exactly the consumed bytes;
//   - split invariance: feeding any prefix, then exactly what is asked for, gives the same result;
//   - parse_reply_frame (shape-free) agrees on the frame length;
//   - the stream's first 70 bytes, read as an ICS allocation table, give whole, even,
//     non-overlapping blocks inside the user area, or errc::bad_allocation_table.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/ops/servos.hpp>
#include <rcb4/rcb4.hpp>

#include <algorithm>

namespace {
void check(bool ok) {
  if (!ok) __builtin_trap();
}

void check_allocation_table(std::span<const std::uint8_t> table) {
  const auto slots = rcb4::ops::parse_allocation_table(table);
  if (!slots) {
    check(slots.error() == rcb4::errc::bad_allocation_table);
    return;
  }
  std::uint32_t previous_end = 0;
  unsigned previous_ics = 0;
  bool first = true;
  auto sorted = *slots;
  for (const auto& s : *slots) {
    check(first || s.ics.value() > previous_ics);  // ascending by ICS, each once
    previous_ics = s.ics.value();
    first = false;
    check(s.address >= 0x0090 && s.address + 20u <= 0x0490 && s.address % 2 == 0);
    const std::size_t k = s.ics.value();
    check(s.address == (table[2 * k] | (table[2 * k + 1] << 8)));
  }
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.address < b.address; });
  for (const auto& s : sorted) {
    check(s.address >= previous_end);
    previous_end = s.address + 20u;
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 3) return 0;
  // Every shape a user can build (reply_shape is a public aggregate): any data size, 0 and 253-255
  // included, and a data size with data off. A parser on a serial line never traps on any of them.
  const std::uint8_t n = data[2];
  const rcb4::reply_shape shape{data[0], (data[1] & 1) != 0, n};
  const std::span<const std::uint8_t> in(data + 3, size - 3);
  if (in.size() >= 70) check_allocation_table(in.first(70));

  const auto r = rcb4::parse_reply(in, shape);
  check(r.consumed <= in.size());
  if (r.status == rcb4::parse_status::need_more) {
    check(r.needed >= 1);
    if (!in.empty()) check(in.size() + r.needed <= std::max<std::size_t>(in[0], 4));
    return 0;
  }
  if (r.status == rcb4::parse_status::error) {
    check(r.error != rcb4::errc{});
    return 0;
  }
  const auto frame = in.first(r.consumed);
  check(frame.size() == shape.frame_size() || frame.size() == rcb4::ack_frame_size);
  check(frame[1] == shape.command);
  check(rcb4::checksum_ok(frame));
  const auto again = rcb4::encode(r.value());
  check(again.size() == frame.size() && std::equal(again.begin(), again.end(), frame.begin()));
  if (!shape.data) check(r.value().kind() != rcb4::reply_kind::data);
  if (shape.data && r.value().kind() == rcb4::reply_kind::data) check(r.value().bytes().size() == shape.data_size);

  // Split invariance: from every prefix, reading exactly what is asked gives the same reply.
  for (std::size_t cut = 0; cut < frame.size(); ++cut) {
    std::size_t have = cut;
    auto p = rcb4::parse_reply(frame.first(have), shape);
    while (p.status == rcb4::parse_status::need_more) {
      have += p.needed;
      check(have <= frame.size());
      p = rcb4::parse_reply(frame.first(have), shape);
    }
    check(p.ok() && p.consumed == frame.size() && p.value() == r.value());
  }
  const auto any = rcb4::parse_reply_frame(frame);
  check(any.ok() && any.consumed == frame.size());
  return 0;
}
