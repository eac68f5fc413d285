// Virtual-board benchmarks: the emulator's cost per command (target ≤ 1 µs), and a ping round
// trip through `rcb4 serve`'s pty server next to a raw pty echo measured in the same run
// (target ≤ 1.2× the echo). Figures are printed, never asserted.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/board/virtual_board.hpp>
#include <rcb4/transport/board_server.hpp>

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

/** Opens @p path raw and measures @p n round trips of @p request; µs per round trip. */
double round_trips(const std::string& path, std::span<const std::uint8_t> request, std::size_t reply_size, int n) {
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY);
  termios t{};
  ::tcgetattr(fd, &t);
  ::cfmakeraw(&t);
  ::tcsetattr(fd, TCSANOW, &t);
  std::array<std::uint8_t, 64> buf{};
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < n; ++i) {
    if (::write(fd, request.data(), request.size()) != static_cast<ssize_t>(request.size())) break;
    std::size_t got = 0;
    while (got < reply_size) {
      const auto r = ::read(fd, buf.data() + got, buf.size() - got);
      if (r <= 0) break;
      got += static_cast<std::size_t>(r);
    }
  }
  const auto us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  ::close(fd);
  return us / n;
}

/** A raw echo on a pty master: the floor any pty server can reach on this machine. */
boost::asio::awaitable<void> echo(boost::asio::posix::stream_descriptor& s) {
  std::array<std::uint8_t, 512> buf{};
  for (;;) {
    boost::system::error_code ec;
    const auto n = co_await s.async_read_some(boost::asio::buffer(buf),
                                              boost::asio::redirect_error(boost::asio::use_awaitable, ec));
    if (ec) co_return;
    co_await boost::asio::async_write(s, boost::asio::buffer(buf.data(), n),
                                      boost::asio::redirect_error(boost::asio::use_awaitable, ec));
    if (ec) co_return;
  }
}
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
  transport::pty_pair echo_pty;
  boost::asio::posix::stream_descriptor echo_stream(io, echo_pty.release_master());
  boost::asio::co_spawn(io, echo(echo_stream), boost::asio::detached);
  board::virtual_board board;
  auto server = transport::board_server::serve_pty(io, board);
  std::thread runner([&io] { io.run(); });
  double echo_us = 0, serve_us = 0;
  for (int round = 0; round < 2; ++round) {  // interleaved to share the machine's noise
    echo_us += round_trips(echo_pty.path(), ping_frame, 4, n) / 2;
    serve_us += round_trips(server->where(), ping_frame, 4, n) / 2;
  }
  std::printf("\npty round trip, %d pings each, two interleaved rounds:\n", 2 * n);
  std::printf("  raw pty echo (floor)        %7.2f us\n", echo_us);
  std::printf("  rcb4 serve --pty, ping      %7.2f us   = %.2fx the floor (target <= 1.2x)\n", serve_us,
              serve_us / echo_us);
  boost::asio::post(io, [&] {
    server->stop();
    echo_stream.close();
    work.reset();
  });
  runner.join();
  return 0;
}
