// rcb4 command-line tool: motion record FILE: teach by demonstration. The joints are sampled while a
// person moves the robot by hand (--free takes their torque off first); robot::recorder keeps the
// poses that replay the movement, and they are saved as a motion file (rcb4/robot/motion_file.hpp).
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/robot/motion_file.hpp>
#include <rcb4/robot/record.hpp>

#include <poll.h>
#include <unistd.h>

#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <thread>

namespace cli {
namespace {

namespace ro = rcb4::robot;

struct record_options {
  std::string file;
  std::vector<std::string> joints;
  bool free = false, force = false;
  long long every_ms = 100;
  double threshold = 2.0;
  double for_s = 0;
};

/** True when Enter came on a terminal's stdin within @p wait; never reads a stdin that is not a terminal. */
bool enter_within(std::chrono::milliseconds wait) {
  if (!::isatty(STDIN_FILENO)) {
    std::this_thread::sleep_for(wait);
    return false;
  }
  pollfd p{STDIN_FILENO, POLLIN, 0};
  if (::poll(&p, 1, static_cast<int>(wait.count())) <= 0) return false;
  char buf[64];
  const auto n = ::read(STDIN_FILENO, buf, sizeof buf);
  return n > 0 && std::memchr(buf, '\n', static_cast<std::size_t>(n)) != nullptr;
}

int record(session& s, const record_options& o, const globals& g) {
  // The file must be writable before the robot goes limp and someone spends a minute moving it.
  {
    const bool existed = std::filesystem::exists(o.file);
    std::ofstream probe(o.file, std::ios::app);
    if (!probe)
      throw failure(exit_io, fmt::format("{}: cannot be written ({}): nothing recorded", o.file, std::strerror(errno)),
                    "name a file in a folder you can write to");
    probe.close();
    if (!existed) std::filesystem::remove(o.file);
  }
  const auto& m = robot_of(g);
  const auto js = joints_of(m, o.joints);
  const auto map = locate(s, m, js);
  const auto period = s.run(rcb4::ops::read_config{}).period;
  if (const auto st = s.run(rcb4::ops::read_motion_state{}); st.running && st.motion)
    throw failure(exit_board, fmt::format("motion {} is running: the robot is not yours to move", *st.motion),
                  "rcb4 motion wait, or rcb4 motion stop");
  // Every joint must answer before anything is freed: a silent servo would record as nothing.
  const auto angles = [&](std::vector<double>& out) {
    const auto rs = read_all(s, map, ro::fields::positions);
    out.clear();
    for (const auto* j : js)
      for (const auto& r : rs)
        if (r.j == j) {
          const auto d = r.degrees();
          if (!d)
            throw failure(exit_board,
                          fmt::format("{} reads position {}: its servo does not answer", j->name, r.position),
                          "rcb4 scan shows which servos answer; --joints leaves it out");
          out.push_back(*d);
        }
  };
  std::vector<double> sample;
  angles(sample);
  rcb4::servo_mask mask;
  for (const auto* j : js) mask.insert(j->ics);
  signal_catcher catcher;
  if (o.free) s.run(rcb4::ops::set_servo_power(rcb4::ops::power_state::free, mask));
  // Whatever happens from here, joints freed are held again where they are.
  struct hold_again {
    session& s;
    rcb4::servo_mask mask;
    bool on;
    ~hold_again() {
      if (!on) return;
      try {
        s.run(rcb4::ops::set_servo_power(rcb4::ops::power_state::hold, mask));
      } catch (...) {  // the failure that brought us here is the one to report
      }
    }
  } guard{s, mask, o.free};
  if (!g.json)
    fmt::print(stderr, "recording {} every {} ms{}: move the robot by hand; {}\n", plural(js.size(), "joint"),
               o.every_ms, o.free ? " (free)" : "",
               o.for_s > 0 ? fmt::format("stops after {:g} s (or Enter, Ctrl-C)", o.for_s)
                           : std::string(::isatty(STDIN_FILENO) ? "Enter or Ctrl-C stops" : "Ctrl-C stops"));
  ro::recorder rec(js, o.threshold, period);
  const auto start = std::chrono::steady_clock::now();
  const auto every = std::chrono::milliseconds(o.every_ms);
  const bool tty = ::isatty(STDERR_FILENO) && !g.json;
  std::exception_ptr lost;
  for (auto next = start;;) {
    const auto now = std::chrono::steady_clock::now();
    rec.sample(std::chrono::duration_cast<std::chrono::milliseconds>(now - start), sample);
    if (tty)
      fmt::print(stderr, "\r  {:5.1f} s  {} samples  {} poses ", std::chrono::duration<double>(now - start).count(),
                 rec.samples(), rec.poses().size());
    if (o.for_s > 0 && now - start >= std::chrono::duration<double>(o.for_s)) break;
    next += every;
    const auto wait = std::chrono::duration_cast<std::chrono::milliseconds>(next - std::chrono::steady_clock::now());
    if (signal_catcher::caught() || enter_within(std::max(wait, std::chrono::milliseconds(0))) ||
        signal_catcher::caught())
      break;
    try {
      angles(sample);
    } catch (...) {  // the board went away: what was recorded is kept, then the failure is reported
      lost = std::current_exception();
      break;
    }
  }
  rec.finish();
  if (tty) fmt::print(stderr, "\r{:60}\r", "");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // A lost board: the guard still tries to hold the joints on the way out, and fails quietly.
  if (o.free && !lost) {
    guard.on = false;
    s.run(rcb4::ops::set_servo_power(rcb4::ops::power_state::hold, mask));
  }
  ro::motion_document d;
  d.robot = m.name();
  d.period = period;
  for (const auto& p : rec.poses()) {
    ro::motion_pose mp;
    for (std::size_t i = 0; i < js.size(); ++i) mp.targets.push_back({js[i]->name, p.degrees[i], std::nullopt});
    mp.time = p.time;
    d.steps.emplace_back(std::move(mp));
  }
  d.steps.emplace_back(rcb4::motion::end{});
  try {
    ro::save_motion(o.file, d,
                    fmt::format("recorded by rcb4 motion record: {} samples every {} ms over {:.1f} s, kept where the "
                                "movement left a straight line by more than {:g} degrees\nthe first pose takes {} ms "
                                "from wherever the robot is when it plays",
                                rec.samples(), o.every_ms, seconds, o.threshold, rec.poses().front().time.count()));
  } catch (const ro::profile_error& e) {
    throw failure(exit_io, e.what());
  }
  if (lost) {
    fmt::print(stderr, "rcb4 motion record: the {} recorded before the board stopped answering are in {}\n",
               plural(rec.poses().size(), "pose"), o.file);
    std::rethrow_exception(lost);
  }
  if (rec.clamped() && !g.json)
    fmt::print(stderr, "note: {} angles were beyond a joint's limit and were recorded at the limit\n", rec.clamped());
  if (g.json)
    emit(json{{"file", o.file},
              {"samples", rec.samples()},
              {"poses", rec.poses().size()},
              {"seconds", std::round(seconds * 10) / 10},
              {"period_ms", rcb4::milliseconds(period)},
              {"clamped", rec.clamped()},
              {"held", o.free}});
  else
    fmt::print(
        "recorded {} from {} over {:.1f} s -> {}{} (rcb4 motion play {} replays it; motion push {} N stores it)\n",
        plural(rec.poses().size(), "pose"), plural(rec.samples(), "sample"), seconds, o.file,
        o.free ? " (the joints hold where they are)" : "", o.file, o.file);
  return exit_ok;
}

}  // namespace

void add_record_command(CLI::App* motion, context& ctx) {
  auto o = std::make_shared<record_options>();
  auto* cmd = motion->add_subcommand(
      "record",
      "teach by demonstration: sample the joints while you move the robot by hand, save the poses that "
      "replay it as a motion file");
  cmd->add_option("FILE", o->file, "the motion file to write (.yaml or .yml)")->required();
  cmd->add_flag("--free", o->free, "free the joints first (no torque) and hold them again at the end");
  cmd->add_option("--joints", o->joints, "joints or groups to record (default: all)");
  cmd->add_option("--every", o->every_ms, "sample every MS milliseconds (default 100)")
      ->type_name("MS")
      ->check(CLI::Range(20, 2000));
  cmd->add_option("--threshold", o->threshold,
                  "degrees a joint may leave the straight line between two poses before a pose is kept (default 2)")
      ->type_name("DEG")
      ->check(CLI::Range(0.1, 45.0));
  cmd->add_option("--for", o->for_s, "stop after S seconds (default: Enter on a terminal, or Ctrl-C)")
      ->type_name("S")
      ->check(CLI::Range(0.1, 3600.0));
  cmd->add_flag("--force", o->force, "replace FILE when it exists");
  cmd->callback([&ctx, o] {
    const auto ext = std::filesystem::path(o->file).extension();
    if (ext != ".yaml" && ext != ".yml")
      throw usage_error(fmt::format("FILE: {} does not end in .yaml or .yml", o->file));
    if (!o->force && std::filesystem::exists(o->file))
      throw usage_error(fmt::format("FILE: {} exists (--force replaces it)", o->file));
    ctx.action = [&ctx, o] {
      session s(ctx.g);
      return record(s, *o, ctx.g);
    };
  });
}

}  // namespace cli
