// rcb4 command-line tool: motion play|stop|resume|status|wait|list|show (the ROM program's motions, §8);
// motion buttons is in cmd_buttons.cpp.
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/robot/services/motion_slots.hpp>
#include <rcb4/robot/services/slot_names.hpp>

#include <rcb4/motion/disassemble.hpp>
#include <rcb4/ops/layout.hpp>

#include <unistd.h>

#include <filesystem>

namespace cli {

void add_layout(CLI::App* cmd, motion_options& o) {
  cmd->add_option("--layout", o.layout,
                  "the HeartToHeart4 version that wrote the board's program: auto (default: told from the ROM, "
                  "where motion 1 and the main loop are), 2.2 (also later versions), 2.0 or 2.1, 1.3. It sets "
                  "where the motions start in ROM (protocol.md §8)")
      ->check(CLI::IsMember({"auto", "1.3", "2.0", "2.1", "2.2"}));
}

const rcb4::rom_layout* named_layout(const motion_options& o) {
  if (o.layout == "1.3") return &rcb4::hth4_1_3;
  if (o.layout == "2.0" || o.layout == "2.1") return &rcb4::hth4_2_0;
  if (o.layout == "2.2") return &rcb4::hth4_2_2;
  return nullptr;
}

const rcb4::rom_layout& layout_for(session& s, const motion_options& o) {
  const auto guess = s.run(rcb4::ops::detect_layout{});
  if (const auto* named = named_layout(o)) {
    // Named, but the ROM says another: its slots would cut across the board's motions.
    if (guess.layout && guess.layout != named)
      throw failure(exit_board,
                    fmt::format("--layout {} is another layout than this board's ROM has: {} ({}); its slots would "
                                "cut across the board's motions",
                                o.layout, guess.layout->name, guess.reason),
                    "leave --layout out (auto), or name the board's own");
    return *named;
  }
  if (!guess.layout)
    throw failure(exit_board,
                  fmt::format("cannot tell which HeartToHeart4 layout the board's ROM has: {}", guess.reason),
                  "name it: --layout 2.2 (motion 1 at 0x000B80), --layout 2.0 or --layout 1.3 (at 0x000BB8)");
  return *guess.layout;
}

namespace {

CLI::Option* add_timeout(CLI::App* cmd, motion_options& o, std::string_view what) {
  return cmd->add_option("--timeout", o.timeout_s, fmt::format("seconds to wait{} (default 60)", what))
      ->type_name("S")
      ->check(CLI::Range(0.001, 3600.0));
}

json state_json(const rcb4::ops::motion_state& st) {
  json j;
  j["running"] = st.running;
  j["suspended"] = st.suspended;
  j["program_on"] = st.program_on;
  j["motion"] = st.motion ? json(*st.motion) : json(nullptr);
  j["program_counter"] = st.program_counter;
  return j;
}

std::string state_text(const rcb4::ops::motion_state& st) {
  if (st.suspended)
    return fmt::format(
        "{} stopped part way (program counter 0x{:06X}; the ROM program is off: rcb4 motion resume "
        "continues it)",
        st.motion ? fmt::format("motion {}", *st.motion) : std::string("a program"), st.program_counter);
  if (!st.running && !st.program_on)
    return fmt::format(
        "no motion running (program counter 0x{:06X}); the ROM program is off, so buttons play nothing: rcb4 "
        "motion resume lets it run",
        st.program_counter);
  if (!st.running) return fmt::format("no motion running (program counter 0x{:06X})", st.program_counter);
  if (st.motion) return fmt::format("motion {} running (program counter 0x{:06X})", *st.motion, st.program_counter);
  return fmt::format("a program is running outside the motion slots (program counter 0x{:06X})", st.program_counter);
}

/** Waits until no motion runs; returns the seconds waited and the last state. */
std::pair<double, rcb4::ops::motion_state> wait(session& s, const rcb4::rom_layout& layout, const motion_options& o,
                                                const globals& g) {
  const bool tty = ::isatty(STDERR_FILENO) && !g.json;
  const auto start = std::chrono::steady_clock::now();
  const auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  std::optional<rcb4::ops::motion_state> last;
  rcb4::transport::error_code ec;
  const auto st = rcb4::transport::wait_motion(
      s.c(), std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::duration<double>(o.timeout_s)), ec,
      [&](const rcb4::ops::motion_state& m) {
        last = m;
        if (tty && m.running)
          fmt::print(stderr, "\r  motion {} running  {:5.1f} s  pc 0x{:06X} ",
                     m.motion ? fmt::format("{}", *m.motion) : "?", seconds(), m.program_counter);
      },
      layout);
  if (tty) fmt::print(stderr, "\r{:60}\r", "");
  // The board answered every poll, but the motion outlived the wait: say that, not "no reply".
  if (ec == rcb4::transport::transport_errc::timeout && last && last->running && seconds() >= o.timeout_s)
    throw failure(exit_timeout,
                  fmt::format("{} still running after {:.1f} s (program counter 0x{:06X})",
                              last->motion ? fmt::format("motion {}", *last->motion) : std::string("a program"),
                              seconds(), last->program_counter),
                  "wait longer (--timeout S), or stop it: rcb4 motion stop");
  if (ec) throw rcb4::transport::system_error(ec);
  // Not running because the ROM program is off with a CALL pending: it did not end, it stopped.
  if (st.suspended && s.run(rcb4::ops::read_config{}).program_error)
    throw failure(exit_board,
                  fmt::format("{} stopped after {:.1f} s on an error of the board's program at 0x{:06X} "
                              "(program-error: no frame there, such as an erased motion)",
                              st.motion ? fmt::format("motion {}", *st.motion) : std::string("a program"), seconds(),
                              st.program_counter),
                  "rcb4 motion show / motion list show what is there; motion resume would stop again: rcb4 motion "
                  "play N (or a power cycle) starts the program afresh");
  if (st.suspended)
    throw failure(exit_board,
                  fmt::format("{} stopped part way after {:.1f} s: the ROM program is off (program counter 0x{:06X})",
                              st.motion ? fmt::format("motion {}", *st.motion) : std::string("a program"), seconds(),
                              st.program_counter),
                  "rcb4 motion stop does that, and so does the board on an error (rcb4 config shows program-error); "
                  "rcb4 motion resume continues it");
  return {seconds(), st};
}

int play(session& s, unsigned n, bool release, bool and_wait, const motion_options& o, const globals& g) {
  const auto& layout = layout_for(s, o);
  if (n > layout.motion_count)
    throw usage_error(fmt::format("N: {} is outside 1..{} ({} layout)", n, layout.motion_count, layout.name));
  {
    // An empty or broken slot (as motion list marks it) would stop the board's program: refused first.
    session_link link(s, g.json);
    rcb4::robot::services::require_playable(link, layout, n, "");  // the tool prefixes its command
  }
  s.run(rcb4::ops::play_motion(n, layout, release ? rcb4::ops::servo_power::release : rcb4::ops::servo_power::keep));
  if (!and_wait) {
    if (g.json) {
      json j;
      j["playing"] = n;
      j["layout"] = layout.name;
      emit(j);
    } else {
      fmt::print("playing motion {} ({} layout)\n", n, layout.name);
    }
    return exit_ok;
  }
  if (!g.json) fmt::print("playing motion {} ({} layout)\n", n, layout.name);
  const auto [t, st] = wait(s, layout, o, g);
  if (g.json) {
    json j;
    j["played"] = n;
    j["layout"] = layout.name;
    j["seconds"] = std::round(t * 10) / 10;
    j["state"] = state_json(st);
    emit(j);
  } else {
    fmt::print("done after {:.1f} s\n{}\n", t, state_text(st));
  }
  return exit_ok;
}

/** `motion show N`: the slot's code as the board runs it, poses in the robot's joints. */
int show_motion(session& s, int n, const motion_options& o, const globals& g) {
  namespace m = rcb4::motion;
  if (const auto* named = named_layout(o); named && !m::slot_of(*named, static_cast<unsigned>(n)))
    throw usage_error(fmt::format("motion {}: the {} layout has motions 1-{}", n, named->name, named->motion_count));
  const auto& layout = layout_for(s, o);
  const auto where = m::slot_of(layout, static_cast<unsigned>(n));
  if (!where)
    throw usage_error(fmt::format("motion {}: the {} layout has motions 1-{}", n, layout.name, layout.motion_count));
  const auto bytes = s.run(rcb4::ops::read_memory(rcb4::ops::memory::rom, where->address.value(), where->size));
  const auto& robot = robot_of(g);
  const bool empty = bytes.empty() || bytes[0] == 0xFF;
  const auto l = m::disassemble(bytes, *where);
  const auto lifted = empty ? m::outcome<m::program>{m::failure{"the slot is empty"}} : m::lift(l);
  json code = json::array();
  const auto motion_name = rcb4::robot::services::slot_name(robot, static_cast<unsigned>(n), bytes);
  if (!g.json)
    fmt::print("motion {}{} at 0x{:06X} ({} layout, slot of {} bytes){}\n", n,
               motion_name.empty() ? std::string() : fmt::format(" ({})", motion_name), where->address.value(),
               layout.name, where->size, empty ? ": empty (erased ROM)" : "");
  for (const auto& in : empty ? std::vector<m::instruction>{} : l.code) {
    const std::string meaning = in.cmd ? fmt::format("{}", *in.cmd) : fmt::format("not a frame: {}", in.error);
    json joints = json::object();
    std::string pose_text;
    std::vector<std::string> beyond;
    if (in.cmd)
      if (const auto* c = std::get_if<rcb4::const_servo>(&*in.cmd))
        for (const auto& e : c->targets()) {
          const auto* j = robot.on(e.ics);
          // Set in two steps: GCC 12 at -O3 took `j ? to_degrees(...) : nullopt` for uninitialised.
          std::optional<double> d;
          if (j) d = rcb4::robot::to_degrees(*j, e.value.value());
          const std::string name = j ? j->name : fmt::format("ICS {}", e.ics.value());
          joints[name] = d ? json(std::round(*d * 100) / 100) : json(nullptr);
          pose_text +=
              fmt::format("  {} {}", name, d ? fmt::format("{:+.1f}", *d) : position_text(e.value.value(), "0"));
          // Beyond the profile's limit: shown, not hidden (a motion written for another robot or trim).
          if (j && d && (*d < j->lower - 1e-6 || *d > j->upper + 1e-6)) {
            pose_text += fmt::format(" (beyond its {} limit {})", *d < j->lower ? "lower" : "upper",
                                     *d < j->lower ? j->lower : j->upper);
            beyond.push_back(j->name);
          }
        }
    if (g.json) {
      json j{{"address", in.address}, {"hex", fmt::format("{}", rcb4::hex_view{in.bytes})}, {"meaning", meaning}};
      if (!joints.empty()) j["joints"] = joints;
      if (!beyond.empty()) j["beyond_limits"] = beyond;
      code.push_back(j);
    } else {
      fmt::print("  0x{:06X}  {}\n", in.address, meaning);
      if (!pose_text.empty()) fmt::print("            {}\n", pose_text.substr(2));
    }
  }
  std::vector<std::string> calls;
  for (const auto a : l.calls) {
    const auto k = a >= layout.motion_base.value() ? (a - layout.motion_base.value()) / layout.slot_size + 1 : 0;
    const bool slot_start = k >= 1 && k <= layout.motion_count && m::slot_of(layout, k)->address.value() == a;
    calls.push_back(slot_start ? fmt::format("motion {} (0x{:06X})", k, a) : fmt::format("0x{:06X}", a));
  }
  std::string steps;  // what the code is as steps, checked by assembling them again
  if (m::ok(lifted)) {
    std::vector<std::uint8_t> code_bytes;
    for (const auto& in : l.code) code_bytes.insert(code_bytes.end(), in.bytes.begin(), in.bytes.end());
    const auto again = m::assemble(std::get<m::program>(lifted), *where);
    const bool same = m::ok(again) && std::get<std::vector<std::uint8_t>>(again) == code_bytes;
    steps = fmt::format("{} steps{}", std::get<m::program>(lifted).steps.size(),
                        same ? ", assembled back to the same bytes" : " that do not assemble back to these bytes");
  } else {
    steps = std::get<m::failure>(lifted).message;
  }
  if (g.json) {
    json problems = json::array();
    if (!empty)
      for (const auto& p : l.problems) problems.push_back(p);
    emit(json{{"motion", n},
              {"name", motion_name.empty() ? json(nullptr) : json(std::string(motion_name))},
              {"address", where->address.value()},
              {"layout", layout.name},
              {"empty", empty},
              {"code", code},
              {"calls", calls},
              {"problems", problems},
              {"notes", empty ? json::array() : json(l.notes)},
              {"steps", m::ok(lifted) ? json(std::get<m::program>(lifted).steps.size()) : json(nullptr)},
              {"not_steps", m::ok(lifted) ? json(nullptr) : json(steps)}});
    return exit_ok;
  }
  if (empty) return exit_ok;
  for (const auto& c : calls) fmt::print("calls {}\n", c);
  for (const auto& p : l.problems) fmt::print("the board stops: {}\n", p);
  for (const auto& note : l.notes) fmt::print("note: {}\n", note);
  fmt::print("{} reachable frames, {} bytes; {}\n", l.code.size(),
             l.code.empty() ? 0 : l.code.back().address + l.code.back().bytes.size() - where->address.value(),
             m::ok(lifted) ? steps : "as steps: " + steps);
  return exit_ok;
}

}  // namespace

