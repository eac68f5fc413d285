// The firmware-size bench's job (job_codec.cpp) with each command passed as the `rcb4::command`
// variant, as the operations and the transport take it today: what the variant costs an image.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/rcb4.hpp>

#include "uart.hpp"

#include <array>

namespace {

std::array<std::uint8_t, rcb4::max_reply_size> g_rx{};

rcb4::result<rcb4::reply> exchange(const rcb4::command& c) noexcept {
  std::array<std::uint8_t, rcb4::max_request_size> tx{};
  const auto n = rcb4::serialize(c, tx);
  if (!n) return n.error();
  for (std::size_t i = 0; i < *n; ++i) bench::uart_put(tx[i]);
  const std::uint32_t deadline = bench::now_ms() + 100;
  std::size_t got = 0;
  for (;;) {
    const auto p = rcb4::parse_reply({g_rx.data(), got}, rcb4::expected_reply(c));
    if (p.ok()) return p.value();
    if (p.status == rcb4::parse_status::error) return p.error;
    for (std::size_t k = 0; k < p.needed; ++k) {
      const int b = bench::uart_get(deadline);
      if (b < 0) return rcb4::errc::link_timeout;
      g_rx[got++] = static_cast<std::uint8_t>(b);
    }
  }
}

}  // namespace

int main() {
  using namespace rcb4;
  if (auto r = exchange(command{ping{}}); !r || !r->is_ack()) bench::finish(1);
  const auto config = exchange(command{move::read_ram(ram::config, 2).value()});
  if (!config || config->bytes().size() != 2) bench::finish(2);
  std::uint32_t sum = config->bytes()[0];
  for (unsigned i = 0; i < 20; ++i) {
    const auto r =
        exchange(command{move::read_ics(ics_number::make(i).value(), servo_block::position.offset, 2).value()});
    if (!r || r->bytes().size() != 2) bench::finish(3);
    sum += static_cast<std::uint32_t>(r->bytes()[0] | r->bytes()[1] << 8);
  }
  servo_set<servo_position> two{{ics_number{1}, servo_position{8000}}, {ics_number{3}, servo_position{7000}}};
  if (auto r = exchange(command{const_servo::make(two, frames{20}).value()}); !r || !r->is_ack()) bench::finish(4);
  bench::finish(sum == 0 ? 5 : 0);
}
