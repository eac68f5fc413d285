// rcb4 — the virtual board's vector-jump table and down-timers: what the firmware does each cycle
// besides the servos and the program.
// SPDX-License-Identifier: BSL-1.0
//
// Vectors (DOC-FW p7, p13-15; motions.md §2, §4): at boot HTH4's code copies the table address
// (ROM 0x0919 → RAM 0x008C) and up to 32 entries of 8 bytes (ROM 0x091B → RAM 0x0357); what
// HTH4's image holds after the last entry is unknown, so the model copies the entries up to the
// one marked EOF and leaves the rest of RAM at 0 (erased ROM, 0xFF, is no entry). Every cycle,
// while the ROM program runs and the vector switch (config bit 3) is on, the entries are compared
// from the table address on until one with EOF; the first that holds fires (CALL or JUMP) and the
// switch is cleared. An entry that does not decode (erased ROM reads 0xFF) ends the table (model).
// Timers (DOC-FW p11): four 16-bit down-counters at 0x003C in 100 ms units; bit 15 set: stopped,
// and the firmware sets it when a count reaches 0.
#pragma once

#include <rcb4/board/memory.hpp>
#include <rcb4/vector_entry.hpp>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <span>

namespace rcb4::board {

/** Where HTH4 keeps the vector table in ROM and how many entries its boot code copies (motions.md §4). */
namespace vectors {
inline constexpr rom_address table_address_image{0x00919};  ///< ROM word copied to RAM 0x008C
inline constexpr rom_address entries_image{0x0091B};        ///< ROM image of the entries
inline constexpr unsigned entry_count = 32;                 ///< HTH4 2.x: entries 00–31
}  // namespace vectors

/**
 * What HTH4's boot code does for the vector table: the table address from ROM to RAM 0x008C, and
 * the entries from ROM 0x091B to RAM 0x0357, up to the one marked EOF (at most 32). Returns how
 * many were copied.
 */
inline unsigned load_vector_table(memory& m) noexcept {
  m.put16(ram::vector_table.value(), m.rom16(vectors::table_address_image.value()));
  const std::uint32_t from = vectors::entries_image.value(), to = hth4_ram::vector_entries.value();
  for (unsigned j = 0; j < vectors::entry_count; ++j) {
    const std::uint32_t at = j * std::uint32_t{vector_entry::size};
    const auto e = vector_entry::decode(std::span(m.rom).subspan(from + at).first<vector_entry::size>());
    if (!e) return j;
    std::copy_n(m.rom.begin() + static_cast<std::ptrdiff_t>(from + at), vector_entry::size,
                m.ram.begin() + static_cast<std::ptrdiff_t>(to + at));
    if (e->last) return j + 1;
  }
  return vectors::entry_count;
}

/**
 * The entry that fires now, if any: the table at RAM[0x008C] walked to its EOF entry (at most
 * 32), each compare made on the values in RAM now. Whether the program and the switch are on is
 * the caller's test.
 */
inline std::optional<vector_entry> firing_vector(const memory& m) noexcept {
  std::uint32_t at = m.ram16(ram::vector_table.value());
  for (unsigned j = 0; j < vectors::entry_count; ++j, at += vector_entry::size) {
    if (at + vector_entry::size > ram_size) return std::nullopt;
    const auto e = vector_entry::decode(std::span(m.ram).subspan(at).first<vector_entry::size>());
    if (!e) return std::nullopt;
    const std::size_t size = e->word ? 2 : 1;
    const auto left = m.read_operand(e->dst, size);
    const auto right = e->src_literal ? std::optional(e->src) : m.read_operand(vector_operand{e->src}, size);
    if (left && right && e->fires(*left, *right)) return *e;
    if (e->last) return std::nullopt;
  }
  return std::nullopt;
}

/** One 100 ms step of the four down-timers: a running one counts down and stops (bit 15) at 0. */
inline void count_down_timers(memory& m) noexcept {
  for (unsigned k = 0; k < ram::timers; ++k) {
    const std::uint32_t a = ram::timer.value() + 2 * k;
    const std::uint16_t t = m.ram16(a);
    if ((t & ram::timer_stopped) != 0) continue;
    m.put16(a, t <= 1 ? ram::timer_stopped : static_cast<std::uint16_t>(t - 1));
  }
}

}  // namespace rcb4::board
