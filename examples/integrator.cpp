// integrator: a closed loop at 50 Hz. It reads a gyro on an AD channel, integrates its rate into
// a tilt angle, and turns an ankle servo the other way by that angle.
// Run: rcb4_integrator [/dev/ttyUSB0] [ad_channel ics]   (no device: a virtual board, AD 3, ICS 7)
// On the virtual board, the example plays the gyro itself: 1 s of +20 deg/s, then 1 s at rest.
// Scale for a KONDO KRG-4 class gyro: about 0.67 deg/s per count around its rest value. Measure
// your own sensor before relying on it.
// SPDX-License-Identifier: BSL-1.0
#include "example_board.hpp"

#include <rcb4/transport/operations.hpp>

#include <chrono>
#include <cstdlib>
#include <thread>

int main(int argc, char** argv) try {
  using namespace rcb4;
  using clock = std::chrono::steady_clock;
  example::connection board(argc > 1 && argv[1][0] ? 2 : 1, argv);
  auto& c = *board;
  const unsigned channel = argc > 3 ? static_cast<unsigned>(std::atoi(argv[2])) : 3;
  const auto ankle = ics_number::make(argc > 3 ? std::atoi(argv[3]) : 7).value();
  if (channel < 1 || channel >= ram::ad_channels) throw std::runtime_error("AD channel must be 1..10");
  constexpr double deg_per_count = 0.67;
  constexpr std::chrono::milliseconds period{20};

  // The rest value: the average of 10 samples while the robot stands still.
  double rest = 0;
  for (int i = 0; i < 10; ++i) rest += transport::run(c, ops::read_analog{}).values[channel] / 10.0;

  double angle = 0;
  auto next = clock::now();
  const auto start = next;
  for (int step = 0; step < 100; ++step) {  // 2 s
    if (board.board) {                      // the virtual board: feed the gyro (on the board's own thread)
      const bool turning = clock::now() - start < std::chrono::seconds(1);
      const auto raw = static_cast<std::uint16_t>(rest + (turning ? 20.0 / deg_per_count : 0.0));
      boost::asio::post(board.board_io->context(), [&b = *board.board, channel, raw] { b.set_ad_raw(channel, raw); });
    }
    const double rate = (transport::run(c, ops::read_analog{}).values[channel] - rest) * deg_per_count;
    angle += rate * std::chrono::duration<double>(period).count();
    const auto target = ops::from_degrees(-angle);
    if (target) c.execute(single_servo(ankle, *target, frames{2}));
    if (step % 10 == 9)
      std::printf("t=%.1f s  rate %+6.1f deg/s  tilt %+6.1f deg  ankle %+6.1f deg\n",
                  std::chrono::duration<double>(clock::now() - start).count(), rate, angle, -angle);
    next += period;
    std::this_thread::sleep_until(next);
  }
  std::printf("integrated tilt after 2 s: %+.1f deg\n", angle);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "integrator: %s\n", e.what());
  return 1;
}
