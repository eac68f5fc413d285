// rcb4 — robot services, private: which motion slot a ROM address is in, and its name in messages.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/memory_map.hpp>
#include <rcb4/motion/disassemble.hpp>

#include <fmt/format.h>

#include <cstdint>
#include <optional>
#include <string>

namespace rcb4::robot::services {

/** The motion slot that holds ROM address @p a, if any. */
inline std::optional<unsigned> slot_number(const rom_layout& layout, std::uint32_t a) {
  const std::uint32_t base = layout.motion_base.value();
  if (a < base || (a - base) / layout.slot_size >= layout.motion_count) return std::nullopt;
  return (a - base) / layout.slot_size + 1;
}

/** "motion 5 (0x002B80)", or the address alone outside the slots. */
inline std::string name_of(const rom_layout& layout, std::uint32_t a) {
  const auto n = slot_number(layout, a);
  if (!n) return motion::hex_address(a);
  const std::uint32_t start = layout.motion_base.value() + (*n - 1) * layout.slot_size;
  return a == start ? fmt::format("motion {} ({})", *n, motion::hex_address(a))
                    : fmt::format("motion {} at {}", *n, motion::hex_address(a));
}

}  // namespace rcb4::robot::services
