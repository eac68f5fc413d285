// rcb4 — commands as the link's requests (frame, reply shape, whether it may be repeated), and an
// operation (rcb4/ops/) run over any link with an exchange(request) -> result<reply>: a
// device_link, or a link of a program's own. A concrete command type becomes a request without the
// command variant; the variant's overloads are here for operations, whose next() gives one.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/command.hpp>
#include <rcb4/link/types.hpp>
#include <rcb4/ops/operation.hpp>

#include <concepts>
#include <type_traits>
#include <variant>

namespace rcb4::link {

/** True when @p c can be repeated without changing the board: ping, VERSION, MOV → COM. */
template <Command C>
constexpr bool is_idempotent(const C& c) noexcept {
  if constexpr (std::is_same_v<C, ping> || std::is_same_v<C, version>)
    return true;
  else if constexpr (std::is_same_v<C, rcb4::move>)
    return c.dst().kind() == dst_kind::com;
  else
    return false;
}
/** The same for a command held in the variant. */
constexpr bool is_idempotent(const command& c) noexcept {
  return std::visit([](const auto& x) { return is_idempotent(x); }, c);
}

/** The request for @p c, a concrete command (no variant). */
template <Command C>
constexpr request request_of(const C& c) noexcept {
  return request{encode(c), c.expected_reply(), is_idempotent(c)};
}
/** The request for @p c, a command held in the variant. */
constexpr request request_of(const command& c) noexcept { return request{encode(c), expected_reply(c), is_idempotent(c)}; }

/**
 * Runs @p op to its end over @p link: each command exchanged, each reply handed to the operation.
 * Returns errc{} when it succeeded, the link's error when an exchange failed (the operation keeps
 * what it did so far), or the operation's own (errc::nack when the board refused).
 */
template <class Link, ops::Operation Op>
errc run(Link& link, Op& op) {
  while (auto c = op.next()) {
    const auto r = link.exchange(request_of(*c));
    if (!r) return r.error();
    op.on_reply(*r);
  }
  return op.error();
}

}  // namespace rcb4::link
