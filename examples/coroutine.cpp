// coroutine: the asynchronous API with C++20 coroutines on one thread. Several servo moves are
// queued at once, a motion plays, and the program waits for it with a deadline, without blocking.
// Run: rcb4_coroutine [/dev/ttyUSB0]   (no device: a virtual board)
// SPDX-License-Identifier: BSL-1.0
#include "example_board.hpp"

#include <rcb4/transport/operations.hpp>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/use_future.hpp>

using namespace rcb4;
namespace asio = boost::asio;

asio::awaitable<void> robot(transport::basic_client<transport::serial_port>& c) {
  co_await c.async_execute(ping{}, asio::use_awaitable);
  const auto v = co_await transport::async_run(c, ops::read_version{});
  std::printf("connected: %s\n", v.c_str());
  // Queue three moves without waiting between them: the client sends them in order.
  for (int k = 0; k < 3; ++k)
    c.async_execute(single_servo(ics_number::make(k).value(), servo_position{8000}, frames{10}), asio::detached);
  const auto states = co_await transport::async_run(c, ops::read_servo_states{});
  std::printf("%zu servos allocated\n", states.size());
  co_await transport::async_run(c, ops::play_motion(3));  // bow
  const auto done = co_await transport::async_wait_motion(c, std::chrono::seconds(10), [](const ops::motion_state& s) {
    if (s.running) std::printf("  motion %u running\n", s.motion.value_or(0));
  });
  std::printf("motion finished, program at 0x%06X\n", static_cast<unsigned>(done.program_counter));
}

int main(int argc, char** argv) try {
  example::connection board(argc, argv);
  // The client's executor is the io thread's; the coroutine runs there.
  asio::co_spawn((*board).get_executor(), robot(*board), asio::use_future).get();
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "coroutine: %s\n", e.what());
  return 1;
}
