// rcb4 — robot services: power-on (see rcb4/robot/services/boot.hpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/ops/memory.hpp>
#include <rcb4/robot/services/boot.hpp>
#include <rcb4/robot/services/motion_slots.hpp>

#include <fmt/format.h>

namespace rcb4::robot::services {
namespace {

using rcb4::ops::memory;

/** DefaultStartup's address under @p layout (DOC-PRG: 2.2 only), or 0. */
std::uint32_t default_startup(const rom_layout& layout) {
  return &layout == &hth4_2_2 ? layout.motion_base.value() + layout.motion_count * layout.slot_size : 0;
}

}  // namespace

startup_info read_startup(link& l, const rom_layout& layout) {
  const auto b = run(l, rcb4::ops::read_memory(memory::rom, layout.startup.value(), 7));
  startup_info s;
  const auto target = call_target(b);
  s.has_call = target.has_value();
  if (!s.has_call) return s;
  s.target = *target;
  const auto base = layout.motion_base.value();
  if (s.target >= base && s.target < base + layout.motion_count * layout.slot_size &&
      (s.target - base) % layout.slot_size == 0)
    s.motion = (s.target - base) / layout.slot_size + 1;
  s.default_startup = s.target == default_startup(layout) && s.target != 0;
  return s;
}

startup_info set_startup(link& l, const rom_layout& layout, std::optional<unsigned> n) {
  const auto now = read_startup(l, layout);
  if (!now.has_call)
    throw refused(refusal_kind::board,
                  fmt::format("the board has no start-up CALL at 0x{:06X}: its boot code is not HTH4 2.x's (nothing "
                              "written)",
                              layout.startup.value()),
                  "write the board once with HTH4, or `rcb4 project import` a project (its boot code stays)");
  std::uint32_t target = 0;
  if (n) {
    target = slot_for(layout, *n).address.value();
    require_playable(l, layout, *n, fmt::format("the start-up motion {}", *n));
  } else {
    target = default_startup(layout);
    if (!target)
      throw refused(
          refusal_kind::usage,
          fmt::format("where DefaultStartup is in the {} layout is not known: give a motion instead", layout.name));
  }
  const auto f = encode(call{rom_address::make(target).value()});  // 07 0C a0 a1 a2 00 SUM
  run(l, rcb4::ops::write_memory(memory::rom, layout.startup.value(), f.bytes()));
  const auto back = read_startup(l, layout);
  if (back.target != target)
    throw refused(refusal_kind::board,
                  fmt::format("the start-up CALL was written, but the board reads back 0x{:06X}", back.target));
  return back;
}

config_word boot_config(link& l) {
  const auto b = run(l, rcb4::ops::read_memory(memory::rom, hth4_2_2.config.value(), 2));
  return config_word::decode(static_cast<std::uint16_t>(b[0] | (b[1] << 8)));
}

void persist_config(link& l, config_word word) {
  word.zero_flag = word.carry_flag = word.program_error = false;
  const auto w = word.encode();
  const std::uint8_t bytes[] = {static_cast<std::uint8_t>(w), static_cast<std::uint8_t>(w >> 8)};
  run(l, rcb4::ops::write_memory(memory::rom, hth4_2_2.config.value(), bytes));
  const auto back = run(l, rcb4::ops::read_memory(memory::rom, hth4_2_2.config.value(), 2));
  if ((back[0] | (back[1] << 8)) != w)
    throw refused(
        refusal_kind::board,
        fmt::format("config word 0x{:04X} written to ROM, the board reads back 0x{:02X}{:02X}", w, back[1], back[0]));
}

}  // namespace rcb4::robot::services
