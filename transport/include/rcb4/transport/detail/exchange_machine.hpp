// rcb4 — the link's exchange machine (rcb4/link/exchange_machine.hpp, std only) as the Asio and
// caller-thread drivers speak to it: Boost.System error codes in and out, the client's counters
// and trace as its observer, std::chrono::steady_clock as its clock. The policy is all in the
// link machine; this file only translates.
//
//   auto a = m.start(req, now, stray_bytes);
//   while (a.what != action::kind::done) {
//     io_result r = perform(a);           // write a.out / read into a.in before a.deadline /
//     a = m.resume(r, now());             // reopen the link, not before a.deadline
//   }
//   complete(a.ec, m.reply());
//
// Errors out: the link's codes as transport_errc (timeout, truncated, echo, line_error, closed,
// reconnect_failed, cancelled), a lost or failed stream as the stream's own error code, a
// malformed or refused reply as rcb4::errc.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/link/exchange_machine.hpp>
#include <rcb4/transport/error.hpp>
#include <rcb4/transport/options.hpp>
#include <rcb4/transport/response.hpp>

#include <chrono>
#include <cstdint>
#include <span>

namespace rcb4::transport::detail {

using clock = std::chrono::steady_clock;

/** What a driver must do next (the link's action, with an error code). */
struct action {
  using kind = link::basic_action<clock::time_point>::kind;  ///< write, read, reopen, done
  kind what = kind::done;                                    ///< what to do
  std::span<const std::uint8_t> out{};                       ///< write: the bytes still to write
  std::span<std::uint8_t> in{};                              ///< read: where the bytes go
  clock::time_point deadline{};                              ///< write/read: give up then; reopen: not before
  clock::time_point expected{};                              ///< read: when the reply is due on the wire
  error_code ec{};                                           ///< done: the outcome
};

/** How the last action ended, as a stream says it. */
struct io_result {
  std::size_t n = 0;       ///< bytes written or read (also with an error or a timeout)
  error_code ec{};         ///< the stream's error (end of file included), or the reopen's
  bool timed_out = false;  ///< the deadline passed first
};

/** The link machine's observer for a client: its counters, and its options' trace function. */
struct client_observer {
  client_counters* n = nullptr;        ///< where counts go
  const client_options* opt = nullptr;  ///< whose trace is called
  /** Calls the trace function, when one is set. */
  void trace(link::direction d, clock::time_point t, std::span<const std::uint8_t> b) const {
    if (opt->trace) opt->trace(d, t, b);
  }
  /** Adds @p k to counter @p c. */
  void count(link::counter c, std::size_t k = 1) const noexcept {
    switch (c) {
      case link::counter::exchanges: n->exchanges += k; break;
      case link::counter::errors: n->errors += k; break;
      case link::counter::retries: n->retries += k; break;
      case link::counter::timeouts: n->timeouts += k; break;
      case link::counter::nacks: n->nacks += k; break;
      case link::counter::resyncs: n->resyncs += k; break;
      case link::counter::reconnects: n->reconnects += k; break;
      case link::counter::bytes_out: n->bytes_out += k; break;
      case link::counter::bytes_in: n->bytes_in += k; break;
      case link::counter::line_errors: n->line_errors += k; break;
    }
  }
  /** (The client reports the exchange's outcome, not each attempt's.) */
  void attempt_failed(errc) const noexcept {}
};

/** The policy of one exchange at a time and the state of the line (link::exchange_machine). */
class exchange_machine {
 public:
  /** A machine using @p opt (read as it goes) and counting into @p counters. */
  exchange_machine(const client_options& opt, client_counters& counters) noexcept
      : m_(opt, client_observer{&counters, &opt}) {}

  /** Whether the line's reads are marked (PARMRK) and must be decoded. */
  void set_marked(bool marked) noexcept { m_.set_marked(marked); }
  /** True while the line's reads are decoded as marked. */
  bool marked() const noexcept { return m_.marked(); }
  /** Whether a lost link can be reopened (a reopen function is set), and with which policy. */
  void set_reopen(bool can, reconnect_policy policy = {}) noexcept { m_.set_reopen(can, policy); }

