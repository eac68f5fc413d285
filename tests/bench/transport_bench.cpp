// Transport benchmarks, printed side by side in one run (never asserted):
//  - for ping, a 2-byte MOV read, CONST36 and a control loop (five 126-byte reads + CONST36, the
//    scheme of iory/rcb4), against the virtual board on a pty: the blocking API and the async API
//    (a callback chain) next to a raw C loop (write the frame, read exactly the reply) on an
//    identical board server, and for the async API next to a bare Asio coroutine loop too;
//    targets: blocking >= 0.90x the raw loop, async >= 0.85x; heap allocations per exchange in
//    steady state (target 0), the client's only;
//  - a control cycle (read every servo's state + write 36 servos) against the board paced at
//    1.25 Mbaud, next to the wire limit of those bytes and to the same cycle by a raw loop;
//  - with `--device PATH [--baud B]`, instead: the same workloads by the blocking API next to a raw
//    C loop on a board that is not this project's (tests/integration/standin.py, or a real one).
// The machine's speed drifts (a 2-core virtual machine: tens of µs per wake-up, changing from
// second to second), so the floors and the client take turns in short rounds, in a rotating
// order; each ratio printed is the median of the rounds' own ratios (each compares neighbours
// in time), next to the median rates.
// Everything runs twice: with the CPUs' idle states as the machine has them, then holding a
// PM QoS request of 0 µs (cpu_latency_guard, as a control loop would; needs root).
// SPDX-License-Identifier: BSL-1.0
#include "alloc_count.hpp"
#include "pty_echo.hpp"
#include "rounds.hpp"
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
using rcb4::bench::median;
using rcb4::bench::ratio;
using rcb4::bench::take_turns;

double us_since(clock_type::time_point start, int n) {
  return std::chrono::duration<double, std::micro>(clock_type::now() - start).count() / n;
}

/** A workload: commands sent in turn, one "operation" being the whole list once. */
struct workload {
  const char* name;
  std::vector<command> cmds;
};

/** @p w's frames and the sizes of their replies, for the bare loops. */
struct wire_script {
  std::vector<request_frame> frames;
  std::vector<std::size_t> sizes;
  explicit wire_script(const workload& w) {
    for (const auto& c : w.cmds) {
      frames.push_back(encode(c));
      sizes.push_back(expected_reply(c).frame_size());
    }
  }
};

/** A raw C loop on @p path: each frame written, exactly its reply read; µs per pass over @p w. */
double raw_loop_us(const std::string& path, const workload& w, int n) {
  const int fd = rcb4::testing::open_raw(path);
  const wire_script script(w);
  const auto& frames = script.frames;
  const auto& sizes = script.sizes;
  std::array<std::uint8_t, max_reply_size> buf{};
  bool ok = true;
  const auto start = clock_type::now();
  for (int i = 0; i < n && ok; ++i)
    for (std::size_t k = 0; k < frames.size() && ok; ++k)
      ok = rcb4::testing::raw_round_trip(fd, frames[k].bytes(), std::span(buf).first(sizes[k]));
  const double us = us_since(start, n);
  ::close(fd);
  return ok ? us : -1.0;
}

/** A bare Asio coroutine loop on @p path over @p w (no strand, no deadline); µs per pass. */
double asio_loop_us(const std::string& path, const workload& w, int n) {
  boost::asio::io_context io;
  boost::asio::posix::stream_descriptor s(io, rcb4::testing::open_raw(path));
  double us = -1.0;
  boost::asio::co_spawn(
      io,
      [&]() -> boost::asio::awaitable<void> {
        const wire_script script(w);
        const auto& frames = script.frames;
        const auto& sizes = script.sizes;
        std::array<std::uint8_t, max_reply_size> buf{};
        const auto start = clock_type::now();
        for (int i = 0; i < n; ++i)
          for (std::size_t k = 0; k < frames.size(); ++k) {
            co_await boost::asio::async_write(s, boost::asio::buffer(frames[k].bytes().data(), frames[k].size()),
                                              boost::asio::use_awaitable);
            std::size_t got = 0;
            while (got < sizes[k])
              got += co_await s.async_read_some(boost::asio::buffer(buf.data() + got, sizes[k] - got),
                                                boost::asio::use_awaitable);
          }
        us = us_since(start, n);
      },
      boost::asio::detached);
  io.run();
  return us;
}

