// Built with -fno-exceptions -fno-rtti (and, where present, arm-none-eabi-g++ -mcpu=cortex-m4):
// the whole codec in firmware. Only <rcb4/rcb4.hpp> is included.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/rcb4.hpp>

// What a microcontroller does: build a frame into a static buffer and parse the reply.
extern "C" unsigned rcb4_firmware_probe(const unsigned char* rx, unsigned rx_len, unsigned char* tx) {
  using namespace rcb4;
  servo_set<servo_position> targets;
  for (int i = 0; i < 36; ++i) targets.insert(ics_number::make(i).value(), servo_position{7500});
  auto c = const_servo::make(targets, 10);
  if (!c) return 0;
  auto n = serialize(*c, std::span<std::uint8_t>(tx, 128));
  auto r = parse_reply(std::span<const std::uint8_t>(rx, rx_len), expected_reply(*c));
  auto p = parse_command(std::span<const std::uint8_t>(rx, rx_len));
  return static_cast<unsigned>(n.value_or(0) + r.consumed + p.consumed);
}
