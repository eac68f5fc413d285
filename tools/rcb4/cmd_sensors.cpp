// rcb4 command-line tool: sensors (one reading) and monitor (a live table, or JSON lines).
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/motion/buttons.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <thread>

namespace cli {
namespace {

using namespace std::chrono_literals;

/** The names of the buttons held in @p b, as `rcb4 motion buttons` takes them (motion/buttons.hpp). */
std::vector<std::string> button_names(std::uint16_t b) {
  std::vector<std::string> out;
  for (const auto& n : rcb4::motion::button_names)
    if (b & n.bit) out.emplace_back(n.name);
  return out;
}

std::string buttons_text(std::uint16_t b) { return rcb4::motion::buttons_text(b); }

/** A joint's measured angle for JSON, to a hundredth; null when its servo never answered. */
json degrees_of(const rcb4::robot::joint_reading& r) {
  const auto d = r.degrees();
  return d ? json(std::round(*d * 100) / 100) : json(nullptr);
}

/** One reading of everything a KHR carries on its inputs. */
struct reading {
  rcb4::ops::analog_inputs analog;
  rcb4::ops::pio_state pio;
  rcb4::ops::receiver_state rx;
};

reading read_all(session& s) {
  return {s.run(rcb4::ops::read_analog{}), s.run(rcb4::ops::read_pio{}), s.run(rcb4::ops::read_receiver{})};
}

/** The sensor fields of `sensors --json` and of each `monitor --json` line. */
void put(json& j, const reading& r) {
  j["battery_volts"] = std::round(r.analog.battery_volts * 100) / 100;
  j["ad"] = r.analog.values;
  j["pio_direction"] = r.pio.direction;
  j["pio_value"] = r.pio.value;
  j["buttons"] = r.rx.buttons;
  j["button_names"] = button_names(r.rx.buttons);
  j["pa"] = r.rx.analog;
}

int sensors(session& s, const globals& g) {
  const auto r = read_all(s);
  if (g.json) {
    json j;
    put(j, r);
    emit(j);
    return exit_ok;
  }
  fmt::print("battery   {:.2f} V (AD0 = {})\n", r.analog.battery_volts, r.analog.values[0]);
  for (std::size_t k = 1; k < r.analog.values.size(); ++k) fmt::print("AD{:<2}      {}\n", k, r.analog.values[k]);
  fmt::print("PIO       direction 0b{:010b} (1 = output), levels 0b{:010b}\n", r.pio.direction, r.pio.value);
  fmt::print("buttons   0x{:04X} {}\n", r.rx.buttons, buttons_text(r.rx.buttons));
  fmt::print("PA1..PA4  {} {} {} {}\n", r.rx.analog[0], r.rx.analog[1], r.rx.analog[2], r.rx.analog[3]);
  return exit_ok;
}

/**
 * The joints --joints names (none: every joint of the profile the board has a servo block for),
 * located once; a joint named outright that the board lacks is an error naming it.
 */
std::pair<rcb4::robot::joint_map, std::vector<const rcb4::robot::joint*>> monitored(
    session& s, const globals& g, const std::vector<std::string>& words) {
  const auto& m = robot_of(g);
  if (!words.empty()) {
    auto need = joints_of(m, words);
    return {locate(s, m, need), std::move(need)};
  }
  auto map = s.run(rcb4::robot::locate_joints(m));
  std::vector<const rcb4::robot::joint*> have;
  for (const auto* j : joints_of(m, {}))
    if (map.block_of(*j)) have.push_back(j);
  return {std::move(map), std::move(have)};
}

int monitor(session& s, long long hz, long long count, const std::vector<std::string>& words, const globals& g) {
  const signal_catcher catcher;  // Ctrl-C ends the monitor after the sample under way
  const auto [map, shown] = monitored(s, g, words);
  const bool tty = ::isatty(STDOUT_FILENO) && !g.json;
  const auto period = std::chrono::microseconds(1000000 / hz);
  const auto start = std::chrono::steady_clock::now();
  auto next = start;
  bool warned = false;
  for (long long n = 0; !signal_catcher::caught() && (count == 0 || n < count); ++n) {
    // Every allocated servo (JSON "positions" by ICS number), and the joints by name.
    const auto states = s.run(rcb4::ops::read_servo_states(rcb4::ops::link_cost::at(s.baud(), 1ms)));
    const auto joints = cli::read_all(s, map, rcb4::robot::fields::positions);
    const auto r = read_all(s);
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - start).count();
    if (g.json) {
      json j;
      j["sample"] = n;
      j["time"] =
          std::round(std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count() *
                     1000) /
          1000;
      j["elapsed_s"] = std::round(elapsed * 1000) / 1000;
      put(j, r);
      json pos = json::object();
      for (const auto& st : states) pos[std::to_string(st.ics.value())] = st.position;
      j["positions"] = pos;
      json by_name = json::object();
      for (const auto& jr : joints)
        if (std::find(shown.begin(), shown.end(), jr.j) != shown.end()) by_name[jr.j->name] = degrees_of(jr);
      j["joints"] = by_name;
      emit(j);
    } else {
      if (tty) fmt::print("\x1b[H\x1b[2J");
      fmt::print("rcb4 monitor  {}  {} Hz  sample {}  {:.1f} s  (Ctrl-C to stop)\n", s.where(), hz, n, elapsed);
      fmt::print("battery {:.2f} V   buttons {}   PA1..4 {} {} {} {}   PIO 0b{:010b}\n", r.analog.battery_volts,
                 buttons_text(r.rx.buttons), r.rx.analog[0], r.rx.analog[1], r.rx.analog[2], r.rx.analog[3],
                 r.pio.value);
      fmt::print("AD1..10");
      for (std::size_t k = 1; k < r.analog.values.size(); ++k) fmt::print(" {:4}", r.analog.values[k]);
      fmt::print("\n");
      std::size_t i = 0;
      for (const auto& jr : joints) {
        if (std::find(shown.begin(), shown.end(), jr.j) == shown.end()) continue;
        const auto d = jr.degrees();
        fmt::print("{:<22} {:>7}{}", jr.j->name,
                   d ? fmt::format("{:+.1f}", *d) : std::string(jr.answered() ? "?" : "silent"),
                   ++i % 3 == 0 ? "\n" : "   ");
      }
      if (i % 3 != 0) fmt::print("\n");
      if (shown.empty())
        fmt::print("no joint of {} has a servo on this board (rcb4 scan shows its slots)\n", robot_of(g).name());
      std::fflush(stdout);
    }
    next += period;
    // The rate the user asked for, or as fast as the link allows: then say so once (stderr), and
    // keep the schedule from running ahead of the clock (no burst when the link is quick again).
    const auto after = std::chrono::steady_clock::now();
    if (after > next + period) {
      next = after;
      if (!warned && n >= 4) {
        warned = true;
        const double achieved = static_cast<double>(n + 1) / std::chrono::duration<double>(after - start).count();
        fmt::print(stderr,
                   "rcb4 monitor: warning: {} Hz asked, the board and link give {:.0f} samples a second; every "
                   "sample is shown as it comes\n",
                   hz, achieved);
      }
    }
    std::this_thread::sleep_until(next);  // the sampling rate the user asked for
  }
  return exit_ok;
}

}  // namespace

void add_sensor_commands(CLI::App& app, context& ctx) {
  auto* sensors_cmd = app.add_subcommand("sensors", "AD0..AD10, battery volts, PIO, receiver buttons and PA1..PA4");
  on_device(sensors_cmd, ctx, [&ctx](session& s) { return sensors(s, ctx.g); });

  auto* monitor_cmd =
      app.add_subcommand("monitor", "a live table of servo positions and sensors until Ctrl-C (--json: a line each)");
  auto hz = std::make_shared<long long>(5);
  auto count = std::make_shared<long long>(0);
  monitor_cmd->add_option("--hz", *hz, "samples per second (default 5)")->check(int_range(1, 1000));
  monitor_cmd->add_option("--count", *count, "stop after N samples (default: until Ctrl-C)")
      ->check(int_range(1, 100000000));
  auto words = std::make_shared<std::vector<std::string>>();
  monitor_cmd->add_option("--joints", *words,
                          "joints, groups (left_arm, legs, ...) or all of --robot's profile (default: every joint the "
                          "board has a servo for)");
  on_device(monitor_cmd, ctx, [&ctx, hz, count, words](session& s) { return monitor(s, *hz, *count, *words, ctx.g); });
}

}  // namespace cli
