// rcb4 — program flow: JUMP (0x0B), CALL (0x0C), RETURN (0x0D).
// SPDX-License-Identifier: BSL-1.0
//
// Wire layouts (protocol.md §4.3–§4.4):
//   JUMP:   [07][0B][addrL][addrM][addrH][COND][SUM]    e.g. unconditional to 0x000B80: 07 0B 80 0B 00 00 9D
//   CALL:   [07][0C][addrL][addrM][addrH][COND][SUM]    e.g. motion 1 (HTH4 2.2):       07 0C 80 0B 00 00 9E
//   RETURN: [03][0D][SUM] = 03 0D 10
// COND: bit 0 required Z, bit 1 required C, bit 2 compare Z, bit 3 compare C, bits 4-7 zero.
// Reply: ACK [04][CMD][06][SUM]. CALL pushes the return address; the stack is 16 deep.
#pragma once

#include <rcb4/commands/common.hpp>
#include <rcb4/values.hpp>

#include <optional>

namespace rcb4 {

/**
 * How the board takes a JUMP/CALL whose COND compares both flags: when either compared flag has
 * its required value, or only when both do. DOC-CMD p13 defines the COND bits but not this.
 * Evidence (hth4-files.md §8; motions.md §0 sources): KONDO's own KXR get-up motion branches
 * after a flags-only SUB of an AD channel minus a limit (Z = 1 equal, C = 0 on a borrow,
 * protocol.md §5) with COND 0D on the blocks HTH4 labels "≤" and 0F on those labelled "≥". Read
 * as "both", 0D (Z = 1 and C = 0) could never be taken and 0F only on equality; read as
 * "either", 0D is ≤ and 0F is ≥, as labelled, and no other sample (one flag compared) tells the
 * two apart. So: either, an inference from KONDO's own output, not yet seen on a board. The
 * hardware test of hth4-files.md §8 settles it; build with -DRCB4_JUMP_NEEDS_BOTH_FLAGS=1 to
 * flip the codec, the virtual board, the disassembler and the vector table together.
 */
enum class two_flag_rule : std::uint8_t { either, both };
#if defined(RCB4_JUMP_NEEDS_BOTH_FLAGS) && RCB4_JUMP_NEEDS_BOTH_FLAGS
inline constexpr two_flag_rule two_flag_jump = two_flag_rule::both;
#else
inline constexpr two_flag_rule two_flag_jump = two_flag_rule::either;  ///< the rule this build follows
#endif

/** When JUMP/CALL is taken: each flag either ignored or required to have a value. */
struct condition {
  std::optional<bool> zero;   ///< required Z flag, or not compared
  std::optional<bool> carry;  ///< required C flag, or not compared

  /** Always taken (COND 00), what every library sends. */
  static constexpr condition always() noexcept { return {}; }
  /** The COND byte. */
  constexpr std::uint8_t encode() const noexcept {
    unsigned b = 0;
    if (zero) b |= 0x04u | (*zero ? 0x01u : 0u);
    if (carry) b |= 0x08u | (*carry ? 0x02u : 0u);
    return static_cast<std::uint8_t>(b);
  }
  /** Decodes a COND byte; bits 4-7, or a required value without its compare bit, are refused. */
  static constexpr result<condition> decode(std::uint8_t b) noexcept {
    if ((b & 0xF0u) != 0) return errc::bad_condition;
    if ((b & 0x01u) && !(b & 0x04u)) return errc::bad_condition;
    if ((b & 0x02u) && !(b & 0x08u)) return errc::bad_condition;
    condition c;
    if (b & 0x04u) c.zero = (b & 0x01u) != 0;
    if (b & 0x08u) c.carry = (b & 0x02u) != 0;
    return c;
  }
  /** True when flags @p z and @p c satisfy the condition (two compared flags: two_flag_jump). */
  constexpr bool holds(bool z, bool c) const noexcept {
    if (zero && carry && two_flag_jump == two_flag_rule::either) return *zero == z || *carry == c;
    return (!zero || *zero == z) && (!carry || *carry == c);
  }
  /**
   * What the condition tests after a flags-only SUB of a left minus a right value: "always",
   * "never", "==", "!=", "<", "<=", ">", ">=" (Z = 1 when equal, C = 0 on a borrow).
   */
  constexpr const char* relation() const noexcept {
    const unsigned less = holds(false, false), equal = holds(true, true), greater = holds(false, true);
    constexpr const char* names[] = {"never", ">", "==", ">=", "<", "!=", "<=", "always"};
    return names[less * 4 + equal * 2 + greater];
  }
  friend constexpr bool operator==(const condition&, const condition&) noexcept = default;
};

namespace detail {
/** JUMP and CALL: same layout, different CMD byte. */
template <std::uint8_t Code>
class branch {
 public:
  static constexpr std::uint8_t command_code = Code;  ///< CMD byte

