// Transport benchmarks, printed side by side in one run (never asserted):
//  - exchanges per second through the blocking API for ping, a 2-byte MOV read and CONST36 over
//    a pty against the virtual board, next to a raw pty echo floor (target >= 0.9x the floor)
//    and a bare blocking loop sending the same frame to a second board server; floors and
//    client take turns in rounds and the medians are printed (the machine's speed drifts);
//  - the same with the async API (a callback chain), next to a bare Asio coroutine loop;
//  - a control cycle (read every servo's state + write 36 servos) against the board paced at
//    1.25 Mbaud, next to the wire limit of those bytes (target >= 0.97x) and to the same cycle
//    by a bare blocking loop (what the pty allows any client);
//  - heap allocations per exchange in steady state (target 0), the client's only.
// SPDX-License-Identifier: BSL-1.0
#include "alloc_count.hpp"
#include "pty_echo.hpp"
#include "served_board.hpp"

#include <rcb4/transport/board_server.hpp>
#include <rcb4/transport/client.hpp>
#include <rcb4/transport/operations.hpp>
#include <rcb4/transport/serial.hpp>

#include <algorithm>
#include <cstdio>
#include <vector>

namespace {
using namespace rcb4;
namespace t = rcb4::transport;
using clock_type = std::chrono::steady_clock;

double us_since(clock_type::time_point start, int n) {
  return std::chrono::duration<double, std::micro>(clock_type::now() - start).count() / n;
}

/** The median of @p v. */
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
}  // namespace

