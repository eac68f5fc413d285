// rcb4 — sources and destinations of MOV and the ALU commands (protocol.md §4.1).
// SPDX-License-Identifier: BSL-1.0
//
// TYPE byte (commands 0x00–0x0A):   bit 7 S | bit 6 0 | bits 5-4 DST | bits 3-2 0 | bits 1-0 SRC
// DST field, always 3 bytes:        RAM [addrL][addrH][00]   ICS [offset][ics][00]
//                                   COM [00][00][00]         ROM [L][M][H]
// SRC field:                        RAM [addrL][addrH][size] ICS [offset][ics][size]
//                                   literal [bytes ...]       ROM [L][M][H][size]
#pragma once

#include <rcb4/frame.hpp>
#include <rcb4/values.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>

namespace rcb4 {

/** Destination kinds, as TYPE bits 5-4. */
enum class dst_kind : std::uint8_t { ram = 0, ics = 1, com = 2, rom = 3 };
/** Source kinds, as TYPE bits 1-0. */
enum class src_kind : std::uint8_t { ram = 0, ics = 1, literal = 2, rom = 3 };

namespace detail {
// Defaults of the command types' default constructors, named here because clang 14 crashes on
// consteval constructor calls nested in default member initializers.
inline constexpr ram_address default_ram{0x0090};
inline constexpr ram_address zero_ram{0x0000};
inline constexpr transfer_size one_byte{1};
}  // namespace detail

/** The largest literal a MOV can carry: 128-byte frame minus 7 bytes of framing. */
inline constexpr std::size_t max_literal_size = max_request_size - 7;

/** Where a MOV or ALU result goes: RAM, an ICS slot's fields, the COM port (a data reply) or ROM. */
class destination {
 public:
  /** RAM at @p a. */
  static constexpr destination ram(ram_address a) noexcept { return {dst_kind::ram, a.value(), {}}; }
  /** Field @p offset of ICS slot @p n (through the board's allocation table). */
  static constexpr destination ics(ics_number n, std::uint8_t offset) noexcept { return {dst_kind::ics, offset, n}; }
  /** The COM port: the board replies with the data. */
  static constexpr destination com() noexcept { return {dst_kind::com, 0, {}}; }
  /** EEPROM at @p a. */
  static constexpr destination rom(rom_address a) noexcept { return {dst_kind::rom, a.value(), {}}; }

  /** Which memory. */
  constexpr dst_kind kind() const noexcept { return kind_; }
  /** RAM/ROM address, or the ICS field offset. */
  constexpr std::uint32_t address() const noexcept { return address_; }
  /** The ICS slot (meaningful for dst_kind::ics). */
  constexpr ics_number ics_slot() const noexcept { return ics_; }
  /** Checks that @p size bytes starting here stay inside the memory. */
  constexpr result<void> check_range(std::size_t size) const noexcept {
    switch (kind_) {
      case dst_kind::ram: return address_ + size <= ram_size ? errc{} : errc::ram_address_out_of_range;
      case dst_kind::rom: return address_ + size <= rom_size ? errc{} : errc::rom_address_out_of_range;
      case dst_kind::ics: return address_ + size <= 256 ? errc{} : errc::ics_offset_out_of_range;
      case dst_kind::com: break;
    }
    return errc{};
  }
  /** Writes the 3-byte DST field. */
  constexpr void write(detail::writer& w) const noexcept {
    switch (kind_) {
      case dst_kind::ram:
        w.u16(static_cast<std::uint16_t>(address_));
        w.u8(0);
        break;
      case dst_kind::ics:
        w.u8(static_cast<std::uint8_t>(address_));
        w.u8(ics_.value());
        w.u8(0);
        break;
      case dst_kind::com: w.u24(0); break;
      case dst_kind::rom: w.u24(address_); break;
    }
  }
  /** Reads a 3-byte DST field of kind @p k, rejecting reserved bytes and ranges. */
  static constexpr result<destination> read(dst_kind k, detail::reader& r) noexcept {
    const std::uint8_t b0 = r.u8(), b1 = r.u8(), b2 = r.u8();
    switch (k) {
      case dst_kind::ram: {
        if (b2 != 0) return errc::reserved_bits_set;
        auto a = ram_address::make(b0 | (b1 << 8));
        if (!a) return a.error();
        return ram(*a);
      }
      case dst_kind::ics: {
        if (b2 != 0) return errc::reserved_bits_set;
        auto n = ics_number::make(b1);
        if (!n) return n.error();
        return ics(*n, b0);
      }
      case dst_kind::com:
        if ((b0 | b1 | b2) != 0) return errc::reserved_bits_set;
        return com();
      case dst_kind::rom: {
        auto a = rom_address::make(b0 | (b1 << 8) | (b2 << 16));
        if (!a) return a.error();
        return rom(*a);
      }
    }
    return errc::bad_type_byte;
  }
  /** Bytes of the DST field. */
  static constexpr std::size_t wire_size = 3;
  friend constexpr bool operator==(const destination&, const destination&) noexcept = default;

  constexpr destination() noexcept = default;

