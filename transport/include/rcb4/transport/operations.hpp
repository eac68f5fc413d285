// rcb4 — running sans-I/O operations (rcb4/ops.hpp) on a client, blocking or asynchronously.
// SPDX-License-Identifier: BSL-1.0
//
//   auto states = rcb4::transport::run(client, rcb4::ops::read_servo_states{});       // throws
//   auto s = co_await rcb4::transport::async_run(client, rcb4::ops::read_analog{});   // coroutine
//   rcb4::transport::async_run(client, rcb4::ops::read_analog{},                      // any token:
//       [](rcb4::transport::error_code ec, auto values) { ... });                     // a callback,
//   auto f = rcb4::transport::async_run(client, op, boost::asio::use_future);        // a future, ...
#pragma once

#include <rcb4/ops.hpp>
#include <rcb4/transport/client.hpp>
#include <rcb4/transport/serial.hpp>

#include <boost/asio/awaitable.hpp>
#include <boost/asio/co_spawn.hpp>
#include <boost/asio/compose.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/use_future.hpp>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <thread>
#include <vector>

namespace rcb4::transport {

/**
 * Runs @p op to the end on @p c; a failed exchange or a refused step sets @p ec. Replies reach
 * the operation as the board sent them (basic_client::exchange): a NACK is the operation's to
 * judge, never an error first.
 */
template <AsyncByteStream Stream, ops::Operation Op>
Op& run(basic_client<Stream>& c, Op& op, error_code& ec) {
  ec.clear();
  while (auto cmd = op.next()) {
    const response r = c.exchange(*cmd, ec);
    if (ec) return op;  // the line failed, or the reply was malformed
    op.on_reply(r.view());
  }
  if (op.error() != rcb4::errc{}) ec = op.error();
  return op;
}

/** Runs @p op (taken by value) and returns its value; throws system_error on failure. */
template <AsyncByteStream Stream, ops::Operation Op>
auto run(basic_client<Stream>& c, Op op) {
  error_code ec;
  run(c, op, ec);
  if (ec) throw system_error(ec, "rcb4 operation");
  return op.value();
}

namespace detail {
/** Runs @p op to the end in a coroutine; the error of the line or of the operation, if any. */
template <AsyncByteStream Stream, ops::Operation Op>
boost::asio::awaitable<error_code> async_run_ec(basic_client<Stream>& c, Op& op) {
  while (auto cmd = op.next()) {
    auto [ec, r] = co_await c.async_exchange(*cmd, boost::asio::as_tuple(boost::asio::use_awaitable));
    if (ec) co_return ec;   // the line failed, or the reply was malformed
    op.on_reply(r.view());  // a NACK is the operation's to judge
  }
  co_return op.error() != rcb4::errc{} ? error_code(op.error()) : error_code{};
}
}  // namespace detail

/** Coroutine form: co_await async_run(client, op) → the operation's value; throws on failure. */
template <AsyncByteStream Stream, ops::Operation Op>
boost::asio::awaitable<std::decay_t<decltype(std::declval<Op&>().value())>> async_run(basic_client<Stream>& c, Op op) {
  if (const auto ec = co_await detail::async_run_ec(c, op)) throw system_error(ec, "rcb4 operation");
  co_return op.value();
}

namespace detail {
/** async_run's composed operation: each step's exchange, then the next, on the client's executor. */
template <class Stream, class Op>
struct run_composed {
  using value_type = std::decay_t<decltype(std::declval<Op&>().value())>;
  basic_client<Stream>* client;
  Op op;
  bool waiting = false;  // an exchange of op's is under way: the call is its completion

