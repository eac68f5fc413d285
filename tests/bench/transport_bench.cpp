// Transport benchmarks, printed side by side in one run (never asserted):
//  - exchanges per second through the blocking API for ping, a 2-byte MOV read and CONST36 over
//    a pty against the virtual board, next to a raw pty echo floor (target >= 0.9x the floor)
//    and a bare blocking loop sending the same frame to a second board server;
//  - the same with the async API (a callback chain), next to a bare Asio coroutine loop;
//  - a control cycle (read every servo's state + write 36 servos) against the board paced at
//    1.25 Mbaud, next to the wire limit of those bytes (target >= 0.97x) and to the same cycle
//    by a bare blocking loop (what the pty allows any client);
//  - heap allocations per exchange in steady state (target 0), the client's only.
// The machine's speed drifts (a 2-core virtual machine: tens of µs per wake-up, changing from
// second to second), so the floors and the client take turns in short rounds, in a rotating
// order; each ratio printed is the median of the rounds' own ratios (each compares neighbours
// in time), next to the median times.
// Everything runs twice: with the CPUs' idle states as the machine has them, then holding a
// PM QoS request of 0 µs (cpu_latency_guard, as a control loop would; needs root).
// SPDX-License-Identifier: BSL-1.0
#include "alloc_count.hpp"
#include "pty_echo.hpp"
#include "served_board.hpp"

#include <rcb4/transport/board_server.hpp>
#include <rcb4/transport/client.hpp>
#include <rcb4/transport/cpu_latency.hpp>
#include <rcb4/transport/operations.hpp>
#include <rcb4/transport/serial.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <functional>
#include <optional>
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

/**
 * Runs the measurements @p m (each returns µs per operation) for @p rounds rounds, rotating
 * their order every round; per measurement, its times.
 */
std::vector<std::vector<double>> take_turns(const std::vector<std::function<double()>>& m, int rounds) {
  std::vector<std::vector<double>> us(m.size());
  for (int r = 0; r < rounds; ++r)
    for (std::size_t k = 0; k < m.size(); ++k) {
      const std::size_t i = (k + static_cast<std::size_t>(r)) % m.size();
      us[i].push_back(m[i]());
    }
  return us;
}

/** The median over rounds of a[r] / b[r]: how fast b is next to a (times in µs). */
double ratio(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double> r;
  for (std::size_t i = 0; i < a.size(); ++i) r.push_back(a[i] / b[i]);
  return median(r);
}

/** The exchanges per second for one command: the client's blocking API against its floors. */
void exchanges(const char* name, const command& cmd, t::basic_client<t::serial_port>& c, const std::string& echo_path,
               const std::string& raw_path) {
  const auto frame = encode(cmd);
  const auto request = frame.bytes();
  const auto rep = expected_reply(cmd).frame_size();
  const std::vector<std::uint8_t> echoed(std::max(request.size(), rep), 0x55);
  for (int i = 0; i < 200; ++i) c.execute(cmd);  // warm up
  const int per_round = 1000, rounds = 15;
  std::size_t allocs = 0;
  const auto us =
      take_turns({[&] { return rcb4::testing::pty_round_trips(echo_path, echoed, echoed.size(), per_round); },
                  [&] { return rcb4::testing::pty_round_trips(raw_path, request, rep, per_round); },
                  [&] {
                    const auto a0 = bench::allocations();
                    const auto start = clock_type::now();
                    for (int i = 0; i < per_round; ++i) c.execute(cmd);
                    const double r = us_since(start, per_round);
                    allocs += bench::allocations() - a0;
                    return r;
                  }},
                 rounds);
  const double client = median(us[2]);
  std::printf(
      "  %-16s %6.0f/s (%5.1f us)   echo floor %6.0f/s: %.2fx (target >= 0.9)   raw loop on a board %6.0f/s: %.2fx"
      "   %.1f allocs/exchange\n",
      name, 1e6 / client, client, 1e6 / median(us[0]), ratio(us[0], us[2]), 1e6 / median(us[1]), ratio(us[1], us[2]),
      static_cast<double>(allocs) / (rounds * per_round));
}

/** Pings by the async API (a callback chain) against a bare Asio coroutine loop. */
void async_pings(t::basic_client<t::serial_port>& c, const std::string& echo_path, const std::string& raw_path) {
  const auto ping_frame = encode(ping{});
  const auto ping_bytes = ping_frame.bytes();
  const auto ping_reply = expected_reply(ping{}).frame_size();
  const int per_round = 1000, rounds = 15;
  std::size_t allocs = 0;
  const auto chain = [&] {
    std::atomic<int> left{per_round};
    std::promise<void> all_done;
    std::function<void()> next = [&] {
      c.async_execute(ping{}, [&](boost::system::error_code, t::response) {
        if (--left == 0)
          all_done.set_value();
        else
          next();
      });
    };
    const auto a0 = bench::allocations();
    const auto start = clock_type::now();
    next();
    all_done.get_future().wait();
    const double r = us_since(start, per_round);
    allocs += bench::allocations() - a0;
    return r;
  };
  chain();  // warm up
  allocs = 0;
  const auto us =
      take_turns({[&] { return rcb4::testing::pty_round_trips(echo_path, ping_bytes, ping_reply, per_round); },
                  [&] { return rcb4::testing::asio_round_trips(raw_path, ping_bytes, ping_reply, per_round); }, chain},
                 rounds);
  const double client = median(us[2]);
  std::printf(
      "  %-16s %6.0f/s (%5.1f us)   echo floor %6.0f/s: %.2fx              bare Asio coroutine loop %6.0f/s: %.2fx"
      "   %.1f allocs/exchange\n",
      "ping (async)", 1e6 / client, client, 1e6 / median(us[0]), ratio(us[0], us[2]), 1e6 / median(us[1]),
      ratio(us[1], us[2]), static_cast<double>(allocs) / (rounds * per_round));
}