/** One workload: raw C loop, blocking API, async API (callback chain), bare Asio loop, in turns. */
void measure(const workload& w, t::basic_client<t::serial_port>& c, const std::string& raw_path) {
  const int per_round = std::max<int>(40, 1000 / static_cast<int>(w.cmds.size() * w.cmds.size())), rounds = 15;
  std::size_t sync_allocs = 0, async_allocs = 0;
  const auto blocking = [&] {
    const auto a0 = bench::allocations();
    const auto start = clock_type::now();
    for (int i = 0; i < per_round; ++i)
      for (const auto& cmd : w.cmds) c.execute(cmd);
    const double r = us_since(start, per_round);
    sync_allocs += bench::allocations() - a0;
    return r;
  };
  const auto chain = [&] {
    const std::size_t total = static_cast<std::size_t>(per_round) * w.cmds.size();
    std::size_t sent = 0;
    std::promise<void> all_done;
    std::function<void()> next = [&] {
      c.async_execute(w.cmds[sent++ % w.cmds.size()], [&](boost::system::error_code, t::response) {
        if (sent == total)
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
    async_allocs += bench::allocations() - a0;
    return r;
  };
  blocking();  // warm up
  chain();
  sync_allocs = async_allocs = 0;
  const auto us = take_turns({[&] { return raw_loop_us(raw_path, w, per_round); }, blocking, chain,
                              [&] { return asio_loop_us(raw_path, w, per_round); }},
                             rounds);
  const double exchanges = static_cast<double>(rounds * per_round) * static_cast<double>(w.cmds.size());
  std::printf("  %-22s %7.0f/s   %7.0f/s %5.2fx   %7.0f/s %5.2fx   %7.0f/s %5.2fx   %4.1f  %4.1f\n", w.name,
              1e6 / median(us[0]), 1e6 / median(us[1]), ratio(us[0], us[1]), 1e6 / median(us[2]), ratio(us[0], us[2]),
              1e6 / median(us[3]), ratio(us[3], us[2]), static_cast<double>(sync_allocs) / exchanges,
              static_cast<double>(async_allocs) / exchanges);
}

/** Control cycles at 1.25 Mbaud against a paced board: read all servo states + CONST36. */
void control_cycle(const command& write36) {
  t::serve_options so;
  so.pace = true;
  board::options bo;
  bo.servos = rcb4::board::first_slots(35);
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
void pass(const std::vector<workload>& loads, const command& write36) {
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
    rcb4::testing::served_board raw_board;  // an identical board for the raw loops
    std::printf("  %-22s %9s   %16s   %16s   %16s   %s\n", "per second", "raw C loop", "blocking API", "async API",
                "bare Asio (async", "allocs/exchange");
    std::printf("  %-22s %9s   %16s   %16s   %16s   %s\n", "", "", "(target 0.90x)", "(target 0.85x)", "vs it)",
                "sync async");
    for (const auto& w : loads) measure(w, c, raw_board.server->where());
  }
  control_cycle(write36);
}
/**
 * Against a board that is not part of this project (a stand-in in another language on a pty,
 * or a real board): the blocking API next to a raw C loop on the same device, in turns. The
 * client is opened for each of its rounds and closed after, so the raw loop never shares the line.
 */
int external(const std::string& path, std::uint32_t baud, const std::vector<workload>& loads) {
  std::printf(
      "rcb4 transport bench against %s at %u baud: the blocking API next to a raw C loop on the same\n"
      "device, in turns (15 rounds); operations per second, ratios are medians of per-round ratios\n\n",
      path.c_str(), baud);
  std::printf("  %-22s %9s   %16s\n", "per second", "raw C loop", "blocking API");
  t::io_thread io;
  for (const auto& w : loads) {
    const int per_round = std::max<int>(20, 400 / static_cast<int>(w.cmds.size() * w.cmds.size())), rounds = 15;
    const auto blocking = [&] {
      t::client_options opt;
      opt.baud = baud;
      auto c = t::make_client(t::open_serial(io.context(), path, baud), opt);
      for (const auto& cmd : w.cmds) c.execute(cmd);  // warm up
      const auto start = clock_type::now();
      for (int i = 0; i < per_round; ++i)
        for (const auto& cmd : w.cmds) c.execute(cmd);
      return us_since(start, per_round);
    };
    const auto us = take_turns({[&] { return raw_loop_us(path, w, per_round); }, blocking}, rounds);
    std::printf("  %-22s %7.0f/s   %7.0f/s %5.2fx (target 0.90x)\n", w.name, 1e6 / median(us[0]), 1e6 / median(us[1]),
                ratio(us[0], us[1]));
  }
  return 0;
}
}  // namespace

int main(int argc, char** argv) {
  std::string device;
  std::uint32_t device_baud = 115200;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string_view a = argv[i];
    if (a == "--device") device = argv[i + 1];
    if (a == "--baud") device_baud = static_cast<std::uint32_t>(std::stoul(argv[i + 1]));
  }

  servo_set<servo_position> all36;
  for (int i = 0; i < 36; ++i) all36.insert(ics_number::make(i).value(), 7600);
  const command write36 = const_servo::make(all36, 10).value();
  workload control{"5 x MOV 126 + CONST36", {}};
  for (unsigned k = 0; k < 5; ++k)
    control.cmds.push_back(move::read_ram(ram_address::make(0x0090 + 126 * k).value(), 126).value());
  control.cmds.push_back(write36);
  const std::vector<workload> loads = {
      {"ping", {ping{}}}, {"MOV read 2 bytes", {move::read_ram(0x0090, 2).value()}}, {"CONST36", {write36}}, control};
  if (!device.empty()) return external(device, device_baud, loads);
  std::printf("rcb4 transport benchmarks: pty, virtual board (unpaced unless said); operations per second\n");
  std::printf("(a control loop's operation is its 6 exchanges); ratios are medians of per-round ratios\n\n");
  return rcb4::bench::two_passes([&] { pass(loads, write36); });
}
