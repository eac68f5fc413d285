// rcb4 — which remote button plays which motion: the vector-jump table as a list of entries, and
// KRR button combinations by name (motions.md §4; protocol.md §6).
// SPDX-License-Identifier: BSL-1.0
//
// The table is up to 32 entries of 8 bytes (vector_entry.hpp), the last marked EOF; HTH4 keeps
// its image at ROM 0x091B (the board copies it to RAM 0x0357 at boot) and its RAM address at ROM
// 0x0919 (→ RAM 0x008C). A table with no entry is written as one entry that can never fire
// (vector_entry::never), so the firmware always finds an EOF.
#pragma once

#include <rcb4/motion/program.hpp>
#include <rcb4/vector_entry.hpp>

#include <array>
#include <cctype>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace rcb4::motion {

/** HTH4's table: 32 entries, image in ROM, copy in RAM (motions.md §4). */
namespace vector_table_layout {
inline constexpr std::uint32_t entry_count = 32;                        ///< entries 00–31
inline constexpr rom_address rom_address_word{0x00919};                 ///< ROM: the table's RAM address
inline constexpr rom_address rom_entries{0x0091B};                      ///< ROM: the entries
inline constexpr ram_address ram_entries = hth4_ram::vector_entries;    ///< RAM 0x0357
inline constexpr std::size_t bytes = entry_count * vector_entry::size;  ///< 256
}  // namespace vector_table_layout

/** A KRR button's name and bit (names as the tool prints them; "tri" also reads as triangle). */
struct button_name {
  std::string_view name;  ///< lower case
  std::uint16_t bit;      ///< its bit in the button word
};
/** Every KRR/KRC button (protocol.md §6). */
inline constexpr std::array<button_name, 12> button_names = {{{"up", 0x0001},
                                                              {"down", 0x0002},
                                                              {"right", 0x0004},
                                                              {"left", 0x0008},
                                                              {"triangle", 0x0010},
                                                              {"cross", 0x0020},
                                                              {"circle", 0x0040},
                                                              {"square", 0x0100},
                                                              {"s1", 0x0200},
                                                              {"s2", 0x0400},
                                                              {"s3", 0x0800},
                                                              {"s4", 0x1000}}};

/** "up", "s1+up", … for a button word; "none" for 0; bits no button has are shown as hex. */
inline std::string buttons_text(std::uint16_t word) {
  std::string out;
  std::uint16_t rest = word;
  for (const auto& b : button_names)
    if (word & b.bit) {
      if (!out.empty()) out += '+';  // appended piece by piece: GCC 12's -Wrestrict misfires on "+" + string at -O2
      out += b.name;
      rest = static_cast<std::uint16_t>(rest & ~b.bit);
    }
  if (rest != 0) {
    static constexpr char hex[] = "0123456789ABCDEF";
    std::string h = "0x";
    for (int s = 12; s >= 0; s -= 4) h += hex[(rest >> s) & 0xF];
    if (!out.empty()) out += '+';
    out += h;
  }
  return out.empty() ? "none" : out;
}

/**
 * Reads a button combination: names joined by '+' (any case; "tri" is triangle), or a number
 * (0x0201) of defined bits only. The failure names the word it did not know.
 */
inline outcome<std::uint16_t> parse_buttons(std::string_view text) {
  if (text.empty()) return failure{"no buttons given (e.g. up, s1+up, 0x0201)"};
  if (std::isdigit(static_cast<unsigned char>(text[0]))) {
    unsigned v = 0;
    const bool hex = text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
    for (std::size_t i = hex ? 2 : 0; i < text.size(); ++i) {
      const char c = static_cast<char>(std::tolower(static_cast<unsigned char>(text[i])));
      const int d = c >= '0' && c <= '9' ? c - '0' : hex && c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
      if (d < 0 || v > 0xFFFF) return failure{"'" + std::string(text) + "' is not a button word"};
      v = v * (hex ? 16u : 10u) + static_cast<unsigned>(d);
    }
    if (v == 0 || v > 0xFFFF || (v & ~unsigned{krr::valid_buttons}) != 0)
      return failure{"'" + std::string(text) + "' is not a combination of buttons (defined bits: 0x1F7F)"};
    return static_cast<std::uint16_t>(v);
  }
  std::uint16_t word = 0;
  std::size_t start = 0;
  while (start <= text.size()) {
    const auto end = std::min(text.find('+', start), text.size());
    std::string part;
    for (char c : text.substr(start, end - start))
      part += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (part == "tri") part = "triangle";
    std::uint16_t bit = 0;
    for (const auto& b : button_names)
      if (b.name == part) bit = b.bit;
    if (bit == 0) {
      std::string known;
      for (const auto& b : button_names) known += (known.empty() ? "" : ", ") + std::string(b.name);
      return failure{"'" + part + "' is no button (buttons: " + known + ")"};
    }
    word = static_cast<std::uint16_t>(word | bit);
    start = end + 1;
  }
  return word;
}

