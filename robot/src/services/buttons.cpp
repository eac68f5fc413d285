// rcb4 — robot services: the remote's buttons (see rcb4/robot/services/buttons.hpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/ops/layout.hpp>
#include <rcb4/ops/memory.hpp>
#include <rcb4/ops/system.hpp>
#include <rcb4/robot/services/buttons.hpp>
#include <rcb4/robot/services/motion_slots.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>

namespace rcb4::robot::services {
namespace {

namespace mo = rcb4::motion;
namespace tl = rcb4::motion::vector_table_layout;
using rcb4::ops::memory;

std::string operand_text(vector_operand o) {
  return o.is_ics() ? fmt::format("ICS {} +{}", o.ics_slot(), o.address()) : fmt::format("RAM 0x{:04X}", o.address());
}

/** The motion whose slot starts at @p a, if any. */
std::optional<unsigned> motion_at(std::uint32_t a, const rom_layout& layout) {
  const std::uint32_t base = layout.motion_base.value();
  if (a < base || (a - base) % layout.slot_size != 0) return std::nullopt;
  const auto k = (a - base) / layout.slot_size + 1;
  return k <= layout.motion_count ? std::optional<unsigned>(k) : std::nullopt;
}

void write(link& l, memory m, std::uint32_t at, std::span<const std::uint8_t> b) {
  run(l, rcb4::ops::write_memory(m, at, b));
}

}  // namespace

button_tables read_buttons(link& l) {
  button_tables t;
  const auto a = run(l, rcb4::ops::read_memory(memory::ram, rcb4::ram::vector_table.value(), 2));
  t.ram_at = static_cast<std::uint16_t>(a[0] | (a[1] << 8));
  const auto r = run(l, rcb4::ops::read_memory(memory::rom, tl::rom_address_word.value(), 2 + tl::bytes));
  t.rom_at = static_cast<std::uint16_t>(r[0] | (r[1] << 8));
  t.rom_bytes.assign(r.begin() + 2, r.end());
  t.rom = mo::decode_vector_table(t.rom_bytes);
  if (std::uint32_t{t.ram_at} + vector_entry::size <= ram_size) {
    const auto n = std::min<std::size_t>(tl::bytes, ram_size - t.ram_at);
    t.ram_bytes = run(l, rcb4::ops::read_memory(memory::ram, t.ram_at, n));
    t.ram = mo::decode_vector_table(t.ram_bytes);
  } else {
    t.ram.problem = fmt::format("its address 0x{:04X} (RAM 0x008C) is outside RAM: no HTH4 project loaded", t.ram_at);
  }
  return t;
}

std::vector<std::string> entries_playing(const button_tables& t, std::uint32_t address) {
  std::vector<std::string> out;
  for (const auto* table : {&t.rom, &t.ram})
    for (const auto& e : table->entries)
      if (e.target.value() == address) {
        const auto b = e.buttons();
        std::string what = b ? mo::buttons_text(*b) : fmt::format("an entry on {}", operand_text(e.dst));
        if (std::find(out.begin(), out.end(), what) == out.end()) out.push_back(std::move(what));
      }
  return out;
}

table_report write_buttons(link& l, const button_tables& before, std::vector<vector_entry> entries, std::string done) {
  for (std::size_t j = 0; j < entries.size(); ++j) entries[j].last = j + 1 == entries.size();  // as encoded: EOF last
  const auto bytes = mo::encode_vector_table(entries);
  if (!mo::ok(bytes)) throw refused(refusal_kind::board, std::get<mo::failure>(bytes).message);
  const auto& b = std::get<std::vector<std::uint8_t>>(bytes);
  const std::uint16_t at = tl::ram_entries.value();
  const std::array<std::uint8_t, 2> at_bytes = {static_cast<std::uint8_t>(at & 0xFF),
                                                static_cast<std::uint8_t>(at >> 8)};
  write(l, memory::rom, tl::rom_entries.value(), b);
  if (before.rom_at != at) write(l, memory::rom, tl::rom_address_word.value(), at_bytes);
  write(l, memory::ram, at, b);
  if (before.ram_at != at) write(l, memory::ram, rcb4::ram::vector_table.value(), at_bytes);
  const auto after = read_buttons(l);
  if (after.rom.entries != entries || after.ram.entries != entries)
    throw refused(refusal_kind::board,
                  fmt::format("the table read back is not what was written ({} differs)",
                              after.rom.entries != entries ? "ROM" : "RAM"),
                  "the board may not accept ROM writes (write-protected, or another program rewrites the table)");
  return {std::move(done), after.rom.entries, !before.same()};
}

namespace {
/** The table to edit: ROM's (what survives power-off); erased ROM is an empty table, anything else unreadable is
 * refused. */
std::vector<vector_entry> editable(const button_tables& t) {
  if (!t.rom.problem.empty() && !(t.rom.entries.empty() && !t.rom_bytes.empty() && t.rom_bytes[0] == 0xFF))
    throw refused(refusal_kind::board,
                  fmt::format("the vector table in ROM (0x091B) cannot be read: {}", t.rom.problem),
                  "rcb4 read rom 0x091B 256 shows it; rcb4 motion buttons reset writes an empty table");
  return t.rom.entries;
}
}  // namespace

table_report set_button(link& l, const rom_layout& layout, std::uint16_t buttons, unsigned n) {
  const auto target = slot_for(layout, n).address;
  require_playable(l, layout, n, fmt::format("a button playing motion {}", n));
  // The board compares the table with the button word every period: an entry for the buttons held
  // now (a press --hold, a receiver's remote) would start the motion the moment it is written.
  const auto word = run(l, rcb4::ops::read_memory(memory::ram, krr::buttons.value(), 2));
  if (buttons != 0 && krr::decode_buttons(word[0], word[1]) == buttons)
    throw refused(refusal_kind::board,
                  fmt::format("{} are held now: an entry for them would play motion {} at once, so nothing was "
                              "written",
                              mo::buttons_text(buttons), n),
                  "rcb4 motion buttons release lets them go (or let go of the remote)");
  const auto t = read_buttons(l);
  auto entries = mo::assign_button(editable(t), buttons, target);
  if (!mo::ok(entries)) throw refused(refusal_kind::board, std::get<mo::failure>(entries).message);
  return write_buttons(l, t, std::get<std::vector<vector_entry>>(entries),
                       fmt::format("{} plays motion {}", mo::buttons_text(buttons), n));
}

table_report clear_button(link& l, std::uint16_t buttons) {
  const auto t = read_buttons(l);
  // The entry may be in either copy (RAM differs from ROM after a ROM restore or another program's
  // write): both are written as ROM's entries without it, so what `buttons` lists is what goes.
  auto rom = editable(t);
  const auto in_ram = std::any_of(t.ram.entries.begin(), t.ram.entries.end(),
                                  [&](const vector_entry& e) { return e.buttons() == buttons; });
  auto entries = mo::clear_button(rom, buttons);
  if (!entries && !in_ram)
    throw refused(refusal_kind::board, fmt::format("no entry plays anything for {}", mo::buttons_text(buttons)),
                  "rcb4 motion buttons lists the entries");
  return write_buttons(l, t, entries ? *entries : rom, fmt::format("{} plays nothing", mo::buttons_text(buttons)));
}

table_report reset_buttons(link& l) { return write_buttons(l, read_buttons(l), {}, "no button plays anything"); }

bool load_buttons_from_rom(link& l) {
  const auto t = read_buttons(l);
  if (!t.rom.problem.empty() && !t.rom.entries.empty()) return false;
  if (t.same() && t.ram_at == tl::ram_entries.value()) return true;
  const auto bytes = mo::encode_vector_table(t.rom.entries);
  if (!mo::ok(bytes)) return false;
  const std::uint16_t at = tl::ram_entries.value();
  const std::array<std::uint8_t, 2> at_bytes = {static_cast<std::uint8_t>(at & 0xFF),
                                                static_cast<std::uint8_t>(at >> 8)};
  write(l, memory::ram, at, std::get<std::vector<std::uint8_t>>(bytes));
  if (t.ram_at != at) write(l, memory::ram, rcb4::ram::vector_table.value(), at_bytes);
  return read_buttons(l).ram.entries == t.rom.entries;
}

press_report press(link& l, const rom_layout& layout, std::uint16_t buttons, bool hold) {
  press_report r;
  r.buttons = buttons;
  r.held = hold;
  // What the board would do, from the table it compares (RAM): nothing, or a call of an empty or
  // broken slot (which stops its program), is said before anything is pressed.
  const auto t = read_buttons(l);
  const vector_entry* entry = nullptr;
  for (const auto& e : t.ram.entries)
    if (e.buttons() == buttons) {
      entry = &e;
      break;
    }
  r.entry = entry ||
            std::any_of(t.ram.entries.begin(), t.ram.entries.end(), [](const vector_entry& e) { return !e.buttons(); });
  if (!r.entry && !hold)
    throw refused(refusal_kind::board,
                  fmt::format("no entry of the table plays anything for {}: a press would only be seen by a "
                              "motion that tests the buttons",
                              mo::buttons_text(buttons)),
                  "--hold holds them as a receiver would (for a motion's if_buttons); rcb4 motion buttons set "
                  "BUTTONS N adds an entry");
  if (entry) {
    const std::uint32_t a = entry->target.value();
    if (const auto n = motion_at(a, layout)) {
      require_playable(l, layout, *n, fmt::format("{} plays it", mo::buttons_text(buttons)));
    } else if (!ops::detail::holds_frame(run(l, rcb4::ops::read_memory(memory::rom, a, 128)))) {
      throw refused(refusal_kind::board,
                    fmt::format("{} plays 0x{:06X}, which holds no motion: a press would stop the board's program",
                                mo::buttons_text(buttons), a),
                    fmt::format("rcb4 motion buttons clear {}", mo::buttons_text(buttons)));
    }
  }
  // The board compares the table only while its ROM program runs (a ROM restore or a stop leaves it off).
  if (r.entry && !run(l, rcb4::ops::read_config{}).rom_program)
    throw refused(refusal_kind::board,
                  fmt::format("the ROM program is off (a ROM restore or a stop leaves it off): a press of {} would "
                              "play nothing until it runs, so nothing was pressed",
                              mo::buttons_text(buttons)),
                  "rcb4 motion resume lets it run");
  write(l, memory::ram, krr::buttons.value(), krr::encode_buttons(buttons));
  if (!r.entry) {  // held as a receiver would hold them: only a motion's button test sees them
    r.state = run(l, rcb4::ops::read_motion_state(layout));
    return r;
  }
  // The board compares the table once per output period (10-25 ms): a motion runs within a few.
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  do {
    r.state = run(l, rcb4::ops::read_motion_state(layout));
  } while (!r.state.running && std::chrono::steady_clock::now() < until);
  if (!hold) release(l);
  if (!r.state.running)
    throw refused(refusal_kind::board, fmt::format("{} pressed for 1 s: no motion started", mo::buttons_text(buttons)),
                  "rcb4 motion buttons shows which buttons play what, and whether the ROM program runs");
  return r;
}

void release(link& l) {
  static constexpr std::array<std::uint8_t, 2> neutral{};
  write(l, memory::ram, krr::buttons.value(), neutral);
}

}  // namespace rcb4::robot::services
