// rcb4 command-line tool: the robot by joint names in degrees (--robot): joint list|move|free|hold,
// pose capture|play|show, trim get|set, scan.
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/robot/services/moves.hpp>
#include <rcb4/robot/services/trims.hpp>

#include <cerrno>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <thread>

#include <unistd.h>

namespace cli {

/** Reads stdin up to a newline: true when Enter came; false at its end or on a caught signal. */
bool wait_for_enter() {
  for (char c = 0; !signal_catcher::caught();) {
    const auto n = ::read(STDIN_FILENO, &c, 1);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    if (c == '\n') return !signal_catcher::caught();
  }
  return false;
}

/** The joints the words name (joints, groups, "all"; none: all), each once, in the model's order. */
std::vector<const rcb4::robot::joint*> joints_of(const rcb4::robot::model& m, const std::vector<std::string>& words) {
  if (words.empty()) return std::get<std::vector<const rcb4::robot::joint*>>(m.select("all"));
  std::vector<const rcb4::robot::joint*> chosen;
  for (const auto& w : words) {
    auto sel = m.select(w);
    if (!rcb4::robot::ok(sel))
      throw usage_error(
          fmt::format("{} (robot {}: see rcb4 joint list)", std::get<rcb4::robot::problem>(sel).message, m.name()));
    for (const auto* j : std::get<std::vector<const rcb4::robot::joint*>>(sel))
      if (std::find(chosen.begin(), chosen.end(), j) == chosen.end()) chosen.push_back(j);
  }
  std::vector<const rcb4::robot::joint*> ordered;
  for (const auto& j : m.joints())
    if (std::find(chosen.begin(), chosen.end(), &j) != chosen.end()) ordered.push_back(&j);
  return ordered;
}

/** Refuses (exit 1) naming @p missing, the joints of @p m the board has no servo block for; nothing when none. */
void refuse_missing(const rcb4::robot::model& m, const std::vector<const rcb4::robot::joint*>& missing) {
  if (missing.empty()) return;
  std::vector<std::string> names;
  for (const auto* j : missing) names.push_back(fmt::format("{} (ICS {})", j->name, j->ics.value()));
  throw failure(
      exit_board, fmt::format("the board has no servo allocated for {}", fmt::join(names, ", ")),
      fmt::format("is this a {}? rcb4 scan shows the board's slots; --robot FILE names another robot", m.name()));
}

/** Where the joints are on this board; joints without a block are an error naming them. */
rcb4::robot::joint_map locate(session& s, const rcb4::robot::model& m,
                              const std::vector<const rcb4::robot::joint*>& need) {
  auto map = s.run(rcb4::robot::locate_joints(m));
  std::vector<const rcb4::robot::joint*> missing;
  for (const auto* j : need)
    if (!map.block_of(*j)) missing.push_back(j);
  refuse_missing(m, missing);
  return map;
}

std::vector<rcb4::robot::joint_reading> read_all(session& s, const rcb4::robot::joint_map& map, rcb4::robot::fields f) {
  return s.run(rcb4::robot::read_joints(map, f, rcb4::ops::link_cost::at(s.baud(), std::chrono::milliseconds(1))));
}

namespace {

using namespace std::chrono_literals;
namespace robot = rcb4::robot;

/** Degrees to a hundredth for JSON, without -0; null for none. */
json rounded(std::optional<double> d) {
  if (!d) return nullptr;
  const double r = std::round(*d * 100) / 100;
  return r == 0 ? 0.0 : r;
}

/** Degrees to a tenth, signed, without "-0.0"; "-" for none. */
std::string deg_text(std::optional<double> d) {
  if (!d) return "-";
  const double tenths = std::round(*d * 10) / 10;
  return fmt::format("{:+.1f}", tenths == 0 ? 0.0 : tenths);
}

/** Checked targets, or a usage error (exit 2, nothing sent) naming the joint and the limit. */
std::vector<robot::joint_move> checked(const robot::model& m, const std::vector<robot::joint_target>& t,
                                       std::chrono::milliseconds time) {
  auto r = robot::check_targets(m, t, time);
  if (!robot::ok(r)) throw usage_error(std::get<robot::problem>(r).message);
  return std::get<std::vector<robot::joint_move>>(std::move(r));
}

/** Moves sent, and the board's output period that times them. */
struct sent_moves {
  std::vector<robot::joint_move> moves;
  long long period_ms = 10;
};

/** Sends checked moves; with @p wait, polls until every moved joint's output reached its target. */
sent_moves move(session& s, const robot::model& m, std::vector<robot::joint_move> moves, bool wait) {
  std::vector<const robot::joint*> need;
  for (const auto& mv : moves) need.push_back(mv.j);
  const auto map = locate(s, m, need);
  // The one rule (rcb4/robot/services/moves.hpp): no move while a ROM motion runs.
  if (const auto why = rcb4::robot::services::move_refusal(s.run(rcb4::ops::read_motion_state{})))
    throw failure(exit_board, *why, "rcb4 motion wait lets it finish; rcb4 motion stop suspends it");
  robot::move_joints op(std::move(moves));
  rcb4::transport::error_code ec;
  s.run_steps(op, ec, [] {});
  // Possible on a board with a longer period (25 ms: 6375 ms), so the board's limit (exit 1), not a typo (2).
  if (ec == rcb4::errc::frames_out_of_range)
    throw failure(exit_board,
                  fmt::format("a move takes at most 255 output periods: {} ms at this board's {} ms period; nothing "
                              "was sent",
                              255 * milliseconds(op.period()), milliseconds(op.period())),
                  "a shorter time, or a longer period: rcb4 config set period=25");
  if (ec) throw rcb4::transport::system_error(ec);
  auto done = op.value();
  if (wait) {
    // The board's output reaches the target when its interpolation ends (+6 = the CONST's position).
    std::chrono::milliseconds longest{0};
    for (const auto& mv : done)
      longest = std::max(longest, std::chrono::milliseconds(mv.frames * milliseconds(op.period())));
    const auto deadline = std::chrono::steady_clock::now() + longest + 2s;
    while (true) {
      const auto now = read_all(s, map, robot::fields::state);
      const bool arrived = std::all_of(done.begin(), done.end(), [&](const auto& mv) {
        return std::any_of(now.begin(), now.end(),
                           [&](const auto& r) { return r.j == mv.j && r.target == mv.position.value(); });
      });
      if (arrived) break;
      if (std::chrono::steady_clock::now() > deadline)
        throw failure(exit_timeout,
                      fmt::format("the joints did not reach their targets within {} ms", (longest + 2s).count()),
                      "is the board's ICS switch off (rcb4 config)? a held program can overwrite the targets");
      std::this_thread::sleep_for(std::chrono::milliseconds(milliseconds(op.period())));
    }
  }
  return {std::move(done), static_cast<long long>(milliseconds(op.period()))};
}

/** One line (or JSON object) per joint moved: its angle, position, and the time it takes in frames. */
void print_moves(const sent_moves& sent, const globals& g, std::string_view verb) {
  if (g.json) {
    json list = json::array();
    for (const auto& mv : sent.moves)
      list.push_back({{"name", mv.j->name},
                      {"degrees", mv.degrees},
                      {"position", mv.position.value()},
                      {"frames", mv.frames},
                      {"ms", mv.frames * sent.period_ms},
                      {"asked_ms", mv.time.count()}});
    emit(json{{verb, list}});
    return;
  }
  for (const auto& mv : sent.moves) {
    // The board moves in whole output periods: a time between two is rounded to the nearest.
    const long long ms = mv.frames * sent.period_ms;
    fmt::print("{} {} to {} deg (position {}) over {} ms ({} of {} ms{})\n", verb, mv.j->name, deg_text(mv.degrees),
               mv.position.value(), ms, plural(mv.frames, "frame"), sent.period_ms,
               ms != mv.time.count() ? fmt::format("; {} ms asked", mv.time.count()) : std::string());
  }
}

/** NAME=DEG[@MS] items. */
std::vector<robot::joint_target> targets_of(const std::vector<std::string>& items) {
  std::vector<robot::joint_target> out;
  for (const std::string_view item : items) {
    const auto eq = item.find('=');
    if (eq == std::string_view::npos || eq == 0) throw usage_error(fmt::format("expected NAME=DEG, not '{}'", item));
    robot::joint_target t;
    t.joint = std::string(item.substr(0, eq));
    auto rest = item.substr(eq + 1);
    if (const auto at = rest.find('@'); at != std::string_view::npos) {
      t.time =
          std::chrono::milliseconds(parse_int(rest.substr(at + 1), t.joint + ": MS", 0, robot::longest_move.count()));
      rest = rest.substr(0, at);
    }
    const std::string str(rest);
    char* end = nullptr;
    t.degrees = std::strtod(str.c_str(), &end);
    if (str.empty() || end != str.c_str() + str.size() || !std::isfinite(t.degrees))
      throw usage_error(fmt::format("{}: '{}' is not degrees", t.joint, rest));
    out.push_back(t);
  }
  return out;
}

/** A usage error unless @p path names a pose file by its extension (or is -, stdin/stdout). */
void check_pose_name(const std::string& path) {
  if (path == "-") return;
  const auto ext = std::filesystem::path(path).extension();
  if (ext != ".json" && ext != ".yaml" && ext != ".yml")
    throw usage_error(fmt::format("{}: a pose file ends in .json, .yaml or .yml (- for stdin/stdout)", path));
}

/** The pose file @p path (- : stdin) for @p m; a bad one is a usage error with its file:line. */
robot::pose pose_of(const std::string& path, const robot::model& m) {
  check_pose_name(path);
  try {
    if (path == "-") {
      const std::string text{std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>()};
      return robot::parse_pose(text, "<stdin>", m);
    }
    return robot::load_pose(path, m);
  } catch (const robot::profile_error& e) {
    throw usage_error(e.what());
  }
}

void print_joints(const robot::model& m, const std::vector<robot::joint_reading>& rs, const globals& g) {
  if (g.json) {
    json list = json::array();
    for (const auto& r : rs) {
      json j;
      j["name"] = r.j->name;
      j["ics"] = r.j->ics.value();
      j["id"] = r.j->servo_id();
      j["bus"] = r.j->bus();
      j["allocated"] = r.allocated;
      j["degrees"] = rounded(r.degrees());
      j["target"] = rounded(r.target_degrees());
      j["state"] = !r.allocated ? "unallocated" : r.is_free() ? "free" : r.is_hold() ? "hold" : "position";
      j["position"] = r.allocated ? json(r.position) : json(nullptr);
      j["trim"] = r.allocated ? rounded(robot::trim_degrees(*r.j, r.trim)) : json(nullptr);
      j["lower"] = r.j->lower;
      j["upper"] = r.j->upper;
      list.push_back(j);
    }
    emit(list);
    return;
  }
  fmt::print("{} ({})\n", m.name(), plural(rs.size(), "joint"));
  fmt::print("{:<22} {:>4} {:>6}  {:>8}  {:>8}  {:>6}  {}\n", "joint", "ICS", "ID/bus", "degrees", "target", "trim",
             "limits");
  for (const auto& r : rs) {
    const std::string target = !r.allocated  ? "no servo"
                               : r.is_free() ? "FREE"
                               : r.is_hold() ? "HOLD"
                                             : deg_text(r.target_degrees());
    fmt::print("{:<22} {:>4} {:>4}/{}  {:>8}  {:>8}  {:>6}  {:g}..{:g}\n", r.j->name, r.j->ics.value(), r.j->servo_id(),
               r.j->bus(), deg_text(r.degrees()), target,
               r.allocated ? deg_text(robot::trim_degrees(*r.j, r.trim)) : "-", r.j->lower, r.j->upper);
  }
}

void add_joint(CLI::App& app, context& ctx) {
  auto* joint = app.add_subcommand("joint", "the robot's joints by name, in degrees within their limits (--robot)");
  joint->require_subcommand(1);

  auto* list = joint->add_subcommand("list", "every joint: ICS, degrees, target, trim, limits");
  auto names = std::make_shared<std::vector<std::string>>();
  list->add_option("NAME", *names, "joints or groups (default: all)");
  list->callback([&ctx, names] {
    ctx.action = [&ctx, names] {
      const auto& m = robot_of(ctx.g);
      const auto want = joints_of(m, *names);
      session s(ctx.g);
      const auto map = s.run(robot::locate_joints(m));
      auto rs = read_all(s, map, robot::fields::state);
      std::erase_if(rs, [&](const auto& r) { return std::find(want.begin(), want.end(), r.j) == want.end(); });
      if (std::none_of(rs.begin(), rs.end(), [](const auto& r) { return r.allocated; }))
        throw failure(exit_board, fmt::format("the board allocates none of {}'s joints", m.name()),
                      "rcb4 scan shows the board's slots; --robot FILE names another robot");
      print_joints(m, rs, ctx.g);
      return exit_ok;
    };
  });

  auto* mv =
      joint->add_subcommand("move", "move joints: NAME=DEG[@MS] ... (an angle beyond a limit: exit 2, nothing moves)");
  struct move_options {
    std::vector<std::string> items;
    long long time_ms = 500;
    bool wait = false;
  };
  auto mo = std::make_shared<move_options>();
  mv->add_option("NAME=DEG[@MS]", mo->items, "degrees from the joint's zero; MS its own duration")->required();
  mv->add_option("--time", mo->time_ms, "duration in ms for joints without @MS (default 500; at most 6375)")
      ->type_name("MS")
      ->check(int_range(0, robot::longest_move.count()));
  mv->add_flag("--wait", mo->wait, "return when the board's outputs have reached the targets");
  mv->footer("examples:\n  rcb4 joint move head_yaw=30\n  rcb4 joint move left_knee=40@800 right_knee=40@800 --wait");
  mv->callback([&ctx, mo] {
    auto targets = targets_of(mo->items);
    ctx.action = [&ctx, mo, targets] {
      const auto& m = robot_of(ctx.g);
      auto moves = checked(m, targets, std::chrono::milliseconds(mo->time_ms));
      session s(ctx.g);
      print_moves(move(s, m, std::move(moves), mo->wait), ctx.g, mo->wait ? "moved" : "moving");
      return exit_ok;
    };
  });

  for (const bool free : {true, false}) {
    auto* power = joint->add_subcommand(free ? "free" : "hold", free ? "torque off: the joints can be moved by hand"
                                                                     : "torque on, holding where the joints are");
    auto which = std::make_shared<std::vector<std::string>>();
    power->add_option("NAME", *which, "joints or groups (left_arm, legs, ...; default: all)");
    power->callback([&ctx, which, free] {
      ctx.action = [&ctx, which, free] {
        const auto& m = robot_of(ctx.g);
        const auto js = joints_of(m, *which);
        session s(ctx.g);
        locate(s, m, js);
        rcb4::servo_mask mask;
        for (const auto* j : js) mask.insert(j->ics);
        s.run(rcb4::ops::set_servo_power(free ? rcb4::ops::power_state::free : rcb4::ops::power_state::hold, mask));
        json done = json::array();
        for (const auto* j : js) done.push_back(j->name);
        if (ctx.g.json)
          emit(json{{free ? "freed" : "holding", done}});
        else
          fmt::print("{} {}\n", free ? "freed" : "holding", plural(js.size(), "joint"));
        return exit_ok;
      };
    });
  }
}

void add_pose(CLI::App& app, context& ctx) {
  auto* pose = app.add_subcommand("pose", "poses: joint angles saved in a file (JSON or YAML) and played back");
  pose->require_subcommand(1);

  auto* capture = pose->add_subcommand("capture", "read the joints and save them as a pose");
  struct capture_options {
    std::string file;
    std::vector<std::string> joints;
    bool free = false;
    bool force = false;
  };
  auto co = std::make_shared<capture_options>();
  capture->add_option("FILE", co->file, "pose file: .json, .yaml or .yml; - for JSON on stdout")->required();
  capture->add_option("--joints", co->joints, "joints or groups to capture (default: all)");
  capture->add_flag("--free", co->free,
                    "free the joints first, wait for Enter while you pose the robot by hand, then capture and hold "
                    "(Ctrl-C or the end of stdin: hold them again, capture nothing)");
  capture->add_flag("--force", co->force, "replace FILE if it exists");
  capture->callback([&ctx, co] {
    check_pose_name(co->file);
    if (co->file != "-" && !co->force && std::filesystem::exists(co->file))
      throw usage_error(fmt::format("{} exists: --force replaces it", co->file));
    ctx.action = [&ctx, co] {
      const auto& m = robot_of(ctx.g);
      const auto js = joints_of(m, co->joints);
      session s(ctx.g);
      const auto map = locate(s, m, js);
      rcb4::servo_mask mask;
      for (const auto* j : js) mask.insert(j->ics);
      std::optional<signal_catcher> catcher;  // from before the joints go free until they hold again
      if (co->free) {
        catcher.emplace();
        s.run(rcb4::ops::set_servo_power(rcb4::ops::power_state::free, mask));
        fmt::print(stderr, "{} free: pose the robot by hand, then press Enter (Ctrl-C: hold them, capture nothing)\n",
                   plural(js.size(), "joint"));
        if (!wait_for_enter()) {
          s.run(rcb4::ops::set_servo_power(rcb4::ops::power_state::hold, mask));
          if (signal_catcher::caught())
            throw failure(exit_interrupted,
                          "interrupted before Enter: nothing captured; the joints hold where they are");
          throw usage_error(
              "stdin ended before Enter: nothing captured; the joints hold where they are (--free waits "
              "for Enter on a terminal)");
        }
      }
      const auto rs = read_all(s, map, robot::fields::positions);
      robot::pose p{m.name(), {}, std::nullopt};
      for (const auto& r : rs) {
        if (std::find(js.begin(), js.end(), r.j) == js.end()) continue;
        const auto d = r.degrees();
        if (!d)
          throw failure(exit_board, fmt::format("{} reads position {}, not an angle", r.j->name, r.position),
                        "a servo that never answered reads 0: rcb4 scan");
        if (*d < r.j->lower || *d > r.j->upper)
          fmt::print(stderr,
                     "rcb4 pose capture: warning: {} is at {:+.1f} deg, beyond its limits {:g}..{:g}: "
                     "the pose cannot be played as it is\n",
                     r.j->name, *d, r.j->lower, r.j->upper);
        p.joints.emplace_back(r.j->name, *d);
      }
      if (co->free) s.run(rcb4::ops::set_servo_power(rcb4::ops::power_state::hold, mask));
      if (co->file == "-") {
        fmt::print("{}", robot::pose_json(p));
        return exit_ok;
      }
      try {
        robot::save_pose(co->file, p);
      } catch (const robot::profile_error& e) {
        throw failure(exit_io, e.what());
      }
      if (ctx.g.json)
        emit(json{{"file", co->file}, {"joints", p.joints.size()}, {"held", co->free}});
      else
        fmt::print("captured {} in {}{}\n", plural(p.joints.size(), "joint"), co->file,
                   co->free ? " (held there)" : "");
      return exit_ok;
    };
  });

  auto* play = pose->add_subcommand("play", "move the joints to a saved pose");
  struct play_options {
    std::string file;
    long long time_ms = -1;
    bool wait = false;
  };
  auto po = std::make_shared<play_options>();
  play->add_option("FILE", po->file, "pose file (.json, .yaml or .yml)")->required();
  play->add_option("--time", po->time_ms, "duration in ms (default: the file's time_ms, else 1000)")
      ->type_name("MS")
      ->check(int_range(0, robot::longest_move.count()));
  play->add_flag("--wait", po->wait, "return when the board's outputs have reached the pose");
  play->callback([&ctx, po] {
    ctx.action = [&ctx, po] {
      const auto& m = robot_of(ctx.g);
      const auto p = pose_of(po->file, m);
      std::vector<robot::joint_target> t;
      for (const auto& [n, d] : p.joints) t.push_back({n, d, std::nullopt});
      const auto time = po->time_ms >= 0 ? std::chrono::milliseconds(po->time_ms) : p.time.value_or(1000ms);
      auto moves = checked(m, t, time);
      session s(ctx.g);
      print_moves(move(s, m, std::move(moves), po->wait), ctx.g, po->wait ? "moved" : "moving");
      return exit_ok;
    };
  });

  auto* show = pose->add_subcommand("show", "print a pose file's joints and check them against the limits");
  auto file = std::make_shared<std::string>();
  show->add_option("FILE", *file, "pose file (.json, .yaml or .yml)")->required();
  on_run(show, ctx, [&ctx, file] {
    const auto& m = robot_of(ctx.g);
    const auto p = pose_of(*file, m);
    std::vector<std::string> problems;
    json list = json::array();
    for (const auto& [n, d] : p.joints) {
      const auto* j = m.find(n);
      const auto pos = robot::to_position(*j, d);
      if (!robot::ok(pos)) problems.push_back(std::get<robot::problem>(pos).message);
      list.push_back({{"name", n}, {"degrees", d}, {"ok", robot::ok(pos)}});
      if (!ctx.g.json)
        fmt::print(
            "{:<22} {:+8.2f}  {}\n", n, d,
            robot::ok(pos) ? fmt::format("position {}", std::get<rcb4::servo_position>(pos).value()) : "BEYOND LIMITS");
    }
    if (ctx.g.json)
      emit(json{{"robot", p.robot},
                {"time_ms", p.time ? json(p.time->count()) : json(nullptr)},
                {"joints", list},
                {"playable", problems.empty()}});
    if (!problems.empty()) throw usage_error(fmt::format("{} cannot be played: {}", *file, fmt::join(problems, "; ")));
    return exit_ok;
  });
}

void add_trim(CLI::App& app, context& ctx) {
  auto* trim = app.add_subcommand("trim", "trims: per-joint corrections of a servo horn's mounting (block +2)");
  trim->require_subcommand(1);
  auto* get = trim->add_subcommand("get", "every joint's trim, in degrees and counts");
  auto names = std::make_shared<std::vector<std::string>>();
  get->add_option("NAME", *names, "joints or groups (default: all)");
  get->callback([&ctx, names] {
    ctx.action = [&ctx, names] {
      const auto& m = robot_of(ctx.g);
      const auto js = joints_of(m, *names);
      session s(ctx.g);
      session_link link(s, ctx.g.json);
      const auto trims = rcb4::robot::services::read_trims(link, m, js);
      std::vector<const rcb4::robot::joint*> missing;
      for (const auto& t : trims)
        if (!t.allocated) missing.push_back(t.j);
      refuse_missing(m, missing);
      json list = json::array();
      for (const auto& t : trims) {
        const auto rom = t.rom_degrees();
        if (ctx.g.json)
          list.push_back({{"name", t.j->name},
                          {"degrees", std::round(t.degrees() * 100) / 100},
                          {"counts", t.ram},
                          {"rom_degrees", rom ? json(std::round(*rom * 100) / 100) : json(nullptr)},
                          {"rom_counts", t.rom ? json(*t.rom) : json(nullptr)}});
        else
          fmt::print("{:<22} {:+6.2f} deg  ({:+d} counts){}\n", t.j->name, t.degrees(), t.ram,
                     !t.rom            ? std::string("  ROM: none")
                     : *t.rom == t.ram ? std::string()
                                       : fmt::format("  ROM {:+.2f} deg ({:+d}): power-on loads that", *rom, *t.rom));
      }
      if (ctx.g.json) emit(list);
      return exit_ok;
    };
  });
  add_trim_import(trim, ctx);
  auto* set = trim->add_subcommand("set", "set trims: NAME=DEG ... (within ±30 deg)");
  struct set_options {
    std::vector<std::string> items;
    bool persist = false;
  };
  auto so = std::make_shared<set_options>();
  set->add_option("NAME=DEG", so->items, "the joint's trim in degrees")->required();
  set->add_flag("--persist", so->persist,
                "also write HeartToHeart4's servo image in ROM, which the board loads at power-on (protocol.md §8)");
  set->callback([&ctx, so] {
    auto items = targets_of(so->items);
    ctx.action = [&ctx, so, items] {
      const auto& m = robot_of(ctx.g);
      std::vector<std::pair<std::string, double>> trims;
      for (const auto& t : items) {
        if (t.time) throw usage_error(fmt::format("{}: a trim has no duration (@MS)", t.joint));
        trims.emplace_back(t.joint, t.degrees);
      }
      session s(ctx.g);
      session_link link(s, ctx.g.json);
      const auto report = rcb4::robot::services::set_trims(link, m, trims, so->persist);
      const auto& done = report.written;
      json list = json::array();
      for (const auto& t : done) {
        if (ctx.g.json)
          list.push_back({{"name", t.j->name}, {"counts", t.counts}});
        else
          fmt::print("{} trim {:+d} counts{}\n", t.j->name, t.counts, so->persist ? " (RAM and ROM)" : " (RAM)");
      }
      if (ctx.g.json) emit(json{{"trims", list}, {"persistent", so->persist}});
      return exit_ok;
    };
  });
}

void add_scan(CLI::App& app, context& ctx) {
  auto* scan =
      app.add_subcommand("scan", "which servo slots the board allocates, which answer, and the robot's joints on them");
  on_device(scan, ctx, [&ctx](session& s) {
    const auto& m = robot_of(ctx.g);
    const auto probes = s.run(rcb4::ops::scan_slots(rcb4::ops::link_cost::at(s.baud(), std::chrono::milliseconds(1))));
    std::vector<std::string> missing;
    for (const auto& j : m.joints())
      if (std::none_of(probes.begin(), probes.end(), [&](const auto& p) { return p.ics == j.ics; }))
        missing.push_back(j.name);
    if (ctx.g.json) {
      json slots = json::array();
      for (const auto& p : probes) {
        const auto* j = m.on(p.ics);
        slots.push_back({{"ics", p.ics.value()},
                         {"id", p.ics.value() / 2},
                         {"bus", p.ics.value() % 2 + 1},
                         {"joint", j ? json(j->name) : json(nullptr)},
                         {"answers", p.answers()},
                         {"position", p.position}});
      }
      emit(json{{"robot", m.name()}, {"slots", slots}, {"unallocated_joints", missing}});
      return exit_ok;
    }
    fmt::print("{:>4} {:>6}  {:<22} {}\n", "ICS", "ID/bus", "joint", "servo");
    for (const auto& p : probes) {
      const auto* j = m.on(p.ics);
      fmt::print("{:>4} {:>4}/{}  {:<22} {}\n", p.ics.value(), p.ics.value() / 2, p.ics.value() % 2 + 1,
                 j ? j->name : std::string("-"),
                 p.answers() ? fmt::format("answers (position {})", p.position) : "silent (never answered)");
    }
    const auto silent = std::count_if(probes.begin(), probes.end(), [](const auto& p) { return !p.answers(); });
    fmt::print("{} allocated, {} silent", plural(probes.size(), "slot"), silent);
    if (!missing.empty())
      fmt::print("; {} of {} without a slot: {}", plural(missing.size(), "joint"), m.name(), fmt::join(missing, ", "));
    fmt::print("\n");
    return exit_ok;
  });
}

}  // namespace

void add_robot_commands(CLI::App& app, context& ctx) {
  add_joint(app, ctx);
  add_pose(app, ctx);
  add_trim(app, ctx);
  add_scan(app, ctx);
}

}  // namespace cli
