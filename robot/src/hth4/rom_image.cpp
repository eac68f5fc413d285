// rcb4 — an HTH4 project into a ROM image and back (see rcb4/robot/hth4/rom_image.hpp).
// SPDX-License-Identifier: BSL-1.0
#include "project_check.hpp"

#include <rcb4/board/memory.hpp>
#include <rcb4/motion/buttons.hpp>
#include <rcb4/motion/disassemble.hpp>
#include <rcb4/robot/hth4/rom_image.hpp>

#include <algorithm>
#include <set>

namespace rcb4::robot::hth4 {

namespace {

namespace mo = rcb4::motion;
namespace vt = rcb4::motion::vector_table_layout;

constexpr std::uint32_t config_at = 0x005DC, adc_at = 0x008F6, startup_at = 0x00444;
constexpr std::uint32_t allocation_at = 0x005DE, blocks_at = 0x00626;
constexpr std::uint8_t tail[] = {0x03, 0x0D, 0x10, 0xFF};
constexpr auto slots = static_cast<std::uint32_t>(motion_count);

std::string hex(std::uint32_t a) { return mo::hex_address(a); }

/** Writes @p bytes at @p at into the plan's image, recording the area. */
void put(import_plan& plan, std::string what, std::uint32_t at, std::span<const std::uint8_t> bytes) {
  const bool changes = !std::equal(bytes.begin(), bytes.end(), plan.image.begin() + at);
  std::copy(bytes.begin(), bytes.end(), plan.image.begin() + at);
  plan.areas.push_back({std::move(what), at, bytes.size(), changes});
}

std::uint16_t word_at(std::span<const std::uint8_t> b, std::uint32_t at) {
  return static_cast<std::uint16_t>(b[at] | (b[at + 1] << 8));
}

}  // namespace

import_plan plan_import(std::span<const std::uint8_t> rom, const project& p, const import_options& opt) {
  if (rom.size() != rom_size)
    throw profile_error("ROM",
                        "the image is " + std::to_string(rom.size()) + " bytes, not " + std::to_string(rom_size));
  import_plan plan;
  plan.image.assign(rom.begin(), rom.end());
  const rom_layout& board = opt.layout ? *opt.layout : p.layout();
  const std::uint32_t from = p.layout().motion_base.value(), to = board.motion_base.value();
  const auto moved = [&](std::uint32_t a) {
    return a >= from && a < from + slots * board.slot_size ? a - from + to : a;
  };
  // 1. Motions (§10.1), relocated (§4).
  std::vector<std::string> empty_over_used;
  for (const auto& m : p.motions) {
    const std::uint32_t at = to + m.number * board.slot_size;
    if (m.frames.empty()) {
      if (plan.image[at] != 0xFF) empty_over_used.push_back(std::to_string(m.number + 1));
      if (m.buttons != 0)
        plan.not_written.push_back("the button word " + std::to_string(m.buttons) + " of motion " +
                                   std::to_string(m.number + 1) +
                                   ", an empty slot (a press would stop the board's program)");
      continue;
    }
    std::vector<std::uint8_t> code;
    for (const auto& f : from == to ? m.frames : relocate(m.frames, from, to))
      code.insert(code.end(), f.begin(), f.end());
    put(plan,
        "motion " + std::to_string(m.number + 1) + " '" + m.name + "' (" + std::to_string(code.size()) + " bytes" +
            (from == to ? "" : ", moved from " + hex(m.address)) + ")",
        at, code);
  }
  if (!empty_over_used.empty()) {
    std::string list;
    for (const auto& n : empty_over_used) list += (list.empty() ? "" : ", ") + n;
    plan.not_written.push_back("slots " + list +
                               ": empty in the project, they hold code on the board and are left as they are (whether "
                               "HTH4 erases them is unknown, hth4-files.md §11.7; `rcb4 motion erase N` empties one)");
  }
  // 2. The button table (§9): CALL entries, in motion order.
  std::vector<vector_entry> entries;
  unsigned other_compare = 0;
  for (const auto& m : p.motions) {
    if (m.buttons == 0 || m.frames.empty()) continue;
    if (m.compare != compare_type::equals) {
      ++other_compare;
      continue;
    }
    entries.push_back(vector_entry::button(m.buttons, rom_address::make(to + m.number * board.slot_size).value()));
  }
  if (other_compare)
    plan.not_written.push_back(std::to_string(other_compare) +
                               " button assignment(s) with a CompareType other than Equals: how HTH4 encodes them is "
                               "unknown (hth4-files.md §9)");
  const std::size_t limit = opt.boot_2x ? vt::entry_count : 25;
  if (entries.size() > limit)
    throw profile_error("the project", std::to_string(entries.size()) +
                                           " motions have buttons; the board's table takes " + std::to_string(limit) +
                                           " (hth4-files.md §9)");
  const auto now = mo::decode_vector_table(rom.subspan(vt::rom_entries.value(), vt::bytes));
  const auto as_set = [](const std::vector<vector_entry>& es) {
    std::set<std::pair<std::uint16_t, std::uint32_t>> s;
    for (const auto& e : es) s.insert({e.buttons().value_or(0xFFFF), e.target.value()});
    return s;
  };
  const bool only_buttons =
      std::all_of(now.entries.begin(), now.entries.end(), [](const auto& e) { return e.buttons(); });
  const std::uint8_t address_word[] = {static_cast<std::uint8_t>(vt::ram_entries.value()),
                                       static_cast<std::uint8_t>(vt::ram_entries.value() >> 8)};
  if (now.ended && only_buttons && as_set(now.entries) == as_set(entries) &&
      word_at(rom, vt::rom_address_word.value()) == vt::ram_entries.value()) {
    plan.areas.push_back({"button table (" + std::to_string(entries.size()) + " entries, as the board has them)",
                          vt::rom_entries.value(), 0, false});
  } else {
    const auto bytes = mo::encode_vector_table(entries);
    if (!mo::ok(bytes)) throw profile_error("the project", std::get<mo::failure>(bytes).message);
    put(plan, "button table address", vt::rom_address_word.value(), address_word);
    put(plan, "button table (" + std::to_string(entries.size()) + " entries)", vt::rom_entries.value(),
        std::get<std::vector<std::uint8_t>>(bytes));
  }
  // 3. Servos (§2.3): the allocation image and each block's category, ID and trim.
  std::vector<std::uint8_t> alloc(rom.begin() + allocation_at, rom.begin() + allocation_at + 2 * servo_count);
  unsigned mixing = 0;
  for (const auto& s : p.servos) {
    const std::uint16_t w = s.mode == servo_mode::normal ? static_cast<std::uint16_t>(s.ram_address) : 0xFFFF;
    alloc[2 * s.device_number] = static_cast<std::uint8_t>(w);
    alloc[2 * s.device_number + 1] = static_cast<std::uint8_t>(w >> 8);
    mixing += s.mixing1_address != 0xFFFF || s.mixing2_address != 0xFFFF;
  }
  put(plan,
      "servo allocation (" +
          std::to_string(std::count_if(p.servos.begin(), p.servos.end(),
                                       [](const auto& s) { return s.mode == servo_mode::normal; })) +
          " servos)",
      allocation_at, alloc);
  for (const auto& s : p.servos) {
    if (s.mode != servo_mode::normal) continue;  // an unallocated servo's block does nothing
    const auto t = static_cast<std::uint16_t>(static_cast<std::int16_t>(s.trim));
    const std::uint8_t trim[] = {static_cast<std::uint8_t>(t), static_cast<std::uint8_t>(t >> 8)};
    put(plan, "servo ICS " + std::to_string(s.device_number) + " '" + s.name + "' trim " + std::to_string(s.trim),
        blocks_at + 20 * s.device_number + 2, trim);
    plan.trims.push_back({s.device_number, static_cast<std::int16_t>(s.trim)});
  }
  plan.not_written.push_back(
      "the servo blocks' category and ID bytes (+0, +1): left as the board has them (their "
      "meaning is inferred, not confirmed: hth4-files.md §2.3)");
  if (mixing)
    plan.not_written.push_back(std::to_string(mixing) +
                               " servo(s) with mixing: the rate's encoding in the block is unknown (hth4-files.md "
                               "§2.3); their mixing bytes are left as the board has them");
  // 4. Config word and AD references (§10.4).
  auto config = config_word::decode(p.config);
  const auto board_config = config_word::decode(word_at(rom, config_at));
  std::string baud_note;
  if (opt.keep_baud && config.com_baud != board_config.com_baud) {
    config.com_baud = board_config.com_baud;
    baud_note = ", the board's COM baud kept";
  }
  char cw[40];
  std::snprintf(cw, sizeof cw, "config word 0x%04X", static_cast<unsigned>(config.encode()));
  const std::uint8_t cbytes[] = {static_cast<std::uint8_t>(config.encode()),
                                 static_cast<std::uint8_t>(config.encode() >> 8)};
  put(plan, cw + baud_note, config_at, cbytes);
  std::array<std::uint8_t, 22> adc{};
  for (std::size_t i = 0; i < 11; ++i) {
    adc[2 * i] = static_cast<std::uint8_t>(p.adc_reference[i]);
    adc[2 * i + 1] = static_cast<std::uint8_t>(p.adc_reference[i] >> 8);
  }
  put(plan, "AD references", adc_at, adc);
  // 5. The start-up motion (§3: the CALL at 0x0444).
  if (p.startup_address >= 0) {
    if (!call_target(rom.subspan(startup_at)))
      plan.not_written.push_back("the start-up motion: the board has no CALL at 0x000444 (not HTH4 2.x boot code)");
    else {
      const auto target = moved(static_cast<std::uint32_t>(p.startup_address));
      const auto f = encode(call{rom_address::make(target).value()});  // 07 0C a0 a1 a2 00 SUM (§3)
      put(plan, "start-up motion " + hex(target), startup_at, f.bytes());
    }
  }
  // 6. What is not written (§10.6).
  if (std::any_of(p.priority.begin(), p.priority.end(), [](const auto& e) { return e.value.has_value(); }))
    plan.not_written.push_back("priority motions: their bytes in ROM are unknown (hth4-files.md §11.3)");
  if (p.low_power_address >= 0)
    plan.not_written.push_back("the low-power motion: its bytes in ROM are unknown (hth4-files.md §2.1)");
  if (!p.title.empty())
    plan.not_written.push_back("the title '" + p.title +
                               "': its encoding at 0x000A1B is unknown (hth4-files.md §11.4)");
  plan.not_written.push_back("the KRI-3 receiver block: where its image lives is unknown (hth4-files.md §11.4)");
  return plan;
}

export_result project_from_rom(std::span<const std::uint8_t> rom, const rom_layout& layout,
                               const std::vector<std::string>& names, const std::vector<std::string>& slot_names,
                               const std::string& date) {
  if (rom.size() != rom_size)
    throw profile_error("ROM",
                        "the image is " + std::to_string(rom.size()) + " bytes, not " + std::to_string(rom_size));
  export_result out{empty_project(layout), {}};
  auto& p = out.value;
  p.config = word_at(rom, config_at);
  for (std::size_t i = 0; i < 11; ++i) p.adc_reference[i] = word_at(rom, adc_at + static_cast<std::uint32_t>(2 * i));
  for (auto& s : p.servos) {
    const auto k = s.device_number;
    if (k < names.size() && !names[k].empty()) s.name = names[k];
    const auto w = word_at(rom, allocation_at + 2 * k);
    s.mode = w == s.ram_address ? servo_mode::normal : servo_mode::none;
    if (w != s.ram_address && w != 0xFFFF)
      out.left_out.push_back("ICS " + std::to_string(k) + "'s allocation word 0x" + hex(w).substr(4) +
                             " (neither its block nor none): exported as not allocated");
    // The trim as the image holds it (erased reads as -1: written back, it stays erased).
    if (s.mode == servo_mode::normal) s.trim = static_cast<std::int16_t>(word_at(rom, blocks_at + 20 * k + 2));
  }
  const std::uint32_t base = layout.motion_base.value();
  for (auto& m : p.motions) {
    m.date = date;
    const auto at = base + m.number * layout.slot_size;
    if (rom[at] == 0xFF) continue;
    const mo::slot where{rom_address::make(at).value(), layout.slot_size};
    const auto code = mo::disassemble(rom.subspan(at, layout.slot_size), where);
    const auto label = "motion " + std::to_string(m.number + 1);
    if (!code.problems.empty()) {
      out.left_out.push_back(label + ": " + code.problems.front());
      continue;
    }
    // The frames in a row from the slot's start to the end of the reachable code.
    const auto end = code.code.back().address + code.code.back().bytes.size();
    std::uint32_t a = at;
    std::vector<std::vector<std::uint8_t>> frames;
    bool in_row = true;
    while (a < end) {
      const auto size = rom[a];
      if (size < min_frame_size || a + size > end || !checksum_ok(rom.subspan(a, size))) {
        in_row = false;
        break;
      }
      frames.emplace_back(rom.begin() + a, rom.begin() + a + size);
      a += size;
    }
    if (!in_row) {
      out.left_out.push_back(label + ": bytes between its frames are not frames (the .h4p holds frames only)");
      continue;
    }
    // HTH4 ends a motion with 03 0D 10 FF (§2.2): kept when it follows the code (HTH4 wrote the
    // slot), else a final RETURN followed by FF is it; otherwise the import will write it there.
    const bool tail_follows =
        end + 4 <= at + layout.slot_size &&
        std::equal(std::begin(tail), std::end(tail), rom.begin() + static_cast<std::ptrdiff_t>(end));
    const bool ends_in_return = frames.back() == std::vector<std::uint8_t>{0x03, 0x0D, 0x10};
    if (!tail_follows && ends_in_return) {
      frames.pop_back();
      if (rom[end] != 0xFF)
        out.left_out.push_back(label +
                               ": the byte after its RETURN is not FF; an import writes HTH4's tail 03 0D 10 FF there");
    } else if (!tail_follows) {
      out.left_out.push_back(label +
                             ": its code does not end in a RETURN; an import writes HTH4's tail 03 0D 10 FF after it");
    }
    frames.emplace_back(std::begin(tail), std::end(tail));
    m.frames = std::move(frames);
    m.name = m.number < slot_names.size() && !slot_names[m.number].empty() ? slot_names[m.number] : label;
  }
  // Buttons: CALL entries of the table that play a slot's start.
  const auto table = mo::decode_vector_table(rom.subspan(vt::rom_entries.value(), vt::bytes));
  for (const auto& e : table.entries) {
    const auto b = e.buttons();
    const auto t = e.target.value();
    const bool slot_start = t >= base && t < base + slots * layout.slot_size && (t - base) % layout.slot_size == 0;
    auto* m = slot_start ? &p.motions[(t - base) / layout.slot_size] : nullptr;
    if (!b || e.action != vector_action::call || !m || m->frames.empty() || m->buttons != 0) {
      out.left_out.push_back(
          "a button-table entry that is not one button combination calling a motion's start (the "
          ".h4p holds one combination per motion)");
      continue;
    }
    m->buttons = *b;
  }
  // The start-up motion: the CALL at 0x0444.
  if (const auto startup = call_target(rom.subspan(startup_at))) {
    const std::uint32_t t = *startup;
    const std::uint32_t end = base + slots * layout.slot_size;  // 2.2's DefaultStartup, a RETURN
    const bool used_start = t >= base && t < end && (t - base) % layout.slot_size == 0 &&
                            !p.motions[(t - base) / layout.slot_size].frames.empty();
    p.startup_address = used_start || t == end ? static_cast<long>(t) : -1;
    if (!used_start && t != end)
      out.left_out.push_back("the start-up CALL to " + hex(t) + ", not a used motion's start");
  }
  check_project(p, "the board's ROM");
  return out;
}

}  // namespace rcb4::robot::hth4
