// rcb4 — the ALU commands: AND/OR/XOR (0x01–0x03), NOT (0x04), SHIFT (0x05), ADD…MOD (0x06–0x0A).
// SPDX-License-Identifier: BSL-1.0
//
// Wire layouts (protocol.md §4.2):
//   AND/OR/XOR, ADD…MOD:  [SIZE][CMD][TYPE][DST d0 d1 d2][SRC ...][SUM]   (as MOV, §4.1)
//   NOT:                  [0A][04][TYPE][DST d0 d1 d2][00][00][size][SUM]
//   SHIFT:                [0A][05][TYPE][DST d0 d1 d2][00][count][size][SUM]
// TYPE bit 7 (S) = 1 updates the Z/C flags only. The result is `dst = dst op src`.
// Reply: a data frame with the result, as many bytes as the operand ([N+3][CMD][result][SUM]).
#pragma once

#include <rcb4/commands/transfer.hpp>

namespace rcb4 {

/** The bitwise operations, valued as their CMD bytes. */
enum class logic_op : std::uint8_t { and_ = 0x01, or_ = 0x02, xor_ = 0x03 };

/** The arithmetic operations, valued as their CMD bytes. Unsigned (2015 report). */
enum class arith_op : std::uint8_t { add = 0x06, sub = 0x07, mul = 0x08, div = 0x09, mod = 0x0A };

/** AND/OR/XOR: `dst = dst op src` over 1–128 bytes; COM is not a valid destination (DOC-CMD 禁止). */
class logic {
 public:
  /** @p op of @p src into @p dst; errc::destination_not_allowed for COM. */
  static constexpr result<logic> make(logic_op op, destination dst, source src,
                                      store_mode mode = store_mode::store) noexcept {
    if (dst.kind() == dst_kind::com) return errc::destination_not_allowed;
    if (auto ok = dst.check_range(src.size()); !ok) return ok.error();
    return logic{op, detail::transfer{mode, dst, src}};
  }
  /** The operation. */
  constexpr logic_op op() const noexcept { return op_; }
  /** Left operand and (unless flags-only) result. */
  constexpr const destination& dst() const noexcept { return t_.dst; }
  /** Right operand. */
  constexpr const source& src() const noexcept { return t_.src; }
  /** Store or flags only. */
  constexpr store_mode mode() const noexcept { return t_.mode; }

  /** CMD byte (0x01–0x03). */
  constexpr std::uint8_t code() const noexcept { return static_cast<std::uint8_t>(op_); }
  /** Frame length. */
  constexpr std::size_t wire_size() const noexcept { return t_.wire_size(); }
  /** Writes TYPE, DST and SRC. */
  constexpr void write_body(detail::writer& w) const noexcept { t_.write_body(w); }
  /** Data: the result, operand-sized. */
  constexpr reply_shape expected_reply() const noexcept { return {code(), true, t_.src.size()}; }
  /** Reads AND/OR/XOR from a checked frame. */
  static constexpr result<logic> parse(std::span<const std::uint8_t> frame, const codec_options&) noexcept {
    auto t = detail::transfer::parse(frame);
    if (!t) return t.error();
    return make(static_cast<logic_op>(frame[1]), t->dst, t->src, t->mode);
  }
  /** Value equality. */
  friend constexpr bool operator==(const logic&, const logic&) noexcept = default;
  /** No default: it writes RAM, so every operand is the caller's. */
  logic() = delete;

 private:
  constexpr logic(logic_op op, detail::transfer t) noexcept : op_(op), t_(t) {}
  logic_op op_ = logic_op::and_;
  detail::transfer t_{store_mode::store, destination::ram(detail::default_ram),
                      source::ram(detail::default_ram, detail::one_byte).value()};
};

/**
 * ADD/SUB/MUL/DIV/MOD: `dst = dst op src`, unsigned, operand 1 or 2 bytes (DOC-CMD).
 * Flags: ADD/MUL C=1 on carry, SUB C=0 on borrow, DIV/MOD C=0; Z=1 if the result is 0.
 * COM as destination is disputed (protocol.md §11.6): DOC-CMD lists it, the 2015 report found
 * the board refuses it, so it needs `com_output::allow`.
 */
class arith {
 public:
  /** Whether COM may be the destination (§11.6). */
  enum class com_output : std::uint8_t { forbid, allow };

