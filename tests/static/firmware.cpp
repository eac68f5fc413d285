// Built with -fno-exceptions -fno-rtti (and, where present, arm-none-eabi-g++ -mcpu=cortex-m4):
// the whole codec in firmware: <rcb4/rcb4.hpp> and the ICS servo codec <rcb4/ics/commands.hpp>.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/ics/commands.hpp>
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

// A microcontroller that sets up an ICS servo: read its EEPROM, change the stretch, write it back.
extern "C" unsigned rcb4_firmware_ics_probe(const unsigned char* rx, unsigned rx_len, unsigned char* tx) {
  using namespace rcb4::ics;
  const auto id = servo_id::make(rx_len % 32).value();
  const read_eeprom read(id);
  const auto got = parse_exchange(read, std::span<const std::uint8_t>(rx, rx_len));
  if (!got.ok()) return 0;
  auto image = got.value();
  if (!image.set(field::stretch, 40)) return 0;
  const auto f = write_eeprom(id, image).request();
  for (std::size_t i = 0; i < f.size; ++i) tx[i] = f.data[i];
  return static_cast<unsigned>(f.size);
}
