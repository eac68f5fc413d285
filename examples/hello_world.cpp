// hello_world: connect, say hello (ping and VERSION), read the config, move one servo and read
// it back. Run: rcb4_hello_world [/dev/ttyUSB0]   (no device: a virtual board)
// SPDX-License-Identifier: BSL-1.0
#include "example_board.hpp"

#include <rcb4/transport/operations.hpp>

#include <chrono>
#include <thread>

int main(int argc, char** argv) try {
  using namespace rcb4;
  example::connection board(argc, argv);
  auto& c = *board;

  c.execute(ping{});  // throws if the board does not answer
  std::printf("board says: %s\n", transport::run(c, ops::read_version{}).c_str());

  const config_word cfg = transport::run(c, ops::read_config{});
  std::printf("config 0x%04X: servos %s, ROM program %s, %u baud\n", cfg.encode(), cfg.ics_enabled ? "on" : "off",
              cfg.rom_program ? "on" : "off", static_cast<unsigned>(bits_per_second(cfg.com_baud)));

  // ICS 0 to +30 degrees in 20 frames (20 x 10 ms), then read its measured position.
  c.execute(single_servo(ics_number{0}, ops::from_degrees(30).value(), frames{20}));
  std::this_thread::sleep_for(std::chrono::milliseconds(400));  // let it get there
  for (const auto& s : transport::run(c, ops::read_servo_states{}))
    if (s.ics == ics_number{0})
      std::printf("ICS 0 is at %u (%.1f degrees)\n", s.position,
                  ops::to_degrees(servo_position::make(s.position).value()));
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "hello_world: %s\n", e.what());
  return 1;
}
