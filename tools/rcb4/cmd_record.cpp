// rcb4 command-line tool: motion record FILE: teach by demonstration. The joints are sampled while a
// person moves the robot by hand (--free takes their torque off first); robot::recorder keeps the
// poses that replay the movement, and they are saved as a motion file (rcb4/robot/motion_file.hpp).
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/robot/motion_file.hpp>
#include <rcb4/robot/services/record.hpp>

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
namespace sv = rcb4::robot::services;

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
    std::this_thread::sleep_for(wait);  // the tool's own pacing: stdin is not a terminal to poll
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
  session_link link(s, g.json);
  signal_catcher catcher;
  // Checked first (no motion runs, every joint answers), then the joints freed when asked.
  sv::recording rec(link, m, joints_of(m, o.joints),
                    {.threshold = o.threshold,
                     .free = o.free,
                     .lead_in = std::chrono::milliseconds(1000),
                     .cost = rcb4::ops::link_cost::at(s.baud(), std::chrono::milliseconds(1))});
  const auto joints = o.joints.empty() ? m.joints().size() : joints_of(m, o.joints).size();
  if (!g.json)
    fmt::print(stderr, "recording {} every {} ms{}: move the robot by hand; {}\n", plural(joints, "joint"), o.every_ms,
               o.free ? " (free)" : "",
               o.for_s > 0 ? fmt::format("stops after {:g} s (or Enter, Ctrl-C)", o.for_s)
                           : std::string(::isatty(STDIN_FILENO) ? "Enter or Ctrl-C stops" : "Ctrl-C stops"));
  const auto start = std::chrono::steady_clock::now();
  const auto every = std::chrono::milliseconds(o.every_ms);
  const bool tty = ::isatty(STDERR_FILENO) && !g.json;
  std::exception_ptr lost;
  for (auto next = start;;) {
    const auto now = std::chrono::steady_clock::now();
    try {
      rec.sample(std::chrono::duration_cast<std::chrono::milliseconds>(now - start));
    } catch (...) {  // the board went away: what was recorded is kept, then the failure is reported
      lost = std::current_exception();
      break;
    }
    if (tty)
      fmt::print(stderr, "\r  {:5.1f} s  {} samples  {} poses ", std::chrono::duration<double>(now - start).count(),
                 rec.poses().samples(), rec.poses().poses().size());
    if (o.for_s > 0 && now - start >= std::chrono::duration<double>(o.for_s)) break;
    next += every;
    const auto wait = std::chrono::duration_cast<std::chrono::milliseconds>(next - std::chrono::steady_clock::now());
    if (signal_catcher::caught() || enter_within(std::max(wait, std::chrono::milliseconds(0))) ||
        signal_catcher::caught())
      break;
  }
  if (tty) fmt::print(stderr, "\r{:60}\r", "");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // A lost board: the joints are not held again (the recording tries once more as it goes, quietly).
  const auto r = rec.finish(lost != nullptr);
  if (r.document.steps.size() < 2) std::rethrow_exception(lost);  // not even the first sample
  try {
    ro::save_motion(o.file, r.document,
                    fmt::format("recorded by rcb4 motion record: {} samples every {} ms over {:.1f} s, kept where the "
                                "movement left a straight line by more than {:g} degrees\nthe first pose takes {} ms "
                                "from wherever the robot is when it plays",
                                r.samples, o.every_ms, seconds, o.threshold, rec.poses().poses().front().time.count()));
  } catch (const ro::profile_error& e) {
    throw failure(exit_io, e.what());
  }
  const auto poses = r.document.steps.size() - 1;
  if (lost) {
    fmt::print(stderr, "rcb4 motion record: the {} recorded before the board stopped answering are in {}\n",
               plural(poses, "pose"), o.file);
    std::rethrow_exception(lost);
  }
  if (r.clamped && !g.json)
    fmt::print(stderr, "note: {} angles were beyond a joint's limit and were recorded at the limit\n", r.clamped);
  if (g.json)
    emit(json{{"file", o.file},
              {"samples", r.samples},
              {"poses", poses},
              {"seconds", std::round(seconds * 10) / 10},
              {"period_ms", rcb4::milliseconds(r.document.period)},
              {"clamped", r.clamped},
              {"held", r.held}});
  else
    fmt::print(
        "recorded {} from {} over {:.1f} s -> {}{} (rcb4 motion play {} replays it; motion push {} N stores it)\n",
        plural(poses, "pose"), plural(r.samples, "sample"), seconds, o.file,
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
