// Virtual-board benchmarks: the emulator's cost per command (target ≤ 1 µs), and a ping round
// trip through `rcb4 serve`'s pty server next to a raw pty echo measured in the same run
// (target ≤ 1.2× the echo). Figures are printed, never asserted.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/board/virtual_board.hpp>
#include <rcb4/transport/board_server.hpp>

#include "pty_echo.hpp"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <thread>

namespace {
using namespace rcb4;

void feed(benchmark::State& state, const request_frame& frame) {
  board::virtual_board b;
  std::vector<std::uint8_t> out;
  out.reserve(512);
  board::board_time now{0};
  for (auto _ : state) {
    out.clear();
    now += std::chrono::microseconds(1);  // stays within one output period: no tick in the loop
    if (now.count() > 9000) now = board::board_time{0} + b.now();
    b.receive(frame.bytes(), now, out);
    benchmark::DoNotOptimize(out.data());
  }
}
void BM_board_ping(benchmark::State& s) { feed(s, encode(ping{})); }
void BM_board_mov_read_2(benchmark::State& s) { feed(s, encode(move::read_ram(0x0090, 2).value())); }
void BM_board_const36(benchmark::State& s) {
  servo_set<servo_position> all;
  for (int i = 0; i < 36; ++i) all.insert(ics_number::make(i).value(), 7600);
  feed(s, encode(const_servo::make(all, 10).value()));
}
BENCHMARK(BM_board_ping);
BENCHMARK(BM_board_mov_read_2);
BENCHMARK(BM_board_const36);

}  // namespace

int main(int argc, char** argv) {
  std::printf("virtual board benchmarks. Targets: <= 1 us per command; pty ping <= 1.2x a raw pty echo.\n");
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();

  const int n = 20000;
  const std::uint8_t ping_frame[] = {0x04, 0xFE, 0x06, 0x08};
  boost::asio::io_context io;
  auto work = boost::asio::make_work_guard(io);
  std::thread runner([&io] { io.run(); });
  double echo_us = 0, serve_us = 0;
  {
    rcb4::testing::pty_echo echo_pty(io);
    board::virtual_board board;
    auto server = transport::board_server::serve_pty(io, board);
    for (int round = 0; round < 2; ++round) {  // interleaved to share the machine's noise
      echo_us += rcb4::testing::pty_round_trips(echo_pty.path(), ping_frame, 4, n) / 2;
      serve_us += rcb4::testing::pty_round_trips(server->where(), ping_frame, 4, n) / 2;
    }
    transport::board_server::shutdown(server);  // the board must outlive the server's last use of it
  }
  std::printf("\npty round trip, %d pings each, two interleaved rounds:\n", 2 * n);
  std::printf("  raw pty echo (floor)        %7.2f us\n", echo_us);
  std::printf("  rcb4 serve --pty, ping      %7.2f us   = %.2fx the floor (target <= 1.2x)\n", serve_us,
              serve_us / echo_us);
  work.reset();
  runner.join();
  return 0;
}
