// rcb4 — the link's whole policy for one exchange and for the line, as a sans-I/O state machine
// for any transport: std only, no heap, no exceptions, no clock read, no Boost. A driver (the
// Boost.Asio client, a polled UART on a microcontroller, libftdi, a test) asks it what to do and
// tells it how that went, with the time from a clock it chooses:
//
//   rcb4::link::exchange_machine<my_clock> m(opts);
//   auto a = m.start(rcb4::link::request_of(rcb4::ping{}), now());   // requests.hpp
//   while (a.what != action::kind::done) {
//     io_result r = perform(a);           // write a.out / read into a.in before a.deadline /
//     a = m.resume(r, now());             // reopen the link, not before a.deadline
//   }
//   if (a.error == rcb4::errc{}) use(*m.last_reply());   // ACK, NACK or data
//
// What it decides (DESIGN.md §4, §8):
// - one attempt = write the frame, then read exactly what the reply can still hold (the first
//   byte is its length, so the next reply is never eaten), all before the attempt's deadline:
//   the wire time of request and reply (11 bits a byte at 8E1, protocol.md §1) plus the
//   turnaround allowance;
// - after any error (timeout, a malformed reply, stray bytes, a cancelled exchange) the line is
//   dirty, and the next attempt first resynchronises: it sends a ping (03 FE 01) and discards
//   everything up to its ACK (the board answers in order, so a late or split reply cannot be taken
//   for the next one), then the line must stay quiet for `quiet`;
// - idempotent requests (ping, VERSION, MOV → COM) get `read_retries` more attempts, writes none
//   unless `retry_writes` ("a write goes once");
// - a lost link (the driver says closed or lost) is reopened before the next attempt when the
//   driver can reopen it, with a backoff from `first_delay` doubling to `max_delay`, for
//   `give_up_after`;
// - a reply that is the request's own bytes coming back is a loopback, not a board (link_echo);
// - on a marked serial line (PARMRK) the bytes read are decoded (line_marks.hpp): a byte that
//   failed its parity or framing check fails the attempt at once (link_line_error), never data.
// A well-formed reply ends the exchange without error, a NACK included: the caller decides what a
// NACK means. Outcomes are the codec's errors (rcb4::errc: the link_* codes, and the reply's own).
//
// Time: any std::chrono-shaped clock, as its time_point and duration (it must not wrap: widen a
// 32-bit tick counter). Durations are rounded up to its ticks, and on a clock coarser than a
// microsecond a deadline gets one tick more (its now() is rounded down): never early, at most two
// ticks late. A reply complete when it is read is taken even past its deadline; bytes that keep
// coming past it do not keep an attempt alive.
// Tracing and counters go to an Observer (no_observer: nothing, compiled away); cancellation is an
// input (cancel()).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/link/exchange.hpp>
#include <rcb4/link/line_marks.hpp>
#include <rcb4/link/types.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

namespace rcb4::link {

/**
 * The policy of one exchange at a time, and the state of the line between them (see above).
 * @tparam Clock    gives time_point and duration (std::chrono::steady_clock, or a tick counter's)
 * @tparam Options  has baud, turnaround, quiet, read_retries, retry_writes (see options)
 * @tparam Observer has trace(direction, time_point, bytes), count(counter, n) and
 *                  attempt_failed(errc): derive from no_observer and write the ones you want (a
 *                  member with a wrong signature then hides the base's and fails to compile)
 */
template <class Clock = std::chrono::steady_clock, class Options = options, class Observer = no_observer>
class exchange_machine {
 public:
  using time_point = typename Clock::time_point;  ///< the driver's time
  using duration = typename Clock::duration;      ///< its ticks
  using action = basic_action<time_point>;        ///< what to do next

