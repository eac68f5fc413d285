// rcb4 — a vector-jump entry: how the firmware maps a button (or any RAM/ICS value) to a motion.
// SPDX-License-Identifier: BSL-1.0
//
// Wire layout (protocol.md §6 "Vector-jump entry", DOC-FW p13-15; motions.md §4), 8 bytes in RAM
// (HTH4: table at 0x0357, its address at 0x008C) and in ROM (HTH4: copied from 0x091B at boot):
//   [COND][dstL][dstH][srcL][srcH][addrL][addrM][addrH]
//   COND bit 7 EOF (the last entry), bit 6 JUMP (1) or CALL (0), bit 5 WORD (2-byte compare, else
//        1 byte), bit 4 src is a literal, bits 3-0 as a JUMP's COND: compare C, compare Z,
//        required C, required Z (flags of dst − src, as SUB sets them: Z equal, C no borrow).
//   dst / src word: a RAM address, or 0x8000 | ics << 8 | offset for a field of ICS slot ics.
//   The words are little-endian (model: as every address of the protocol).
// e.g. HTH4's pattern for "KRR UP plays motion 2 (HTH4 2.2+: 0x001380)", last entry:
//   B5 50 03 00 01 80 13 00   (EOF | WORD | literal | Z compared, Z = 1; dst RAM 0x0350; literal
//   bytes 00 01: the button word as it lies in RAM, high byte first, §11.11; CALL 0x001380)
#pragma once

#include <rcb4/commands/flow.hpp>
#include <rcb4/memory_map.hpp>
#include <rcb4/servo_set.hpp>
#include <rcb4/values.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <span>

namespace rcb4 {

/** A compare operand of a vector entry: a RAM address or a field of an ICS slot's servo block. */
struct vector_operand {
  std::uint16_t word = 0;  ///< as stored: RAM address, or 0x8000 | ics << 8 | offset

  /** RAM address @p a. */
  static constexpr vector_operand ram(ram_address a) noexcept { return {a.value()}; }
  /** Byte @p offset of ICS slot @p n's servo block. */
  static constexpr vector_operand ics(ics_number n, std::uint8_t offset) noexcept {
    return {static_cast<std::uint16_t>(0x8000u | (unsigned{n.value()} << 8) | offset)};
  }
  /** True for an ICS field. */
  constexpr bool is_ics() const noexcept { return (word & 0x8000u) != 0; }
  /** The ICS slot number (bits 8-14) of an ICS field. */
  constexpr unsigned ics_slot() const noexcept { return (word >> 8) & 0x7Fu; }
  /** The RAM address, or the offset in the servo block of an ICS field. */
  constexpr std::uint16_t address() const noexcept {
    return is_ics() ? static_cast<std::uint16_t>(word & 0xFFu) : word;
  }
  friend constexpr bool operator==(const vector_operand&, const vector_operand&) noexcept = default;
};

/** What a vector does when its compare holds. */
enum class vector_action : std::uint8_t {
  call,  ///< push the PC, go to the address (a motion that ends in RETURN comes back)
  jump,  ///< go to the address
};

/** One 8-byte vector-jump entry. */
struct vector_entry {
  static constexpr std::size_t size = 8;  ///< bytes per entry

  vector_operand dst{};                        ///< left operand of the compare
  std::uint16_t src = 0;                       ///< literal value (bytes as stored), or an operand's word
  bool src_literal = true;                     ///< src is a literal
  bool word = true;                            ///< 2-byte compare (else the low byte only)
  condition cond{};                            ///< when the entry fires
  vector_action action = vector_action::call;  ///< JUMP or CALL
  bool last = false;                           ///< EOF: the table ends with this entry
  rom_address target{};                        ///< where it goes

