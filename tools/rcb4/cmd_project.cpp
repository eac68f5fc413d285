// rcb4 command-line tool: HeartToHeart4 files (hth4-files.md). project import FILE.h4p [--dry-run]
// puts a project on the board as HTH4's "write to robot" would, as far as its bytes are known;
// project export FILE.h4p writes the board as a project; trim import FILE.h4t writes a trim file's
// trims by ICS number. The work is in the robot services (rcb4/robot/services/project.hpp, trims.hpp).
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/motion/disassemble.hpp>
#include <rcb4/robot/hth4/flowchart.hpp>
#include <rcb4/robot/hth4/project.hpp>
#include <rcb4/robot/hth4/to_files.hpp>
#include <rcb4/robot/hth4/trim_file.hpp>
#include <rcb4/robot/motion_file.hpp>
#include <rcb4/robot/services/motion_slots.hpp>
#include <rcb4/robot/services/project.hpp>
#include <rcb4/robot/services/slot_names.hpp>
#include <rcb4/robot/services/trims.hpp>

#include <filesystem>
#include <fstream>

namespace cli {
namespace ro = rcb4::robot;
namespace {

namespace sv = rcb4::robot::services;
namespace h4 = rcb4::robot::hth4;

h4::project load(const std::string& file) {
  try {
    return h4::load_project(file);
  } catch (const rcb4::robot::profile_error& e) {
    throw usage_error(e.what());
  }
}

struct import_options {
  motion_options m;
  std::string file, to;
  bool dry_run = false, project_baud = false, force = false;
};

/** project import FILE --to DIR: the project as rcb4's files (no board needed). */
int import_to(const import_options& o, const globals& g) {
  const auto p = load(o.file);
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(o.to) && !fs::is_empty(o.to, ec) && !o.force)
    throw usage_error(fmt::format("--to: {} exists and is not empty (--force writes into it)", o.to));
  h4::project_files files;
  try {
    files = h4::project_as_files(p, p.name.empty() ? fs::path(o.file).stem().string() : p.name);
  } catch (const rcb4::robot::profile_error& e) {
    throw usage_error(e.what());
  }
  fs::create_directories(o.to, ec);
  if (ec) throw usage_error(fmt::format("--to: cannot create {}: {}", o.to, ec.message()));
  for (const auto& f : files.files) {
    const auto path = fs::path(o.to) / f.name;
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (f.bytes.empty())
      out << f.text;
    else
      out.write(reinterpret_cast<const char*>(f.bytes.data()), static_cast<std::streamsize>(f.bytes.size()));
    if (!out.flush()) throw usage_error(fmt::format("--to: cannot write {}", path.string()));
    if (f.name == "push.sh")
      fs::permissions(path, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add, ec);
  }
  if (g.json) {
    json names = json::array();
    for (const auto& f : files.files) names.push_back(f.name);
    emit(json{{"project", o.file}, {"to", o.to}, {"files", names}, {"notes", files.notes}});
    return exit_ok;
  }
  fmt::print("{} -> {}: {} files\n", o.file, o.to, files.files.size());
  for (const auto& f : files.files) fmt::print("  {}\n", f.name);
  for (const auto& n : files.notes) fmt::print("note: {}\n", n);
  fmt::print("sh {}/push.sh puts it on a board (RCB4=\"rcb4 --device PORT\")\n", o.to);
  return exit_ok;
}

int import(session& s, const import_options& o, const globals& g) {
  const auto p = load(o.file);
  const auto& layout = layout_for(s, o.m);
  const auto version = s.run(rcb4::ops::read_version{});
  session_link link(s, g.json);
  const auto save_before = [&](std::span<const std::uint8_t> now) {
    const std::string before = fmt::format("rom-before-import-{}.bin", file_stamp());
    sv::save_rom_image(before, now, version);
    return before;
  };
  const auto r = sv::import_project(link, layout, robot_of(g), p, {o.dry_run, !o.project_baud}, save_before);
  const auto changing =
      std::count_if(r.plan.areas.begin(), r.plan.areas.end(), [](const auto& a) { return a.changes; });
  if (g.json) {
    json areas = json::array();
    for (const auto& a : r.plan.areas)
      areas.push_back({{"what", a.what}, {"address", a.address}, {"bytes", a.size}, {"changes", a.changes}});
    emit(json{{"project", o.file},
              {"dry_run", o.dry_run},
              {"layout", layout.name},
              {"relocated", r.relocated},
              {"areas", areas},
              {"changes", changing},
              {"not_written", r.plan.not_written},
              {"backup", r.written.before.empty() ? json(nullptr) : json(r.written.before)},
              {"pieces_written", r.written.pieces},
              {"ram_trims", r.ram_trims},
              {"period_set", r.period_set}});
    return exit_ok;
  }
  fmt::print("{} ({} layout{}) {} the board ({}):\n", o.file, p.layout().name,
             r.relocated ? fmt::format(", moved to the board's {}", layout.name) : std::string(),
             o.dry_run ? "would write to" : "written to",
             o.dry_run ? "dry run: nothing written" : "each piece read back");
  for (const auto& a : r.plan.areas)
    fmt::print("  {} 0x{:06X}  {}\n", a.changes ? (o.dry_run ? "change" : "wrote ") : "same  ", a.address, a.what);
  for (const auto& n : r.plan.not_written) fmt::print("  not written: {}\n", n);
  if (o.dry_run)
    fmt::print("{} of {} areas would change; run it again without --dry-run to write them\n", changing,
               r.plan.areas.size());
  else if (r.written.unchanged)
    fmt::print("the board already held all of it: nothing written\n");
  else
    fmt::print(
        "{} areas changed ({} of ROM written); the ROM it replaced is in {}\n"
        "trims also in RAM for {} servos; {} slot names set; the rest acts after the board is powered off and on\n",
        changing, plural(r.written.pieces, "piece"), r.written.before, r.ram_trims, r.names);
  if (r.period_set)
    fmt::print("the board's output period is now {} ms, the project's (its motions were made for it)\n",
               rcb4::milliseconds(rcb4::config_word::decode(p.config).period));
  if (r.written.program_stopped)
    fmt::print(
        "the ROM program was stopped for the write: `rcb4 motion resume` runs it again (buttons play nothing until "
        "then)\n");
  return exit_ok;
}

int export_to(session& s, const motion_options& m, const std::string& file, bool force, const globals& g) {
  if (std::filesystem::exists(file) && !force)
    throw usage_error(fmt::format("FILE: {} exists (--force replaces it)", file));
  const auto& layout = layout_for(s, m);
  session_link link(s, g.json);
  auto e = sv::export_project(link, layout, robot_of(g));
  e.value.file_name = std::filesystem::absolute(file).string();
  e.value.path = std::filesystem::absolute(file).parent_path().string();
  e.value.name = std::filesystem::path(file).stem().string();
  try {
    h4::save_project(file, e.value);
  } catch (const rcb4::robot::profile_error& x) {
    throw usage_error(x.what());
  }
  const auto used =
      std::count_if(e.value.motions.begin(), e.value.motions.end(), [](const auto& x) { return !x.frames.empty(); });
  if (g.json) {
    emit(json{{"file", file}, {"layout", layout.name}, {"motions", used}, {"left_out", e.left_out}});
    return exit_ok;
  }
  fmt::print("the board ({} layout) -> {}: {}, config 0x{:04X}, {} allocated servos\n", layout.name, file,
             plural(static_cast<std::size_t>(used), "motion"), e.value.config,
             std::count_if(e.value.servos.begin(), e.value.servos.end(),
                           [](const auto& x) { return x.mode == h4::servo_mode::normal; }));
  for (const auto& l : e.left_out) fmt::print("  left out: {}\n", l);
  return exit_ok;
}

/** project export FILE --from DIR: rcb4's files as a project (no board). */
int export_from(const std::string& dir, const std::string& file, bool force, const globals& g) {
  if (std::filesystem::exists(file) && !force)
    throw usage_error(fmt::format("FILE: {} exists (--force replaces it)", file));
  if (!std::filesystem::is_directory(dir)) throw usage_error(fmt::format("--from: {} is not a directory", dir));
  h4::project p;
  try {
    p = h4::load_project_dir(dir);
    p.file_name = std::filesystem::absolute(file).string();
    p.path = std::filesystem::absolute(file).parent_path().string();
    h4::save_project(file, p);
  } catch (const rcb4::robot::profile_error& e) {
    throw usage_error(e.what());
  }
  const auto used = std::count_if(p.motions.begin(), p.motions.end(), [](const auto& x) { return !x.frames.empty(); });
  if (g.json)
    emit(json{{"file", file}, {"from", dir}, {"motions", used}});
  else
    fmt::print("{} -> {}: {}, config 0x{:04X}\n", dir, file, plural(static_cast<std::size_t>(used), "motion"),
               p.config);
  return exit_ok;
}

int trim_import(session& s, const std::string& file, bool persist, const globals& g) {
  std::vector<h4::trim_entry> entries;
  try {
    entries = h4::load_trim_file(file);
  } catch (const rcb4::robot::profile_error& e) {
    throw usage_error(e.what());
  }
  std::vector<std::pair<unsigned, std::int16_t>> trims;
  for (const auto& t : entries) trims.push_back({t.device_number, static_cast<std::int16_t>(t.trim)});
  session_link link(s, g.json);
  const auto r = sv::set_ics_trims(link, trims, persist);
  const auto name_of = [&](unsigned ics) {
    for (const auto& t : entries)
      if (t.device_number == ics) return t.name;
    return std::string();
  };
  if (g.json) {
    json written = json::array(), skipped = json::array();
    for (const auto& [ics, c] : r.written) written.push_back({{"ics", ics}, {"name", name_of(ics)}, {"counts", c}});
    for (const auto& [ics, c] : r.skipped) skipped.push_back({{"ics", ics}, {"name", name_of(ics)}, {"counts", c}});
    emit(json{{"file", file}, {"persistent", persist}, {"written", written}, {"skipped", skipped}});
    return exit_ok;
  }
  for (const auto& [ics, c] : r.written) fmt::print("  ICS {:>2} {:<22} {:+6d} counts\n", ics, name_of(ics), c);
  std::vector<std::string> skipped;
  for (const auto& [ics, c] : r.skipped)
    if (c != 0) skipped.push_back(fmt::format("ICS {} ({:+d})", ics, c));
  fmt::print("{} trims written to RAM{}, each read back{}\n", r.written.size(), persist ? " and ROM" : "",
             persist ? "" : " (they last until power-off: --persist keeps them)");
  if (!skipped.empty()) fmt::print("not written, the board has no servo allocated for: {}\n", fmt::join(skipped, ", "));
  return exit_ok;
}

struct flow_options {
  motion_options m;
  std::string file, out, backup;
  long long slot = 1, push = 0, period_ms = 10;
  bool force = false;
};

/** A flowchart compiled: its bytes, what was adjusted, and how its blocks are shown (by the address they start at). */
struct compiled {
  std::vector<std::uint8_t> bytes;
  std::vector<std::string> notes;
  std::vector<std::pair<std::uint32_t, ro::step_view>> views;
};

/** FILE.xml compiled into slot @p n of @p layout. */
compiled compile(const std::string& file, const rcb4::rom_layout& layout, unsigned n) {
  try {
    const auto f = h4::load_flowchart(file);
    const auto c = h4::compile_flowchart(f, sv::slot_for(layout, n).address.value(), layout, file);
    compiled out;
    for (const auto& frame : c.frames) out.bytes.insert(out.bytes.end(), frame.begin(), frame.end());
    out.notes = c.notes;
    // A block's place on HTH4's canvas (negative coordinates moved in) and its label, else its name.
    long left = 0, top = 0;
    for (const auto& b : f.blocks)
      if (b.at) left = std::min(left, (*b.at)[0]), top = std::min(top, (*b.at)[1]);
    for (const auto& [address, b] : c.placed) {
      const auto& blk = f.blocks[b];
      ro::step_view v;
      v.name = (blk.text.empty() ? blk.name : blk.text).substr(0, 80);
      if (blk.at) v.at = std::array<long, 2>{(*blk.at)[0] - left, (*blk.at)[1] - top};
      out.views.emplace_back(address, std::move(v));
    }
    return out;
  } catch (const rcb4::robot::profile_error& e) {
    throw usage_error(e.what());
  }
}

/** motion import FILE.xml OUT.yaml: the flowchart as a motion file (no board needed). */
int flow_to_file(const flow_options& o, const globals& g) {
  if (o.out.empty()) throw usage_error("OUT: give the motion file to write, or --push N to write the slot");
  if (std::filesystem::exists(o.out) && !o.force)
    throw usage_error(fmt::format("OUT: {} exists (--force replaces it)", o.out));
  if (o.period_ms < 10 || o.period_ms > 25 || o.period_ms % 5)
    throw usage_error(fmt::format("--period: {} ms is not one of 10, 15, 20 or 25", o.period_ms));
  const auto* named = named_layout(o.m);
  const auto& layout = named ? *named : rcb4::hth4_2_2;
  const auto n = static_cast<unsigned>(o.slot);
  const auto c = compile(o.file, layout, n);
  const auto& bytes = c.bytes;
  const auto& notes = c.notes;
  const auto where = sv::slot_for(layout, n);
  std::vector<std::uint32_t> starts;
  const auto p = rcb4::motion::lift(rcb4::motion::disassemble(bytes, where), &starts);
  if (!rcb4::motion::ok(p))
    throw failure(exit_usage,
                  fmt::format("{}: compiled, but a motion file cannot express it: {}", o.file,
                              std::get<rcb4::motion::failure>(p).message),
                  fmt::format("write it to the board as compiled: rcb4 motion import {} --push N", o.file));
  auto d = ro::from_program(std::get<rcb4::motion::program>(p), robot_of(g), layout,
                            static_cast<rcb4::output_period>((o.period_ms - 10) / 5));
  d.name = std::filesystem::path(o.file).stem().string();
  // Each block's place and name on the step its code starts with (past a label there: the studio
  // draws a label above the step it names); blocks without code share the next one's step.
  d.views.resize(d.steps.size());
  for (const auto& [address, view] : c.views)
    for (std::size_t k = 0; k < starts.size() && k < d.steps.size(); ++k) {
      if (starts[k] != address || std::holds_alternative<rcb4::motion::label>(d.steps[k])) continue;
      if (d.views[k] == ro::step_view{}) d.views[k] = view;
      break;
    }
  try {
    ro::save_motion(o.out, d,
                    fmt::format("imported by rcb4 from the HTH4 flowchart {} (compiled for slot {}, {} layout)", o.file,
                                n, layout.name));
  } catch (const ro::profile_error& e) {
    throw usage_error(e.what());
  }
  if (g.json) {
    emit(json{{"file", o.file}, {"out", o.out}, {"steps", d.steps.size()}, {"bytes", bytes.size()}, {"notes", notes}});
    return exit_ok;
  }
  for (const auto& note : notes) fmt::print(stderr, "note: {}\n", note);
  fmt::print("{} -> {}: {} steps ({} bytes compiled, {} ms frames)\n", o.file, o.out, d.steps.size(), bytes.size(),
             o.period_ms);
  return exit_ok;
}

/** motion import FILE.xml --push N: compiled into slot N as HTH4 would, through the push service. */
int flow_push(session& s, const flow_options& o, const globals& g) {
  const auto& layout = layout_for(s, o.m);
  const auto n = static_cast<unsigned>(o.push);
  sv::slot_for(layout, n);
  const auto c = compile(o.file, layout, n);
  const auto& bytes = c.bytes;
  const auto& notes = c.notes;
  session_link link(s, g.json);
  sv::push_source src;
  src.bin = bytes;
  src.name = o.file;
  const auto r = sv::push_motion(
      link, robot_of(g), layout, n, src,
      [&](unsigned motion, std::span<const std::uint8_t> old) { return sv::save_backup_file(motion, old, o.backup); });
  sv::set_slot_name(robot_of(g).name(), n, std::filesystem::path(o.file).stem().string(), r.fingerprint);
  if (g.json) {
    emit(json{{"file", o.file},
              {"pushed", n},
              {"bytes", bytes.size()},
              {"unchanged", r.unchanged},
              {"backup", r.backup},
              {"notes", notes}});
    return exit_ok;
  }
  for (const auto& note : notes) fmt::print(stderr, "note: {}\n", note);
  if (r.unchanged)
    fmt::print("motion {} already holds {} as compiled: nothing written\n", n, o.file);
  else
    fmt::print("{} compiled ({} bytes) -> motion {} (0x{:06X}), read back; the old bytes are in {}\n", o.file,
               bytes.size(), n, r.address, r.backup);
  return exit_ok;
}

}  // namespace

