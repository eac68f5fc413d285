// Robot-level control loop benchmark, printed side by side in one run (never asserted):
// read every joint's position and write every joint's target, for the KHR-3HV profile, against
// the virtual board paced at 1.25 Mbaud (the board_server of `rcb4 serve --pty --pace`) with
// 0 and 1,000 µs of adapter latency (`--latency`). Each figure sits next to:
//  - the wire-plus-latency limit of its own plan (its bytes at 11 bits each, plus the latency
//    once per exchange);
//  - iory/rcb4's scheme on the same link: five 126-byte reads of the servo area + CONST36 (its
//    limit at 0 latency is 145.7 Hz).
// The plan is the read planner's for the link as measured (transport::measure_link); the
// program says what it chose and why. Goals: >= 0.9x the plan's limit, >= 1.5x iory's scheme's
// rate at 0 latency. The loops take turns in short rounds (a noisy 2-core machine); figures are
// medians. Everything runs with the CPUs' idle states as configured, then again holding a 0 µs
// PM QoS request when the process may (root).
// SPDX-License-Identifier: BSL-1.0
#include "pty_echo.hpp"
#include "rounds.hpp"
#include "served_board.hpp"

#include <rcb4/robot/ops.hpp>
#include <rcb4/robot/profile.hpp>
#include <rcb4/transport/client.hpp>
#include <rcb4/transport/cpu_latency.hpp>
#include <rcb4/transport/operations.hpp>
#include <rcb4/transport/serial.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace {
using namespace rcb4;
namespace t = rcb4::transport;
using clock_type = std::chrono::steady_clock;
constexpr std::uint32_t baud = 1250000;
using rcb4::bench::median;
using rcb4::bench::ratio;
using rcb4::bench::take_turns;

/** The wire time of @p bytes at 1.25 Mbaud in µs. */
double wire_us(std::size_t bytes) { return static_cast<double>(bytes) * 11.0 / 1.25; }

/** One exchange's bytes: request and reply. */
std::size_t bytes_of(const command& c) { return wire_size(c) + expected_reply(c).frame_size(); }

/** A cycle's shape: exchanges and bytes. */
struct cycle_shape {
  std::size_t exchanges = 0;
  std::size_t bytes = 0;
  double limit_us(std::chrono::microseconds latency) const {
    return wire_us(bytes) + static_cast<double>(exchanges) * static_cast<double>(latency.count());
  }
};