/**
 * An entry that can never fire, marked EOF: an empty table. It compares the button word with the
 * literal 0 and fires on a borrow (C = 0 alone), which an unsigned value minus 0 never has, under
 * either rule for two flags (rcb4::two_flag_jump). Bytes: F8 50 03 00 00 00 00 00 (EOF 80, JUMP
 * 40, WORD 20, literal 10, compare C 08, C = 0). rcb4 before 0.2 wrote Z = 1 and C = 0 (FD …),
 * which under the "either" rule fires whenever no button is held: never_fires() does not hide it
 * then, so `motion buttons` lists it and `motion buttons reset` replaces it.
 */
constexpr vector_entry never_entry() noexcept {
  vector_entry e;
  e.dst = vector_operand::ram(krr::buttons);
  e.cond = condition{std::nullopt, false};
  e.src_literal = true;
  e.src = 0;
  e.action = vector_action::jump;
  e.last = true;
  return e;
}
/** True for an entry that cannot fire: never_entry()'s test (any destination), or rcb4 0.1's under the "both" rule. */
constexpr bool never_fires(const vector_entry& e) noexcept {
  if (e.cond == condition{std::nullopt, false} && e.src_literal && e.src == 0) return true;
  return two_flag_jump == two_flag_rule::both && e.cond == condition{true, false};
}

/** A table as read: its entries in order, and why the walk ended. */
struct vector_table {
  std::vector<vector_entry> entries;  ///< up to the EOF entry (never-firing entries left out)
  bool ended = false;                 ///< an EOF entry was found
  std::string problem;                ///< when the walk stopped on bytes that are no entry (erased ROM…)
};

/** Decodes a table from its bytes (up to 32 entries). */
inline vector_table decode_vector_table(std::span<const std::uint8_t> bytes) {
  vector_table t;
  for (std::size_t j = 0; j < vector_table_layout::entry_count && (j + 1) * vector_entry::size <= bytes.size(); ++j) {
    const auto e = vector_entry::decode(bytes.subspan(j * vector_entry::size).first<vector_entry::size>());
    if (!e) {
      t.problem = "entry " + std::to_string(j) + " is no entry (" + std::string(message(e.error())) + ")" +
                  (bytes[j * vector_entry::size] == 0xFF ? ": erased" : "");
      return t;
    }
    if (!never_fires(*e)) t.entries.push_back(*e);  // it means nothing but, with EOF, the end
    if (e->last) {
      t.ended = true;
      return t;
    }
  }
  if (!t.ended && t.problem.empty()) t.problem = "no entry is marked EOF";
  return t;
}

/** The bytes of a table holding @p entries (EOF on the last; never_entry() when there is none). */
inline outcome<std::vector<std::uint8_t>> encode_vector_table(std::span<const vector_entry> entries) {
  if (entries.size() > vector_table_layout::entry_count)
    return failure{"the table holds at most 32 entries; this one would have " + std::to_string(entries.size())};
  std::vector<std::uint8_t> out;
  const auto put = [&](vector_entry e, bool last) {
    e.last = last;
    const auto b = e.encode();
    out.insert(out.end(), b.begin(), b.end());
  };
  if (entries.empty()) put(never_entry(), true);
  for (std::size_t j = 0; j < entries.size(); ++j) put(entries[j], j + 1 == entries.size());
  return out;
}

/**
 * @p entries with @p buttons playing (CALL) @p target: the entry of the same combination
 * replaced in place, or a new one added at the end. Nothing when the table is full.
 */
inline outcome<std::vector<vector_entry>> assign_button(std::vector<vector_entry> entries, std::uint16_t buttons,
                                                        rom_address target) {
  for (auto& e : entries)
    if (e.buttons() == buttons) {
      e = vector_entry::button(buttons, target, e.last);
      return entries;
    }
  if (entries.size() >= vector_table_layout::entry_count)
    return failure{"the table is full (32 entries): clear a button first"};
  entries.push_back(vector_entry::button(buttons, target));
  return entries;
}

/** @p entries without the one for @p buttons; nothing when no entry has that combination. */
inline std::optional<std::vector<vector_entry>> clear_button(std::vector<vector_entry> entries, std::uint16_t buttons) {
  for (auto it = entries.begin(); it != entries.end(); ++it)
    if (it->buttons() == buttons) {
      entries.erase(it);
      return entries;
    }
  return std::nullopt;
}

}  // namespace rcb4::motion
