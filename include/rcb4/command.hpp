// rcb4 — every RCB-4 command as one std::variant, host-side serialize and board-side parse.
// SPDX-License-Identifier: BSL-1.0
//
// Request frame (protocol.md §2.1): [SIZE][CMD][payload ...][SUM], 3 ≤ SIZE ≤ 128,
// SUM = low byte of the sum of all preceding bytes. Each command's own header shows its layout.
#pragma once

#include <rcb4/commands/alu.hpp>
#include <rcb4/commands/flow.hpp>
#include <rcb4/commands/move.hpp>
#include <rcb4/commands/servo.hpp>
#include <rcb4/commands/system.hpp>
#include <rcb4/parse_result.hpp>

#include <array>
#include <variant>

namespace rcb4 {

/** Any RCB-4 command. Every alternative satisfies rcb4::Command. */
using command = std::variant<ping, version, move, logic, bit_not, shift, arith, jump, call, ret, ics_exchange,
                             single_servo, const_servo, series_servo, servo_params>;

/** The frame length of @p c. */
template <Command C>
constexpr std::size_t wire_size(const C& c) noexcept {
  return c.wire_size();
}
/** The frame length of @p c. */
constexpr std::size_t wire_size(const command& c) noexcept {
  return std::visit([](const auto& x) { return x.wire_size(); }, c);
}

/** What the board answers to @p c when it succeeds (failures are a 4-byte NACK). */
template <Command C>
constexpr reply_shape expected_reply(const C& c) noexcept {
  return c.expected_reply();
}
/** What the board answers to @p c when it succeeds (failures are a 4-byte NACK). */
constexpr reply_shape expected_reply(const command& c) noexcept {
  return std::visit([](const auto& x) { return x.expected_reply(); }, c);
}

/** Writes the frame of @p c into @p out; returns its length or errc::buffer_too_small. */
template <Command C>
constexpr result<std::size_t> serialize(const C& c, std::span<std::uint8_t> out) noexcept {
  const std::size_t n = c.wire_size();
  if (out.size() < n) return errc::buffer_too_small;
  detail::writer w(out);
  w.u8(static_cast<std::uint8_t>(n));
  w.u8(c.code());
  c.write_body(w);
  out[n - 1] = checksum(out.first(n - 1));
  return n;
}
/** Writes the frame of @p c into @p out; returns its length or errc::buffer_too_small. */
constexpr result<std::size_t> serialize(const command& c, std::span<std::uint8_t> out) noexcept {
  return std::visit([out](const auto& x) { return serialize(x, out); }, c);
}

/** The frame of @p c in a 128-byte inline buffer (every command fits). */
template <class C>
requires Command<C> || std::same_as<C, command>
constexpr request_frame encode(const C& c) noexcept {
  request_frame f;
  const auto n = serialize(c, f.storage());
  f.commit(n.value());  // cannot fail: every command is at most 128 bytes
  return f;
}

/**
 * A result of make() is no command: encode(C::make(...)) does not compile, and says why (check
 * the result, then take .value(); or give the command's values as constants).
 */
template <class C>
constexpr request_frame encode(const result<C>&) noexcept {
  static_assert(detail::always_false<C>,
                "rcb4: encode() takes a command, not the result of make(): check it (has_value()), then .value()");
  return {};
}

/** Frame length of commands whose length never varies; 0 for the others. */
template <class C>
inline constexpr std::size_t fixed_wire_size = 0;
template <>
inline constexpr std::size_t fixed_wire_size<version> = 3;
template <>
inline constexpr std::size_t fixed_wire_size<ret> = 3;
template <>
inline constexpr std::size_t fixed_wire_size<jump> = 7;
template <>
inline constexpr std::size_t fixed_wire_size<call> = 7;
template <>
inline constexpr std::size_t fixed_wire_size<single_servo> = 7;
template <>
inline constexpr std::size_t fixed_wire_size<ics_exchange> = 9;
template <>
inline constexpr std::size_t fixed_wire_size<bit_not> = 10;
template <>
inline constexpr std::size_t fixed_wire_size<shift> = 10;

/** The frame of a fixed-length command as a std::array of exactly its length. */
template <Command C>
requires(fixed_wire_size<C> != 0) constexpr std::array<std::uint8_t, fixed_wire_size<C>> to_array(const C& c) noexcept {
  std::array<std::uint8_t, fixed_wire_size<C>> out{};
  (void)serialize(c, out);  // the size is exact by construction
  return out;
}

namespace detail {
template <class T>
constexpr bool accepts_code(std::uint8_t code) noexcept {
  if constexpr (std::same_as<T, logic>)
    return code >= 0x01 && code <= 0x03;
  else if constexpr (std::same_as<T, arith>)
    return code >= 0x06 && code <= 0x0A;
  else
    return code == T::command_code;
}

template <std::size_t I = 0>
constexpr result<command> parse_alternative(std::span<const std::uint8_t> frame, const codec_options& opt) noexcept {
  if constexpr (I == std::variant_size_v<command>) {
    return errc::unknown_command;
  } else {
    using T = std::variant_alternative_t<I, command>;
    if (!accepts_code<T>(frame[1])) return parse_alternative<I + 1>(frame, opt);
    auto r = T::parse(frame, opt);
    if (!r) return r.error();
    return command{std::in_place_index<I>, *r};
  }
}
}  // namespace detail

/**
 * Board side: parses one request frame from the start of @p in.
 * need_more when the frame is incomplete; on error, `consumed` is the length of the bad frame
 * when its SIZE byte was plausible (so a board can NACK it and go on), else 1.
 */
constexpr parse_result<command> parse_command(std::span<const std::uint8_t> in,
                                              const codec_options& opt = {}) noexcept {
  parse_result<command> r;
  if (in.empty()) {
    r.needed = min_frame_size;
    return r;
  }
  const std::size_t size = in[0];
  auto fail = [&r](errc e, std::size_t consumed) {
    r.status = parse_status::error;
    r.error = e;
    r.consumed = consumed;
    return r;
  };
  if (size < min_frame_size) return fail(errc::frame_too_short, 1);
  if (size > max_request_size) return fail(errc::frame_too_long, 1);
  if (in.size() < size) {
    r.needed = size - in.size();
    if (in.size() >= 2) r.command = in[1];
    return r;
  }
  const auto frame = in.first(size);
  r.command = frame[1];
  if (!checksum_ok(frame)) return fail(errc::bad_checksum, size);
  auto c = detail::parse_alternative(frame, opt);
  if (!c) return fail(c.error(), size);
  r.consumed = size;
  r.complete(*c);
  return r;
}

}  // namespace rcb4
