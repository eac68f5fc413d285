// rcb4 command-line tool: bench — round trips and the robot's control cycle per second next to the
// wire limit and the link's limit (wire plus each exchange's measured cost), and next to
// iory/rcb4's cycle on the same link.
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/transport/cpu_latency.hpp>

#include <cmath>

namespace cli {
namespace {

using namespace std::chrono_literals;

struct bench_options {
  long long count = 500;
  bool low_latency = false;
};

int bench(session& s, const bench_options& o, const globals& g) {
  std::optional<rcb4::transport::cpu_latency_guard> low;
  if (o.low_latency) {
    low.emplace(0us);
    if (!low->active())
      throw failure(exit_io,
                    fmt::format("--low-latency: cannot write /dev/cpu_dma_latency: {}", low->error().message()),
                    "run as root, or let a group write it (udev: KERNEL==\"cpu_dma_latency\", GROUP=\"dialout\", "
                    "MODE=\"0660\")");
  }
  // The wire limit needs the line's rate: known on a serial port, unknown behind a TCP bridge.
  const auto limit = [&](std::size_t bytes) -> std::optional<double> {
    if (!s.rate_known()) return std::nullopt;
    return 1.0 / std::chrono::duration<double>(rcb4::transport::wire_time(bytes, s.baud())).count();
  };
  int stage = 0;
  auto rate = [&](std::string_view label, auto&& one) {
    progress bar(fmt::format("{} ({}/4)", label, ++stage), static_cast<std::size_t>(o.count), g.json);
    const auto t0 = std::chrono::steady_clock::now();
    for (long long i = 0; i < o.count; ++i) {
      one();
      bar.update(static_cast<std::size_t>(i + 1));
    }
    return static_cast<double>(o.count) / std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  const auto read = rcb4::move::read_ram(rcb4::ram::config, 2).value();
  const double ping_rate = rate("ping", [&] { s.c().execute(rcb4::ping{}); });
  const double read_rate = rate("read", [&] { s.c().execute(read); });
  // The robot's control cycle: every joint's position, in the reads the planner picks for this
  // link as measured, then one CONST of every joint. The targets are HOLD (stay where you are):
  // nothing moves on a real robot.
  const auto& model = robot_of(g);
  const auto map = s.run(rcb4::robot::locate_joints(model));
  const rcb4::robot::joint_targets targets(map);
  if (targets.joints().empty())
    throw failure(exit_board, fmt::format("the board has no servo allocated for any joint of the {}", model.name()),
                  "rcb4 scan shows the board's slots; --robot FILE names another robot");
  const auto cost = rcb4::transport::measure_link(s.c());
  rcb4::robot::read_joints reads(map, rcb4::robot::fields::positions, cost);
  const rcb4::command hold_all = targets.frame(rcb4::frames{1}).value();
  const auto cycle_bytes_of = [](const auto& plan, const rcb4::command& write) {
    std::size_t n = rcb4::encode(write).size() + rcb4::expected_reply(write).frame_size();
    for (const auto& r : plan) n += 10 + r.size + 3;
    return n;
  };
  const std::size_t cycle_bytes = cycle_bytes_of(reads.plan(), hold_all);
  const double cycle_rate = rate("robot cycle", [&] {
    reads.restart();
    rcb4::transport::error_code ec;
    rcb4::transport::run(s.c(), reads, ec);
    if (ec) throw rcb4::transport::system_error(ec);
    s.c().execute(hold_all);
  });
  // iory/rcb4's scheme on the same link: the servo area in five 126-byte reads, then CONST36 of
  // HOLD. ICS 35 is the receiver's slot (protocol.md §5): on a real board it is left out (CONST35).
  std::vector<rcb4::command> iory;
  for (unsigned k = 0; k < 5; ++k)
    iory.emplace_back(rcb4::move::read_ram(rcb4::ram_address::make(0x0090 + 126 * k).value(), 126).value());
  rcb4::servo_set<rcb4::servo_position> all;
  for (int i = 0; i < 35; ++i) all.insert(rcb4::ics_number::make(i).value(), rcb4::servo_position::hold());
  iory.emplace_back(rcb4::const_servo::make(all, rcb4::frames{1}).value());
  std::size_t iory_bytes = 0;
  for (const auto& x : iory) iory_bytes += rcb4::encode(x).size() + rcb4::expected_reply(x).frame_size();
  const double iory_rate = rate("iory/rcb4 cycle", [&] {
    for (const auto& x : iory) s.c().execute(x);
  });
  const double overhead_us = std::chrono::duration<double, std::micro>(cost.exchange).count();
  std::vector<unsigned> read_sizes;
  for (const auto& r : reads.plan()) read_sizes.push_back(static_cast<unsigned>(r.size));
  const auto ping_limit = limit(3 + 4), read_limit = limit(10 + 5), cycle_limit = limit(cycle_bytes),
             iory_limit = limit(iory_bytes);
  // The link's limit: the bytes at what the link charges for them (its rate, or as measured when
  // it is not paced at one), plus each exchange's measured cost.
  const auto link_limit = [&](std::size_t bytes, std::size_t exchanges) {
    const auto t = cost.byte_time * static_cast<long long>(bytes) + cost.exchange * static_cast<long long>(exchanges);
    return 1.0 / std::chrono::duration<double>(t).count();
  };
  const double cycle_link = link_limit(cycle_bytes, reads.plan().size() + 1), iory_link = link_limit(iory_bytes, 6);
  // Faster than the wire: the board answers sooner than its bytes could cross a line at this rate.
  const bool beyond_wire = (ping_limit && ping_rate > *ping_limit * 1.02) ||
                           (read_limit && read_rate > *read_limit * 1.02) ||
                           (cycle_limit && cycle_rate > *cycle_limit * 1.02);
  const auto opt = [](std::optional<double> v) { return v ? json(std::round(*v * 10) / 10) : json(nullptr); };
  if (g.json) {
    json j;
    j["where"] = s.where();
    j["baud"] = s.rate_known() ? json(s.baud()) : json(nullptr);
    j["count"] = o.count;
    j["ping_per_s"] = std::round(ping_rate);
    j["ping_wire_limit"] = opt(ping_limit);
    j["read_per_s"] = std::round(read_rate);
    j["read_wire_limit"] = opt(read_limit);
    j["cycle_hz"] = std::round(cycle_rate * 10) / 10;
    j["cycle_wire_limit_hz"] = opt(cycle_limit);
    j["cycle_link_limit_hz"] = std::round(cycle_link * 10) / 10;
    j["cycle_bytes"] = cycle_bytes;
    j["servos"] = targets.joints().size();
    j["robot"] = model.name();
    j["plan_reads"] = read_sizes;
    j["exchange_overhead_us"] = std::round(overhead_us * 10) / 10;
    j["byte_time_ns"] = cost.byte_time.count();
    // Paced: the board answered no faster than its bytes cross a line at the known rate; with the
    // rate unknown (a TCP bridge) there is nothing to compare with: null, not true.
    j["paced"] = s.rate_known() ? json(!beyond_wire) : json(nullptr);
    // measure_link keeps the rate's 11 bits a byte unless the link carries bytes faster.
    j["byte_time_measured"] =
        cost.byte_time !=
        rcb4::ops::link_cost::at(s.c().options().baud > 0 ? s.c().options().baud : 115200u, {}).byte_time;
    j["iory_cycle_hz"] = std::round(iory_rate * 10) / 10;
    j["iory_cycle_wire_limit_hz"] = opt(iory_limit);
    j["iory_cycle_link_limit_hz"] = std::round(iory_link * 10) / 10;
    j["iory_cycle_bytes"] = iory_bytes;
    emit(j);
    return exit_ok;
  }
  fmt::print("rcb4 bench against {} {}, {} runs each{}\n", s.where(),
             s.rate_known() ? fmt::format("at {} baud", s.baud()) : std::string("(line rate unknown: give --baud)"),
             o.count, low ? ", CPU wake-up latency held at 0 us" : "");
  const auto row = [](std::string_view what, double got, std::optional<double> lim, std::string_view unit,
                      std::optional<double> link = std::nullopt) {
    std::string line = fmt::format("  {:<46} {:>9.1f} {:<3}", what, got, unit);
    if (lim) line += fmt::format(" wire limit {:>9.1f} ({:.2f}x)", *lim, got / *lim);
    if (link) line += fmt::format("  link limit {:>8.1f} ({:.2f}x)", *link, got / *link);
    fmt::print("{}\n", line);
  };
  row("ping", ping_rate, ping_limit, "/s");
  row("MOV read 2 bytes", read_rate, read_limit, "/s");
  row(fmt::format("{} cycle ({} joints, {} B)", model.name(), targets.joints().size(), cycle_bytes), cycle_rate,
      cycle_limit, "Hz", cycle_link);
  row(fmt::format("iory/rcb4 cycle (5 x MOV 126 + CONST35, {} B)", iory_bytes), iory_rate, iory_limit, "Hz", iory_link);
  fmt::print("  {} cycle / iory/rcb4 cycle: {:.2f}x\n", model.name(), cycle_rate / iory_rate);
  fmt::print(
      "  link measured at {:.0f} us per exchange beyond the wire, {:.2f} us a byte: the planner reads the "
      "joints in {} ({} bytes)\n",
      overhead_us, std::chrono::duration<double, std::micro>(cost.byte_time).count(), plural(read_sizes.size(), "read"),
      fmt::join(read_sizes, "+"));
  fmt::print("  (link limit: the bytes plus each exchange's measured cost{})\n",
             s.rate_known() ? "; the wire limit counts the bytes only" : "");
  if (beyond_wire)
    fmt::print(
        "  warning: faster than {} baud carries the bytes: this board is not paced at that rate (a virtual "
        "board, a pty, a bridge that buffers), so these figures say nothing of a real line{}\n",
        s.baud(), s.is_virtual() ? "; rcb4 serve --pace paces one" : "");
  return exit_ok;
}

}  // namespace

void add_bench_command(CLI::App& app, context& ctx) {
  auto* cmd = app.add_subcommand(
      "bench", "round trips and the robot's control cycle per second next to the wire limit and iory/rcb4's cycle");
  auto o = std::make_shared<bench_options>();
  cmd->add_option("--count", o->count, "runs of each workload (default 500)")->check(int_range(1, 10000000));
  cmd->add_flag("--low-latency", o->low_latency,
                "hold the CPUs' wake-up latency at 0 us meanwhile (a PM QoS request on /dev/cpu_dma_latency: root)");
  on_device(cmd, ctx, [&ctx, o](session& s) { return bench(s, *o, ctx.g); });
}

}  // namespace cli