void add_flowchart_import(CLI::App* motion, context& ctx) {
  auto o = std::make_shared<flow_options>();
  auto* imp = motion->add_subcommand(
      "import",
      "an HTH4 motion flowchart (FILE.xml, either schema) compiled as HTH4 does: into a motion file OUT, "
      "or with --push N into slot N of the board");
  imp->add_option("FILE", o->file, "an HTH4 flowchart (.xml)")->required();
  imp->add_option("OUT", o->out, "the motion file to write (YAML)");
  imp->add_option("--slot", o->slot, "the slot it is compiled for (its jumps are absolute; default 1)")
      ->check(CLI::Range(1, 120));
  imp->add_option("--period", o->period_ms, "the output period its frames were made for, in ms (default 10)");
  imp->add_option("--push", o->push, "write it compiled into slot N of the board (backup first, read back)")
      ->check(CLI::Range(1, 120));
  imp->add_option("--backup", o->backup, "with --push: where the slot's old bytes go (default motion-N-DATE.bin)");
  imp->add_flag("--force", o->force, "replace OUT when it exists");
  add_layout(imp, o->m);
  imp->callback([&ctx, o] {
    if (o->push)
      ctx.action = [&ctx, o] {
        session s(ctx.g);
        return flow_push(s, *o, ctx.g);
      };
    else
      ctx.action = [&ctx, o] { return flow_to_file(*o, ctx.g); };
  });
}

