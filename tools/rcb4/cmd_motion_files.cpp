// rcb4 command-line tool: motion pull N FILE, motion push FILE N, motion erase N: ROM motion slots
// to and from motion files (rcb4/robot/motion_file.hpp), with a backup of what a write replaces.
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/motion/disassemble.hpp>
#include <rcb4/motion/player.hpp>
#include <rcb4/robot/motion_file.hpp>
#include <rcb4/robot/services/host_play.hpp>
#include <rcb4/robot/services/motion_slots.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <ctime>
#include <filesystem>
#include <fstream>
#include <thread>

namespace cli {
namespace {

namespace mo = rcb4::motion;
namespace ro = rcb4::robot;
namespace sv = rcb4::robot::services;
using rcb4::ops::memory;

/** The board's output period (config bits 4-5). */
rcb4::output_period board_period(session& s) { return s.run(rcb4::ops::read_config{}).period; }

/** A backup sink for the services: --backup FILE, or motion-N-DATE.bin here; a failure to save is a usage error. */
sv::backup_sink backup_to(const std::string& path) {
  return [path](unsigned n, std::span<const std::uint8_t> old) { return sv::save_backup_file(n, old, path); };
}

/** Warns when a remote button plays motion @p n (erased or changed, a press plays what is there now). */
void warn_buttons(session& s, const mo::slot& where, unsigned n, std::string_view what, const globals& g) {
  const auto b = entries_playing(s, where.address.value());
  if (!b.empty() && !g.json) fmt::print(stderr, "note: {} plays motion {}: {}\n", fmt::join(b, ", "), n, what);
}

/** The --layout value that names @p layout, for hints a user can paste. */
std::string_view layout_flag(const rcb4::rom_layout& layout) {
  if (&layout == &rcb4::hth4_1_3) return "1.3";
  if (&layout == &rcb4::hth4_2_0) return "2.0";
  return "2.2";
}

struct pull_options {
  motion_options m;
  long long n = 0;
  std::string file;
  bool force = false;
};

int pull(session& s, const pull_options& o, const globals& g) {
  const auto& layout = layout_for(s, o.m);
  sv::slot_for(layout, o.n);  // a number outside the layout before anything else
  const auto n = static_cast<unsigned>(o.n);
  if (std::filesystem::exists(o.file) && !o.force)
    throw usage_error(fmt::format("FILE: {} exists (--force replaces it)", o.file));
  session_link link(s, g.json);
  const auto r = sv::pull_motion(link, robot_of(g), layout, n);
  std::string comment = fmt::format(
      "motion {} of the board (0x{:06X}, {} layout), pulled by rcb4 on {}\n"
      "rcb4 motion push {} {} writes it back",
      n, r.address, layout.name, file_stamp(), o.file, n);
  try {
    ro::save_motion(o.file, r.document, comment);
  } catch (const ro::profile_error& e) {
    throw usage_error(e.what());
  }
  if (g.json) {
    emit(json{{"pulled", n},
              {"file", o.file},
              {"layout", layout.name},
              {"address", r.address},
              {"bytes", r.bytes},
              {"steps", r.document.steps.size()},
              {"poses", r.poses},
              {"pose_ms", r.pose_ms},
              {"plays", r.plays},
              {"period_ms", rcb4::milliseconds(r.period)},
              {"problem", r.beyond.empty() ? json(nullptr) : json(r.beyond)}});
  } else {
    fmt::print("motion {} (0x{:06X}, {} layout): {} bytes, {} steps, {} ({}, {} ms frames) -> {}\n", n, r.address,
               layout.name, r.bytes, r.document.steps.size(), plural(r.poses, "pose"), r.plays,
               rcb4::milliseconds(r.period), o.file);
    if (!r.beyond.empty()) fmt::print(stderr, "note: as it is, the file would not push back: {}\n", r.beyond);
  }
  return exit_ok;
}

struct push_options {
  motion_options m;
  std::string file, backup;
  long long n = 0;
  bool rescale = false, dry_run = false;
};

/** What FILE stands for: a motion file's document, or a .bin backup's bytes. */
sv::push_source source_of(const push_options& o, const globals& g) {
  sv::push_source src;
  src.name = o.file;
  src.rescale = o.rescale;
  if (std::filesystem::path(o.file).extension() == ".bin") {
    src.bin = sv::read_backup_file(o.file);
    return src;
  }
  try {
    src.document = ro::load_motion(o.file, robot_of(g));
  } catch (const ro::profile_error& e) {
    throw usage_error(e.what());
  }
  return src;
}

int push(session& s, const push_options& o, const globals& g) {
  const auto& layout = layout_for(s, o.m);
  sv::slot_for(layout, o.n);  // a number outside the layout before anything else
  const auto n = static_cast<unsigned>(o.n);
  const auto src = source_of(o, g);
  session_link link(s, g.json);
  const auto r = sv::push_motion(link, robot_of(g), layout, n, src, backup_to(o.backup), o.dry_run);
  if (!g.json)
    for (const auto& note : r.notes) fmt::print(stderr, "note: {}\n", note);
  if (r.dry_run) {
    if (g.json)
      emit(json{{"dry_run", true},
                {"motion", n},
                {"address", r.address},
                {"bytes", r.bytes.size()},
                {"hex", fmt::format("{}", rcb4::hex_view{r.bytes})},
                {"notes", r.notes}});
    else
      fmt::print("would write {} to motion {} (0x{:06X}, {} layout): {}\n{}\n", plural(r.bytes.size(), "byte"), n,
                 r.address, layout.name, r.summary, rcb4::hex_view{r.bytes});
    return exit_ok;
  }
  if (r.unchanged) {
    if (g.json)
      emit(json{{"pushed", n},
                {"address", r.address},
                {"bytes", r.bytes.size()},
                {"unchanged", true},
                {"name", r.name.empty() ? json(nullptr) : json(r.name)}});
    else
      fmt::print("motion {} (0x{:06X}) already holds these {}: nothing written{}\n", n, r.address,
                 plural(r.bytes.size(), "byte"), r.name.empty() ? "" : fmt::format(" (named '{}')", r.name));
    return exit_ok;
  }
  warn_buttons(s, mo::slot_of(layout, n).value(), n, "a press plays the new one", g);
  if (g.json) {
    emit(json{{"pushed", n},
              {"address", r.address},
              {"layout", layout.name},
              {"bytes", r.bytes.size()},
              {"unchanged", false},
              {"backup", r.backup},
              {"name", r.name.empty() ? json(nullptr) : json(r.name)},
              {"notes", r.notes}});
  } else {
    fmt::print("wrote {} to motion {}{} (0x{:06X}..0x{:06X}, {} layout) and read them back: {}\n",
               plural(r.bytes.size(), "byte"), n, r.name.empty() ? "" : fmt::format(" '{}'", r.name), r.address,
               r.address + r.bytes.size() - 1, layout.name, r.summary);
    fmt::print("the slot's old bytes are in {} (rcb4 motion push {} {} puts them back)\n", r.backup, r.backup, n);
  }
  return exit_ok;
}

int erase(session& s, const push_options& o, const globals& g) {
  const auto& layout = layout_for(s, o.m);
  sv::slot_for(layout, o.n);  // a number outside the layout before anything else
  const auto n = static_cast<unsigned>(o.n);
  session_link link(s, g.json);
  const auto r = sv::erase_motion(link, layout, n, backup_to(o.backup), robot_of(g).name());
  if (r.unchanged) {
    if (g.json)
      emit(json{{"erased", n}, {"address", r.address}, {"unchanged", true}});
    else
      fmt::print("motion {} (0x{:06X}) is already empty: nothing written\n", n, r.address);
    return exit_ok;
  }
  warn_buttons(s, mo::slot_of(layout, n).value(), n,
               "a press now stops the board's program (rcb4 motion buttons clear)", g);
  if (!r.callers.empty() && !g.json)
    fmt::print(stderr, "note: {} {} {} it: {} refused from now on (played, {} stop the board's program there)\n",
               r.callers.size() == 1 ? "motion" : "motions", fmt::join(r.callers, ", "),
               r.callers.size() == 1 ? "calls" : "call", r.callers.size() == 1 ? "its play is" : "their plays are",
               r.callers.size() == 1 ? "it would" : "they would");
  // Motion 1 is where the layout is told from: without it, --layout must say it.
  const std::string again = n == 1 && o.m.layout == "auto" ? fmt::format(" --layout {}", layout_flag(layout)) : "";
  if (!again.empty() && !g.json)
    fmt::print(stderr, "note: motion 1 told the board's layout ({}); from now on give it: --layout {}\n", layout.name,
               layout_flag(layout));
  if (g.json)
    emit(json{
        {"erased", n}, {"address", r.address}, {"unchanged", false}, {"backup", r.backup}, {"callers", r.callers}});
  else
    fmt::print(
        "erased motion {} (0x{:06X}, {} bytes of 0xFF, read back); the old bytes are in {} "
        "(rcb4 motion push {} {}{} puts them back)\n",
        n, r.address, r.size, r.backup, r.backup, n, again);
  return exit_ok;
}

/** Waits until @p t, waking every 50 ms for Ctrl-C; false when a signal came. */
bool wait_until(std::chrono::steady_clock::time_point t) {
  while (!signal_catcher::caught()) {
    const auto now = std::chrono::steady_clock::now();
    if (now >= t) return true;
    std::this_thread::sleep_until(std::min(t, now + std::chrono::milliseconds(50)));
  }
  return false;
}

}  // namespace

int play_file(session& s, const std::string& file, bool rescale, const motion_options& o, const globals& g) {
  const auto& robot = robot_of(g);
  ro::motion_document d;
  try {
    d = ro::load_motion(file, robot);
  } catch (const ro::profile_error& e) {
    throw usage_error(e.what());
  }
  const auto& layout = sv::needs_layout(d) ? layout_for(s, o) : rcb4::hth4_2_2;
  session_link link(s, g.json);
  sv::host_play play(link, robot, layout, board_period(s), d, file, rescale,
                     std::chrono::milliseconds(static_cast<long long>(o.timeout_s * 1000)));
  if (!g.json)
    for (const auto& note : play.notes()) fmt::print(stderr, "note: {}\n", note);
  const bool tty = ::isatty(STDERR_FILENO) && !g.json;
  signal_catcher catcher;
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&] {
    return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start);
  };
  const auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  bool stopped = false;
  for (auto next = play.advance(elapsed()); next; next = play.advance(elapsed())) {
    if (tty) fmt::print(stderr, "\r  step {}  pose {}  {:5.1f} s ", play.step(), play.poses(), seconds());
    if (!wait_until(start + *next)) {
      play.stop();
      stopped = true;
      break;
    }
  }
  if (tty) fmt::print(stderr, "\r{:60}\r", "");
  const auto period = play.period();
  if (stopped) {
    if (g.json)
      emit(json{{"played", file}, {"interrupted", true}, {"poses", play.poses()}, {"seconds", seconds()}});
    else
      fmt::print(stderr, "interrupted at step {} after {} ({:.1f} s): {}\n", play.step(), plural(play.poses(), "pose"),
                 seconds(),
                 play.calls() ? "every servo holds where it is (a ROM motion it called was stopped: rcb4 motion play N "
                                "starts afresh)"
                              : "the servos it moved hold where they are");
    return exit_interrupted;
  }
  if (g.json)
    emit(json{{"played", file},
              {"interrupted", false},
              {"poses", play.poses()},
              {"calls", play.calls()},
              {"seconds", std::round(seconds() * 100) / 100},
              {"period_ms", rcb4::milliseconds(period)},
              {"notes", play.notes()}});
  else
    fmt::print("played {} from the host: {}{} in {:.2f} s ({} ms frames; nothing written to ROM)\n", file,
               plural(play.poses(), "pose"), play.calls() ? ", " + plural(play.calls(), "ROM motion") : "", seconds(),
               rcb4::milliseconds(period));
  return exit_ok;
}