  /** A machine using @p opt (kept by reference: it must outlive the machine) and @p obs. */
  explicit exchange_machine(const Options& opt, Observer obs = {}) noexcept : opt_(&opt), obs_(obs) {}
  /** Not from a temporary: the machine keeps the options by reference. */
  explicit exchange_machine(const Options&&, Observer = {}) = delete;
  // Actions point into the machine (the frame, its buffers): it stays where it was made.
  exchange_machine(const exchange_machine&) = delete;
  exchange_machine& operator=(const exchange_machine&) = delete;

  /**
   * Whether the line's reads are marked (PARMRK: a damaged byte as FF 00 X, an intact FF doubled)
   * and must be decoded. A change starts the decoder clean.
   */
  void set_marked(bool marked) noexcept {
    if (marked != marked_) marks_.reset();
    marked_ = marked;
  }
  /** True while the line's reads are decoded as marked. */
  bool marked() const noexcept { return marked_; }

  /** Whether the driver can reopen a lost link, and with which policy. */
  void set_reopen(bool can, reconnect_policy policy = {}) noexcept {
    can_reopen_ = can;
    policy_ = policy;
  }

  /**
   * Begins @p r (copied: a temporary is fine) at @p now. @p stray: bytes found waiting on the
   * line before anything was sent (a late or duplicated reply): a resync comes first.
   */
  action start(const request& r, time_point now, std::size_t stray = 0) {
    if (r.shape.frame_size() > max_reply_size || r.frame.size() == 0) {  // a hand-made shape no reply can have
      ex_.reset();
      return done(errc::frame_too_long);
    }
    req_ = r;
    replied_ = false;
    attempt_ = 0;
    attempts_ = 1 + ((r.idempotent || opt_->retry_writes) ? opt_->read_retries : 0);
    ex_.reset();
    telling_ = {};
    if (stray > 0) dirty_ = true;
    return begin_attempt(now);
  }

  /** The last action ended with @p r at @p now: what next. */
  action resume(const io_result& r, time_point now) {
    switch (phase_) {
      case phase::reopen: return reopened(r, now);
      case phase::sync_write:
      case phase::write: return written(r, now);
      case phase::sync_read: return sync_read(r, now);
      case phase::read: return read(r, now);
      case phase::echo_check: return echo_check(r, now);
      case phase::idle: break;
    }
    return done(errc::link_cancelled);  // nothing was running
  }

  /**
   * The running exchange is abandoned (its I/O was cancelled, a stop was asked, the driver is
   * closing): it ends with @p e, and the next one resynchronises first (part of a frame may be on
   * the wire).
   */
  action cancel(errc e = errc::link_cancelled) {
    if (e == errc{}) e = errc::link_cancelled;  // a cancelled exchange has no reply
    if (phase_ == phase::idle) return done(e);
    if (phase_ != phase::reopen) dirty_ = true;
    return finish(e);
  }

  /**
   * The reply of the last exchange, when it ended without error (ACK, NACK or data): a view into
   * the machine, valid until the next start(); nothing after a failure or a cancel.
   */
  std::optional<rcb4::reply> last_reply() const noexcept {
    if (!idle() || !ex_ || ex_->result().status != parse_status::complete || !replied_) return std::nullopt;
    return ex_->result().value();
  }
  /** True while no exchange runs. */
  bool idle() const noexcept { return phase_ == phase::idle; }
  /** True when the next exchange will resynchronise first. */
  bool dirty() const noexcept { return dirty_; }
  /** True when the link was lost (the next exchange reopens it first, when it can). */
  bool lost() const noexcept { return lost_; }
  /** The link was replaced from outside (a new stream): it starts clean. */
  void replaced() noexcept {
    dirty_ = lost_ = false;
    marks_.reset();
  }
  /** The running attempt's deadline (while an exchange runs). */
  time_point deadline() const noexcept { return deadline_; }
  /** The observer (to read what it counted). */
  const Observer& observer() const noexcept { return obs_; }