  /** @p op of @p src into @p dst; operand 1–2 bytes; COM only with com_output::allow. */
  static constexpr result<arith> make(arith_op op, destination dst, source src, store_mode mode = store_mode::store,
                                      com_output com = com_output::forbid) noexcept {
    if (dst.kind() == dst_kind::com && com != com_output::allow) return errc::destination_not_allowed;
    if (src.size() < 1 || src.size() > 2) return errc::operand_size_out_of_range;
    if (auto ok = dst.check_range(src.size()); !ok) return ok.error();
    return arith{op, detail::transfer{mode, dst, src}};
  }
  /** The operation. */
  constexpr arith_op op() const noexcept { return op_; }
  /** Left operand and (unless flags-only) result. */
  constexpr const destination& dst() const noexcept { return t_.dst; }
  /** Right operand. */
  constexpr const source& src() const noexcept { return t_.src; }
  /** Store or flags only. */
  constexpr store_mode mode() const noexcept { return t_.mode; }

  /** CMD byte (0x06–0x0A). */
  constexpr std::uint8_t code() const noexcept { return static_cast<std::uint8_t>(op_); }
  /** Frame length. */
  constexpr std::size_t wire_size() const noexcept { return t_.wire_size(); }
  /** Writes TYPE, DST and SRC. */
  constexpr void write_body(detail::writer& w) const noexcept { t_.write_body(w); }
  /** Data: the result, operand-sized. */
  constexpr reply_shape expected_reply() const noexcept { return {code(), true, t_.src.size()}; }
  /** Reads ADD…MOD from a checked frame; COM destination only if @p opt allows it. */
  static constexpr result<arith> parse(std::span<const std::uint8_t> frame, const codec_options& opt) noexcept {
    auto t = detail::transfer::parse(frame);
    if (!t) return t.error();
    return make(static_cast<arith_op>(frame[1]), t->dst, t->src, t->mode,
                opt.allow_arith_to_com ? com_output::allow : com_output::forbid);
  }
  /** Value equality. */
  friend constexpr bool operator==(const arith&, const arith&) noexcept = default;
  /** No default: it writes RAM, so every operand is the caller's. */
  arith() = delete;

 private:
  constexpr arith(arith_op op, detail::transfer t) noexcept : op_(op), t_(t) {}
  arith_op op_ = arith_op::add;
  detail::transfer t_{store_mode::store, destination::ram(detail::default_ram),
                      source::ram(detail::default_ram, detail::one_byte).value()};
};

namespace detail {
/** The 10-byte single-operand layout of NOT and SHIFT: TYPE, DST, 00, arg, size. */
struct unary_layout {
  store_mode mode = store_mode::store;
  destination dst{};
  std::uint8_t arg = 0;
  transfer_size size = detail::one_byte;

  static constexpr std::size_t wire_size = 10;
  constexpr void write_body(writer& w) const noexcept {
    w.u8(type_byte(mode, dst.kind(), src_kind::ram));
    dst.write(w);
    w.u8(0);
    w.u8(arg);
    w.u8(size.value());
  }
  static constexpr result<unary_layout> parse(std::span<const std::uint8_t> frame) noexcept {
    if (frame.size() != wire_size) return errc::bad_frame_size;
    reader r(frame.subspan(2, wire_size - 3));
    auto t = decode_type(r.u8());
    if (!t) return t.error();
    if (t->src != src_kind::ram) return errc::bad_type_byte;  // SRC bits unused, must be 00
    auto d = destination::read(t->dst, r);
    if (!d) return d.error();
    if (d->kind() == dst_kind::com) return errc::destination_not_allowed;
    if (r.u8() != 0) return errc::reserved_bits_set;
    const std::uint8_t arg = r.u8();
    auto s = transfer_size::make(r.u8());
    if (!s) return s.error();
    if (auto ok = d->check_range(s->value()); !ok) return ok.error();
    return unary_layout{t->mode, *d, arg, *s};
  }
  friend constexpr bool operator==(const unary_layout&, const unary_layout&) noexcept = default;
};
}  // namespace detail

/** NOT (0x04): `dst = ~dst` over 1–128 bytes; COM is not a valid destination. */
class bit_not {
 public:
  static constexpr std::uint8_t command_code = 0x04;  ///< CMD byte
  /** Inverts @p size bytes at @p dst. */
  static constexpr result<bit_not> make(destination dst, transfer_size size,
                                        store_mode mode = store_mode::store) noexcept {
    if (dst.kind() == dst_kind::com) return errc::destination_not_allowed;
    if (auto ok = dst.check_range(size.value()); !ok) return ok.error();
    return bit_not{detail::unary_layout{mode, dst, 0, size}};
  }
  /** The operand. */
  constexpr const destination& dst() const noexcept { return l_.dst; }
  /** Operand bytes. */
  constexpr transfer_size size() const noexcept { return l_.size; }
  /** Store or flags only. */
  constexpr store_mode mode() const noexcept { return l_.mode; }