void add_motion_file_commands(CLI::App* motion, context& ctx) {
  // A backup is what `motion push FILE.bin N` puts back, and never replaces a file.
  const CLI::Validator backup_name(
      [](std::string& v) -> std::string {
        if (std::filesystem::path(v).extension() != ".bin")
          return fmt::format("{} does not end in .bin (motion push puts a .bin back)", v);
        if (std::filesystem::exists(v)) return fmt::format("{} exists: a backup never replaces a file", v);
        return {};
      },
      "FILE.bin");
  auto pl = std::make_shared<pull_options>();
  auto* pull_cmd = motion->add_subcommand(
      "pull", "motion N to a motion file (YAML: the profile's joints in degrees, times in ms; see the README)");
  pull_cmd->add_option("N", pl->n, "the motion's number")->required()->check(int_range(1, 120));
  pull_cmd->add_option("FILE", pl->file, "the motion file to write (.yaml or .yml)")->required();
  pull_cmd->add_flag("--force", pl->force, "replace FILE when it exists");
  add_layout(pull_cmd, pl->m);
  pull_cmd->callback([&ctx, pl] {
    const auto ext = std::filesystem::path(pl->file).extension();
    if (ext != ".yaml" && ext != ".yml")
      throw usage_error(fmt::format("FILE: {} does not end in .yaml or .yml", pl->file));
    ctx.action = [&ctx, pl] {
      session s(ctx.g);
      return pull(s, *pl, ctx.g);
    };
  });

  auto pu = std::make_shared<push_options>();
  auto* push_cmd = motion->add_subcommand(
      "push", "write a motion file (or a .bin backup) into motion N: checked, the old bytes backed up, read back");
  push_cmd->add_option("FILE", pu->file, "a motion file (.yaml/.yml), or a backup (.bin) to put back")->required();
  push_cmd->add_option("N", pu->n, "the motion's number")->required()->check(int_range(1, 120));
  push_cmd
      ->add_option("--backup", pu->backup,
                   "where the slot's old bytes go: a new .bin file (default: motion-N-DATE.bin here)")
      ->check(backup_name);
  push_cmd->add_flag("--rescale", pu->rescale,
                     "a file made for another output period: keep its times in ms (frames of the board's period)");
  push_cmd->add_flag("--dry-run", pu->dry_run, "check and assemble, print the bytes, write nothing");
  add_layout(push_cmd, pu->m);
  on_device(push_cmd, ctx, [&ctx, pu](session& s) { return push(s, *pu, ctx.g); });

  auto er = std::make_shared<push_options>();
  auto* erase_cmd =
      motion->add_subcommand("erase", "empty motion N (0xFF, as erased ROM reads), the old bytes backed up first");
  erase_cmd->add_option("N", er->n, "the motion's number")->required()->check(int_range(1, 120));
  erase_cmd
      ->add_option("--backup", er->backup,
                   "where the slot's old bytes go: a new .bin file (default: motion-N-DATE.bin here)")
      ->check(backup_name);
  add_layout(erase_cmd, er->m);
  on_device(erase_cmd, ctx, [&ctx, er](session& s) { return erase(s, *er, ctx.g); });
}

}  // namespace cli