/** Control cycles at 1.25 Mbaud against a paced board: read all servo states + CONST36. */
void control_cycle(const command& write36) {
  t::serve_options so;
  so.pace = true;
  board::options bo;
  bo.servo_count = 35;
  rcb4::testing::served_board b(so, bo), raw_board(so, bo);
  const auto cost = ops::link_cost::at(1250000, std::chrono::microseconds(25));
  t::io_thread io;
  t::client_options co;
  co.baud = 1250000;
  auto c = t::make_client(t::open_serial(io.context(), b.server->where(), 1250000), co);
  t::client_options spin = co;
  spin.busy_poll = std::chrono::microseconds(200);
  t::io_thread spin_io;
  rcb4::testing::served_board spin_board(so, bo);
  auto cs = t::make_client(t::open_serial(spin_io.context(), spin_board.server->where(), 1250000), spin);
  std::size_t wire_bytes = 0;
  ops::read_servo_states probe(cost);
  t::error_code ec;
  t::run(c, probe, ec);
  wire_bytes += 10 + 73;  // the allocation-table read
  for (const auto& r : probe.plan()) wire_bytes += 10 + r.size + 3;
  wire_bytes += wire_size(write36) + 4;
  const int per_round = 40, rounds = 9;
  const auto cycles = [&](t::basic_client<t::serial_port>& client) {
    const auto start = clock_type::now();
    for (int i = 0; i < per_round; ++i) {
      t::run(client, ops::read_servo_states(cost));
      client.execute(write36);
    }
    return us_since(start, per_round);
  };
  // The floor on a paced pty: the same frames by a bare blocking loop (write, then read the
  // reply's length), which pays the pty's own latency each way and nothing else.
  const auto us =
      take_turns({[&] { return rcb4::testing::raw_cycle_us(raw_board.server->where(), cost, write36, per_round); },
                  [&] { return cycles(c); }, [&] { return cycles(cs); }},
                 rounds);
  const double limit_us = static_cast<double>(wire_bytes) * 11.0 / 1.25;  // 11 bits per byte at 1.25 Mbaud
  const std::vector<double> limit(us[0].size(), limit_us);
  std::printf("  control cycle at 1.25 Mbaud (paced board): read %zu servos in %zu exchanges + CONST36\n",
              probe.value().size(), probe.plan().size() + 1);
  std::printf("    wire limit            %7.0f us (%5.1f Hz, %zu bytes)\n", limit_us, 1e6 / limit_us, wire_bytes);
  std::printf("    raw blocking loop     %7.0f us (%5.1f Hz): %.2fx wire (the pty's floor)\n", median(us[0]),
              1e6 / median(us[0]), limit_us / median(us[0]));
  std::printf("    rcb4 sync API         %7.0f us (%5.1f Hz): %.2fx wire (target >= 0.97)   %.2fx raw loop\n",
              median(us[1]), 1e6 / median(us[1]), limit_us / median(us[1]), ratio(us[0], us[1]));
  std::printf("    rcb4, busy_poll 200us %7.0f us (%5.1f Hz): %.2fx wire (target >= 0.97)   %.2fx raw loop\n",
              median(us[2]), 1e6 / median(us[2]), limit_us / median(us[2]), ratio(us[0], us[2]));
}

/** One pass of every measurement. */
void pass(const command (&cmds)[3]) {
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
    // The floors: a raw echo on a pty (the yardstick), and a bare loop sending the same
    // frame to a second board server (what any client can reach against this board).
    t::io_thread echo_io;
    rcb4::testing::pty_echo echo(echo_io.context());
    rcb4::testing::served_board raw_board;
    const char* names[] = {"ping", "MOV read 2 bytes", "CONST36"};
    for (std::size_t k = 0; k < 3; ++k) exchanges(names[k], cmds[k], c, echo.path(), raw_board.server->where());
    async_pings(c, echo.path(), raw_board.server->where());
  }
  control_cycle(cmds[2]);
}
}  // namespace

int main() {
  servo_set<servo_position> all36;
  for (int i = 0; i < 36; ++i) all36.insert(ics_number::make(i).value(), 7600);
  const command cmds[] = {ping{}, move::read_ram(0x0090, 2).value(), const_servo::make(all36, 10).value()};
  std::printf("rcb4 transport benchmarks: pty, virtual board (unpaced unless said), sync API unless said;\n");
  std::printf("ratios are medians of per-round ratios (15 rounds of 1,000 exchanges, order rotating)\n\n");
  std::printf("CPU idle states as configured (wake-up latency bound %lld us):\n",
              static_cast<long long>(t::cpu_latency_bound_us()));
  pass(cmds);
  t::cpu_latency_guard low(std::chrono::microseconds(0));
  if (!low.active()) {
    std::printf("\n(no second pass: a PM QoS request needs write access to /dev/cpu_dma_latency: %s)\n",
                low.error().message().c_str());
    return 0;
  }
  std::printf("\nholding the CPUs' wake-up latency at 0 us (cpu_latency_guard, as a control loop would):\n");
  pass(cmds);
  return 0;
}
