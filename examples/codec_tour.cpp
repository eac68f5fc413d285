// A tour of the codec: build the frames a host sends to play motion 1 and move servos, show
// each as hex and in words, then parse the replies a board would send back. No I/O at all:
// the codec is sans-I/O, so these bytes could go to any UART.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/fmt.hpp>
#include <rcb4/rcb4.hpp>

#include <fmt/core.h>

#include <cstdlib>

namespace {
void show(const rcb4::command& c) {
  const auto frame = rcb4::encode(c);
  fmt::print("  {:<44}  {}\n", rcb4::hex(frame.bytes()), c);
}
}  // namespace

int main() {
  using namespace rcb4;

  fmt::print("KONDO's motion-play sequence for motion 1 (HTH4 2.2+ layout, protocol.md §8.1):\n");
  const std::uint16_t config = 0x408B;  // as a board might report it
  auto suspended = config_word::decode(config);
  suspended.rom_program = suspended.vector_jump = suspended.ics_enabled = suspended.interpolation_message = false;
  const std::uint16_t suspended_word = suspended.encode();
  const std::uint8_t suspend_bytes[] = {static_cast<std::uint8_t>(suspended_word & 0xFF),
                                        static_cast<std::uint8_t>(suspended_word >> 8)};
  const std::uint32_t pc = hth4_2_2.main_loop.value();
  const std::uint8_t reset_pc[10] = {static_cast<std::uint8_t>(pc & 0xFF), static_cast<std::uint8_t>(pc >> 8),
                                     static_cast<std::uint8_t>(pc >> 16)};
  auto resumed = config_word::decode(config);
  resumed.rom_program = resumed.vector_jump = resumed.ics_enabled = true;
  resumed.interpolation_message = false;
  const std::uint16_t resumed_word = resumed.encode();
  const std::uint8_t resume_bytes[] = {static_cast<std::uint8_t>(resumed_word & 0xFF),
                                       static_cast<std::uint8_t>(resumed_word >> 8)};
  show(move::write_ram(ram::config, suspend_bytes).value());
  show(move::write_ram(ram::program_counter, reset_pc).value());
  show(call{motion_address(hth4_2_2, 1).value()});
  show(move::write_ram(ram::config, resume_bytes).value());

  fmt::print("\nServos (values sorted by ICS number whatever the order given, §4.7):\n");
  show(single_servo{0, 7500, 10});
  show(const_servo::make({{3, 8000}, {1, 7000}, {2, servo_position::free()}}, 30).value());
  show(servo_params::make(param_kind::stretch, {{0, 60}, {1, 60}}).value());

  fmt::print("\nReading state:\n");
  const auto read_config = move::read_ram(ram::config, 2).value();
  const auto read_pos = move::read_ics(3, servo_block::position.offset, 2).value();
  show(read_config);
  show(read_pos);

  fmt::print("\nParsing what the board answers (the reply shape is known from the command):\n");
  const std::uint8_t config_reply[] = {0x05, 0x00, 0x8B, 0x40, 0xD0};
  auto r = parse_reply(config_reply, expected_reply(read_config));
  if (!r.ok()) {
    fmt::print("unexpected: {}\n", r.error);
    return EXIT_FAILURE;
  }
  fmt::print("  {:<44}  {}\n  config {}\n", hex(config_reply), r.value(), config_word::decode(r.value().u16()));
  const std::uint8_t nack[] = {0x04, 0x00, 0x15, 0x19};
  auto n = parse_reply(nack, expected_reply(read_pos));
  fmt::print("  {:<44}  {}\n", hex(nack), n.value());
  const std::uint8_t corrupted[] = {0x05, 0x00, 0x8B, 0x40, 0xD1};
  auto bad = parse_reply(corrupted, expected_reply(read_config));
  fmt::print("  {:<44}  error: {}\n", hex(corrupted), bad.error);

  fmt::print("\nBad values never reach the wire:\n");
  fmt::print("  read 32 bytes at 0x0480: {}\n", move::read_ram(0x0480, 32).error());
  fmt::print("  ICS 40:                  {}\n", ics_number::make(40).error());
  fmt::print("  AND into COM:            {}\n",
             logic::make(logic_op::and_, destination::com(), source::literal_u8(1)).error());
  return bad.error == errc::bad_checksum && n.value().is_nack() ? EXIT_SUCCESS : EXIT_FAILURE;
}
