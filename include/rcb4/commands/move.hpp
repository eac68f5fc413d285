// rcb4 — MOV (0x00): copy bytes between RAM, ICS slots, the COM port, literals and ROM.
// SPDX-License-Identifier: BSL-1.0
//
// Wire layout (protocol.md §4.1):
//   [SIZE][00][TYPE][DST d0 d1 d2][SRC ...][SUM]
//   SIZE = 10 (RAM or ICS source), 11 (ROM source), 7 + n (literal source of n bytes, n ≤ 121)
//   e.g. read 2 bytes of RAM 0x0000 to COM:  0A 00 20 00 00 00 00 00 02 2C
// Reply: a data frame [size+3][00][data ...][SUM] when DST is COM, otherwise ACK [04][00][06][0A].
#pragma once

#include <rcb4/commands/transfer.hpp>

namespace rcb4 {

/** MOV: copies `source.size()` bytes from a source to a destination. */
class move {
 public:
  static constexpr std::uint8_t command_code = 0x00;  ///< CMD byte

  /** Any source to any destination; the destination range must hold the source's size. */
  static constexpr result<move> make(destination dst, source src) noexcept {
    if (auto ok = dst.check_range(src.size()); !ok) return ok.error();
    return result<move>(std::in_place, detail::transfer{store_mode::store, dst, src});
  }
  /** Reads @p size bytes of RAM at @p a (RAM → COM, TYPE 0x20). */
  static constexpr result<move> read_ram(ram_address a, transfer_size size) noexcept {
    if (a.value() + std::size_t{size.value()} > ram_size) return errc::ram_address_out_of_range;
    return result<move>(std::in_place,
                        detail::transfer{store_mode::store, destination::com(), source::ram(a, size).value()});
  }
  /** Writes @p bytes (1–121) to RAM at @p a (literal → RAM, TYPE 0x02). */
  static constexpr result<move> write_ram(ram_address a, std::span<const std::uint8_t> bytes) noexcept {
    auto s = source::literal(bytes);
    if (!s) return s.error();
    return make(destination::ram(a), *s);
  }
  /** Reads @p size bytes of ICS slot @p n from field @p offset (ICS → COM, TYPE 0x21). */
  static constexpr result<move> read_ics(ics_number n, std::uint8_t offset, transfer_size size) noexcept {
    auto s = source::ics(n, offset, size);
    if (!s) return s.error();
    return make(destination::com(), *s);
  }
  /** Writes @p bytes to field @p offset of ICS slot @p n (literal → ICS, TYPE 0x12). */
  static constexpr result<move> write_ics(ics_number n, std::uint8_t offset,
                                          std::span<const std::uint8_t> bytes) noexcept {
    auto s = source::literal(bytes);
    if (!s) return s.error();
    return make(destination::ics(n, offset), *s);
  }
  /** Reads @p size bytes of ROM at @p a (ROM → COM, TYPE 0x23). */
  static constexpr result<move> read_rom(rom_address a, transfer_size size) noexcept {
    auto s = source::rom(a, size);
    if (!s) return s.error();
    return make(destination::com(), *s);
  }
  /** Writes @p bytes to ROM at @p a (literal → ROM, TYPE 0x32). */
  static constexpr result<move> write_rom(rom_address a, std::span<const std::uint8_t> bytes) noexcept {
    auto s = source::literal(bytes);
    if (!s) return s.error();
    return make(destination::rom(a), *s);
  }

  /** Where the bytes go. */
  constexpr const destination& dst() const noexcept { return t_.dst; }
  /** Where the bytes come from. */
  constexpr const source& src() const noexcept { return t_.src; }

  /** CMD byte. */
  constexpr std::uint8_t code() const noexcept { return command_code; }
  /** Frame length. */
  constexpr std::size_t wire_size() const noexcept { return t_.wire_size(); }
  /** Writes TYPE, DST and SRC. */
  constexpr void write_body(detail::writer& w) const noexcept { t_.write_body(w); }
  /** Data of the moved size when DST is COM, else ACK. */
  constexpr reply_shape expected_reply() const noexcept {
    if (t_.dst.kind() == dst_kind::com) return {command_code, true, t_.src.size()};
    return {command_code, false, 0};
  }
  /** Reads a MOV from a checked frame; the S bit is refused (errc::flags_only_not_allowed). */
  static constexpr result<move> parse(std::span<const std::uint8_t> frame, const codec_options&) noexcept {
    auto t = detail::transfer::parse(frame);
    if (!t) return t.error();
    if (t->mode != store_mode::store) return errc::flags_only_not_allowed;
    return move{*t};
  }
  /** Value equality. */
  friend constexpr bool operator==(const move&, const move&) noexcept = default;

  /** A RAM-to-COM read of one byte at 0x0000. */
  constexpr move() noexcept = default;

 private:
  friend class result<move>;
  constexpr explicit move(detail::transfer t) noexcept : t_(t) {}
  detail::transfer t_{store_mode::store, destination::com(), source::ram(detail::zero_ram, detail::one_byte).value()};
};

}  // namespace rcb4
