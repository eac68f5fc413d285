// The firmware-size bench's job through the documented operations path (docs/firmware.md): the
// library's link (rcb4/link/device_link.hpp) over the polled UART, ops::read_config, every
// allocated servo read through the planner (ops::read_servo_states_fixed), then one CONST.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/link/device_link.hpp>
#include <rcb4/link/requests.hpp>
#include <rcb4/ops/servos.hpp>
#include <rcb4/ops/system.hpp>

#include "uart.hpp"

#include <chrono>

namespace {

struct uart {
  bool poll_in(std::uint8_t& b) noexcept { return bench::uart_poll_in(b); }
  bool poll_out(std::uint8_t b) noexcept { return bench::uart_poll_out(b); }
};

struct clock {
  using rep = std::int64_t;
  using period = std::milli;
  using duration = std::chrono::duration<rep, period>;
  using time_point = std::chrono::time_point<clock, duration>;
  static time_point now() noexcept { return time_point{duration{bench::now_ms()}}; }
};

using device = rcb4::link::polled_uart_device<uart>;
using board_link = rcb4::link::device_link<device, clock>;

}  // namespace

int main() {
  using namespace rcb4;
  uart u;
  device d(u);
  link::options opt;
  board_link board(d, opt);
  if (auto r = board.exchange(link::request_of(ping{})); !r || !r->is_ack()) bench::finish(1);
  ops::read_config config;
  if (link::run(board, config) != errc{}) bench::finish(2);
  ops::read_servo_states_fixed states;
  if (link::run(board, states) != errc{} || states.value().size() < 2) bench::finish(3);
  servo_set<servo_position> two;
  two.insert(states.value()[0].ics, servo_position{8000});
  two.insert(states.value()[1].ics, servo_position{7000});
  const auto move = const_servo::make(two, frames{20});
  if (!move) bench::finish(4);
  if (auto r = board.exchange(link::request_of(*move)); !r || !r->is_ack()) bench::finish(4);
  bench::finish(config.value().encode() == 0 ? 5 : 0);
}
