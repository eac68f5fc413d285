// libFuzzer harness: the ICS codec (rcb4/ics) on whatever a line or a file gives. Input byte 0
// picks the command, byte 1 its ID, byte 2 its value; the rest is what came back. Properties:
//   - parse_exchange consumes no more than it got; need_more asks for ≥ 1 byte, exactly what the
//     echo and the reply still lack; complete means the echo is the request, byte for byte;
//   - a request parsed on the servo side writes back to exactly the bytes it was read from;
//   - an EEPROM image that parses has nibbles only and the check mark; setting any field to the
//     value it reads (when in range) reads back that value and, but for the doubled stretch
//     fields, changes no byte; with_factory_of() of itself is itself;
//   - the virtual line echoes every byte first and never crashes on noise.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/ics/commands.hpp>
#include <rcb4/ics/virtual_servo.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace {
void check(bool ok) {
  if (!ok) __builtin_trap();
}

using rcb4::ics::servo_id;

template <class Cmd>
void exchange(const Cmd& c, std::span<const std::uint8_t> rx) {
  const auto r = rcb4::ics::parse_exchange(c, rx);
  const auto req = c.request();
  check(r.consumed <= rx.size());
  if (r.status == rcb4::parse_status::need_more) {
    check(r.needed >= 1 && rx.size() + r.needed == req.size + Cmd::reply_size);
  } else if (r.ok()) {
    check(r.consumed == req.size + Cmd::reply_size);
    check(std::equal(req.data.begin(), req.data.begin() + static_cast<std::ptrdiff_t>(req.size), rx.begin()));
  }
}

template <class Cmd>
void request_round_trip(std::span<const std::uint8_t> f) {
  const auto c = Cmd::parse(f);
  if (!c) return;
  const auto back = c->request();
  check(back.size == f.size() && std::equal(f.begin(), f.end(), back.data.begin()));
}

void image(std::span<const std::uint8_t> raw) {
  const auto e = rcb4::ics::eeprom_image::parse(raw);
  if (!e) return;
  for (auto b : e->bytes()) check(b <= 0x0F);
  check(e->bytes()[0] == 0x05 && e->bytes()[1] == 0x0A);
  check(e->with_factory_of(*e) == *e && e->same_unit(*e));
  for (const auto& i : rcb4::ics::fields) {
    auto copy = *e;
    const long v = e->get(i.f);
    if (!copy.set(i.f, v)) continue;
    check(copy.get(i.f) == v);
    // A stretch is stored doubled: an odd stored byte (no tool writes one) reads back one lower.
    const bool doubled = i.f == rcb4::ics::field::stretch || i.f >= rcb4::ics::field::stretch_1;
    if (!doubled) check(copy == *e);
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 3) return 0;
  const auto id = servo_id::make(data[1] & 0x1F).value();
  const std::span<const std::uint8_t> rx(data + 3, size - 3);
  using namespace rcb4::ics;
  switch (data[0] % 8) {
    case 0:
      if (auto c = set_position::make(id, 3500 + data[2] * 31)) exchange(*c, rx);
      exchange(set_position::free(id), rx);
      break;
    case 1:
      if (auto c = read_parameter::make(id, static_cast<sub>(1 + data[2] % 4))) exchange(*c, rx);
      break;
    case 2:
      if (auto c = write_parameter::make(id, static_cast<sub>(1 + data[2] % 4), 1 + data[2] % 63)) exchange(*c, rx);
      break;
    case 3: exchange(read_position(id), rx); break;
    case 4: exchange(read_eeprom(id), rx); break;
    case 5:
      exchange(read_id{}, rx);
      exchange(write_id(id), rx);
      break;
    case 6: {
      if (rx.size() >= 64) {
        image(rx.first(64));
        if (auto e = eeprom_image::parse(rx.first(64))) exchange(write_eeprom(id, *e), rx.subspan(64));
      }
      image(rx);
      break;
    }
    default: {
      request_round_trip<set_position>(rx);
      request_round_trip<read_parameter>(rx);
      request_round_trip<write_parameter>(rx);
      request_round_trip<read_position>(rx);
      request_round_trip<read_eeprom>(rx);
      request_round_trip<write_eeprom>(rx);
      request_round_trip<read_id>(rx);
      request_round_trip<write_id>(rx);
      virtual_line line({virtual_servo(id, 115200, data[2])}, line_faults{false, (data[2] & 1) != 0});
      std::vector<std::uint8_t> out;
      line.feed(rx, 115200, line_time{data[2]}, out);
      check(out.size() >= rx.size() && std::equal(rx.begin(), rx.end(), out.begin()));
      break;
    }
  }
  return 0;
}