 private:
  enum class phase : std::uint8_t { idle, reopen, sync_write, sync_read, write, read, echo_check };
  // The resync's ping is the short one (protocol.md §4.11): its ACK differs from its frame, so a
  // loopback plug, which echoes the frame, can never look like a board answering.
  static constexpr std::array<std::uint8_t, 3> sync_ping{0x03, 0xFE, 0x01};
  static constexpr std::array<std::uint8_t, 4> ping_ack{0x04, 0xFE, 0x06, 0x08};  // protocol.md §4.11
  static constexpr unsigned max_resettles = 8;  // a line that keeps talking after the ACK is not settling

  void trace(direction d, time_point t, std::span<const std::uint8_t> b) {
    if (!b.empty()) obs_.trace(d, t, b);
  }
  void count(counter c, std::size_t n = 1) { obs_.count(c, n); }
  /**
   * The wire time of @p bytes (at most 386: a 128-byte request and a 258-byte reply) in the clock's
   * ticks, rounded up. A clock of microseconds or coarser counts it in 32 bits (no 64-bit division
   * on a microcontroller); a finer one through wire_time().
   */
  duration wire_ticks(std::size_t bytes) const noexcept {
    using period = typename duration::period;
    if constexpr (period::num == 1 && period::den <= 1'000'000) {
      static_assert(std::uint64_t{386} * 11 * 1'000'000 < (std::uint64_t{1} << 32), "386 bytes of bits fit 32 bits");
      const std::uint32_t bits = static_cast<std::uint32_t>(std::min<std::size_t>(bytes, 386)) * 11u *
                                 static_cast<std::uint32_t>(period::den);
      const std::uint32_t baud = opt_->baud > 0 ? opt_->baud : 1u;
      return duration(static_cast<typename duration::rep>(bits / baud + (bits % baud != 0 ? 1u : 0u)));
    } else {
      return ticks(wire_time(bytes, opt_->baud));
    }
  }
  /**
   * The deadline @p d after @p now: on a clock coarser than a microsecond one tick more, since its
   * now() is rounded down (a deadline k ticks on could otherwise pass after k - 1 ticks and a bit).
   */
  static time_point after(time_point now, duration d) noexcept {
    using period = typename duration::period;
    constexpr bool coarse = static_cast<std::intmax_t>(period::num) * 1'000'000 > static_cast<std::intmax_t>(period::den);
    return now + d + (coarse ? duration(1) : duration(0));
  }
  /** @p d as the clock's ticks, rounded up. */
  template <class Rep, class Period>
  static duration ticks(std::chrono::duration<Rep, Period> d) noexcept {
    return std::chrono::ceil<duration>(d);
  }

  action done(errc e) const {
    action a;
    a.error = e;
    return a;
  }
  action write(std::span<const std::uint8_t> bytes) const {
    action a;
    a.what = action::kind::write;
    a.out = bytes;
    a.deadline = deadline_;
    return a;
  }
  action read_into(std::span<std::uint8_t> buf) const {
    action a;
    a.what = action::kind::read;
    a.in = buf;
    a.deadline = deadline_;
    a.expected = expected_;
    return a;
  }
  action reopen_at(time_point t) const {
    action a;
    a.what = action::kind::reopen;
    a.deadline = t;
    return a;
  }

  /**
   * The first @p n bytes of @p buf as read: on a marked line they are decoded in place. Returns
   * the data bytes' count; @p d says what was damaged (nothing on an unmarked line).
   */
  std::size_t decode(std::span<std::uint8_t> buf, std::size_t n, line_marks::decoded& d) {
    n = std::min(n, buf.size());
    count(counter::bytes_in, n);
    if (!marked_) {
      d = line_marks::decoded{};
      d.size = n;
      return n;
    }
    d = marks_.decode(buf.first(n));
    if (d.damaged > 0) count(counter::line_errors, d.damaged);
    return d.size;
  }