void add_motion_commands(CLI::App& app, context& ctx) {
  auto* motion = app.add_subcommand("motion", "the motions in ROM that the board's program plays (HTH4 projects)");
  motion->require_subcommand(1);

  auto* play_cmd = motion->add_subcommand(
      "play", "play motion N: suspend, reset, CALL, resume (KONDO's four steps); or a motion FILE from the host");
  struct play_options {
    motion_options m;
    std::string what;
    bool wait = false, release = false, rescale = false;
  };
  auto po = std::make_shared<play_options>();
  play_cmd
      ->add_option("N|FILE", po->what,
                   "the motion's number (1..120; 1..50 for --layout 1.3), or a motion file (.yaml) to play from the "
                   "host, pose by pose with the board's timing, without writing ROM (it always waits)")
      ->required();
  auto* wait_flag = play_cmd->add_flag("--wait", po->wait, "wait until it ends, with a progress line on a terminal");
  add_timeout(play_cmd, po->m, " with --wait")->needs(wait_flag);
  add_layout(play_cmd, po->m);
  play_cmd->add_flag("--release", po->release,
                     "turn the servo outputs off while the program is suspended (KONDO's libraries do; "
                     "by default they keep holding, so the robot does not go limp between motions)");
  play_cmd->add_flag("--rescale", po->rescale,
                     "FILE made for another output period: keep its times in ms (frames of the board's period)");
  play_cmd->callback([&ctx, po] {
    const bool number = !po->what.empty() && std::all_of(po->what.begin(), po->what.end(), [](char c) {
      return std::isdigit(static_cast<unsigned char>(c));
    });
    if (!number) {
      const auto ext = std::filesystem::path(po->what).extension();
      if (ext != ".yaml" && ext != ".yml")
        throw usage_error(
            fmt::format("N|FILE: '{}' is neither a motion number nor a motion file (.yaml, .yml)", po->what));
      if (po->release) throw usage_error("--release is for ROM motions: a file played from the host keeps the servos");
      ctx.action = [&ctx, po] {
        session s(ctx.g);
        return play_file(s, po->what, po->rescale, po->m, ctx.g);
      };
      return;
    }
    if (po->rescale) throw usage_error("--rescale is for a motion file; motion N plays the ROM's frames as they are");
    const long long n = po->what.size() > 4 ? 0 : std::stoll(po->what);
    if (n < 1 || n > 120) throw usage_error(fmt::format("N: {} is outside 1..120", po->what));
    ctx.action = [&ctx, po, n] {
      session s(ctx.g);
      return play(s, static_cast<unsigned>(n), po->release, po->wait, po->m, ctx.g);
    };
  });

  auto* stop = motion->add_subcommand("stop", "suspend the ROM program (motion resume continues it)");
  on_device(stop, ctx, [&ctx](session& s) {
    s.run(rcb4::ops::stop_motion{});
    if (ctx.g.json)
      emit(json{{"stopped", true}});
    else
      fmt::print("stopped (the ROM program is suspended; rcb4 motion resume continues it)\n");
    return exit_ok;
  });

  auto* resume = motion->add_subcommand("resume", "let the ROM program run again");
  on_device(resume, ctx, [&ctx](session& s) {
    if (s.run(rcb4::ops::read_config{}).program_error)
      throw failure(exit_board,
                    "the board's program stopped on an error (program-error: no frame where it was, such as an erased "
                    "motion): resuming would stop it again at once",
                    "rcb4 motion status shows where; rcb4 motion play N starts the program afresh");
    s.run(rcb4::ops::resume_motion());
    if (ctx.g.json)
      emit(json{{"resumed", true}});
    else
      fmt::print("resumed\n");
    return exit_ok;
  });

  auto* status = motion->add_subcommand("status", "whether a motion runs, which, and the program counter");
  auto so = std::make_shared<motion_options>();
  add_layout(status, *so);
  on_device(status, ctx, [&ctx, so](session& s) {
    const auto st = s.run(rcb4::ops::read_motion_state(layout_for(s, *so)));
    const bool error = st.suspended && s.run(rcb4::ops::read_config{}).program_error;
    if (ctx.g.json) {
      auto j = state_json(st);
      j["program_error"] = error;
      emit(j);
    } else if (error) {
      fmt::print(
          "{} stopped on an error of the board's program at 0x{:06X} (program-error: no frame there, such as an "
          "erased motion); motion resume would stop again: rcb4 motion play N starts afresh\n",
          st.motion ? fmt::format("motion {}", *st.motion) : std::string("a program"), st.program_counter);
    } else {
      fmt::print("{}\n", state_text(st));
    }
    return exit_ok;
  });

  auto* list = motion->add_subcommand("list", "the used motion slots in ROM: number, name (from --robot), size");
  auto lo = std::make_shared<motion_options>();
  add_layout(list, *lo);
  on_device(list, ctx, [&ctx, lo](session& s) {
    const auto& layout = layout_for(s, *lo);
    const auto& m = robot_of(ctx.g);
    rcb4::ops::list_motions op(layout);
    progress bar("reading motion slots", layout.motion_count, ctx.g.json);
    rcb4::transport::error_code ec;
    s.run_steps(op, ec, [&] { bar.update(op.slots_done()); });
    bar.finish();
    if (ec) throw rcb4::transport::system_error(ec);
    json arr = json::array();
    // "commands": the frames of the protocol walked to the first RETURN, not interpolation frames.
    if (!ctx.g.json)
      fmt::print("{:>4}  {:<20} {:>8}  {:>6}  {:>8}  {:>8}  {}\n", "slot", "name", "address", "bytes", "commands",
                 "seconds", "");
    const auto period = s.run(rcb4::ops::read_config{}).period;
    const auto names = rcb4::robot::services::load_slot_labels(m.name());
    const auto states = rcb4::robot::services::slot_states(op.value(), layout);
    for (std::size_t i = 0; i < op.value().size(); ++i) {
      const auto& v = op.value()[i];
      const auto& state = states[i];
      const auto name = rcb4::robot::services::slot_name(m, v.number, names, v.code);
      // Its time as the board plays it (loops counted); one that calls others plays for as long as
      // they do too: not counted here ("calls").
      const auto& plays = state.plays;
      // (A lambda, not ?: : GCC 12 at -O3 takes the ?: optional's payload for uninitialised.)
      const auto seconds = [&]() -> std::optional<double> {
        if (!plays) return std::nullopt;
        return rcb4::robot::services::play_seconds(*plays, period);
      }();
      const std::string seconds_text = !plays           ? "-"
                                       : plays->endless ? "for ever"
                                       : plays->calls   ? "calls"
                                       : seconds        ? fmt::format("{:.2f}", *seconds)
                                                        : "-";
      if (ctx.g.json)
        arr.push_back({{"slot", v.number},
                       {"name", name.empty() ? json(nullptr) : json(std::string(name))},
                       {"address", v.address},
                       {"size", v.size},
                       {"frames", v.frames},  // kept for scripts: the same count as "commands"
                       {"commands", v.frames},
                       {"seconds", seconds ? json(*seconds) : json(nullptr)},  // loops counted; calls not
                       {"endless", state.endless},
                       {"ends", v.ends},  // a RETURN was reached (a loop with no way out plays: endless)
                       {"readable", v.readable},
                       {"broken", !state.problem.empty()},
                       {"problem", state.problem.empty() ? json(nullptr) : json(state.problem)}});
      else
        fmt::print("{:>4}  {:<20} 0x{:05X}  {:>6}  {:>8}  {:>8}  {}\n", v.number, name.empty() ? "-" : name, v.address,
                   v.size, v.frames, seconds_text, state.problem.empty() ? "" : "broken: " + state.problem);
    }
    if (ctx.g.json)
      emit(json{{"layout", layout.name}, {"motions", arr}});
    else
      fmt::print("{} of {} slots used ({} layout)\n", op.value().size(), layout.motion_count, layout.name);
    return exit_ok;
  });

  auto* show = motion->add_subcommand(
      "show", "a motion slot disassembled: addresses, frames, and each pose's joints in degrees (from --robot)");
  auto sho = std::make_shared<motion_options>();
  auto show_n = std::make_shared<int>(1);
  show->add_option("N", *show_n, "the motion's number (1-based)")->required()->check(int_range(1, 120));
  add_layout(show, *sho);
  on_device(show, ctx, [&ctx, sho, show_n](session& s) { return show_motion(s, *show_n, *sho, ctx.g); });

  auto* wait_cmd = motion->add_subcommand("wait", "wait until no motion runs, with a progress line on a terminal");
  auto wo = std::make_shared<motion_options>();
  add_timeout(wait_cmd, *wo, "");
  add_layout(wait_cmd, *wo);
  on_device(wait_cmd, ctx, [&ctx, wo](session& s) {
    const auto [t, st] = wait(s, layout_for(s, *wo), *wo, ctx.g);
    if (ctx.g.json) {
      json j = state_json(st);
      j["seconds"] = std::round(t * 10) / 10;
      emit(j);
    } else {
      fmt::print("done after {:.1f} s\n{}\n", t, state_text(st));
    }
    return exit_ok;
  });

  add_motion_file_commands(motion, ctx);
  add_record_command(motion, ctx);
  add_button_commands(motion, ctx);
  add_startup_command(motion, ctx);
  add_flowchart_import(motion, ctx);
  add_motion_check_command(motion, ctx);
}

}  // namespace cli
