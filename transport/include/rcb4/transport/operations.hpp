// rcb4 — running sans-I/O operations (rcb4/ops.hpp) on a client, blocking or asynchronously.
// SPDX-License-Identifier: BSL-1.0
//
//   auto states = rcb4::transport::run(client, rcb4::ops::read_servo_states{});       // throws
//   auto s = co_await rcb4::transport::async_run(client, rcb4::ops::read_analog{});   // coroutine
#pragma once

#include <rcb4/ops.hpp>
#include <rcb4/transport/client.hpp>
#include <rcb4/transport/serial.hpp>

#include <boost/asio/awaitable.hpp>
#include <boost/asio/co_spawn.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/use_future.hpp>

#include <unistd.h>

#include <functional>

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

namespace detail {
/** Runs @p op to the end in a coroutine; the error of the line or of the operation, if any. */
template <AsyncByteStream Stream, ops::Operation Op>
boost::asio::awaitable<std::error_code> async_run_ec(basic_client<Stream>& c, Op& op) {
  while (auto cmd = op.next()) {
    auto [ec, r] = co_await c.async_execute(*cmd, boost::asio::as_tuple(boost::asio::use_awaitable));
    if (ec && std::error_code(ec) != rcb4::errc::nack) co_return std::error_code(ec);  // the line failed
    op.on_reply(r.view());  // a NACK is the operation's to judge
  }
  co_return op.error() != rcb4::errc{} ? std::error_code(op.error()) : std::error_code{};
}
}  // namespace detail

/** Coroutine form: co_await async_run(client, op) → the operation's value; throws on failure. */
template <AsyncByteStream Stream, ops::Operation Op>
boost::asio::awaitable<std::decay_t<decltype(std::declval<Op&>().value())>> async_run(basic_client<Stream>& c, Op op) {
  if (const auto ec = co_await detail::async_run_ec(c, op)) throw std::system_error(ec, "rcb4 operation");
  co_return op.value();
}

/**
 * Switches the board's COM rate to @p bps and follows it on the host: the board acknowledges at
 * the old rate (protocol.md §9), then a serial port (any stream whose descriptor is a tty) is set
 * to the new rate (termios2, read back),
 * the client's deadlines are recomputed, and a ping confirms the board answers. Other streams
 * (TCP to ser2net) only get the deadlines: switch the bridge's rate yourself. Call it while no
 * other thread uses the client. The change is RAM-only: a power cycle restores the ROM rate.
 */
template <AsyncByteStream Stream>
void switch_baud(basic_client<Stream>& c, std::uint32_t bps, std::error_code& ec) {
  auto op = ops::switch_baud(bps);
  run(c, op, ec);
  if (ec) return;
  if constexpr (requires { c.stream().native_handle(); }) {
    const int fd = c.stream().native_handle();
    if (::isatty(fd)) {  // a serial port (also when wrapped as a plain descriptor); not a socket
      const auto got = detail::set_custom_baud(fd, bps);
      if (!got || (*got > bps ? *got - bps : bps - *got) > bps / 50) {
        ec = errc::unsupported_baud;  // the board moved but this port cannot follow
        return;
      }
    }
  }
  c.options().baud = bps;
  c.execute(ping{}, ec);
}

/** switch_baud that throws std::system_error. */
template <AsyncByteStream Stream>
void switch_baud(basic_client<Stream>& c, std::uint32_t bps) {
  std::error_code ec;
  switch_baud(c, bps, ec);
  if (ec) throw std::system_error(ec, "rcb4 switch baud");
}

/** Called with each motion state wait_motion reads (for a progress display). */
using motion_progress = std::function<void(const ops::motion_state&)>;

/** How often wait_motion reads the state: the board refreshes it every 50 ms (protocol.md §8.2). */
inline constexpr std::chrono::milliseconds motion_poll{50};

namespace detail {
template <AsyncByteStream Stream>
boost::asio::awaitable<std::pair<std::error_code, ops::motion_state>> wait_motion(
    basic_client<Stream>& c, std::chrono::steady_clock::duration timeout, motion_progress progress, rom_layout layout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  boost::asio::steady_timer timer(co_await boost::asio::this_coro::executor);
  for (;;) {
    ops::read_motion_state op(layout);
    if (const auto ec = co_await async_run_ec(c, op)) co_return std::pair{ec, op.value()};
    if (progress) progress(op.value());
    if (!op.value().running) co_return std::pair{std::error_code{}, op.value()};
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline) co_return std::pair{std::error_code(errc::timeout), op.value()};
    timer.expires_at(std::min(deadline, now + motion_poll));
    co_await timer.async_wait(boost::asio::as_tuple(boost::asio::use_awaitable));
  }
}
}  // namespace detail

/**
 * Coroutine: reads the motion state every 50 ms until no motion runs, and returns the last state.
 * Throws std::system_error with errc::timeout when a motion still runs after @p timeout.
 */
template <AsyncByteStream Stream>
boost::asio::awaitable<ops::motion_state> async_wait_motion(basic_client<Stream>& c,
                                                            std::chrono::steady_clock::duration timeout,
                                                            motion_progress progress = {},
                                                            const rom_layout& layout = hth4_2_2) {
  auto [ec, st] = co_await detail::wait_motion(c, timeout, std::move(progress), layout);
  if (ec) throw std::system_error(ec, "rcb4 wait for motion");
  co_return st;
}

/**
 * Blocking: waits until no motion runs or @p timeout passes (then @p ec is errc::timeout and the
 * state still says running). The client's executor must run on another thread (io_thread).
 */
template <AsyncByteStream Stream>
ops::motion_state wait_motion(basic_client<Stream>& c, std::chrono::steady_clock::duration timeout, std::error_code& ec,
                              motion_progress progress = {}, const rom_layout& layout = hth4_2_2) {
  auto f = boost::asio::co_spawn(c.get_executor(), detail::wait_motion(c, timeout, std::move(progress), layout),
                                 boost::asio::use_future);
  auto [e, st] = f.get();
  ec = e;
  return st;
}

}  // namespace rcb4::transport
