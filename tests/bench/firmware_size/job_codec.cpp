// The firmware-size bench's job, written with the codec's command types as a firmware author
// would from docs/codec.md: ping, read the config word and 20 servo positions, move 2 servos with
// one CONST. Every reply is checked (its size, checksum, kind and length: parse_reply with the
// command's expected shape); a reply that does not come within 100 ms fails the job.
// SPDX-License-Identifier: BSL-1.0
#include "exchange.hpp"

using bench::exchange;

int main() {
  using namespace rcb4;
  if (auto r = exchange(ping{}); !r || !r->is_ack()) bench::finish(1);
  const auto config = exchange(move::read_ram(ram::config, 2).value());
  if (!config || config->bytes().size() != 2) bench::finish(2);
  std::uint32_t sum = config->bytes()[0];
  for (unsigned i = 0; i < 20; ++i) {
    const auto at = move::read_ics(ics_number::make(i).value(), servo_block::position.offset, 2).value();
    const auto r = exchange(at);
    if (!r || r->bytes().size() != 2) bench::finish(3);
    sum += static_cast<std::uint32_t>(r->bytes()[0] | r->bytes()[1] << 8);
  }
  servo_set<servo_position> two{{ics_number{1}, servo_position{8000}}, {ics_number{3}, servo_position{7000}}};
  if (auto r = exchange(const_servo::make(two, frames{20}).value()); !r || !r->is_ack()) bench::finish(4);
  bench::finish(sum == 0 ? 5 : 0);
}