int main() {
  const int n = 20000;
  std::printf("rcb4 transport benchmarks (%d exchanges each; pty, virtual board unpaced; sync API)\n", n);
  servo_set<servo_position> all36;
  for (int i = 0; i < 36; ++i) all36.insert(ics_number::make(i).value(), 7600);
  const command cmds[] = {ping{}, move::read_ram(0x0090, 2).value(), const_servo::make(all36, 10).value()};
  const char* names[] = {"ping", "MOV read 2 bytes", "CONST36"};
  {
    rcb4::testing::served_board b;
    {  // count the client's allocations only: the in-process board's thread is not the client
      std::promise<void> excluded;
      boost::asio::post(b.server_io.context(), [&] {
        bench::exclude_this_thread();
        excluded.set_value();
      });
      excluded.get_future().wait();
    }
    t::io_thread io;
    auto c = t::make_client(t::open_serial(io.context(), b.server->where(), 1250000));
    // The floors: a raw echo on a pty (the yardstick), and a bare blocking loop sending
    // the same frame to a second board server (what any client can reach against this board).
    t::io_thread echo_io;
    rcb4::testing::pty_echo echo(echo_io.context());
    rcb4::testing::served_board raw_board;
    // Floors and the client take turns in rounds (the machine's speed drifts); medians are shown.
    const int rounds = 7, per_round = n / rounds;
    double ping_floor_us = 0;
    for (std::size_t k = 0; k < 3; ++k) {
      const auto frame = encode(cmds[k]);
      const std::vector<std::uint8_t> request(frame.bytes().begin(), frame.bytes().end());
      const auto rep = expected_reply(cmds[k]).frame_size();
      const std::vector<std::uint8_t> echoed(std::max(request.size(), rep), 0x55);
      for (int i = 0; i < 100; ++i) c.execute(cmds[k]);  // warm up
      std::vector<double> client_us, echo_us, raw_us;
      std::size_t allocs = 0;
      for (int r = 0; r < rounds; ++r) {
        echo_us.push_back(rcb4::testing::pty_round_trips(echo.path(), echoed, echoed.size(), per_round / 4));
        raw_us.push_back(rcb4::testing::pty_round_trips(raw_board.server->where(), request, rep, per_round / 4));
        const auto a0 = bench::allocations();
        const auto start = clock_type::now();
        for (int i = 0; i < per_round; ++i) c.execute(cmds[k]);
        client_us.push_back(us_since(start, per_round));
        allocs += bench::allocations() - a0;
      }
      const double us = median(client_us), floor_us = median(echo_us), raw = median(raw_us);
      if (k == 0) ping_floor_us = floor_us;
      std::printf(
          "  %-16s %6.0f/s (%5.1f us)   echo floor %6.0f/s = %.2fx (target >= 0.9)   raw loop on a board %6.0f/s = "
          "%.2fx   %.1f allocs/exchange\n",
          names[k], 1e6 / us, us, 1e6 / floor_us, floor_us / us, 1e6 / raw, raw / us,
          static_cast<double>(allocs) / (rounds * per_round));
    }
    // The async API with a callback, for its allocation count.
    std::atomic<int> left{n};
    std::promise<void> all_done;
    const auto allocs = bench::allocations();
    const auto start = clock_type::now();
    std::function<void()> next = [&] {
      c.async_execute(cmds[0], [&](boost::system::error_code, t::response) {
        if (--left == 0)
          all_done.set_value();
        else
          next();
      });
    };
    next();
    all_done.get_future().wait();
    const double async_us = us_since(start, n);
    const double async_allocs = static_cast<double>(bench::allocations() - allocs) / n;
    const auto ping_frame = encode(ping{});
    const std::vector<std::uint8_t> ping_bytes(ping_frame.bytes().begin(), ping_frame.bytes().end());
    const double asio_us = rcb4::testing::asio_round_trips(raw_board.server->where(), ping_bytes, 4, n / 4);
    std::printf(
        "  %-16s %6.0f/s (%5.1f us)   echo floor %6.0f/s = %.2fx (ping's)   bare Asio coroutine loop on a board "
        "%6.0f/s = %.2fx   %.1f allocs/exchange\n",
        "ping (async)", 1e6 / async_us, async_us, 1e6 / ping_floor_us, ping_floor_us / async_us, 1e6 / asio_us,
        asio_us / async_us, async_allocs);
  }
  {
    // Control cycle at 1.25 Mbaud, paced: read all servo states (planned) + CONST to 36 servos.
    t::serve_options so;
    so.pace = true;
    board::options bo;
    bo.servo_count = 35;
    rcb4::testing::served_board b(so, bo);
    const auto cost = ops::link_cost::at(1250000, std::chrono::microseconds(25));
    const int cycles = 300;
    // The floor on this paced pty: the same frames by a bare blocking loop (write, then read the
    // reply's length), which pays the pty's own latency each way and nothing else.
    const double raw_us = rcb4::testing::raw_cycle_us(b.server->where(), cost, cmds[2], cycles);
    t::io_thread io;
    t::client_options co;
    co.baud = 1250000;
    auto c = t::make_client(t::open_serial(io.context(), b.server->where(), 1250000), co);
    std::size_t wire_bytes = 0;
    ops::read_servo_states probe(cost);
    std::error_code ec;
    t::run(c, probe, ec);
    wire_bytes += 10 + 73;  // the allocation-table read
    for (const auto& r : probe.plan()) wire_bytes += 10 + r.size + 3;
    wire_bytes += wire_size(cmds[2]) + 4;
    const auto cycle_us = [&] {
      const auto start = clock_type::now();
      for (int i = 0; i < cycles; ++i) {
        t::run(c, ops::read_servo_states(cost));
        c.execute(cmds[2]);
      }
      return us_since(start, cycles);
    };
    const double us = cycle_us();
    c.options().busy_poll = std::chrono::microseconds(200);
    const double spin_us = cycle_us();
    const double limit_us = static_cast<double>(wire_bytes) * 11.0 / 1.25;  // 11 bits per byte at 1.25 Mbaud
    std::printf("\ncontrol cycle at 1.25 Mbaud (paced board): read %zu servos in %zu exchanges + CONST36\n",
                probe.value().size(), probe.plan().size() + 1);
    std::printf("  wire limit            %7.0f us (%5.1f Hz, %zu bytes)\n", limit_us, 1e6 / limit_us, wire_bytes);
    std::printf("  raw blocking loop     %7.0f us (%5.1f Hz)   = %.2fx wire (the pty's floor)\n", raw_us, 1e6 / raw_us,
                limit_us / raw_us);
    std::printf("  rcb4 sync API         %7.0f us (%5.1f Hz)   = %.2fx wire (target >= 0.97)   %.2fx raw loop\n", us,
                1e6 / us, limit_us / us, raw_us / us);
    std::printf("  rcb4, busy_poll 200us %7.0f us (%5.1f Hz)   = %.2fx wire (target >= 0.97)   %.2fx raw loop\n",
                spin_us, 1e6 / spin_us, limit_us / spin_us, raw_us / spin_us);
  }
  return 0;
}
