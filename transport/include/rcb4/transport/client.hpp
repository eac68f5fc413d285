// rcb4 — a client for any byte stream: async with any completion token, blocking with deadlines.
// SPDX-License-Identifier: BSL-1.0
//
//   rcb4::transport::io_thread io;                        // or run your own io_context
//   auto c = rcb4::transport::make_client(open_serial(io.context(), "/dev/ttyUSB0", 1250000));
//   auto r = c.execute(rcb4::move::read_ram(rcb4::ram::config, 2).value());   // blocking, throws
//   c.async_execute(rcb4::ping{}, [](rcb4::transport::error_code ec, rcb4::transport::response r) { ... });
//   auto r2 = co_await c.async_execute(cmd, boost::asio::use_awaitable);
//
// How it is built (DESIGN.md §8):
// - detail/exchange_machine.hpp holds the whole policy of an exchange and of the line (deadlines,
//   retries, resync, reconnect), sans-I/O;
// - detail/asio_driver.hpp runs it with asynchronous I/O on a strand of the stream's executor
//   (asynchronous requests, and blocking ones that find the line busy);
// - detail/posix_driver.hpp runs it on the calling thread for a blocking call that finds the line
//   idle (streams with a descriptor), with no hand-off to the executor;
// - detail/client_core.hpp: the queue (FIFO from any thread: the bytes of two exchanges never
//   interleave, no caller ever sees "busy"), who owns the line, and shutting down.
#pragma once

#include <rcb4/rcb4.hpp>
#include <rcb4/transport/concepts.hpp>
#include <rcb4/transport/detail/client_core.hpp>
#include <rcb4/transport/error.hpp>
#include <rcb4/transport/io_thread.hpp>
#include <rcb4/transport/options.hpp>
#include <rcb4/transport/response.hpp>

#include <boost/asio/async_result.hpp>

#include <memory>

namespace rcb4::transport {

/**
 * An RCB-4 client over any AsyncByteStream (serial_port, tcp_socket, a posix stream
 * descriptor, a test stream). Movable, not copyable.
 *
 * Errors (see error.hpp): rcb4::errc for replies that are malformed (bad checksum, wrong length,
 * a different command echoed) or refused (nack, from execute), transport_errc for the line
 * (timeout, closed, reconnect_failed, echo ...), and the OS's.
 *
 * Destruction ends everything in every state: queued requests complete with
 * transport_errc::cancelled, the one on the wire is cancelled, the line is closed. When another
 * thread runs the executor, the destructor waits (briefly: the close ends the I/O at once) until
 * the worker has left; when the executor is not running or this is its thread, it returns at once
 * and the rest happens the next time the executor runs, or when its context is destroyed. No
 * blocking call may be running in another thread while the client is destroyed.
 */
template <AsyncByteStream Stream>
class basic_client {
  using core_type = detail::client_core<Stream>;

 public:
  using executor_type = typename Stream::executor_type;  ///< the stream's executor
  /** Completion signature of async_execute and async_exchange. */
  using signature = detail::exchange_signature;

  /** A client that owns @p stream. */
  explicit basic_client(Stream stream, client_options opt = {})
      : core_(core_type::create(std::move(stream), std::move(opt))) {}
  basic_client(basic_client&&) noexcept = default;  ///< moves the line (the old object is then empty)
  basic_client& operator=(basic_client&& other) noexcept {
    if (this != &other) {
      if (core_) core_->shut_down();
      core_ = std::move(other.core_);
    }
    return *this;
  }
  basic_client(const basic_client&) = delete;
  basic_client& operator=(const basic_client&) = delete;
  /** Ends queued and running requests, closes the line (see the class comment). */
  ~basic_client() {
    if (core_) core_->shut_down();
  }

  /**
   * Sends @p c and completes with its reply, with any completion token (a callback, use_future,
   * use_awaitable, deferred). Expecting success: a NACK completes with rcb4::errc::nack (the
   * NACK response alongside). The token's cancellation slot is honoured: a queued request leaves
   * the queue (any cancellation type), the one on the wire is abandoned on terminal
   * cancellation; both complete with boost::asio::error::operation_aborted, and the next
   * exchange resynchronises the line.
   */
  template <class Token = boost::asio::default_completion_token_t<executor_type>>
  auto async_execute(const command& c, Token&& token = {}) {
    return initiate(c, true, std::forward<Token>(token));
  }
  /**
   * Like async_execute, but the board's answer is handed back as it came: ACK, NACK or data,
   * without error. Errors are only the line's and malformed replies. The operations use this.
   */
  template <class Token = boost::asio::default_completion_token_t<executor_type>>
  auto async_exchange(const command& c, Token&& token = {}) {
    return initiate(c, false, std::forward<Token>(token));
  }

  /**
   * Blocking: sends @p c and waits for its reply or its deadline. On an idle line the exchange
   * runs on the calling thread (streams with a descriptor, client_options::direct_io); otherwise
   * it queues behind the others and the executor's thread runs it, which some other thread must
   * run (see io_thread): from the executor's own thread this fails with
   * transport_errc::would_deadlock; when nobody runs it, with executor_not_running after waiting
   * as long as the requests ahead could take. A NACK is rcb4::errc::nack.
   */
  response execute(const command& c, error_code& ec) { return core_->execute(request::of(c), true, ec); }
  /** Blocking; throws system_error on any error (a NACK included). */
  response execute(const command& c) {
    error_code ec;
    auto r = execute(c, ec);
    if (ec) throw system_error(ec, "rcb4");
    return r;
  }
  /** Blocking exchange: the board's answer as it came (a NACK is a reply, not an error). */
  response exchange(const command& c, error_code& ec) { return core_->execute(request::of(c), false, ec); }

  /**
   * Reopens the link after a loss: @p reopen(stream, ec) replaces the stream (e.g. with
   * open_serial on the same path) or sets ec. Call before the first exchange. The exchange that
   * met the loss fails, unless it is a retriable read, which is retried on the new link.
   */
  void set_reconnect(std::function<void(Stream&, error_code&)> reopen, reconnect_policy policy = {}) {
    core_->set_reconnect(std::move(reopen), policy);
  }

  /** The stream (for settings such as the rate; never read or write it). Only while no exchange runs. */
  Stream& stream() { return core_->stream(); }
  /** The options; change them only while no exchange runs. */
  client_options& options() noexcept { return core_->options(); }
  /** What the client has done so far. */
  const client_counters& counters() const noexcept { return core_->counters(); }
  /** The stream's executor (exchanges run on a strand of it). */
  executor_type get_executor() const noexcept { return core_->strand().get_inner_executor(); }

 private:
  template <class Token>
  auto initiate(const command& c, bool nack_is_error, Token&& token) {
    return boost::asio::async_initiate<Token, signature>(
        [core = core_, nack_is_error](auto handler, const request& r) {
          core->enqueue(core->make_pending(r, std::move(handler), nack_is_error));
        },
        token, request::of(c));
  }

  std::shared_ptr<core_type> core_;
};

/** A client for @p stream, deducing the stream type. */
template <AsyncByteStream Stream>
basic_client<Stream> make_client(Stream stream, client_options opt = {}) {
  return basic_client<Stream>(std::move(stream), std::move(opt));
}

}  // namespace rcb4::transport