  /** The 8 bytes. */
  constexpr std::array<std::uint8_t, size> encode() const noexcept {
    const unsigned c = (last ? 0x80u : 0u) | (action == vector_action::jump ? 0x40u : 0u) | (word ? 0x20u : 0u) |
                       (src_literal ? 0x10u : 0u) | cond.encode();
    const std::uint32_t t = target.value();
    return {static_cast<std::uint8_t>(c),
            static_cast<std::uint8_t>(dst.word & 0xFFu),
            static_cast<std::uint8_t>(dst.word >> 8),
            static_cast<std::uint8_t>(src & 0xFFu),
            static_cast<std::uint8_t>(src >> 8),
            static_cast<std::uint8_t>(t & 0xFFu),
            static_cast<std::uint8_t>((t >> 8) & 0xFFu),
            static_cast<std::uint8_t>((t >> 16) & 0xFFu)};
  }

  /**
   * Decodes 8 bytes. Refused: an ICS operand past slot 35 (errc::ics_out_of_range; erased ROM,
   * 0xFF…, is refused so), a RAM operand past 0x048F, a target past the ROM.
   */
  static constexpr result<vector_entry> decode(std::span<const std::uint8_t, size> b) noexcept {
    vector_entry e;
    const std::uint8_t c = b[0];
    auto cond = condition::decode(static_cast<std::uint8_t>(c & 0x0Fu));
    if (!cond) return cond.error();
    e.cond = *cond;
    e.last = (c & 0x80u) != 0;
    e.action = (c & 0x40u) != 0 ? vector_action::jump : vector_action::call;
    e.word = (c & 0x20u) != 0;
    e.src_literal = (c & 0x10u) != 0;
    e.dst = {static_cast<std::uint16_t>(b[1] | (b[2] << 8))};
    e.src = static_cast<std::uint16_t>(b[3] | (b[4] << 8));
    if (auto ok = check(e.dst, e.word); ok != errc{}) return ok;
    if (!e.src_literal)
      if (auto ok = check(vector_operand{e.src}, e.word); ok != errc{}) return ok;
    auto t = rom_address::make(b[5] | (std::uint32_t{b[6]} << 8) | (std::uint32_t{b[7]} << 16));
    if (!t) return t.error();
    e.target = *t;
    return e;
  }

  /**
   * HTH4's entry for a KRR button combination (motions.md §4): a word compare of the button word
   * at 0x0350 with @p buttons, equal, then CALL @p target.
   */
  static constexpr vector_entry button(std::uint16_t buttons, rom_address target, bool last = false) noexcept {
    vector_entry e;
    e.dst = vector_operand::ram(krr::buttons);
    const auto bytes = krr::encode_buttons(buttons);  // as the word lies in RAM, high byte first
    e.src = static_cast<std::uint16_t>(bytes[0] | (bytes[1] << 8));
    e.cond = condition{true, std::nullopt};
    e.target = target;
    e.last = last;
    return e;
  }
  /** The button combination when this entry is one of button()'s pattern (any EOF). */
  constexpr std::optional<std::uint16_t> buttons() const noexcept {
    if (!(dst == vector_operand::ram(krr::buttons)) || !src_literal || !word ||
        !(cond == condition{true, std::nullopt}))
      return std::nullopt;
    return krr::decode_buttons(static_cast<std::uint8_t>(src & 0xFFu), static_cast<std::uint8_t>(src >> 8));
  }

  /** Compares @p left with @p right (values as read, the low byte only unless word) and tells whether it fires. */
  constexpr bool fires(std::uint16_t left, std::uint16_t right) const noexcept {
    const std::uint32_t mask = word ? 0xFFFFu : 0xFFu;
    const std::uint32_t l = left & mask, r = right & mask;
    return cond.holds(l == r, l >= r);  // SUB's flags: Z result zero, C = 0 on borrow
  }

  friend constexpr bool operator==(const vector_entry&, const vector_entry&) noexcept = default;

 private:
  static constexpr errc check(vector_operand o, bool word) noexcept {
    if (o.is_ics()) return o.ics_slot() >= ics_slots ? errc::ics_out_of_range : errc{};
    return std::uint32_t{o.address()} + (word ? 2u : 1u) > ram_size ? errc::ram_address_out_of_range : errc{};
  }
};

}  // namespace rcb4