  /** A byte of a reply arrived damaged: the attempt fails (resync, and a retry where allowed). */
  action damaged(time_point now) { return attempt_failed(errc::link_line_error, now); }

  action begin_attempt(time_point now) {
    if (attempt_ > 0) count(counter::retries);
    if (lost_ && can_reopen_) {  // (without a reopen, the attempt tries the line as it is: the OS says if it is gone)
      phase_ = phase::reopen;
      give_up_ = now + ticks(policy_.give_up_after);
      delay_ = ticks(policy_.first_delay);
      return reopen_at(now);
    }
    return dirty_ ? begin_sync(now) : begin_exchange(now);
  }

  action begin_sync(time_point now) {
    count(counter::resyncs);
    sync_ = sync_state{};
    return begin_write(phase::sync_write, sync_ping, ping_ack.size(), now);
  }

  action begin_exchange(time_point now) {
    ex_.emplace(req_.frame.bytes(), req_.shape);
    return begin_write(phase::write, req_.frame.bytes(), req_.shape.frame_size(), now);
  }

  /** Sends @p frame, whose reply has @p reply_bytes: the reply is due after both have crossed the wire. */
  action begin_write(phase p, std::span<const std::uint8_t> frame, std::size_t reply_bytes, time_point now) {
    phase_ = p;
    expected_ = now + wire_ticks(frame.size() + reply_bytes);
    deadline_ = after(now, wire_ticks(frame.size() + reply_bytes) + ticks(opt_->turnaround));
    out_ = frame;
    trace(direction::tx, now, out_);
    return write(out_);
  }

  action reopened(const io_result& r, time_point now) {
    if (r.status == io_status::ok) {
      lost_ = dirty_ = false;
      marks_.reset();  // a new descriptor (the driver says whether it is marked)
      count(counter::reconnects);
      return begin_exchange(now);
    }
    if (now >= give_up_) return finish(errc::link_reconnect_failed);
    const auto at = std::min(give_up_, now + delay_);
    delay_ = std::min<duration>(ticks(policy_.max_delay), delay_ * 2);
    return reopen_at(at);
  }

  action written(const io_result& r, time_point now) {
    count(counter::bytes_out, r.n);
    out_ = out_.subspan(std::min(r.n, out_.size()));
    if (phase_ == phase::write) ex_->wrote(r.n);
    if (r.status == io_status::timed_out) return timed_out(now);
    if (r.status != io_status::ok) return line_failed(r.status, now);
    if (!out_.empty()) return write(out_);
    if (phase_ == phase::sync_write) {
      phase_ = phase::sync_read;
      return read_into(junk_);
    }
    phase_ = phase::read;
    return read_into(ex_->read_buffer());
  }

  action sync_read(const io_result& r, time_point now) {
    line_marks::decoded d;
    const std::size_t n = decode(junk_, r.n, d);
    trace(direction::rx, now, std::span(junk_).first(n));
    if (d.damaged > 0) sync_ = sync_state{};  // an ACK with a damaged byte is no ACK: look for the next
    for (std::size_t i = d.clean_from; i < n; ++i) {
      std::rotate(sync_.tail.begin(), sync_.tail.begin() + 1, sync_.tail.end());
      sync_.tail.back() = junk_[i];
      ++sync_.seen;
    }
    if (r.status != io_status::ok && r.status != io_status::timed_out) return line_failed(r.status, now);
    const bool at_ack = sync_.seen >= ping_ack.size() && sync_.tail == ping_ack;
    if (r.status == io_status::timed_out) {
      if (at_ack && sync_.synced) {  // the ACK, then silence: the line is clean
        dirty_ = false;
        return begin_exchange(now);
      }
      return sync_failed(now);
    }
    if (at_ack && n > 0) {  // our ACK, unless more bytes follow it within `quiet`
      // (every restart of the quiet period counts: a line that keeps sending ACKs is not settling)
      if (sync_.synced && ++sync_.resettled > max_resettles) return timed_out(now);
      sync_.synced = true;
      deadline_ = after(now, ticks(opt_->quiet));
    } else if (n > 0 && sync_.synced) {  // more came after an ACK-like tail: read on to the real one
      sync_.synced = false;
      if (++sync_.resettled > max_resettles) return timed_out(now);
      deadline_ = after(now, wire_ticks(2 * ping_ack.size()) + ticks(opt_->turnaround));
    }
    if (now >= deadline_) {  // bytes keep coming past the deadline (a babbling line): it has passed all the same
      if (at_ack && sync_.synced) {
        dirty_ = false;
        return begin_exchange(now);
      }
      return sync_failed(now);
    }
    return read_into(junk_);
  }