void run_at(const robot::model& m, std::chrono::microseconds latency) {
  t::serve_options so;
  so.pace = true;
  so.latency = latency;
  rcb4::testing::served_board b(so);  // the KHR-3HV's slots (board::khr3hv_servos)
  t::io_thread io;
  t::client_options co;
  co.baud = baud;
  auto c = t::make_client(t::open_serial(io.context(), b.server->where(), baud), co);

  // The robot loop as a user writes it: locate once, measure the link, plan once, then cycle.
  const auto map = t::run(c, robot::locate_joints(m));
  const auto cost = t::measure_link(c, 15);
  robot::read_joints reads(map, robot::fields::positions, cost);
  robot::joint_targets targets(map);
  for (std::size_t i = 0; i < targets.joints().size(); ++i) {
    const auto& j = *targets.joints()[i];
    if (const auto p = targets.set(i, std::clamp(0.0, j.lower, j.upper))) {
      std::printf("  cannot set %s: %s\n", j.name.c_str(), p->message.c_str());
      return;
    }
  }
  const command write = targets.frame(frames{1}).value();
  // A cycle: the planned reads (10-byte request, size + 3 back), then the write.
  const auto shape_of = [&](const std::vector<ops::byte_range>& plan) {
    cycle_shape shape;
    for (const auto& r : plan) {
      ++shape.exchanges;
      shape.bytes += 10 + r.size + 3;
    }
    ++shape.exchanges;
    shape.bytes += bytes_of(write);
    return shape;
  };
  const cycle_shape ours = shape_of(reads.plan());
  // The reads planned for an ideal link, without a per-exchange cost (to show what measuring changed).
  auto other =
      robot::read_joints(map, robot::fields::positions, ops::link_cost::at(baud, std::chrono::microseconds(0)));

  // iory/rcb4's scheme: the servo area in five 126-byte reads, then CONST36.
  std::vector<command> iory;
  for (unsigned k = 0; k < 5; ++k)
    iory.push_back(move::read_ram(ram_address::make(0x0090 + 126 * k).value(), 126).value());
  servo_set<servo_position> all36;
  for (int i = 0; i < 36; ++i) all36.insert(ics_number::make(i).value(), 7500);
  iory.push_back(const_servo::make(all36, frames{1}).value());
  cycle_shape theirs;
  for (const auto& x : iory) {
    ++theirs.exchanges;
    theirs.bytes += bytes_of(x);
  }

  // The same exchanges by a bare blocking loop (write the frame, read exactly the reply) on an
  // identical board: the pty's own floor, which a real UART does not have.
  std::vector<command> ours_cmds;
  for (reads.restart(); auto x = reads.next();) {
    ours_cmds.push_back(*x);
    reads.on_reply(c.execute(*x).view());
  }
  ours_cmds.push_back(write);
  rcb4::testing::served_board floor_board(so);
  const int fd = rcb4::testing::open_raw(floor_board.server->where());
  // A second client that spins on the line for up to 200 µs before sleeping (client_options::busy_poll).
  rcb4::testing::served_board spin_board(so);
  t::client_options spin = co;
  spin.busy_poll = std::chrono::microseconds(200);
  auto cs = t::make_client(t::open_serial(io.context(), spin_board.server->where(), baud), spin);

  const int per_round = latency.count() > 0 ? 12 : 30, rounds = 9;
  const auto timed = [&](auto&& cycle) {
    const auto start = clock_type::now();
    for (int i = 0; i < per_round; ++i) cycle();
    return std::chrono::duration<double, std::micro>(clock_type::now() - start).count() / per_round;
  };
  const auto robot_cycle = [&](t::basic_client<t::serial_port>& client, robot::read_joints& plan) {
    plan.restart();
    t::error_code ec;
    t::run(client, plan, ec);
    if (ec) throw t::system_error(ec, "joint read");
    client.execute(write);
  };
  const auto raw = [&](const std::vector<command>& cmds) {
    std::array<std::uint8_t, max_reply_size> buf{};
    for (const auto& x : cmds)
      if (!rcb4::testing::raw_round_trip(fd, encode(x).bytes(), std::span(buf).first(expected_reply(x).frame_size())))
        throw std::runtime_error("raw loop: the board did not answer");
  };
  const std::vector<std::function<double()>> loops = {
      [&] { return timed([&] { robot_cycle(c, reads); }); },
      [&] { return timed([&] { robot_cycle(cs, reads); }); },
      [&] { return timed([&] { raw(ours_cmds); }); },
      [&] {
        return timed([&] {
          for (const auto& x : iory) c.execute(x);
        });
      },
      [&] { return timed([&] { raw(iory); }); },
      [&] { return timed([&] { robot_cycle(c, other); }); },
  };
  for (const auto& l : loops) l();  // warm up
  const auto us = take_turns(loops, rounds);
  ::close(fd);
  const auto per_round_ratio = [&](std::size_t x, std::size_t y) { return ratio(us[x], us[y]); };
  const double ours_lim = ours.limit_us(latency), iory_lim = theirs.limit_us(latency);
  std::printf(
      "\n  adapter latency %lld us (board paced at %u baud); link measured: %.1f us per exchange beyond "
      "the wire\n",
      static_cast<long long>(latency.count()), b.board.line_baud(),
      std::chrono::duration<double, std::micro>(cost.exchange).count());
  std::printf("    planner chose %zu read%s for %zu joints (", reads.plan().size(), reads.plan().size() == 1 ? "" : "s",
              targets.joints().size());
  for (std::size_t i = 0; i < reads.plan().size(); ++i)
    std::printf("%s%u", i ? "+" : "", static_cast<unsigned>(reads.plan()[i].size));
  std::printf(" bytes): %s\n",
              reads.plan().size() == targets.joints().size()
                  ? "an exchange costs less than the 18 unwanted bytes between two joints' positions, so each "
                    "joint is its own read"
                  : "an exchange costs more than the 18 unwanted bytes between two joints' positions, so "
                    "neighbouring joints share a read of up to 128 bytes");
  const auto row = [&](const char* what, std::size_t i, double limit, const cycle_shape& shape, std::size_t floor) {
    const double med = median(us[i]);
    std::printf("    %-40s %6.0f us %6.1f Hz  %5.2fx limit (%5.1f Hz, %zu exchanges, %3zu bytes)", what, med, 1e6 / med,
                limit / med, 1e6 / limit, shape.exchanges, shape.bytes);
    if (floor != i) std::printf("  %4.2fx floor", per_round_ratio(floor, i));
    std::printf("\n");
  };
  row("rcb4 joints: read_joints + CONST20", 0, ours_lim, ours, 2);
  row("  the same, busy_poll 200 us", 1, ours_lim, ours, 2);
  row("  the same by a bare loop (pty floor)", 2, ours_lim, ours, 2);
  const cycle_shape alt = shape_of(other.plan());
  const auto alt_label = std::to_string(other.plan().size()) + " reads, planned for no exchange cost";
  row(("  " + alt_label).c_str(), 5, alt.limit_us(latency), alt, 5);
  row("iory/rcb4: 5 x MOV 126 + CONST36", 3, iory_lim, theirs, 4);
  row("  the same by a bare loop (pty floor)", 4, iory_lim, theirs, 4);
  std::printf("    rcb4 joints / iory/rcb4: %.2fx the rate (goal at 0 latency: >= 1.5x)\n", per_round_ratio(3, 0));
}

void pass(const robot::model& m) {
  run_at(m, std::chrono::microseconds(0));
  run_at(m, std::chrono::microseconds(1000));
}
}  // namespace

int main() {
  const auto m = robot::open_profile("khr-3hv");
  std::printf("rcb4 robot control loop: read every joint's position, write every joint's target (%s, %zu joints)\n",
              m.name().c_str(), m.joints().size());
  std::printf("goals: >= 0.90x the plan's wire+latency limit; >= 1.5x iory/rcb4's rate at 0 latency\n");
  std::printf("\n");
  return rcb4::bench::two_passes([&] { pass(m); });
}
