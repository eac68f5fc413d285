// rcb4 — operations: what a robot program does, as sans-I/O scripts of commands plus a decoder.
// SPDX-License-Identifier: BSL-1.0
//
// An operation hands out one command at a time and digests each reply; it never touches I/O,
// so the same code runs on rcb4::transport's client, on the virtual board, or in a user's own
// UART loop on a microcontroller:
//
//   ops::read_memory op(ops::memory::ram, 0x0090, 720);
//   while (auto c = op.next()) op.on_reply(exchange(*c));   // your I/O here
//   if (op.error() == errc{}) use(op.value());
#pragma once

#include <rcb4/rcb4.hpp>

#include <concepts>
#include <optional>

namespace rcb4::ops {

/**
 * An operation: next() gives the command to send (nothing when finished), on_reply() takes its
 * reply, error() says whether it failed (errc{} if not) and value() is the result.
 */
template <class Op>
concept Operation = requires(Op op, const reply& r) {
  { op.next() } -> std::same_as<std::optional<command>>;
  {op.on_reply(r)};
  { op.error() } -> std::same_as<errc>;
  op.value();
};

namespace detail {
/** Checks a reply for the common failures: NACK, or an unexpected kind. */
constexpr errc check_reply(const reply& r, bool want_data, std::size_t size = 0) noexcept {
  if (r.is_nack()) return errc::nack;
  if (want_data && (r.kind() != reply_kind::data || r.bytes().size() != size)) return errc::bad_reply_length;
  if (!want_data && !r.is_ack()) return errc::unexpected_ack;
  return errc{};
}
}  // namespace detail

}  // namespace rcb4::ops