  /**
   * The resync saw no ACK before its deadline. Silence is a timeout; anything else says what the
   * line is: our ping coming back (a loopback), a NACK, an ACK with a bad checksum (wrong rate or
   * parity), or bytes in no framing the board uses.
   */
  action sync_failed(time_point now) {
    static constexpr std::array<std::uint8_t, 4> ping_nack{0x04, 0xFE, 0x15, 0x17};  // protocol.md §2.2
    const auto& t = sync_.tail;
    if (sync_.seen == 0 || (sync_.seen >= 4 && t == ping_ack)) return timed_out(now);  // silence, or a late ACK
    if (sync_.seen >= 3 && std::equal(sync_ping.begin(), sync_ping.end(), t.begin() + 1)) return finish_echo();
    if (sync_.seen >= 4 && t == ping_nack) return attempt_failed(errc::nack, now);
    if (sync_.seen >= 4 && t[0] == 0x04 && t[1] == 0xFE && (t[2] == 0x06 || t[2] == 0x15))
      return attempt_failed(errc::bad_checksum, now);
    return attempt_failed(errc::bad_reply_length, now);
  }

  action read(const io_result& r, time_point now) {
    if (r.n > 0) {
      const auto buf = ex_->read_buffer();
      line_marks::decoded d;
      const std::size_t n = decode(buf, r.n, d);
      trace(direction::rx, now, buf.first(n));
      if (d.damaged > 0) return damaged(now);  // (never more is read than the reply can hold: it is this reply's)
      if (n > 0) ex_->received(n);
    }
    if (ex_->next() == exchange::step::done) return judge(now);
    if (r.status != io_status::ok && r.status != io_status::timed_out) return line_failed(r.status, now);
    if (r.status == io_status::timed_out || now >= deadline_)  // (a reply complete by now was taken above)
      return ex_->received_bytes().empty() ? timed_out(now) : truncated(now);
    return read_into(ex_->read_buffer());
  }

  /** A complete frame arrived: the reply, or a malformed frame (resync, and retry if allowed). */
  action judge(time_point now) {
    const auto& p = ex_->result();
    const auto got = ex_->received_bytes();
    if (p.status == parse_status::error) {
      const auto sent = req_.frame.bytes();
      if (!got.empty() && got.size() <= sent.size() && std::equal(got.begin(), got.end(), sent.begin())) {
        // It starts like our own frame: read the rest of it to tell a loopback (which returns the
        // whole frame, however its bytes are split) from a malformed reply.
        phase_ = phase::echo_check;
        echo_.matched = got.size();
        echo_.error = p.error;
        return echo_.matched == sent.size() ? finish_echo() : read_into(echo_buffer());
      }
      return attempt_failed(p.error, now);
    }
    if (p.consumed < got.size()) dirty_ = true;  // bytes after the reply (a NACK read where data was due)
    if (p.value().kind() == reply_kind::nack) count(counter::nacks);
    replied_ = true;
    return finish({});
  }

  std::span<std::uint8_t> echo_buffer() { return std::span(junk_).first(req_.frame.size() - echo_.matched); }

