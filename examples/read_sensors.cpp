// read_sensors: the battery, the 11 AD channels, PIO and the KRR receiver, five times a second.
// Run: rcb4_read_sensors [/dev/ttyUSB0] [samples]   (no device: a virtual board)
// SPDX-License-Identifier: BSL-1.0
#include "example_board.hpp"

#include <rcb4/transport/operations.hpp>

#include <chrono>
#include <cstdlib>
#include <thread>

int main(int argc, char** argv) try {
  using namespace rcb4;
  example::connection board(argc > 1 && argv[1][0] ? 2 : 1, argv);
  const int samples = argc > 2 ? std::atoi(argv[2]) : 5;
  auto& c = *board;
  auto next = std::chrono::steady_clock::now();
  for (int i = 0; i < samples; ++i) {
    const auto ad = transport::run(c, ops::read_analog{});
    const auto pio = transport::run(c, ops::read_pio{});
    const auto rx = transport::run(c, ops::read_receiver{});
    std::printf("battery %5.2f V  AD1..AD10", ad.battery_volts);
    for (std::size_t k = 1; k < ad.values.size(); ++k) std::printf(" %4u", ad.values[k]);
    std::printf("  PIO 0x%03X  buttons 0x%04X  PA %u %u %u %u\n", pio.value, rx.buttons, rx.analog[0], rx.analog[1],
                rx.analog[2], rx.analog[3]);
    next += std::chrono::milliseconds(200);
    std::this_thread::sleep_until(next);
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "read_sensors: %s\n", e.what());
  return 1;
}
