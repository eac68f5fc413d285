// rcb4 command-line tool: bench — round trips and control cycles per second next to the wire limit.
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
    progress bar(fmt::format("{} ({}/3)", label, ++stage), static_cast<std::size_t>(o.count), g.json);
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
  // Control cycle: read every allocated servo's state (planned reads), then move them all.
  const auto cost = rcb4::ops::link_cost::at(s.baud(), 1ms);
  const auto states = s.run(rcb4::ops::read_servo_states(cost));
  rcb4::servo_set<rcb4::servo_position> hold;
  for (const auto& st : states) hold.insert(st.ics, rcb4::servo_position::hold());
  const auto move_all = rcb4::const_servo::make(hold, rcb4::frames{1});
  std::size_t cycle_bytes = 0;
  {
    rcb4::ops::read_servo_states plan(cost);
    while (auto c = plan.next()) {
      const auto r = s.c().execute(*c);
      cycle_bytes += rcb4::encode(*c).size() + rcb4::expected_reply(*c).frame_size();
      plan.on_reply(r.view());
    }
    if (move_all) cycle_bytes += rcb4::encode(*move_all).size() + 4;
  }
  const double cycle_rate = rate("control cycle", [&] {
    s.run(rcb4::ops::read_servo_states(cost));
    if (move_all) s.c().execute(*move_all);
  });
  const auto ping_limit = limit(3 + 4), read_limit = limit(10 + 5), cycle_limit = limit(cycle_bytes);
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
    j["cycle_bytes"] = cycle_bytes;
    j["servos"] = states.size();
    emit(j);
    return exit_ok;
  }
  fmt::print("rcb4 bench against {} {}, {} runs each{}\n", s.where(),
             s.rate_known() ? fmt::format("at {} baud", s.baud()) : std::string("(line rate unknown: give --baud)"),
             o.count, low ? ", CPU wake-up latency held at 0 us" : "");
  const auto row = [](std::string_view what, double got, std::optional<double> lim, std::string_view unit) {
    if (lim)
      fmt::print("  {:<40} {:>9.1f} {:<3} wire limit {:>9.1f} {:<3} {:.2f}x\n", what, got, unit, *lim, unit,
                 got / *lim);
    else
      fmt::print("  {:<40} {:>9.1f} {}\n", what, got, unit);
  };
  row("ping", ping_rate, ping_limit, "/s");
  row("MOV read 2 bytes", read_rate, read_limit, "/s");
  row(fmt::format("control cycle ({}, {} bytes)", plural(states.size(), "servo"), cycle_bytes), cycle_rate, cycle_limit,
      "Hz");
  if (s.is_virtual())
    fmt::print("  (the in-process virtual board is not paced: it can beat the wire limit; use rcb4 serve --pace)\n");
  return exit_ok;
}

}  // namespace

void add_bench_command(CLI::App& app, context& ctx) {
  auto* cmd = app.add_subcommand("bench", "round trips and control cycles per second next to the wire limit");
  auto o = std::make_shared<bench_options>();
  cmd->add_option("--count", o->count, "runs of each workload (default 500)")->check(int_range(1, 10000000));
  cmd->add_flag("--low-latency", o->low_latency,
                "hold the CPUs' wake-up latency at 0 us meanwhile (a PM QoS request on /dev/cpu_dma_latency: root)");
  on_device(cmd, ctx, [&ctx, o](session& s) { return bench(s, *o, ctx.g); });
}

}  // namespace cli
