// rcb4 — running sans-I/O operations (rcb4/ops.hpp) on a client, blocking or asynchronously.
// SPDX-License-Identifier: BSL-1.0
//
//   auto states = rcb4::transport::run(client, rcb4::ops::read_servo_states{});       // throws
//   auto s = co_await rcb4::transport::async_run(client, rcb4::ops::read_analog{});   // coroutine
#pragma once

#include <rcb4/ops.hpp>
#include <rcb4/transport/client.hpp>

#include <boost/asio/awaitable.hpp>

namespace rcb4::transport {

/** Runs @p op to the end on @p c; a failed exchange or a refused step sets @p ec. */
template <AsyncByteStream Stream, ops::Operation Op>
Op& run(basic_client<Stream>& c, Op& op, std::error_code& ec) {
  ec.clear();
  while (auto cmd = op.next()) {
    const response r = c.execute(*cmd, ec);
    if (ec && std::error_code(ec) != rcb4::errc::nack) return op;  // the line failed
    ec.clear();
    op.on_reply(r.view());  // a NACK is the operation's to judge
  }
  if (op.error() != rcb4::errc{}) ec = op.error();
  return op;
}

/** Runs @p op (taken by value) and returns its value; throws std::system_error on failure. */
template <AsyncByteStream Stream, ops::Operation Op>
auto run(basic_client<Stream>& c, Op op) {
  std::error_code ec;
  run(c, op, ec);
  if (ec) throw std::system_error(ec, "rcb4 operation");
  return op.value();
}

/** Coroutine form: co_await async_run(client, op) → the operation's value; throws on failure. */
template <AsyncByteStream Stream, ops::Operation Op>
boost::asio::awaitable<std::decay_t<decltype(std::declval<Op&>().value())>> async_run(basic_client<Stream>& c, Op op) {
  while (auto cmd = op.next()) {
    auto [ec, r] = co_await c.async_execute(*cmd, boost::asio::as_tuple(boost::asio::use_awaitable));
    if (ec && std::error_code(ec) != rcb4::errc::nack) throw boost::system::system_error(ec, "rcb4 operation");
    op.on_reply(r.view());
  }
  if (op.error() != rcb4::errc{}) throw std::system_error(op.error(), "rcb4 operation");
  co_return op.value();
}

}  // namespace rcb4::transport
