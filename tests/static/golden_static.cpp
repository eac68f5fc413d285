// Compile-time checks: every golden frame (tests/support/golden.hpp) is produced by encode()
// from its API value and parses back to that value; every golden reply parses as written.
// SPDX-License-Identifier: BSL-1.0
#include "golden.hpp"

#include <rcb4/ics/commands.hpp>

#include <algorithm>
#include <variant>

namespace {
using namespace rcb4;

template <std::size_t N>
constexpr bool same(const byte_buffer<N>& a, std::span<const std::uint8_t> b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end());
}

constexpr bool requests_encode() {
  for (const auto& g : golden::requests)
    if (!same(encode(g.value), g.frame)) return false;
  return true;
}
constexpr bool requests_parse() {
  for (const auto& g : golden::requests) {
    auto r = parse_command(g.frame, g.options);
    if (!r.ok() || r.consumed != g.frame.size() || !(r.value() == g.value)) return false;
  }
  return true;
}
constexpr bool requests_wire_size() {
  for (const auto& g : golden::requests)
    if (wire_size(g.value) != g.frame.size()) return false;
  return true;
}
constexpr bool replies_parse() {
  for (const auto& g : golden::replies) {
    auto r = parse_reply(g.frame, g.expected);
    if (!r.ok() || r.consumed != g.frame.size() || !(r.value() == g.value)) return false;
  }
  return true;
}
constexpr bool replies_encode() {
  for (const auto& g : golden::replies)
    if (!same(encode(g.value), g.frame)) return false;
  return true;
}

static_assert(requests_encode(), "a golden request frame differs from encode(value)");
static_assert(requests_parse(), "a golden request frame does not parse to its value");
static_assert(requests_wire_size(), "wire_size() disagrees with a golden frame");
static_assert(replies_parse(), "a golden reply does not parse as written");
static_assert(replies_encode(), "board-side reply encoding differs from a golden reply");

// The board's reply shapes for the golden commands (protocol.md §3 "reply" column).
static_assert(expected_reply(command{move::read_ram(0x0000, 2).value()}) == reply_shape{0x00, true, 2});
static_assert(expected_reply(command{version{}}).frame_size() == 35);
static_assert(expected_reply(command{call{0x000B80}}) == reply_shape{0x0C, false, 0});
static_assert(expected_reply(command{move::read_ram(0x0090, 126).value()}).frame_size() == 129);

// Fixed-size commands serialize into std::array of exactly their length.
static_assert(to_array(ret{}) == std::array<std::uint8_t, 3>{0x03, 0x0D, 0x10});
static_assert(to_array(call{0x000B80}) == std::array<std::uint8_t, 7>{0x07, 0x0C, 0x80, 0x0B, 0x00, 0x00, 0x9E});

// The ICS codec at compile time: ics.md §2.4's worked examples, written by hand.
constexpr bool ics_same(const ics::frame& f, std::initializer_list<std::uint8_t> want) {
  return f.size == want.size() && std::equal(want.begin(), want.end(), f.data.begin());
}
constexpr auto ics_id(unsigned n) { return ics::servo_id::make(n).value(); }
static_assert(ics_same(ics::set_position::make(ics_id(3), 8833).value().request(), {0x83, 0x45, 0x01}));
static_assert(ics_same(ics::read_parameter::make(ics_id(12), ics::sub::temperature).value().request(), {0xAC, 0x04}));
static_assert(ics_same(ics::write_id(ics_id(9)).request(), {0xE9, 0x01, 0x01, 0x01}));
static_assert(ics::parse_exchange(ics::read_id{}, std::array<std::uint8_t, 5>{0xFF, 0x00, 0x00, 0x00, 0xEC}).value() ==
              ics_id(12));
static_assert(ics::parse_exchange(ics::set_position::make(ics_id(3), 8833).value(),
                                  std::array<std::uint8_t, 6>{0x83, 0x45, 0x01, 0x03, 0x3A, 0x4E})
                  .value() == 7502);
static_assert(ics::position::counts(45.0).value() == 8833);
}  // namespace