  /** To ROM address @p target when @p cond holds. */
  constexpr explicit branch(rom_address target, condition cond = condition::always()) noexcept
      : target_(target), cond_(cond) {}
  /** No default: it moves the board's program counter, so the target is the caller's. */
  branch() = delete;

  /** The ROM address. */
  constexpr rom_address target() const noexcept { return target_; }
  /** The condition. */
  constexpr const condition& cond() const noexcept { return cond_; }

  /** CMD byte. */
  constexpr std::uint8_t code() const noexcept { return Code; }
  /** Always 7. */
  constexpr std::size_t wire_size() const noexcept { return 7; }
  /** Writes address (24-bit LE) and COND. */
  constexpr void write_body(writer& w) const noexcept {
    w.u24(target_.value());
    w.u8(cond_.encode());
  }
  /** ACK. */
  constexpr reply_shape expected_reply() const noexcept { return {Code, false, 0}; }
  /** Reads from a checked frame. */
  template <class Self>
  static constexpr result<Self> parse_as(std::span<const std::uint8_t> frame) noexcept {
    if (frame.size() != 7) return errc::bad_frame_size;
    reader r(frame.subspan(2, 4));
    auto a = rom_address::make(r.u24());
    if (!a) return a.error();
    auto c = condition::decode(r.u8());
    if (!c) return c.error();
    return Self{*a, *c};
  }
  friend constexpr bool operator==(const branch&, const branch&) noexcept = default;

 private:
  rom_address target_{};
  condition cond_{};
};
}  // namespace detail

/** JUMP: continue the ROM program at an address. */
struct jump : detail::branch<0x0B> {
  using branch::branch;
  /** Reads JUMP from a checked frame. */
  static constexpr result<jump> parse(std::span<const std::uint8_t> f, const codec_options&) noexcept {
    return parse_as<jump>(f);
  }
};

/** CALL: push the return address and run the ROM program at an address (motion playback, §8.1). */
struct call : detail::branch<0x0C> {
  using branch::branch;
  /** Reads CALL from a checked frame. */
  static constexpr result<call> parse(std::span<const std::uint8_t> f, const codec_options&) noexcept {
    return parse_as<call>(f);
  }
};

/**
 * The target of the CALL frame @p bytes start with (SIZE 7, SUM and COND checked), or nothing:
 * how HTH4's StartupCmd at 0x0444 is told and read (hth4-files.md §3).
 */
constexpr std::optional<std::uint32_t> call_target(std::span<const std::uint8_t> bytes) noexcept {
  if (bytes.size() < 7 || bytes[0] != 7 || bytes[1] != call::command_code || !checksum_ok(bytes.first(7)))
    return std::nullopt;
  const auto c = call::parse(bytes.first(7), codec_options{});
  if (!c) return std::nullopt;
  return c->target().value();
}

/** RETURN: pop the return address; without a pending CALL the board stops the program. */
struct ret {
  static constexpr std::uint8_t command_code = 0x0D;  ///< CMD byte
  /** CMD byte. */
  constexpr std::uint8_t code() const noexcept { return command_code; }
  /** Always 3. */
  constexpr std::size_t wire_size() const noexcept { return 3; }
  /** No body. */
  constexpr void write_body(detail::writer&) const noexcept {}
  /** ACK. */
  constexpr reply_shape expected_reply() const noexcept { return {command_code, false, 0}; }
  /** Reads RETURN from a checked frame. */
  static constexpr result<ret> parse(std::span<const std::uint8_t> f, const codec_options&) noexcept {
    if (f.size() != 3) return errc::bad_frame_size;
    return ret{};
  }
  friend constexpr bool operator==(ret, ret) noexcept = default;
};

}  // namespace rcb4
