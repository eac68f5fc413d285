// Transport benchmarks, printed side by side in one run (never asserted):
//  - exchanges per second for ping, a 2-byte MOV read and CONST36 over a pty against the virtual
//    board, next to a raw pty echo floor (target ≥ 0.9× the floor);
//  - a control cycle (read every servo's state + write 36 servos) against the board paced at
//    1.25 Mbaud, next to the wire limit of those bytes (target ≥ 0.97×);
//  - heap allocations per exchange in steady state (target 0).
// SPDX-License-Identifier: BSL-1.0
#include "alloc_count.hpp"
#include "pty_echo.hpp"
#include "served_board.hpp"

#include <rcb4/transport/board_server.hpp>
#include <rcb4/transport/client.hpp>
#include <rcb4/transport/operations.hpp>
#include <rcb4/transport/serial.hpp>

#include <cstdio>

namespace {
using namespace rcb4;
namespace t = rcb4::transport;
using clock_type = std::chrono::steady_clock;

double us_since(clock_type::time_point start, int n) {
  return std::chrono::duration<double, std::micro>(clock_type::now() - start).count() / n;
}

/** Round trips of a raw echo on a pty of @p bytes each: the floor for any pty server. */
double echo_floor(std::size_t bytes, int n) {
  t::io_thread io;
  rcb4::testing::pty_echo echo(io.context());
  const std::vector<std::uint8_t> req(bytes, 0x55);
  return rcb4::testing::pty_round_trips(echo.path(), req, bytes, n);
}
}  // namespace

int main() {
  const int n = 20000;
  std::printf("rcb4 transport benchmarks (%d exchanges each; pty, virtual board unpaced)\n", n);
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
    for (std::size_t k = 0; k < 3; ++k) {
      const auto req = wire_size(cmds[k]), rep = expected_reply(cmds[k]).frame_size();
      const double floor_us = echo_floor(std::max(req, rep), n / 4);
      for (int i = 0; i < 100; ++i) c.execute(cmds[k]);  // warm up
      const auto allocs = bench::allocations();
      const auto start = clock_type::now();
      for (int i = 0; i < n; ++i) c.execute(cmds[k]);
      const double us = us_since(start, n);
      const double per = static_cast<double>(bench::allocations() - allocs) / n;
      std::printf(
          "  %-18s %8.0f exchanges/s (%6.2f us)   raw echo floor %8.0f/s   = %.2fx (target >= 0.9)   %.1f "
          "client allocs/exchange (sync API)\n",
          names[k], 1e6 / us, us, 1e6 / floor_us, floor_us / us, per);
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
    std::printf("  %-18s %8.0f exchanges/s (%6.2f us)   %.1f client allocs/exchange (async API, callback)\n",
                "ping (async)", 1e6 / us_since(start, n), us_since(start, n),
                static_cast<double>(bench::allocations() - allocs) / n);
  }
  {
    // Control cycle at 1.25 Mbaud, paced: read all servo states (planned) + CONST to 36 servos.
    t::serve_options so;
    so.pace = true;
    board::options bo;
    bo.servo_count = 35;
    rcb4::testing::served_board b(so, bo);
    t::io_thread io;
    t::client_options co;
    co.baud = 1250000;
    auto c = t::make_client(t::open_serial(io.context(), b.server->where(), 1250000), co);
    const auto cost = ops::link_cost::at(1250000, std::chrono::microseconds(25));
    std::size_t wire_bytes = 0;
    ops::read_servo_states probe(cost);
    std::error_code ec;
    t::run(c, probe, ec);
    wire_bytes += 10 + 73;  // the allocation-table read
    for (const auto& r : probe.plan()) wire_bytes += 10 + r.size + 3;
    wire_bytes += wire_size(cmds[2]) + 4;
    const int cycles = 300;
    const auto start = clock_type::now();
    for (int i = 0; i < cycles; ++i) {
      t::run(c, ops::read_servo_states(cost));
      c.execute(cmds[2]);
    }
    const double us = us_since(start, cycles);
    const double limit_us = static_cast<double>(wire_bytes) * 11.0 / 1.25;  // 11 bits per byte at 1.25 Mbaud
    std::printf("\ncontrol cycle at 1.25 Mbaud (paced board): read %zu servos in %zu exchanges + CONST36\n",
                probe.value().size(), probe.plan().size() + 1);
    std::printf(
        "  measured %7.0f us/cycle (%5.1f Hz)   wire limit %7.0f us (%5.1f Hz, %zu bytes)   = %.2fx (target >= 0.97)\n",
        us, 1e6 / us, limit_us, 1e6 / limit_us, wire_bytes, limit_us / us);
  }
  return 0;
}
