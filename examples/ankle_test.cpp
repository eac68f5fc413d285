// ankle_test: swing two ankle servos together (one CONST frame per pose), three times, and check
// after each pose that both reached it. The ICS numbers depend on how your robot is wired.
// Run: rcb4_ankle_test [/dev/ttyUSB0] [left_ics right_ics]   (no device: a virtual board; ICS 7, 8)
// SPDX-License-Identifier: BSL-1.0
#include "example_board.hpp"

#include <rcb4/transport/operations.hpp>

#include <chrono>
#include <cstdlib>
#include <thread>

int main(int argc, char** argv) try {
  using namespace rcb4;
  example::connection board(argc > 1 && argv[1][0] ? 2 : 1, argv);
  auto& c = *board;
  const auto left = ics_number::make(argc > 3 ? std::atoi(argv[2]) : 7).value();
  const auto right = ics_number::make(argc > 3 ? std::atoi(argv[3]) : 8).value();
  int misses = 0;
  for (int swing = 0; swing < 3; ++swing)
    for (const double degrees : {15.0, -15.0, 0.0}) {
      const auto target = ops::from_degrees(degrees).value();
      servo_set<servo_position> pose{{left, target}, {right, target}};
      c.execute(const_servo::make(pose, frames{15}).value());  // 15 frames of 10 ms
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
      for (const auto& s : transport::run(c, ops::read_servo_states{}))
        if (s.ics == left || s.ics == right) {
          const int error = static_cast<int>(s.position) - static_cast<int>(target.value());
          if (std::abs(error) > 40) ++misses;  // ~1.4 degrees
          std::printf("swing %d  %+5.1f deg  ICS %2u at %5u (error %+d)\n", swing + 1, degrees, s.ics.value(),
                      s.position, error);
        }
    }
  std::printf("%s\n", misses == 0 ? "both ankles followed every pose" : "some poses were not reached");
  return misses == 0 ? 0 : 2;
} catch (const std::exception& e) {
  std::fprintf(stderr, "ankle_test: %s\n", e.what());
  return 1;
}