  template <class Self>
  void operator()(Self& self, error_code ec = {}, response r = {}) {
    if (waiting) {
      waiting = false;
      if (ec) return self.complete(ec, value_type{});  // the line failed, or the reply was malformed
      op.on_reply(r.view());                           // a NACK is the operation's to judge
    }
    if (auto cmd = op.next()) {
      waiting = true;
      client->async_exchange(*cmd, std::move(self));
      return;
    }
    if (op.error() != rcb4::errc{}) return self.complete(error_code(op.error()), value_type{});
    self.complete(error_code{}, value_type(op.value()));
  }
};
}  // namespace detail

/**
 * Runs @p op on @p c and completes with (error_code, the operation's value) through any
 * completion token: a callback, use_future, deferred, use_awaitable (as_tuple to get the code
 * without an exception). On an error the value is value-initialised, never a partial result.
 * The token's cancellation slot reaches the exchange under way (basic_client::async_execute).
 */
template <AsyncByteStream Stream, ops::Operation Op, class Token>
auto async_run(basic_client<Stream>& c, Op op, Token&& token) {
  using value_type = typename detail::run_composed<Stream, Op>::value_type;
  return boost::asio::async_compose<Token, void(error_code, value_type)>(
      detail::run_composed<Stream, Op>{&c, std::move(op)}, token, c.get_executor());
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
void switch_baud(basic_client<Stream>& c, std::uint32_t bps, error_code& ec) {
  auto op = ops::switch_baud(bps);
  run(c, op, ec);
  if (ec) return;
  if constexpr (requires { c.stream().native_handle(); }) {
    const int fd = c.stream().native_handle();
    if (::isatty(fd)) {  // a serial port (also when wrapped as a plain descriptor); not a socket
      const auto got = detail::set_custom_baud(fd, bps);
      if (!got || !detail::rate_close(*got, bps)) {
        ec = transport_errc::rate_not_set;  // the board moved but this port cannot follow
        return;
      }
    }
  }
  c.options().baud = bps;
  c.execute(ping{}, ec);
}

/** switch_baud that throws system_error. */
template <AsyncByteStream Stream>
void switch_baud(basic_client<Stream>& c, std::uint32_t bps) {
  error_code ec;
  switch_baud(c, bps, ec);
  if (ec) throw system_error(ec, "rcb4 switch baud");
}

/**
 * Measures what a read costs on @p c: the planner's link_cost (ops::plan_reads, protocol.md §4).
 * Times @p samples pairs of a 2-byte and a 128-byte read of RAM: the exchange from the short
 * reads' median, the bytes from the median of the pairs' differences. The
 * exchange cost is what a read takes beyond its bytes' time on the wire (adapter latency, the
 * board's turnaround, the operating system): on a fast link the planner then reads joints one by
 * one, behind a millisecond of USB latency it merges them into long reads.
 * The bytes cost the client's rate (options().baud, 11 bits a byte) as long as the 126 extra bytes
 * of the long read take at least half their wire time. When they take less, the line is not paced
 * at that rate (a pty, a board in process, a bridge that buffers): the cost is then the measured
 * time per byte and the rest of the short read, so plans fit the link as it is instead of a rate
 * it does not have. Sets @p ec if an exchange fails.
 */
template <AsyncByteStream Stream>
ops::link_cost measure_link(basic_client<Stream>& c, error_code& ec, int samples = 9) {
  const command short_read = move::read_ram(ram::config, 2).value();
  const command long_read = move::read_ram(ram::user_area, 128).value();
  // Short and long reads alternate, and the long read's extra time is the median of each pair's
  // difference: load that comes and goes (another program, a sanitizer's work) then falls on both
  // reads of a pair alike, where timing all short reads and then all long ones let a busy spell in
  // one phase look like a faster or slower line.
  const auto median = [](std::vector<std::chrono::nanoseconds>& v) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  const auto timed = [&](const command& read) {
    const auto t0 = std::chrono::steady_clock::now();
    c.execute(read, ec);
    return std::chrono::nanoseconds(std::chrono::steady_clock::now() - t0);
  };
  c.execute(short_read, ec);  // the first exchange may pay for a cold path; it is not counted
  if (ec) return {};
  std::vector<std::chrono::nanoseconds> shorts, extra;
  for (int i = 0; i < samples && !ec; ++i) {
    const auto t_short = timed(short_read);
    if (ec) break;
    const auto t_long = timed(long_read);
    shorts.push_back(t_short);
    extra.push_back(t_long - t_short);
  }
  if (ec || shorts.empty()) return {};
  const auto t_short = median(shorts);
  const auto baud = c.options().baud > 0 ? c.options().baud : 115200u;
  auto cost = ops::link_cost::at(baud, {});
  const auto per_byte = std::max(median(extra), std::chrono::nanoseconds(0)) / 126;
  if (per_byte * 2 < cost.byte_time) cost.byte_time = per_byte;  // not paced at its rate
  cost.exchange = std::max(t_short - cost.byte_time * 15, std::chrono::nanoseconds(0));
  return cost;
}

/** measure_link that throws system_error. */
template <AsyncByteStream Stream>
ops::link_cost measure_link(basic_client<Stream>& c, int samples = 9) {
  error_code ec;
  const auto cost = measure_link(c, ec, samples);
  if (ec) throw system_error(ec, "rcb4 measure link");
  return cost;
}

/** Called with each motion state wait_motion reads (for a progress display). */
using motion_progress = std::function<void(const ops::motion_state&)>;

/** How often wait_motion reads the state: the board refreshes it every 50 ms (protocol.md §8.2). */
inline constexpr std::chrono::milliseconds motion_poll{50};

namespace detail {
template <AsyncByteStream Stream>
boost::asio::awaitable<std::pair<error_code, ops::motion_state>> wait_motion(
    basic_client<Stream>& c, std::chrono::steady_clock::duration timeout, motion_progress progress, rom_layout layout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  boost::asio::steady_timer timer(co_await boost::asio::this_coro::executor);
  for (;;) {
    ops::read_motion_state op(layout);
    if (const auto ec = co_await async_run_ec(c, op)) co_return std::pair{ec, op.value()};
    if (progress) progress(op.value());
    if (!op.value().running) co_return std::pair{error_code{}, op.value()};
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline) co_return std::pair{error_code(transport_errc::timeout), op.value()};
    timer.expires_at(std::min(deadline, now + motion_poll));
    co_await timer.async_wait(boost::asio::as_tuple(boost::asio::use_awaitable));
  }
}
}  // namespace detail

/**
 * Coroutine: reads the motion state every 50 ms until no motion runs, and returns the last state.
 * Throws system_error with transport_errc::timeout when a motion still runs after @p timeout.
 */
template <AsyncByteStream Stream>
boost::asio::awaitable<ops::motion_state> async_wait_motion(basic_client<Stream>& c,
                                                            std::chrono::steady_clock::duration timeout,
                                                            motion_progress progress = {},
                                                            const rom_layout& layout = hth4_2_2) {
  auto [ec, st] = co_await detail::wait_motion(c, timeout, std::move(progress), layout);
  if (ec) throw system_error(ec, "rcb4 wait for motion");
  co_return st;
}

/**
 * Blocking: reads the motion state every 50 ms on this thread until no motion runs, or
 * @p timeout passes (then @p ec is transport_errc::timeout and the state still says running).
 */
template <AsyncByteStream Stream>
ops::motion_state wait_motion(basic_client<Stream>& c, std::chrono::steady_clock::duration timeout, error_code& ec,
                              motion_progress progress = {}, const rom_layout& layout = hth4_2_2) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    ops::read_motion_state op(layout);
    run(c, op, ec);
    if (ec) return op.value();
    if (progress) progress(op.value());
    if (!op.value().running) return op.value();
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline) {
      ec = transport_errc::timeout;
      return op.value();
    }
    std::this_thread::sleep_until(std::min(deadline, now + motion_poll));  // the board's own refresh period
  }
}

}  // namespace rcb4::transport