  /** CMD byte. */
  constexpr std::uint8_t code() const noexcept { return command_code; }
  /** Always 10. */
  constexpr std::size_t wire_size() const noexcept { return detail::unary_layout::wire_size; }
  /** Writes TYPE, DST, 00 00, size. */
  constexpr void write_body(detail::writer& w) const noexcept { l_.write_body(w); }
  /** Data: the result. */
  constexpr reply_shape expected_reply() const noexcept { return {command_code, true, l_.size.value()}; }
  /** Reads NOT from a checked frame; byte 7 must be 00 too. */
  static constexpr result<bit_not> parse(std::span<const std::uint8_t> frame, const codec_options&) noexcept {
    auto l = detail::unary_layout::parse(frame);
    if (!l) return l.error();
    if (l->arg != 0) return errc::reserved_bits_set;
    return bit_not{*l};
  }
  /** Value equality. */
  friend constexpr bool operator==(const bit_not&, const bit_not&) noexcept = default;
  /** No default: it writes RAM, so every operand is the caller's. */
  bit_not() = delete;

 private:
  constexpr explicit bit_not(detail::unary_layout l) noexcept : l_(l) {}
  detail::unary_layout l_{store_mode::store, destination::ram(detail::default_ram), 0, detail::one_byte};
};

/**
 * SHIFT (0x05): shifts @p size bytes at dst; a positive count shifts left, a negative one
 * right. The count byte's encoding is disputed (protocol.md §11.5), so each value carries the
 * encoding it is sent with; the default is the one measured on hardware in 2015.
 */
class shift {
 public:
  static constexpr std::uint8_t command_code = 0x05;  ///< CMD byte
  /** Shifts @p size bytes at @p dst by @p count (left > 0 > right). */
  static constexpr result<shift> make(destination dst, shift_count count, transfer_size size,
                                      shift_encoding enc = shift_encoding::measured_2015,
                                      store_mode mode = store_mode::store) noexcept {
    if (dst.kind() == dst_kind::com) return errc::destination_not_allowed;
    if (auto ok = dst.check_range(size.value()); !ok) return ok.error();
    return shift{detail::unary_layout{mode, dst, encode(count, enc), size}, count, enc};
  }
  /** The count byte for @p count under @p enc. */
  static constexpr std::uint8_t encode(shift_count count, shift_encoding enc) noexcept {
    const int c = count.value();
    const int left_positive = enc == shift_encoding::measured_2015 ? c : -c;
    return static_cast<std::uint8_t>(left_positive >= 0 ? left_positive : 256 + left_positive);
  }
  /** The count of @p byte under @p enc; 128 is out of range in both encodings. */
  static constexpr result<shift_count> decode(std::uint8_t byte, shift_encoding enc) noexcept {
    if (byte == 128) return errc::shift_count_out_of_range;
    const int v = byte < 128 ? byte : byte - 256;
    return shift_count::make(enc == shift_encoding::measured_2015 ? v : -v);
  }
  /** The operand. */
  constexpr const destination& dst() const noexcept { return l_.dst; }
  /** Signed count: left > 0 > right. */
  constexpr shift_count count() const noexcept { return count_; }
  /** Operand bytes. */
  constexpr transfer_size size() const noexcept { return l_.size; }
  /** Wire encoding of the count. */
  constexpr shift_encoding encoding() const noexcept { return enc_; }
  /** Store or flags only. */
  constexpr store_mode mode() const noexcept { return l_.mode; }

  /** CMD byte. */
  constexpr std::uint8_t code() const noexcept { return command_code; }
  /** Always 10. */
  constexpr std::size_t wire_size() const noexcept { return detail::unary_layout::wire_size; }
  /** Writes TYPE, DST, 00, count, size. */
  constexpr void write_body(detail::writer& w) const noexcept { l_.write_body(w); }
  /** Data: the result. */
  constexpr reply_shape expected_reply() const noexcept { return {command_code, true, l_.size.value()}; }
  /** Reads SHIFT from a checked frame, decoding the count with @p opt.shift. */
  static constexpr result<shift> parse(std::span<const std::uint8_t> frame, const codec_options& opt) noexcept {
    auto l = detail::unary_layout::parse(frame);
    if (!l) return l.error();
    auto c = decode(l->arg, opt.shift);
    if (!c) return c.error();
    return shift{*l, *c, opt.shift};
  }
  /** Value equality. */
  friend constexpr bool operator==(const shift&, const shift&) noexcept = default;
  /** No default: it writes RAM, so every operand is the caller's. */
  shift() = delete;

 private:
  constexpr shift(detail::unary_layout l, shift_count c, shift_encoding e) noexcept : l_(l), count_(c), enc_(e) {}
  detail::unary_layout l_{store_mode::store, destination::ram(detail::default_ram), 0, detail::one_byte};
  shift_count count_{};
  shift_encoding enc_ = shift_encoding::measured_2015;
};

}  // namespace rcb4
