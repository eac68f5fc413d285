// rcb4 command-line tool: motion buttons [set BUTTONS N | clear BUTTONS]: which remote button plays
// which motion (the vector-jump table, motions.md §4; protocol.md §6).
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/robot/services/motion_slots.hpp>

#include <rcb4/motion/buttons.hpp>
#include <rcb4/ops/layout.hpp>

namespace cli {
namespace {

namespace mo = rcb4::motion;
namespace tl = rcb4::motion::vector_table_layout;
using rcb4::ops::memory;

/** Both copies of the table: RAM (what the board compares now) and ROM (what it loads at power-on). */
struct tables {
  std::uint16_t ram_at = 0;  ///< RAM 0x008C: where the board looks
  std::uint16_t rom_at = 0;  ///< ROM 0x0919: what power-on writes to 0x008C
  mo::vector_table ram, rom;
  std::vector<std::uint8_t> ram_bytes, rom_bytes;
};

tables read_tables(session& s) {
  tables t;
  const auto a = s.run(rcb4::ops::read_memory(memory::ram, rcb4::ram::vector_table.value(), 2));
  t.ram_at = static_cast<std::uint16_t>(a[0] | (a[1] << 8));
  const auto r = s.run(rcb4::ops::read_memory(memory::rom, tl::rom_address_word.value(), 2 + tl::bytes));
  t.rom_at = static_cast<std::uint16_t>(r[0] | (r[1] << 8));
  t.rom_bytes.assign(r.begin() + 2, r.end());
  t.rom = mo::decode_vector_table(t.rom_bytes);
  if (std::uint32_t{t.ram_at} + rcb4::vector_entry::size <= rcb4::ram_size) {
    const auto n = std::min<std::size_t>(tl::bytes, rcb4::ram_size - t.ram_at);
    t.ram_bytes = s.run(rcb4::ops::read_memory(memory::ram, t.ram_at, n));
    t.ram = mo::decode_vector_table(t.ram_bytes);
  } else {
    t.ram.problem = fmt::format("its address 0x{:04X} (RAM 0x008C) is outside RAM: no HTH4 project loaded", t.ram_at);
  }
  return t;
}

/** "motion 2 (wave)" for a slot start of @p layout, else the address. */
std::string target_text(std::uint32_t a, const rcb4::rom_layout& layout, const rcb4::robot::model& robot) {
  if (a >= layout.motion_base.value() && (a - layout.motion_base.value()) % layout.slot_size == 0) {
    const auto k = (a - layout.motion_base.value()) / layout.slot_size + 1;
    if (k <= layout.motion_count) {
      const auto name = robot.motion(k);
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

std::string condition_text(const rcb4::condition& c) {
  if (!c.zero && !c.carry) return "always";
  if (c.zero && c.carry) return *c.zero ? (*c.carry ? "==" : "never") : (*c.carry ? ">" : "<");
  if (c.zero) return *c.zero ? "==" : "!=";
  return *c.carry ? ">=" : "<";
}

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

/** RAM and ROM hold the same entries. */
bool same(const tables& t) { return t.ram.entries == t.rom.entries && t.ram.problem.empty() == t.rom.problem.empty(); }

int show(session& s, const motion_options& o, const globals& g) {
  const auto& layout = layout_for(s, o);
  const auto& robot = robot_of(g);
  const auto t = read_tables(s);
  const auto cfg = s.run(rcb4::ops::read_config{});
  if (g.json) {
    emit(json{{"layout", layout.name},
              {"table_address", t.ram_at},
              {"ram", table_json(t.ram, layout)},
              {"rom", table_json(t.rom, layout)},
              {"same", same(t)},
              {"vector_switch", cfg.vector_jump},
              {"rom_program", cfg.rom_program}});
    return exit_ok;
  }
  fmt::print("buttons → motions (the vector-jump table at RAM 0x{:04X}; {} layout)\n", t.ram_at, layout.name);
  for (const auto& e : t.ram.entries) fmt::print("  {}\n", entry_text(e, layout, robot));
  if (t.ram.entries.empty())
    fmt::print("  no entries{}\n", t.ram.problem.empty() ? "" : fmt::format(": {}", t.ram.problem));
  if (!same(t)) {
    fmt::print("ROM (what the board loads at power-on) differs:\n");
    for (const auto& e : t.rom.entries) fmt::print("  {}\n", entry_text(e, layout, robot));
    if (t.rom.entries.empty())
      fmt::print("  no entries{}\n", t.rom.problem.empty() ? "" : fmt::format(": {}", t.rom.problem));
  }
  if (!cfg.rom_program)
    fmt::print("the ROM program is off: no button plays anything until it runs (rcb4 motion resume)\n");
  return exit_ok;
}

/** Writes @p entries to ROM (image and its address word) and RAM (what the board compares now), then reads both back.
 */
int write_table(session& s, const tables& before, std::vector<rcb4::vector_entry> entries, const std::string& what,
                const rcb4::rom_layout& layout, const globals& g) {
  for (std::size_t j = 0; j < entries.size(); ++j) entries[j].last = j + 1 == entries.size();  // as encoded: EOF last
  const auto bytes = mo::encode_vector_table(entries);
  if (!mo::ok(bytes)) throw failure(exit_board, std::get<mo::failure>(bytes).message);
  const auto& b = std::get<std::vector<std::uint8_t>>(bytes);
  const std::uint16_t at = tl::ram_entries.value();
  const std::array<std::uint8_t, 2> at_bytes = {static_cast<std::uint8_t>(at & 0xFF),
                                                static_cast<std::uint8_t>(at >> 8)};
  s.run(rcb4::ops::write_memory(memory::rom, tl::rom_entries.value(), b));
  if (before.rom_at != at) s.run(rcb4::ops::write_memory(memory::rom, tl::rom_address_word.value(), at_bytes));
  s.run(rcb4::ops::write_memory(memory::ram, at, b));
  if (before.ram_at != at) s.run(rcb4::ops::write_memory(memory::ram, rcb4::ram::vector_table.value(), at_bytes));
  const auto after = read_tables(s);
  if (after.rom.entries != entries || after.ram.entries != entries)
    throw failure(exit_board,
                  fmt::format("the table read back is not what was written ({} differs)",
                              after.rom.entries != entries ? "ROM" : "RAM"),
                  "the board may not accept ROM writes (write-protected, or another program rewrites the table)");
  if (g.json) {
    emit(json{{"done", what}, {"layout", layout.name}, {"entries", table_json(after.rom, layout)["entries"]}});
  } else {
    fmt::print("{}; the table now (RAM and ROM, read back):\n", what);
    for (const auto& e : after.rom.entries) fmt::print("  {}\n", entry_text(e, layout, robot_of(g)));
    if (after.rom.entries.empty()) fmt::print("  no entries\n");
  }
  return exit_ok;
}

/** The table to edit: ROM's (what survives power-off); erased ROM is an empty table, anything else unreadable is
 * refused. */
std::vector<rcb4::vector_entry> editable(const tables& t) {
  if (!t.rom.problem.empty() && !(t.rom.entries.empty() && !t.rom_bytes.empty() && t.rom_bytes[0] == 0xFF))
    throw failure(exit_board, fmt::format("the vector table in ROM (0x091B) cannot be read: {}", t.rom.problem),
                  "rcb4 read rom 0x091B 256 shows it; rcb4 motion buttons reset writes an empty table");
  return t.rom.entries;
}

std::uint16_t buttons_of(const std::string& text) {
  const auto b = mo::parse_buttons(text);
  if (!mo::ok(b)) throw usage_error(fmt::format("BUTTONS: {}", std::get<mo::failure>(b).message));
  return std::get<std::uint16_t>(b);
}

}  // namespace

std::vector<std::string> entries_playing(session& s, std::uint32_t address) {
  std::vector<std::string> out;
  const auto t = read_tables(s);
  for (const auto* table : {&t.rom, &t.ram})
    for (const auto& e : table->entries)
      if (e.target.value() == address) {
        const auto b = e.buttons();
        std::string what = b ? mo::buttons_text(*b) : fmt::format("an entry on {}", operand_text(e.dst));
        if (std::find(out.begin(), out.end(), what) == out.end()) out.push_back(std::move(what));
      }
  return out;
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
    if (so->n > layout.motion_count)
      throw usage_error(fmt::format("N: {} is outside 1..{} ({} layout)", so->n, layout.motion_count, layout.name));
    const auto n = static_cast<unsigned>(so->n);
    const auto target = rcb4::motion_address(layout, n).value();
    {  // an empty or broken slot (as motion list marks it) would stop the board's program
      session_link link(s, ctx.g.json);
      rcb4::robot::services::require_playable(link, layout, n,
                                              fmt::format("a button playing motion {}", n));
    }
    const auto t = read_tables(s);
    auto entries = mo::assign_button(editable(t), word, target);
    if (!mo::ok(entries)) throw failure(exit_board, std::get<mo::failure>(entries).message);
    return write_table(s, t, std::get<std::vector<rcb4::vector_entry>>(entries),
                       fmt::format("{} plays motion {}", mo::buttons_text(word), n), layout, ctx.g);
  });

  auto co = std::make_shared<std::string>();
  auto* clear =
      buttons->add_subcommand("clear", "BUTTONS play nothing any more (their entry removed from ROM and RAM)");
  clear->add_option("BUTTONS", *co, "as for set")->required();
  on_device(clear, ctx, [&ctx, o, co](session& s) {
    const auto word = buttons_of(*co);
    const auto& layout = layout_for(s, *o);
    const auto t = read_tables(s);
    auto entries = mo::clear_button(editable(t), word);
    if (!entries)
      throw failure(exit_board, fmt::format("no entry plays anything for {}", mo::buttons_text(word)),
                    "rcb4 motion buttons lists the entries");
    return write_table(s, t, *entries, fmt::format("{} plays nothing", mo::buttons_text(word)), layout, ctx.g);
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
    // What the board would do, from the table it compares (RAM): nothing, or a call of an empty
    // slot (which stops its program), is said before anything is pressed.
    const auto t = read_tables(s);
    const rcb4::vector_entry* entry = nullptr;
    for (const auto& e : t.ram.entries)
      if (e.buttons() == word) {
        entry = &e;
        break;
      }
    const bool plays = entry || std::any_of(t.ram.entries.begin(), t.ram.entries.end(),
                                            [](const auto& e) { return !e.buttons(); });
    if (!plays && !po->hold)
      throw failure(exit_board,
                    fmt::format("no entry of the table plays anything for {}: a press would only be seen by a "
                                "motion that tests the buttons",
                                mo::buttons_text(word)),
                    "--hold holds them as a receiver would (for a motion's if_buttons); rcb4 motion buttons set "
                    "BUTTONS N adds an entry");
    if (entry) {
      const std::uint32_t a = entry->target.value(), base = layout.motion_base.value();
      const bool slot = a >= base && (a - base) % layout.slot_size == 0 && (a - base) / layout.slot_size < layout.motion_count;
      if (slot) {  // an empty or broken slot (as motion list marks it) would stop the board's program
        session_link link(s, ctx.g.json);
        rcb4::robot::services::require_playable(link, layout, (a - base) / layout.slot_size + 1,
                                                fmt::format("{} plays it", mo::buttons_text(word)));
      } else if (!rcb4::ops::detail::holds_frame(s.run(rcb4::ops::read_memory(memory::rom, a, 128)))) {
        throw failure(exit_board,
                      fmt::format("{} plays {}, which holds no motion: a press would stop the board's program",
                                  mo::buttons_text(word), target_text(a, layout, robot_of(ctx.g))),
                      fmt::format("rcb4 motion buttons clear {}, or rcb4 motion push FILE N into that slot",
                                  mo::buttons_text(word)));
      }
    }
    const auto bytes = rcb4::krr::encode_buttons(word);
    s.run(rcb4::ops::write_memory(memory::ram, rcb4::krr::buttons.value(), bytes));
    if (!plays) {  // held as a receiver would hold them: only a motion's button test sees them
      if (ctx.g.json)
        emit(json{{"pressed", mo::buttons_text(word)}, {"motion", nullptr}, {"held", true}, {"entry", false}});
      else
        fmt::print("{} held (no entry of the table plays anything for them; a motion's if_buttons sees them) until "
                   "rcb4 motion buttons release\n",
                   mo::buttons_text(word));
      return exit_ok;
    }
    // The board compares the table once per output period (10-25 ms): a motion runs within a few.
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(1);
    rcb4::ops::motion_state st;
    do {
      st = s.run(rcb4::ops::read_motion_state(layout));
    } while (!st.running && std::chrono::steady_clock::now() < until);
    if (!po->hold) {
      static constexpr std::array<std::uint8_t, 2> neutral{};
      s.run(rcb4::ops::write_memory(memory::ram, rcb4::krr::buttons.value(), neutral));
    }
    if (!st.running)
      throw failure(exit_board, fmt::format("{} pressed for 1 s: no motion started", mo::buttons_text(word)),
                    "rcb4 motion buttons shows which buttons play what, and whether the ROM program runs");
    if (ctx.g.json)
      emit(json{{"pressed", mo::buttons_text(word)},
                {"motion", st.motion ? json(*st.motion) : json(nullptr)},
                {"program_counter", st.program_counter},
                {"held", po->hold}});
    else
      fmt::print(
          "{} pressed: {} runs{}\n", mo::buttons_text(word),
          st.motion ? fmt::format("motion {}", *st.motion) : fmt::format("the program at 0x{:06X}", st.program_counter),
          po->hold ? " (still pressed: it plays again when it ends)" : " (released)");
    return exit_ok;
  });

  auto* release = buttons->add_subcommand("release", "release every button (the button word at 0x0350 to 0)");
  on_device(release, ctx, [&ctx](session& s) {
    static constexpr std::array<std::uint8_t, 2> neutral{};
    s.run(rcb4::ops::write_memory(memory::ram, rcb4::krr::buttons.value(), neutral));
    if (ctx.g.json)
      emit(json{{"released", true}});
    else
      fmt::print("released (a motion that runs plays to its end)\n");
    return exit_ok;
  });

  auto* reset = buttons->add_subcommand("reset", "an empty table: no button plays anything (ROM and RAM)");
  on_device(reset, ctx, [&ctx, o](session& s) {
    const auto& layout = layout_for(s, *o);
    const auto t = read_tables(s);
    return write_table(s, t, {}, "no button plays anything", layout, ctx.g);
  });
}

}  // namespace cli