void add_project_commands(CLI::App& app, context& ctx) {
  auto* project = app.add_subcommand("project", "HeartToHeart4 projects (.h4p): onto the board and back");
  project->require_subcommand(1);
  auto io = std::make_shared<import_options>();
  auto* imp = project->add_subcommand(
      "import",
      "put FILE.h4p on the board as HTH4's \"write to robot\" does, as far as its bytes are known: motions, "
      "buttons, servos and trims, config word, AD references, start-up motion; the ROM saved first "
      "(rom-before-import-DATE.bin), only what differs written, each piece read back");
  imp->add_option("FILE", io->file, "an HTH4 project (.h4p, HTH4 2.x)")->required();
  imp->add_option("--to", io->to,
                  "no board: write the project as rcb4's files into DIR (profile.yaml, a motion file per motion, "
                  "trims.h4t, push.sh)");
  imp->add_flag("--force", io->force, "with --to: write into a directory that is not empty");
  imp->add_flag("--dry-run", io->dry_run, "list every area and whether it would change; write nothing");
  imp->add_flag("--project-baud", io->project_baud,
                "take the COM baud from the project's config word too (default: keep the board's, so the link "
                "survives a power cycle)");
  add_layout(imp, io->m);
  imp->callback([&ctx, io] {
    if (!io->to.empty())
      ctx.action = [&ctx, io] { return import_to(*io, ctx.g); };
    else
      ctx.action = [&ctx, io] {
        session s(ctx.g);
        return import(s, *io, ctx.g);
      };
  });

  struct export_options {
    motion_options m;
    std::string file, from;
    bool force = false;
  };
  auto eo = std::make_shared<export_options>();
  auto* exp = project->add_subcommand(
      "export",
      "write the board as an HTH4 project FILE.h4p: config, servos (named by --robot's joints), every used "
      "slot's code and name, the buttons, the start-up motion");
  exp->add_option("FILE", eo->file, "the project to write")->required();
  exp->add_flag("--force", eo->force, "replace FILE when it exists");
  exp->add_option(
      "--from", eo->from,
      "no board: a directory of rcb4 files instead (profile.yaml, NNN-name.yaml motion files, buttons.yaml, "
      "trims.h4t: what project import --to writes)");
  add_layout(exp, eo->m);
  exp->callback([&ctx, eo] {
    if (!eo->from.empty())
      ctx.action = [&ctx, eo] { return export_from(eo->from, eo->file, eo->force, ctx.g); };
    else
      ctx.action = [&ctx, eo] {
        session s(ctx.g);
        return export_to(s, eo->m, eo->file, eo->force, ctx.g);
      };
  });
}

void add_trim_import(CLI::App* trim, context& ctx) {
  struct options {
    std::string file;
    bool persist = false;
  };
  auto o = std::make_shared<options>();
  auto* imp = trim->add_subcommand(
      "import", "write an HTH4 trim file's trims (FILE.h4t) by ICS number to the servos the board allocates");
  imp->add_option("FILE", o->file, "an HTH4 trim file (.h4t)")->required();
  imp->add_flag("--persist", o->persist, "also into ROM's servo image, so power-on loads them (as trim set --persist)");
  on_device(imp, ctx, [&ctx, o](session& s) { return trim_import(s, o->file, o->persist, ctx.g); });
}

}  // namespace cli