  /** Begins @p r at @p now; @p stray: bytes found waiting on the line (a resync comes first). */
  action start(const request& r, clock::time_point now, std::size_t stray = 0) {
    stream_error_ = {};
    reply_ = response{};
    return from(m_.start(link::request{r.frame, r.shape, r.idempotent}, now, stray));
  }
  /** The last action ended with @p r at @p now: what next. */
  action resume(const io_result& r, clock::time_point now) {
    const auto s = status_of(r);
    // The error the exchange reports for a lost or failed stream: the first one of its attempts
    // (the machine keeps the most telling failure so), or the one that ends it at once (a failure
    // that is no loss); a failed reopen is not the stream's (it ends in reconnect_failed, or is
    // tried again).
    if (last_ != action::kind::reopen) {
      if (s == link::io_status::failed) stream_error_ = r.ec;
      else if ((s == link::io_status::closed || s == link::io_status::lost) && !stream_error_) stream_error_ = r.ec;
    }
    return from(m_.resume(link::io_result{r.n, s}, now));
  }
  /** The running exchange is abandoned: it ends with @p ec; the next one resynchronises first. */
  action cancel(error_code ec = boost::asio::error::operation_aborted) {
    auto a = from(m_.cancel());
    a.ec = ec;
    return a;
  }

  /** The reply of an exchange that ended without error (ACK, NACK or data). */
  const response& reply() const noexcept { return reply_; }
  /** True while no exchange runs. */
  bool idle() const noexcept { return m_.idle(); }
  /** True when the next exchange will resynchronise first. */
  bool dirty() const noexcept { return m_.dirty(); }
  /** True when the link was lost (the next exchange reopens it first, when it can). */
  bool lost() const noexcept { return m_.lost(); }
  /** The link was replaced from outside (a new stream): it starts clean. */
  void replaced() noexcept { m_.replaced(); }
  /** The running attempt's deadline (while an exchange runs). */
  clock::time_point deadline() const noexcept { return m_.deadline(); }

 private:
  using machine = link::exchange_machine<clock, client_options, client_observer>;

  /** What the stream's result is to the link: end of file and a lost link told apart from other failures. */
  static link::io_status status_of(const io_result& r) noexcept {
    if (r.timed_out) return link::io_status::timed_out;
    if (!r.ec) return link::io_status::ok;
    if (r.ec == boost::asio::error::eof || r.ec == transport_errc::closed) return link::io_status::closed;
    return is_link_lost(r.ec) ? link::io_status::lost : link::io_status::failed;
  }

  action from(const machine::action& a) {
    last_ = a.what;
    action out;
    out.what = a.what;
    out.out = a.out;
    out.in = a.in;
    out.deadline = a.deadline;
    out.expected = a.expected;
    if (a.what == action::kind::done) {
      out.ec = error_of(a.error);
      if (const auto r = m_.last_reply(); a.error == errc{} && r) reply_ = response::from(*r);
    }
    return out;
  }

  error_code error_of(errc e) const {
    if (e == errc{}) return {};
    switch (e) {
      case errc::link_timeout: return transport_errc::timeout;
      case errc::link_truncated: return transport_errc::truncated;
      case errc::link_echo: return transport_errc::echo;
      case errc::link_line_error: return transport_errc::line_error;
      case errc::link_closed: return transport_errc::closed;
      case errc::link_reconnect_failed: return transport_errc::reconnect_failed;
      case errc::link_cancelled: return transport_errc::cancelled;
      case errc::link_lost:
      case errc::link_io_error: return stream_error_ ? stream_error_ : error_code(make_error_code(e));
      default: return make_error_code(e);  // the reply's own: malformed, refused
    }
  }

  machine m_;
  error_code stream_error_{};  // the stream's failure this exchange reports (see resume)
  action::kind last_ = action::kind::done;  // what the machine last asked for
  response reply_{};
};

}  // namespace rcb4::transport::detail
