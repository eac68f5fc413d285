// demo: the Quick start's demo. A virtual RCB-4 (or a real one: rcb4_demo /dev/ttyUSB0) plays
// motion 2 from its ROM, the way KONDO's tools do, while this program reads every servo 10 times
// a second and draws the ones that move.
// SPDX-License-Identifier: BSL-1.0
#include "example_board.hpp"

#include <rcb4/transport/operations.hpp>

#include <chrono>
#include <map>
#include <string>
#include <thread>

int main(int argc, char** argv) try {
  using namespace rcb4;
  example::connection board(argc, argv);
  auto& c = *board;
  std::printf("board: %s\n", transport::run(c, ops::read_version{}).c_str());
  const auto start_states = transport::run(c, ops::read_servo_states{});
  std::printf("%zu servos allocated; playing motion 2 (KONDO's four steps: suspend, reset, CALL, resume)\n\n",
              start_states.size());
  transport::run(c, ops::play_motion(2));

  std::map<unsigned, std::uint16_t> first;
  for (const auto& s : start_states) first[s.ics.value()] = s.position;
  auto next = std::chrono::steady_clock::now();
  const auto t0 = next;
  std::size_t moved = 0;
  for (int sample = 0; sample < 40; ++sample) {
    const auto states = transport::run(c, ops::read_servo_states{});
    const auto motion = transport::run(c, ops::read_motion_state{});
    std::string line;
    for (const auto& s : states) {
      const double deg = ops::to_degrees(servo_position::make(s.position).value());
      if (s.position == first[s.ics.value()]) continue;
      ++moved;
      const int bar = static_cast<int>((deg + 90) / 180 * 24);  // -90..+90 degrees over 24 columns
      std::string gauge(25, '.');
      gauge[12] = '|';
      if (bar >= 0 && bar <= 24) gauge[static_cast<std::size_t>(bar)] = '#';
      char cell[80];
      std::snprintf(cell, sizeof cell, "  ICS %2u %+6.1f° [%s]", s.ics.value(), deg, gauge.c_str());
      line += cell;
    }
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("%4.1f s %-9s%s\n", t, motion.running ? "running" : "idle", line.c_str());
    if (!motion.running && sample > 0) break;
    next += std::chrono::milliseconds(100);
    std::this_thread::sleep_until(next);
  }
  std::printf("\n%s\n", moved > 0 ? "the servos moved and came back: the motion played."
                                  : "no servo moved (is the ROM program of this board playing motion 2?)");
  return moved > 0 ? 0 : 2;
} catch (const std::exception& e) {
  std::fprintf(stderr, "demo: %s\n", e.what());
  return 1;
}
