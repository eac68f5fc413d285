// The codec on a microcontroller: standard library only, no heap, no exceptions, no RTTI.
// A firmware would call uart_write()/uart_read(); here they are a loopback so the example runs
// on a PC too (the test suite runs it, and builds it with -fno-exceptions -fno-rtti).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/rcb4.hpp>

#include <array>
#include <cstdio>

namespace {
std::array<std::uint8_t, rcb4::max_reply_size> g_line{};  // what the "board" answers
std::size_t g_line_size = 0;

void uart_write(std::span<const std::uint8_t> frame) {
  // Loopback stand-in for a board: ACK every frame it receives.
  const auto parsed = rcb4::parse_command(frame);
  const auto ack = parsed.ok() ? rcb4::reply::ack(parsed.command) : rcb4::reply::nack(parsed.command);
  g_line_size = rcb4::serialize(ack, g_line).value_or(0);
}
std::span<const std::uint8_t> uart_read() { return {g_line.data(), g_line_size}; }
}  // namespace

int main() {
  using namespace rcb4;
  // Stand the robot up: every servo to the centre over 50 frames.
  servo_set<servo_position> all;
  for (std::uint8_t i = 0; i < 35; ++i) all.insert(ics_number::make(i).value(), servo_position{});
  const auto cmd = const_servo::make(all, 50).value();

  std::array<std::uint8_t, max_request_size> tx{};
  const auto n = serialize(cmd, tx).value();
  uart_write({tx.data(), n});
  const auto r = parse_reply(uart_read(), expected_reply(cmd));
  std::printf("sent %zu bytes, board answered %s\n", n, r.ok() && r.value().is_ack() ? "ACK" : "something else");
  return r.ok() && r.value().is_ack() ? 0 : 1;
}