  action echo_check(const io_result& r, time_point now) {
    const auto sent = req_.frame.bytes();
    line_marks::decoded d;
    const std::size_t n = decode(echo_buffer(), r.n, d);
    trace(direction::rx, now, std::span(junk_).first(n));
    if (d.damaged > 0) return damaged(now);
    if (!std::equal(junk_.begin(), junk_.begin() + static_cast<std::ptrdiff_t>(n),
                    sent.begin() + static_cast<std::ptrdiff_t>(echo_.matched)))
      return attempt_failed(echo_.error, now);  // not our frame after all: the malformed reply it was
    echo_.matched += n;
    if (echo_.matched == sent.size()) return finish_echo();
    if (r.status != io_status::ok && r.status != io_status::timed_out) return line_failed(r.status, now);
    if (r.status == io_status::timed_out || now >= deadline_) return attempt_failed(echo_.error, now);
    return read_into(echo_buffer());
  }

  /** Our own bytes came back: a loopback, never a board (and no retry cures that). */
  action finish_echo() {
    dirty_ = true;
    return finish(errc::link_echo);
  }

  action timed_out(time_point now) {
    count(counter::timeouts);
    return attempt_failed(errc::link_timeout, now);
  }

  /** A reply began and stopped short: a timeout that says more (a board is there, the line fails). */
  action truncated(time_point now) {
    count(counter::timeouts);
    return attempt_failed(errc::link_truncated, now);
  }

  /**
   * The attempt failed in a way another attempt may cure: retry while attempts remain. The
   * exchange reports the first failure that says more than a timeout (a malformed reply, then
   * silence while resynchronising, is a line or board problem, not a missing board).
   */
  action attempt_failed(errc e, time_point now) {
    dirty_ = true;
    obs_.attempt_failed(e);
    if (telling_ == errc{} || telling_ == errc::link_timeout) telling_ = e;
    if (++attempt_ < attempts_) return begin_attempt(now);
    return finish(telling_);
  }

  /** The stream failed: final, unless the link was lost and can be reopened for a retry. */
  action line_failed(io_status s, time_point now) {
    const errc e = s == io_status::closed ? errc::link_closed : s == io_status::lost ? errc::link_lost : errc::link_io_error;
    dirty_ = true;
    if (s == io_status::failed) return finish(e);
    lost_ = true;
    if (can_reopen_) return attempt_failed(e, now);
    return finish(e);
  }

  action finish(errc e) {
    phase_ = phase::idle;
    if (e == errc{}) lost_ = false;  // the line works after all
    count(counter::exchanges);
    if (e != errc{}) count(counter::errors);
    return done(e);
  }

  struct sync_state {
    std::array<std::uint8_t, 4> tail{};  // the last 4 bytes seen, newest last
    std::size_t seen = 0;
    unsigned resettled = 0;
    bool synced = false;  // the tail was the ping's ACK
  };

  const Options* opt_;
  Observer obs_;
  bool can_reopen_ = false;
  reconnect_policy policy_{};
  // the line, between exchanges
  bool marked_ = false;
  line_marks marks_{};
  bool dirty_ = false;
  bool lost_ = false;
  // the running exchange
  phase phase_ = phase::idle;
  request req_{};
  unsigned attempt_ = 0, attempts_ = 1;
  errc telling_{};  // the most telling failure of the attempts so far
  time_point deadline_{}, expected_{};
  std::span<const std::uint8_t> out_{};
  std::optional<exchange> ex_;
  bool replied_ = false;  // the running or last exchange ended with a reply
  sync_state sync_{};
  struct {
    std::size_t matched = 0;  // bytes of our frame seen coming back
    errc error{};             // what the reply is if the rest does not match
  } echo_{};
  std::array<std::uint8_t, max_request_size> junk_{};  // a resync's reads; the rest of our frame coming back (echo)
  time_point give_up_{};
  duration delay_{};
};

}  // namespace rcb4::link
