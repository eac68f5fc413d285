// rcb4 command-line tool: motion buttons [set BUTTONS N | clear BUTTONS]: which remote button plays
// which motion (the vector-jump table, motions.md §4; protocol.md §6).
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/motion/buttons.hpp>
#include <rcb4/ops/layout.hpp>
#include <rcb4/robot/services/buttons.hpp>
#include <rcb4/robot/services/motion_slots.hpp>
#include <rcb4/robot/services/slot_names.hpp>

namespace cli {
namespace {

namespace mo = rcb4::motion;
namespace sv = rcb4::robot::services;
using rcb4::ops::memory;

using tables = sv::button_tables;

/** "motion 2 (wave)" for a slot start of @p layout, else the address. */
std::string target_text(std::uint32_t a, const rcb4::rom_layout& layout, const rcb4::robot::model& robot) {
  if (a >= layout.motion_base.value() && (a - layout.motion_base.value()) % layout.slot_size == 0) {
    const auto k = (a - layout.motion_base.value()) / layout.slot_size + 1;
    if (k <= layout.motion_count) {
      // the profile's name only: a name of the names file is shown where the slot's code is read (motion list)
      const auto name = rcb4::robot::services::slot_name(robot, k, {});
      return fmt::format("motion {}{} (0x{:06X})", k, name.empty() ? "" : fmt::format(" \"{}\"", name), a);
    }
  }
  return fmt::format("0x{:06X} (no motion slot start)", a);
}

std::optional<unsigned> motion_number(std::uint32_t a, const rcb4::rom_layout& layout) {
  if (a < layout.motion_base.value() || (a - layout.motion_base.value()) % layout.slot_size != 0) return std::nullopt;
  const auto k = (a - layout.motion_base.value()) / layout.slot_size + 1;
  return k <= layout.motion_count ? std::optional<unsigned>(k) : std::nullopt;
}

std::string operand_text(rcb4::vector_operand o) {
  return o.is_ics() ? fmt::format("ICS {} +{}", o.ics_slot(), o.address()) : fmt::format("RAM 0x{:04X}", o.address());
}

std::string condition_text(const rcb4::condition& c) { return c.relation(); }

/** What an entry does, in words. */
std::string entry_text(const rcb4::vector_entry& e, const rcb4::rom_layout& layout, const rcb4::robot::model& robot) {
  const std::string go = fmt::format("{} {}", e.action == rcb4::vector_action::call ? "plays" : "jumps to",
                                     target_text(e.target.value(), layout, robot));
  if (const auto b = e.buttons()) return fmt::format("{:<14} {}", mo::buttons_text(*b), go);
  return fmt::format("when {} ({}) {} {}: {}", operand_text(e.dst), e.word ? "word" : "byte", condition_text(e.cond),
                     e.src_literal ? fmt::format("0x{:04X}", e.src) : operand_text(rcb4::vector_operand{e.src}), go);
}

json entry_json(const rcb4::vector_entry& e, const rcb4::rom_layout& layout) {
  json j;
  const auto b = e.buttons();
  j["buttons"] = b ? json(mo::buttons_text(*b)) : json(nullptr);
  j["button_word"] = b ? json(*b) : json(nullptr);
  j["action"] = e.action == rcb4::vector_action::call ? "call" : "jump";
  j["address"] = e.target.value();
  const auto k = motion_number(e.target.value(), layout);
  j["motion"] = k ? json(*k) : json(nullptr);
  const auto bytes = e.encode();
  j["hex"] = fmt::format("{}", rcb4::hex_view{bytes});
  return j;
}

json table_json(const mo::vector_table& t, const rcb4::rom_layout& layout) {
  json entries = json::array();
  for (const auto& e : t.entries) entries.push_back(entry_json(e, layout));
  return json{{"entries", entries}, {"problem", t.problem.empty() ? json(nullptr) : json(t.problem)}};
}

int show(session& s, const motion_options& o, const globals& g) {
  const auto& layout = layout_for(s, o);
  const auto& robot = robot_of(g);
  session_link link(s, g.json);
  const auto t = sv::read_buttons(link);
  const auto cfg = s.run(rcb4::ops::read_config{});
  if (g.json) {
    emit(json{{"layout", layout.name},
              {"table_address", t.ram_at},
              {"ram", table_json(t.ram, layout)},
              {"rom", table_json(t.rom, layout)},
              {"same", t.same()},
              {"vector_switch", cfg.vector_jump},
              {"rom_program", cfg.rom_program}});
    return exit_ok;
  }
  fmt::print("buttons → motions (the vector-jump table at RAM 0x{:04X}; {} layout)\n", t.ram_at, layout.name);
  // A table's entries, then what is wrong with it (a table read only up to its problem).
  const auto table = [&](const rcb4::motion::vector_table& v) {
    for (const auto& e : v.entries) fmt::print("  {}\n", entry_text(e, layout, robot));
    if (v.entries.empty())
      fmt::print("  no entries{}\n", v.problem.empty() ? "" : fmt::format(": {}", v.problem));
    else if (!v.problem.empty())
      fmt::print("  then: {} (rcb4 motion buttons reset writes an empty table)\n", v.problem);
  };
  table(t.ram);
  if (!t.same()) {
    fmt::print("ROM (what the board loads at power-on) differs:\n");
    table(t.rom);
  }
  if (!cfg.rom_program)
    fmt::print("the ROM program is off: no button plays anything until it runs (rcb4 motion resume)\n");
  return exit_ok;
}

/** Prints what a table write did (the service wrote and read back both copies). */
int print_table(const sv::table_report& r, const rcb4::rom_layout& layout, const globals& g) {
  if (g.json) {
    json entries = json::array();
    for (const auto& e : r.entries) entries.push_back(entry_json(e, layout));
    emit(json{
        {"done", r.done}, {"layout", layout.name}, {"entries", entries}, {"ram_followed_rom", r.ram_followed_rom}});
  } else {
    fmt::print("{}; the table now (RAM and ROM, read back):\n", r.done);
    for (const auto& e : r.entries) fmt::print("  {}\n", entry_text(e, layout, robot_of(g)));
    if (r.entries.empty()) fmt::print("  no entries\n");
    if (r.ram_followed_rom)
      fmt::print("(RAM held other entries than ROM: it now holds ROM's, as after a power cycle)\n");
  }
  return exit_ok;
}

std::uint16_t buttons_of(const std::string& text) {
  const auto b = mo::parse_buttons(text);
  if (!mo::ok(b)) throw usage_error(fmt::format("BUTTONS: {}", std::get<mo::failure>(b).message));
  return std::get<std::uint16_t>(b);
}

}  // namespace

std::vector<std::string> entries_playing(session& s, std::uint32_t address) {
  session_link link(s, true);
  return sv::entries_playing(sv::read_buttons(link), address);
}

void add_button_commands(CLI::App* motion, context& ctx) {
  auto* buttons = motion->add_subcommand(
      "buttons", "which remote (KRR) button plays which motion: the vector-jump table, in RAM and ROM");
  auto o = std::make_shared<motion_options>();
  add_layout(buttons, *o);
  buttons->fallthrough();  // --layout after set/clear/press/reset too
  buttons->callback([&ctx, o, buttons] {
    if (!buttons->get_subcommands().empty()) return;  // set, clear, press or reset chose the action
    ctx.action = [&ctx, o] {
      session s(ctx.g);
      return show(s, *o, ctx.g);
    };
  });

  struct set_options {
    std::string buttons;
    long long n = 0;
  };
  auto so = std::make_shared<set_options>();
  auto* set = buttons->add_subcommand(
      "set", "make BUTTONS play motion N (written to ROM and RAM, read back; an entry for BUTTONS is replaced)");
  set->add_option("BUTTONS", so->buttons,
                  "button names joined by + (up, down, left, right, triangle, cross, circle, "
                  "square, s1..s4; e.g. s1+up), or the button word (0x0201)")
      ->required();
  set->add_option("N", so->n, "the motion's number")->required()->check(int_range(1, 120));
  on_device(set, ctx, [&ctx, o, so](session& s) {
    const auto word = buttons_of(so->buttons);
    const auto& layout = layout_for(s, *o);
    sv::slot_for(layout, so->n);
    session_link link(s, ctx.g.json);
    return print_table(sv::set_button(link, layout, word, static_cast<unsigned>(so->n)), layout, ctx.g);
  });

  auto co = std::make_shared<std::string>();
  auto* clear =
      buttons->add_subcommand("clear", "BUTTONS play nothing any more (their entry removed from ROM and RAM)");
  clear->add_option("BUTTONS", *co, "as for set")->required();
  on_device(clear, ctx, [&ctx, o, co](session& s) {
    const auto word = buttons_of(*co);
    const auto& layout = layout_for(s, *o);
    session_link link(s, ctx.g.json);
    return print_table(sv::clear_button(link, word), layout, ctx.g);
  });

  struct press_options {
    std::string buttons;
    bool hold = false;
  };
  auto po = std::make_shared<press_options>();
  auto* press = buttons->add_subcommand(
      "press",
      "press BUTTONS as a KRR receiver would (the button word at 0x0350), until the motion their entry "
      "names runs, then release them");
  press->add_option("BUTTONS", po->buttons, "as for set")->required();
  press->add_flag("--hold", po->hold,
                  "leave them pressed: the motion plays again each time it ends, until rcb4 motion buttons release");
  on_device(press, ctx, [&ctx, o, po](session& s) {
    const auto word = buttons_of(po->buttons);
    const auto& layout = layout_for(s, *o);
    session_link link(s, ctx.g.json);
    const auto r = sv::press(link, layout, word, po->hold);
    const auto& st = r.state;
    if (!r.entry) {
      if (ctx.g.json)
        emit(json{{"pressed", mo::buttons_text(word)}, {"motion", nullptr}, {"held", true}, {"entry", false}});
      else
        fmt::print(
            "{} held (no entry of the table plays anything for them; a motion's if_buttons sees them) until "
            "rcb4 motion buttons release\n",
            mo::buttons_text(word));
      return exit_ok;
    }
    if (ctx.g.json)
      emit(json{{"pressed", mo::buttons_text(word)},
                {"motion", st.motion ? json(*st.motion) : json(nullptr)},
                {"program_counter", st.program_counter},
                {"held", po->hold},
                {"entry", true}});
    else
      fmt::print(
          "{} pressed: {} runs{}\n", mo::buttons_text(word),
          st.motion ? fmt::format("motion {}", *st.motion) : fmt::format("the program at 0x{:06X}", st.program_counter),
          po->hold ? " (still pressed: it plays again when it ends)" : " (released)");
    return exit_ok;
  });

  auto* release = buttons->add_subcommand("release", "release every button (the button word at 0x0350 to 0)");
  on_device(release, ctx, [&ctx](session& s) {
    session_link link(s, ctx.g.json);
    sv::release(link);
    if (ctx.g.json)
      emit(json{{"released", true}});
    else
      fmt::print("released (a motion that runs plays to its end)\n");
    return exit_ok;
  });

  auto* reset = buttons->add_subcommand("reset", "an empty table: no button plays anything (ROM and RAM)");
  on_device(reset, ctx, [&ctx, o](session& s) {
    const auto& layout = layout_for(s, *o);
    session_link link(s, ctx.g.json);
    return print_table(sv::reset_buttons(link), layout, ctx.g);
  });
}

}  // namespace cli
