// rcb4 — the virtual board's memory: RAM, ROM, and operands read and written through them.
// SPDX-License-Identifier: BSL-1.0
//
// RAM 0x0000–0x048F (protocol.md §6) and a 256 KiB ROM. ICS operands reach a slot's servo block
// through the allocation table at 0x0044 (DOC-FW p16). No time, no I/O: a value a test can hold.
#pragma once

#include <rcb4/memory_map.hpp>
#include <rcb4/operand.hpp>
#include <rcb4/vector_entry.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace rcb4::board {

/** RAM and ROM of the board, with the accessors every part of it uses. */
struct memory {
  std::array<std::uint8_t, ram_size> ram{};  ///< RAM 0x0000–0x048F
  std::vector<std::uint8_t> rom;             ///< ROM, rom_size bytes

  /** 16-bit word of RAM at @p a (little-endian). */
  std::uint16_t ram16(std::uint32_t a) const noexcept { return static_cast<std::uint16_t>(ram[a] | (ram[a + 1] << 8)); }
  /** 16-bit word of ROM at @p a (little-endian). */
  std::uint16_t rom16(std::uint32_t a) const noexcept { return static_cast<std::uint16_t>(rom[a] | (rom[a + 1] << 8)); }
  /** Writes a 16-bit word to RAM at @p a. */
  void put16(std::uint32_t a, std::uint16_t v) noexcept {
    ram[a] = static_cast<std::uint8_t>(v & 0xFFu);
    ram[a + 1] = static_cast<std::uint8_t>(v >> 8);
  }
  /** Writes a 24-bit value to RAM at @p a. */
  void put24(std::uint32_t a, std::uint32_t v) noexcept {
    put16(a, static_cast<std::uint16_t>(v & 0xFFFFu));
    ram[a + 2] = static_cast<std::uint8_t>((v >> 16) & 0xFFu);
  }

  /** The config register, decoded. */
  config_word config() const noexcept { return config_word::decode(ram16(ram::config.value())); }
  /** Writes the config register. */
  void set_config(const config_word& c) noexcept { put16(ram::config.value(), c.encode()); }
  /** The ROM program counter (RAM 0x0002, 24 bits). */
  std::uint32_t pc() const noexcept { return ram[2] | (std::uint32_t{ram[3]} << 8) | (std::uint32_t{ram[4]} << 16); }
  /** Sets the program counter. */
  void set_pc(std::uint32_t a) noexcept { put24(ram::program_counter.value(), a); }

  /** ICS @p n's allocation-table entry (0xFFFF: unallocated). */
  std::uint16_t allocation(ics_number n) const noexcept { return ram16(ram::allocation_entry(n).value()); }
  /** The RAM block address of ICS @p n, or nothing when unallocated (0xFFFF, or 0 as on a board without a project). */
  std::optional<std::uint16_t> block_of(ics_number n) const noexcept {
    const std::uint16_t a = allocation(n);
    if (a == ram::no_allocation || a == 0 || std::uint32_t{a} + servo_block::size > ram_size) return std::nullopt;
    return a;
  }
  /** Where @p size bytes at @p offset of ICS @p n's block live in RAM, or nothing (unallocated / out of RAM). */
  std::optional<std::uint32_t> ics_address(ics_number n, std::uint32_t offset, std::size_t size) const noexcept {
    const std::uint16_t a = allocation(n);
    if (a == ram::no_allocation || a + offset + size > ram_size) return std::nullopt;
    return a + offset;
  }

  /** Reads a MOV source into @p out (its size); false for an unallocated ICS slot. */
  bool read_source(const source& s, std::span<std::uint8_t> out) const noexcept {
    const std::size_t n = s.size();
    switch (s.kind()) {
      case src_kind::literal: std::copy_n(s.literal_bytes().begin(), n, out.begin()); return true;
      case src_kind::ram: std::copy_n(ram.begin() + s.address(), n, out.begin()); return true;
      case src_kind::rom: std::copy_n(rom.begin() + s.address(), n, out.begin()); return true;
      case src_kind::ics: return read_ics(s.ics_slot(), s.address(), out);
    }
    return false;
  }
  /** Reads the destination operand (for ALU ops); COM reads as zeros. */
  bool read_destination(const destination& d, std::span<std::uint8_t> out) const noexcept {
    switch (d.kind()) {
      case dst_kind::ram: std::copy_n(ram.begin() + d.address(), out.size(), out.begin()); return true;
      case dst_kind::rom: std::copy_n(rom.begin() + d.address(), out.size(), out.begin()); return true;
      case dst_kind::com: std::fill(out.begin(), out.end(), std::uint8_t{0}); return true;
      case dst_kind::ics: return read_ics(d.ics_slot(), d.address(), out);
    }
    return false;
  }
  /** Writes @p bytes to a destination; COM swallows them; false for an unallocated ICS slot. */
  bool write_destination(const destination& d, std::span<const std::uint8_t> bytes) noexcept {
    switch (d.kind()) {
      case dst_kind::ram: std::copy(bytes.begin(), bytes.end(), ram.begin() + d.address()); return true;
      case dst_kind::rom: std::copy(bytes.begin(), bytes.end(), rom.begin() + d.address()); return true;
      case dst_kind::com: return true;
      case dst_kind::ics: {
        const auto a = ics_address(d.ics_slot(), d.address(), bytes.size());
        if (!a) return false;
        std::copy(bytes.begin(), bytes.end(), ram.begin() + *a);
        return true;
      }
    }
    return false;
  }
  /**
   * The value of a vector entry's operand (protocol.md §6): @p size (1 or 2) bytes, little-endian,
   * at a RAM address or in an ICS slot's block; nothing when the slot is unallocated or the bytes
   * leave RAM.
   */
  std::optional<std::uint16_t> read_operand(vector_operand o, std::size_t size) const noexcept {
    std::uint32_t a = o.address();
    if (o.is_ics()) {
      const auto n = ics_number::make(o.ics_slot());
      if (!n) return std::nullopt;
      const auto block = block_of(*n);  // an entry of 0 or 0xFFFF: no servo there
      if (!block) return std::nullopt;
      a += *block;
    }
    if (a + size > ram_size) return std::nullopt;
    return static_cast<std::uint16_t>(size == 2 ? ram16(a) : ram[a]);
  }

 private:
  bool read_ics(ics_number n, std::uint32_t offset, std::span<std::uint8_t> out) const noexcept {
    const auto a = ics_address(n, offset, out.size());
    if (!a) return false;
    std::copy_n(ram.begin() + *a, out.size(), out.begin());
    return true;
  }
};

}  // namespace rcb4::board
