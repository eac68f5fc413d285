// rcb4 — the layout shared by MOV, AND/OR/XOR and ADD…MOD (protocol.md §4.1–§4.2):
//   [SIZE][CMD][TYPE][DST d0 d1 d2][SRC ...][SUM]
// TYPE: bit 7 S | bit 6 0 | bits 5-4 DST | bits 3-2 0 | bits 1-0 SRC
#pragma once

#include <rcb4/commands/common.hpp>
#include <rcb4/operand.hpp>

namespace rcb4::detail {

/** The TYPE byte of commands 0x00–0x0A. */
constexpr std::uint8_t type_byte(store_mode s, dst_kind d, src_kind k) noexcept {
  return static_cast<std::uint8_t>((static_cast<unsigned>(s) << 7) | (static_cast<unsigned>(d) << 4) |
                                   static_cast<unsigned>(k));
}

/** A decoded TYPE byte. */
struct type_fields {
  store_mode mode;
  dst_kind dst;
  src_kind src;
};

/** Splits a TYPE byte; bits 6, 3 and 2 must be zero. */
constexpr result<type_fields> decode_type(std::uint8_t t) noexcept {
  if ((t & 0x4Cu) != 0) return errc::bad_type_byte;
  return type_fields{static_cast<store_mode>(t >> 7), static_cast<dst_kind>((t >> 4) & 3u),
                     static_cast<src_kind>(t & 3u)};
}

/** TYPE + DST + SRC: the body of MOV and the two-operand ALU commands. */
struct transfer {
  store_mode mode = store_mode::store;
  destination dst{};
  source src{};

  constexpr std::size_t wire_size() const noexcept { return 3 + 1 + destination::wire_size + src.wire_size(); }
  constexpr void write_body(writer& w) const noexcept {
    w.u8(type_byte(mode, dst.kind(), src.kind()));
    dst.write(w);
    src.write(w);
  }
  /** Reads TYPE, DST and SRC from a checked frame and checks the destination range. */
  static constexpr result<transfer> parse(std::span<const std::uint8_t> frame) noexcept {
    if (frame.size() < 3 + 1 + destination::wire_size + 1) return errc::bad_frame_size;
    reader r(frame.subspan(2, frame.size() - 3));
    auto t = decode_type(r.u8());
    if (!t) return t.error();
    auto d = destination::read(t->dst, r);
    if (!d) return d.error();
    auto s = source::read(t->src, r);
    if (!s) return s.error();
    if (auto ok = d->check_range(s->size()); !ok) return ok.error();
    return transfer{t->mode, *d, *s};
  }
  friend constexpr bool operator==(const transfer&, const transfer&) noexcept = default;
};

}  // namespace rcb4::detail
