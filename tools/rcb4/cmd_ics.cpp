// rcb4 command-line tool: `rcb4 ics …`, one ICS servo on a KONDO adapter in ICS mode (ics.md):
// scan, id, eeprom show|backup|restore, set, position, stretch, speed, current, temperature. The
// rules are the robot services' (rcb4/robot/services/ics.hpp); this file parses and prints.
// `rcb4 ics serve` (cmd_ics_serve.cpp) is a virtual servo to try it on.
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include "cmd_ics_line.hpp"

#include <rcb4/ics/virtual_servo.hpp>
#include <rcb4/robot/services/ics.hpp>

#include <cmath>
#include <thread>

namespace cli {
namespace {

namespace sv = rcb4::robot::services;
namespace ics = rcb4::ics;
using namespace std::chrono_literals;
using ics_line::guarded;
using ics_line::line;
using ics_line::options_of;

/** What `rcb4 ics` takes before its command. */
struct ics_globals {
  long long id = -1;             ///< --id, or -1: the one servo on the line
  long long scan_timeout = 30;   ///< scan: ms per ID
  std::string backup_dir = ".";  ///< where set and restore save the old image
  /** The ID --id names, or nothing. */
  std::optional<ics::servo_id> servo() const {
    return id >= 0 ? std::optional(ics::servo_id::make(id).value()) : std::nullopt;
  }
};

/**
 * Runs @p f, guarded, on the servo --id names (or the one on the line), found at --baud or each
 * rate; @p id_work: the ID command follows (see ics_servo).
 */
int with_servo(const context& ctx, const ics_globals& ig, const std::function<int(sv::ics_servo&)>& f,
               bool id_work = false) {
  return guarded([&] {
    line l(ctx.g);
    sv::ics_servo s(l.get(), ig.servo(), ctx.g.baud, options_of(ctx.g), id_work);
    return f(s);
  });
}

/** Makes @p cmd, when chosen, run @p f with_servo. */
void on_servo(CLI::App* cmd, context& ctx, const std::shared_ptr<ics_globals>& ig, std::function<int(sv::ics_servo&)> f,
              bool id_work = false) {
  on_run(cmd, ctx, [&ctx, ig, f, id_work] { return with_servo(ctx, *ig, f, id_work); });
}

double deg(std::uint16_t counts) { return std::round(ics::position::degrees(counts) * 100) / 100; }

json position_json(std::uint16_t counts) { return json{{"counts", counts}, {"degrees", deg(counts)}}; }

std::string value_text(ics::field f, long v) {
  const auto& i = ics::info(f);
  if (i.nibbles == 0) return v ? "on" : "off";
  if (f == ics::field::max_limit || f == ics::field::min_limit)
    return fmt::format("{} ({:+.1f} deg)", v, ics::position::degrees(static_cast<std::uint16_t>(v)));
  return std::to_string(v);
}

/** Field @p f of @p e as value_text shows it, a stretch another tool stored odd as "N.5 (stored odd)". */
std::string field_text(const ics::eeprom_image& e, ics::field f) {
  return e.stored_odd(f) ? fmt::format("{}.5 (stored odd)", e.get(f)) : value_text(f, e.get(f));
}

/** ICSSW p6's temperature points (value, °C), smaller is hotter (ics.md §3; the scales disagree, §7.3). */
double icssw_celsius(int v) {
  constexpr std::pair<double, double> pts[] = {{30, 100}, {47, 90}, {60, 80}, {75, 70}, {87, 60}};
  std::size_t k = 0;
  while (k + 2 < std::size(pts) && v > pts[k + 1].first) ++k;
  const auto [x0, y0] = pts[k];
  const auto [x1, y1] = pts[k + 1];
  return std::round(y0 + (v - x0) * (y1 - y0) / (x1 - x0));
}

int print_report(const sv::ics_eeprom_report& r, const globals& g, std::string_view what, bool dry_run) {
  if (g.json) {
    json changed = json::object();
    for (const auto& [f, v] : r.changed)
      changed[std::string(ics::info(f).name)] = ics::info(f).nibbles == 0 ? json(v != 0) : json(v);
    emit(json{{"written", r.written},
              {"verified", r.verified},
              {"dry_run", dry_run},
              {"changed", changed},
              {"backup", r.backup.empty() ? json(nullptr) : json(r.backup)},
              {"notes", r.notes}});
    return exit_ok;
  }
  if (!r.written && (!dry_run || r.after == r.before)) {
    fmt::print("nothing to change: the EEPROM already holds {}\n", what);
    for (const auto& n : r.notes) fmt::print("note: {}\n", n);
    return exit_ok;
  }
  for (const auto& [f, v] : r.changed)
    fmt::print("{:<18} {} -> {}\n", ics::info(f).name, field_text(r.before, f), value_text(f, v));
  if (dry_run)
    fmt::print("a dry run: nothing was written\n");
  else if (r.verified)
    fmt::print("written and read back (64 bytes equal); the old image is in {}\n", r.backup);
  else
    fmt::print("written, not read back (a slave never answers); the old image is in {}\n", r.backup);
  for (const auto& n : r.notes) fmt::print("note: {}\n", n);
  return exit_ok;
}

/** Every field of @p e, under @p title (text) or as one JSON object. */
int show_image(const ics::eeprom_image& e, const std::string& title, const globals& g) {
  std::string raw;
  for (auto b : e.bytes()) raw += fmt::format("{}{:02X}", raw.empty() ? "" : " ", b);
  if (g.json) {
    json j;
    json odd = json::array();
    for (const auto& i : ics::fields) {
      j[std::string(i.name)] = i.nibbles == 0 ? json(e.get(i.f) != 0) : json(e.get(i.f));
      if (e.stored_odd(i.f)) odd.push_back(std::string(i.name));
    }
    if (!odd.empty()) j["stored_odd"] = odd;  // stretch fields another tool stored odd: the value is N.5
    j["raw"] = raw;
    emit(j);
    return exit_ok;
  }
  fmt::print("{}\n", title);
  for (const auto& i : ics::fields) fmt::print("  {:<18} {:<22} {}\n", i.name, field_text(e, i.f), i.what);
  fmt::print("  raw {}\n", raw);
  return exit_ok;
}

/** "30", "-12.5" (degrees, within ±135), "8833" (counts, 3500-11500). */
std::uint16_t target_of(const std::string& word) {
  double v = 0;
  try {
    std::size_t used = 0;
    v = std::stod(word, &used);
    if (used != word.size()) throw std::invalid_argument(word);
  } catch (const std::exception&) {
    throw usage_error(fmt::format("position '{}': give degrees (-135..135), counts (3500..11500) or free", word));
  }
  if (std::abs(v) <= 135) return *ics::position::counts(v);
  if (v >= ics::position::min && v <= ics::position::max && v == std::floor(v)) return static_cast<std::uint16_t>(v);
  throw usage_error(fmt::format("position {}: give degrees (-135..135) or counts (3500..11500)", word));
}

int position(sv::ics_servo& s, const std::string& word, bool wait, std::chrono::milliseconds max_wait,
             const globals& g) {
  json j{{"id", s.id().value()}};
  if (wait && (word.empty() || word == "free"))
    throw usage_error("--wait goes with a move: position DEG|COUNTS --wait");
  if (word.empty()) {
    const auto p = s.position();
    j.update(position_json(p));
    if (g.json)
      emit(j);
    else
      fmt::print("ICS servo {}: {} ({:+.2f} deg)\n", s.id().value(), p, deg(p));
    return exit_ok;
  }
  if (word == "free") {
    const auto p = s.free();
    j["free"] = true;
    j.update(position_json(p));
    if (g.json)
      emit(j);
    else
      fmt::print("ICS servo {} is free; it stood at {} ({:+.2f} deg)\n", s.id().value(), p, deg(p));
    return exit_ok;
  }
  const auto target = target_of(word);
  if (wait) (void)s.position();  // --wait reads the position (ICS 3.6): a 3.5 servo is refused before it moves
  const auto was = s.move(target);
  j["target"] = position_json(target);
  j["was"] = position_json(was);
  if (!g.json)
    fmt::print("ICS servo {} to {} ({:+.2f} deg); it stood at {} ({:+.2f} deg)\n", s.id().value(), target, deg(target),
               was, deg(was));
  if (!wait) {
    if (g.json) emit(j);
    return exit_ok;
  }
  // Read every 20 ms until there (3 counts, 0.1 degree), no closer for 0.5 s, max_wait, or Ctrl-C.
  std::uint16_t now = was;
  const auto start = std::chrono::steady_clock::now();
  auto closer_at = start;
  int best = std::abs(was - target);
  bool timed_out = false;
  for (;;) {
    try {
      now = s.position();
    } catch (const sv::refused& r) {  // it stopped answering part way: the move sent is in the answer too
      throw failure(exit_of(r.kind), r.what(), r.hint, g.json ? j : json());
    }
    const int off = std::abs(now - target);
    const auto t = std::chrono::steady_clock::now();
    if (off < best) best = off, closer_at = t;
    timed_out = t - start > max_wait;
    if (off <= 3 || timed_out || t - closer_at > 500ms || signal_catcher::caught()) break;
    std::this_thread::sleep_for(20ms);  // the servo's pace: a read every 20 ms is enough
  }
  const bool there = std::abs(now - target) <= ics::position::counts_per_degree;
  j.update(position_json(now));
  j["arrived"] = there;
  if (!g.json) fmt::print("now at {} ({:+.2f} deg)\n", now, deg(now));
  if (there || signal_catcher::caught()) {
    if (g.json) emit(j);
    return exit_ok;
  }
  const double short_by = std::abs(deg(now) - deg(target));
  throw failure(exit_board,
                timed_out
                    ? fmt::format("ICS servo {} is still {:.1f} deg from the target after {} s (still moving: "
                                  "a low speed?)",
                                  s.id().value(), short_by, std::chrono::duration<double>(max_wait).count())
                    : fmt::format("ICS servo {} stopped {:.1f} deg short of the target", s.id().value(), short_by),
                timed_out ? "--max-wait S waits longer"
                          : "a load or an obstacle, its limits (rcb4 ics eeprom show: min_limit, max_limit) or a low "
                            "speed",
                g.json ? j : json());
}

int parameter(sv::ics_servo& s, ics::sub what, const char* name, const std::string& value, const globals& g) {
  std::uint8_t v = 0;
  if (value.empty())
    v = s.read(what);
  else
    v = s.write(what, parse_int(value, name, 1, 127));
  if (g.json)
    emit(json{{"id", s.id().value()}, {name, v}, {"set", !value.empty()}});
  else
    fmt::print("ICS servo {}: {} {}{}\n", s.id().value(), name, v,
               value.empty() ? "" : " (set live; the servo may keep it in EEPROM too: docs/ics-servos.md)");
  return exit_ok;
}

void add_eeprom_commands(CLI::App* ics_cmd, context& ctx, const std::shared_ptr<ics_globals>& ig) {
  auto* eeprom = ics_cmd->add_subcommand("eeprom", "the servo's 64-byte EEPROM: show, backup FILE, restore FILE");
  eeprom->require_subcommand(1);
  auto shown = std::make_shared<std::string>();
  auto* show = eeprom->add_subcommand(
      "show", "every field, decoded (units of ICS Manager: stretch 1-127); with FILE: a backup, no servo needed");
  show->add_option("FILE", *shown, "a backup from `ics eeprom backup` (none: the servo's EEPROM)");
  show->callback([&ctx, ig, shown] {
    ctx.action = [&ctx, ig, shown] {
      if (!shown->empty())
        return show_image(sv::load_ics_image(*shown), fmt::format("{}: EEPROM backup", *shown), ctx.g);
      return with_servo(ctx, *ig, [&](sv::ics_servo& s) {
        return show_image(s.read_eeprom(), fmt::format("ICS servo {} at {} baud: EEPROM", s.id().value(), s.baud()),
                          ctx.g);
      });
    };
  });

  auto file = std::make_shared<std::string>();
  auto* backup = eeprom->add_subcommand("backup", "save the servo's own 64 bytes to FILE");
  auto replace = std::make_shared<bool>(false);
  backup->add_option("FILE", *file, "where (an existing file is refused)")->required();
  backup->add_flag("--force", *replace, "replace FILE if it exists");
  on_servo(backup, ctx, ig, [&ctx, file, replace](sv::ics_servo& s) {
    const auto e = s.read_eeprom();
    sv::save_ics_image(*file, e, *replace);
    if (ctx.g.json)
      emit(json{{"file", *file}, {"id", s.id().value()}, {"baud", s.baud()}});
    else
      fmt::print("ICS servo {}'s EEPROM saved to {} (64 bytes)\n", s.id().value(), *file);
    return exit_ok;
  });

  auto rfile = std::make_shared<std::string>();
  auto force = std::make_shared<bool>(false);
  auto* restore =
      eeprom->add_subcommand("restore", "write a backup back (this servo's own; its factory bytes are never written)");
  restore->add_option("FILE", *rfile, "a file from `ics eeprom backup`")->required();
  restore->add_flag("--force", *force,
                    "write another servo's settings (this servo's factory bytes and user_offset are kept), or a "
                    "slave flag");
  auto dry = std::make_shared<bool>(false);
  restore->add_flag("--dry-run", *dry, "show what would change, write nothing");
  on_servo(restore, ctx, ig, [&ctx, ig, rfile, force, dry](sv::ics_servo& s) {
    const auto image = sv::load_ics_image(*rfile);
    return print_report(s.restore(image, *force, sv::ics_backup_in(ig->backup_dir, s.id()), *dry), ctx.g, *rfile, *dry);
  });
}

}  // namespace

void add_ics_serve_command(CLI::App* ics_cmd, context& ctx);

void add_ics_commands(CLI::App& app, context& ctx) {
  auto ig = std::make_shared<ics_globals>();
  auto* cmd = app.add_subcommand(
      "ics",
      "ICS servos on their own line: a KONDO adapter in ICS mode (--device), one servo with its own supply "
      "(docs/ics-servos.md); without --device, an in-process virtual servo");
  cmd->require_subcommand(1);
  cmd->fallthrough();
  cmd->add_option("--id", ig->id, "the servo's ID (default: the one servo on the line, by the ID command)")
      ->check(int_range(0, 31));
  cmd->add_option("--backup-dir", ig->backup_dir, "where set and eeprom restore save the old image (default .)");

  auto* scan = cmd->add_subcommand("scan", "which servos answer, at which baud and ID (every ID at every rate)");
  scan->add_option("--scan-timeout", ig->scan_timeout, "ms to wait for each ID (default 30)")
      ->check(int_range(1, 10000));
  on_run(scan, ctx, [&ctx, ig] {
    return guarded([&] {
      line l(ctx.g);
      auto o = options_of(ctx.g);
      o.timeout = std::chrono::milliseconds(ig->scan_timeout);
      o.interrupted = [] { return signal_catcher::caught(); };
      std::vector<std::uint32_t> bs;
      if (ctx.g.baud) bs.push_back(*ctx.g.baud);
      const auto only = ig->servo();
      const auto found = sv::ics_scan(
          l.get(), bs, o,
          [&ctx, only](std::uint32_t b) {
            if (!ctx.g.json)
              fmt::print(stderr, "scanning {} at {} baud\n", only ? fmt::format("ID {}", only->value()) : "IDs 0-31",
                         b);
          },
          only);
      json servos = json::array();
      json bad = json::array();
      bool any = false;
      for (const auto& f : found) {
        if (!f.problem.empty()) {
          bad.push_back(json{{"id", f.id.value()}, {"baud", f.baud}, {"problem", f.problem}});
          continue;
        }
        any = true;
        servos.push_back(json{{"id", f.id.value()},
                              {"baud", f.baud},
                              {"ics", f.ics36 ? "3.6" : "3.5"},
                              {"stretch", f.stretch},
                              {"speed", f.speed}});
      }
      if (ctx.g.json)
        emit(json{{"servos", servos}, {"garbled", bad}});
      else if (found.empty())
        fmt::print("no ICS servo answered\n");
      for (const auto& f : found)
        if (ctx.g.json) {
        } else if (f.problem.empty())
          fmt::print("ID {:2}  {:>7} baud  ICS {}  stretch {}  speed {}\n", f.id.value(), f.baud,
                     f.ics36 ? "3.6" : "3.5 (no SC 5 position read)", f.stretch, f.speed);
        else
          fmt::print("ID {:2}  {:>7} baud  answers wrongly: {}\n", f.id.value(), f.baud, f.problem);
      return any ? exit_ok : found.empty() ? exit_timeout : exit_board;
    });
  });

  auto new_id = std::make_shared<long long>(-1);
  auto* id = cmd->add_subcommand("id", "the ID of the one servo on the line; `id set N` gives it a new one");
  auto* id_set = id->add_subcommand("set", "give the servo alone on the line ID N (checked alone first, read back)");
  id_set->add_option("N", *new_id, "0-31")->required()->check(int_range(0, 31));
  on_servo(
      id_set, ctx, ig,
      [&ctx, new_id](sv::ics_servo& s) {
        const auto was = s.id();
        const auto n = s.set_id(ics::servo_id::make(*new_id).value());
        if (ctx.g.json)
          emit(json{{"id", n.value()}, {"was", was.value()}, {"written", was != n}});
        else if (was == n)
          fmt::print("the servo is ID {} already: nothing written\n", n.value());
        else
          fmt::print("ID {} -> {} (read back)\n", was.value(), n.value());
        return exit_ok;
      },
      true);

  // `id` alone reads; its callback runs after `id set`'s, so it leaves set's action alone.
  id->callback([&ctx, ig, id_set] {
    if (id_set->parsed()) return;
    ctx.action = [&ctx, ig] {
      return with_servo(
          ctx, *ig,
          [&](sv::ics_servo& s) {
            const auto n = s.read_id();
            if (ctx.g.json)
              emit(json{{"id", n.value()}, {"baud", s.baud()}});
            else
              fmt::print("{}\n", n.value());
            return exit_ok;
          },
          true);
    };
  });
  add_eeprom_commands(cmd, ctx, ig);

  auto settings = std::make_shared<std::vector<std::string>>();
  auto set_force = std::make_shared<bool>(false);
  auto* set = cmd->add_subcommand("set", "change EEPROM fields: read, modify, back up, write, read back");
  set->add_option("FIELD=VALUE", *settings, "e.g. stretch=40 speed=100 reverse=on baud=625000")->required();
  set->add_flag("--force", *set_force, "write a setting that stops the servo answering (slave=on)");
  auto set_dry = std::make_shared<bool>(false);
  set->add_flag("--dry-run", *set_dry, "show what would change, write nothing");
  set->footer(
      "fields: stretch speed punch dead_band damping safe_timer slave rotation pwm_inhibit reverse max_limit "
      "min_limit baud temperature_limit current_limit response user_offset stretch_1 stretch_2 stretch_3");
  on_run(set, ctx, [&ctx, ig, settings, set_force, set_dry] {
    std::vector<std::pair<ics::field, long>> changes;
    for (const auto& w : *settings) changes.push_back(sv::parse_ics_setting(w));  // before the line opens
    return with_servo(ctx, *ig, [&](sv::ics_servo& s) {
      return print_report(s.set_fields(changes, sv::ics_backup_in(ig->backup_dir, s.id()), *set_force, *set_dry), ctx.g,
                          join(*settings), *set_dry);
    });
  });

  auto where = std::make_shared<std::string>();
  auto wait = std::make_shared<bool>(false);
  auto* pos = cmd->add_subcommand("position", "where it stands (ICS 3.6), or move it: DEG, COUNTS or free");
  pos->add_option("TARGET", *where, "degrees (-135..135), counts (3500..11500) or free")
      ->check(CLI::Validator(
          [](std::string& v) { return v.empty() ? std::string("empty: give DEG, COUNTS or free") : std::string(); },
          "DEG|COUNTS|free"));
  auto* wait_flag =
      pos->add_flag("--wait", *wait, "after a move: read until it is there or stops getting closer (ICS 3.6)");
  auto max_wait = std::make_shared<double>(5.0);
  pos->add_option("--max-wait", *max_wait, "with --wait: give up after S seconds (default 5)")
      ->needs(wait_flag)
      ->type_name("S")
      ->check(CLI::Range(0.1, 600.0));
  on_servo(pos, ctx, ig, [&ctx, where, wait, max_wait](sv::ics_servo& s) {
    return position(s, *where, *wait, std::chrono::milliseconds(static_cast<long long>(*max_wait * 1000)), ctx.g);
  });

  for (auto [name, what, help] : {std::tuple{"stretch", ics::sub::stretch, "stiffness 1-127: read, or set live"},
                                  {"speed", ics::sub::speed, "speed 1-127: read, or set live"}}) {
    auto value = std::make_shared<std::string>();
    auto* c = cmd->add_subcommand(name, help);
    c->add_option("N", *value, "1-127 (none: read)");
    on_servo(c, ctx, ig,
             [&ctx, value, what, name](sv::ics_servo& s) { return parameter(s, what, name, *value, ctx.g); });
  }
  on_servo(cmd->add_subcommand("current", "the current it draws (about 0.1 A a unit; bit 6 the direction)"), ctx, ig,
           [&ctx](sv::ics_servo& s) {
             const auto v = s.read(ics::sub::current);
             const double amps = (v & 0x3F) / 10.0;
             if (ctx.g.json)
               emit(json{{"id", s.id().value()}, {"current", v}, {"amperes", amps}, {"direction", (v >> 6) & 1}});
             else
               fmt::print("ICS servo {}: current {} (about {:.1f} A, direction {})\n", s.id().value(), v, amps,
                          (v >> 6) & 1);
             return exit_ok;
           });
  on_servo(cmd->add_subcommand("temperature", "its temperature value 1-127 (smaller is hotter)"), ctx, ig,
           [&ctx](sv::ics_servo& s) {
             const auto v = s.read(ics::sub::temperature);
             if (ctx.g.json)
               emit(json{{"id", s.id().value()}, {"temperature", v}, {"celsius_icssw", icssw_celsius(v)}});
             else
               fmt::print(
                   "ICS servo {}: temperature {} (about {:.0f} C on KONDO's ICS 3.5 manual's scale; the "
                   "scales disagree: docs/ics-servos.md)\n",
                   s.id().value(), v, icssw_celsius(v));
             return exit_ok;
           });
  add_ics_serve_command(cmd, ctx);
  // Options of `ics` and the global ones may follow the command words too (rcb4 ics eeprom show --id 3).
  const std::function<void(CLI::App*)> through = [&through](CLI::App* a) {
    for (auto* c : a->get_subcommands({})) {
      c->fallthrough();
      through(c);
    }
  };
  through(cmd);
}

}  // namespace cli