 private:
  constexpr destination(dst_kind k, std::uint32_t a, ics_number n) noexcept : kind_(k), address_(a), ics_(n) {}
  dst_kind kind_ = dst_kind::ram;
  std::uint32_t address_ = 0;
  ics_number ics_{};
};

/** Where MOV/ALU data comes from: RAM, an ICS slot's fields, a literal in the frame, or ROM. */
class source {
 public:
  /** @p size bytes of RAM from @p a; errc::ram_address_out_of_range if they leave RAM. */
  static constexpr result<source> ram(ram_address a, transfer_size size) noexcept {
    if (a.value() + std::size_t{size.value()} > ram_size) return errc::ram_address_out_of_range;
    return source{src_kind::ram, a.value(), {}, size.value()};
  }
  /** @p size bytes of ICS slot @p n from field @p offset; offset + size must not pass 256. */
  static constexpr result<source> ics(ics_number n, std::uint8_t offset, transfer_size size) noexcept {
    if (offset + std::size_t{size.value()} > 256) return errc::ics_offset_out_of_range;
    return source{src_kind::ics, offset, n, size.value()};
  }
  /** @p size bytes of ROM from @p a; errc::rom_address_out_of_range if they leave ROM. */
  static constexpr result<source> rom(rom_address a, transfer_size size) noexcept {
    if (a.value() + std::size_t{size.value()} > rom_size) return errc::rom_address_out_of_range;
    return source{src_kind::rom, a.value(), {}, size.value()};
  }
  /**
   * The literal @p bytes (1–121) carried in the frame. The bytes are referenced, not copied
   * (like std::span): keep them alive until the command is serialized.
   */
  static constexpr result<source> literal(std::span<const std::uint8_t> bytes) noexcept {
    if (bytes.empty() || bytes.size() > max_literal_size) return errc::literal_size_out_of_range;
    source s{src_kind::literal, 0, {}, static_cast<std::uint8_t>(bytes.size())};
    s.external_ = bytes.data();
    return s;
  }
  /** A 16-bit literal, little-endian (as every RCB-4 word); stored in the value itself. */
  static constexpr source literal_u16(std::uint16_t v) noexcept {
    source s{src_kind::literal, 0, {}, 2};
    s.inline_ = {static_cast<std::uint8_t>(v & 0xFFu), static_cast<std::uint8_t>(v >> 8)};
    return s;
  }
  /** An 8-bit literal; stored in the value itself. */
  static constexpr source literal_u8(std::uint8_t v) noexcept {
    source s{src_kind::literal, 0, {}, 1};
    s.inline_ = {v, 0};
    return s;
  }

  /** Which memory. */
  constexpr src_kind kind() const noexcept { return kind_; }
  /** RAM/ROM address or ICS offset (0 for a literal). */
  constexpr std::uint32_t address() const noexcept { return address_; }
  /** The ICS slot (meaningful for src_kind::ics). */
  constexpr ics_number ics_slot() const noexcept { return ics_; }
  /** Bytes moved: the transfer size, or the literal's length. */
  constexpr std::uint8_t size() const noexcept { return size_; }
  /** The literal bytes (empty unless src_kind::literal). */
  constexpr std::span<const std::uint8_t> literal_bytes() const noexcept {
    if (kind_ != src_kind::literal) return {};
    return {external_ ? external_ : inline_.data(), size_};
  }
  /** Bytes of the SRC field on the wire. */
  constexpr std::size_t wire_size() const noexcept {
    switch (kind_) {
      case src_kind::ram:
      case src_kind::ics: return 3;
      case src_kind::rom: return 4;
      case src_kind::literal: return size_;
    }
    return 0;
  }
  /** Writes the SRC field. */
  constexpr void write(detail::writer& w) const noexcept {
    switch (kind_) {
      case src_kind::ram:
        w.u16(static_cast<std::uint16_t>(address_));
        w.u8(size_);
        break;
      case src_kind::ics:
        w.u8(static_cast<std::uint8_t>(address_));
        w.u8(ics_.value());
        w.u8(size_);
        break;
      case src_kind::rom:
        w.u24(address_);
        w.u8(size_);
        break;
      case src_kind::literal: w.bytes(literal_bytes()); break;
    }
  }
  /** Reads a SRC field of kind @p k from the rest of @p r (the literal takes all of it). */
  static constexpr result<source> read(src_kind k, detail::reader& r) noexcept {
    if (k == src_kind::literal) return literal(r.rest());
    const std::size_t need = k == src_kind::rom ? 4 : 3;
    if (r.remaining() != need) return errc::bad_frame_size;
    if (k == src_kind::ram) {
      auto a = ram_address::make(r.u16());
      if (!a) return a.error();
      auto s = transfer_size::make(r.u8());
      if (!s) return s.error();
      return ram(*a, *s);
    }
    if (k == src_kind::ics) {
      const std::uint8_t off = r.u8();
      auto n = ics_number::make(r.u8());
      if (!n) return n.error();
      auto s = transfer_size::make(r.u8());
      if (!s) return s.error();
      return ics(*n, off, *s);
    }
    auto a = rom_address::make(r.u24());
    if (!a) return a.error();
    auto s = transfer_size::make(r.u8());
    if (!s) return s.error();
    return rom(*a, *s);
  }
  /** Same kind, place and size; literals compare by content. */
  friend constexpr bool operator==(const source& a, const source& b) noexcept {
    if (a.kind_ != b.kind_ || a.address_ != b.address_ || !(a.ics_ == b.ics_) || a.size_ != b.size_) return false;
    const auto x = a.literal_bytes(), y = b.literal_bytes();
    return std::equal(x.begin(), x.end(), y.begin(), y.end());
  }

  /** One byte of RAM at 0x0000. */
  constexpr source() noexcept = default;

 private:
  constexpr source(src_kind k, std::uint32_t a, ics_number n, std::uint8_t size) noexcept
      : kind_(k), address_(a), ics_(n), size_(size) {}
  src_kind kind_ = src_kind::ram;
  std::uint32_t address_ = 0;
  ics_number ics_{};
  std::uint8_t size_ = 1;
  std::array<std::uint8_t, 2> inline_{};    // literal_u8 / literal_u16
  const std::uint8_t* external_ = nullptr;  // literal(span): referenced bytes
};

}  // namespace rcb4
