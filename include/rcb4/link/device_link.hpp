// rcb4 — the link's whole policy (exchange_machine.hpp: deadlines, resync, retries, "a write goes
// once", loopback, reopen) for a byte device without a file descriptor, driven by polling against
// a clock the program supplies. Two shapes of device, each a few lines to write:
//
//   byte_device    long write(span<const uint8_t>), long read(span<uint8_t>): bytes taken or
//                  read (0: none now), negative: the device failed (the link takes it as lost:
//                  reopened when the device can be). libftdi's ftdi_write_data and ftdi_read_data
//                  have this shape (see libftdi_device.hpp); so has a non-blocking descriptor.
//   polled_uart    bool poll_in(uint8_t&) (a byte was waiting), bool poll_out(uint8_t) (it was
//                  taken): a microcontroller's UART status and data registers. (Zephyr's
//                  uart_poll_in returns 0 when a byte was read: wrap it as `== 0`.) Wrapped as a
//                  byte_device by polled_uart_device.
//
// Optional members of a device: `bool reopen()` (a lost device is reopened with the link's
// backoff), `void idle(time_point until, waiting w)` (called while the link waits: for input, for
// room to write, or only for time (a reopen's backoff); sleep, poll, or wait for an interrupt,
// until then at most). Without it the link polls without pause. A stop (exchange(r, stopped)) is
// noticed between calls: an idle() that blocks to its deadline delays it that long.
//
//   struct my_clock { using duration = std::chrono::duration<std::int64_t, std::milli>;
//                     using time_point = std::chrono::time_point<my_clock>;
//                     static time_point now() { return time_point(duration(ticks_ms())); } };
//   rcb4::link::polled_uart_device<my_uart> device(uart);
//   rcb4::link::device_link<decltype(device), my_clock> link(device, opts);
//   auto r = link.exchange(rcb4::link::request_of(rcb4::ping{}));   // result<reply>
//
// std only, no heap, no exceptions. The clock must not wrap (widen a 32-bit tick counter).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/link/exchange_machine.hpp>
#include <rcb4/result.hpp>

#include <array>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

namespace rcb4::link {

/** A clock the link can read: time_point, duration, and a static now(). */
template <class C>
concept link_clock = requires {
  typename C::time_point;
  typename C::duration;
  { C::now() } -> std::same_as<typename C::time_point>;
};

/** A device that takes and gives bytes without waiting (see above). */
template <class D>
concept byte_device = requires(D& d, std::span<const std::uint8_t> out, std::span<std::uint8_t> in) {
  { d.write(out) } -> std::convertible_to<long>;
  { d.read(in) } -> std::convertible_to<long>;
};

/** A UART polled a byte at a time (see above). */
template <class U>
concept polled_uart = requires(U& u, std::uint8_t& in, std::uint8_t out) {
  { u.poll_in(in) } -> std::convertible_to<bool>;
  { u.poll_out(out) } -> std::convertible_to<bool>;
};

/** What the link waits for when it calls a device's idle(). */
enum class waiting : std::uint8_t {
  input,   ///< bytes to read
  output,  ///< room to write
  time,    ///< only the time to pass (a reopen's backoff)
};

/** A polled UART as a byte_device: as many bytes as it takes or has now. */
template <polled_uart Uart>
class polled_uart_device {
 public:
  /** Over @p u (kept by reference). */
  explicit polled_uart_device(Uart& u) noexcept : u_(&u) {}
  /** Bytes of @p out the UART took now. */
  long write(std::span<const std::uint8_t> out) {
    std::size_t n = 0;
    while (n < out.size() && u_->poll_out(out[n])) ++n;
    return static_cast<long>(n);
  }
  /** Bytes the UART had now, into @p in. */
  long read(std::span<std::uint8_t> in) {
    std::size_t n = 0;
    while (n < in.size() && u_->poll_in(in[n])) ++n;
    return static_cast<long>(n);
  }
  /** The UART's own idle(), when it has one. */
  template <class TimePoint>
  void idle(TimePoint until, waiting w) requires requires(Uart& u) {
    u.idle(until, w);
  }
  { u_->idle(until, w); }

 private:
  Uart* u_;
};

/**
 * One exchange at a time over @p Device, with the link's policy (exchange_machine.hpp). Not
 * thread-safe: one caller at a time. Reads into the machine's buffer: a reply is a view valid
 * until the next exchange. It stays where it was made (the machine points into itself).
 */
template <byte_device Device, link_clock Clock, class Observer = no_observer>
class device_link {
 public:
  using machine = exchange_machine<Clock, options, Observer>;  ///< the policy
  using time_point = typename Clock::time_point;               ///< the clock's time

  /** Over @p d (kept by reference) with @p opt (copied), @p policy for reopening, and @p obs. */
  explicit device_link(Device& d, const options& opt = {}, reconnect_policy policy = {}, Observer obs = {})
      : d_(&d), opt_(opt), m_(opt_, obs) {
    m_.set_reopen(can_reopen, policy);
  }
  device_link(const device_link&) = delete;
  device_link& operator=(const device_link&) = delete;

  /** True when Device has reopen(): a lost device is reopened with the policy's backoff. */
  static constexpr bool can_reopen = requires(Device & dev) {
    { dev.reopen() } -> std::convertible_to<bool>;
  };

  /**
   * Exchanges @p r: the reply (ACK, NACK or data: a NACK is a reply, the caller decides), or the
   * error that ended the exchange (errc::link_timeout, link_echo, bad_checksum, ...).
   */
  result<reply> exchange(const request& r) {
    return exchange(r, [] { return false; });
  }
  /**
   * The same, abandoned with errc::link_cancelled as soon as @p stopped() is true (asked before
   * each step and while waiting): a stop button, a watchdog. The next exchange resynchronises
   * first (part of a frame may be on the wire).
   */
  template <class Stopped>
  result<reply> exchange(const request& r, Stopped&& stopped) {
    const std::size_t stray = drain();  // first: the time is read after it
    auto a = m_.start(r, Clock::now(), stray);
    while (a.what != action_kind::done) {
      const auto done = perform(a, stopped);
      if (!done) {
        a = m_.cancel();
        break;
      }
      a = m_.resume(*done, Clock::now());  // the time read after the action (argument order is unspecified)
    }
    if (a.error != errc{}) return a.error;
    return *m_.last_reply();
  }

  /** The options in force (change them only between exchanges). */
  options& settings() noexcept { return opt_; }
  /** Whether the device's reads are PARMRK-marked (a serial descriptor opened so): decoded then. */
  void set_marked(bool marked) noexcept { m_.set_marked(marked); }
  /** The machine: its observer, whether the line is dirty or lost. */
  const machine& state() const noexcept { return m_; }

 private:
  using action = typename machine::action;
  using action_kind = typename action::kind;

  /** Bytes waiting before anything was sent (a late reply): read and dropped; the machine resyncs. */
  std::size_t drain() {
    std::size_t n = 0;
    for (int i = 0; i < 4; ++i) {  // a few bytes now: the resync reads the rest
      const long got = d_->read(junk_);
      if (got <= 0) break;
      n += static_cast<std::size_t>(got);
    }
    return n;
  }

  void wait(time_point until, waiting w) {
    if constexpr (requires(Device & dev) { dev.idle(until, w); }) d_->idle(until, w);
  }

  /**
   * Calls @p io (a write or a read) until it moves bytes, fails, or @p deadline passes (checked
   * before each try, as a driver must: a line that always has a byte ready cannot hold an attempt
   * open), waiting for @p w between tries; nothing when @p stopped() (a stop comes before the
   * deadline's timeout).
   */
  template <class Stopped, class Io>
  std::optional<io_result> transfer(time_point deadline, waiting w, Stopped& stopped, Io io) {
    for (;;) {
      if (stopped()) return std::nullopt;
      if (Clock::now() >= deadline) return io_result{0, io_status::timed_out};
      const long n = io();
      if (n < 0) return io_result{0, io_status::lost};
      if (n > 0) return io_result{static_cast<std::size_t>(n), io_status::ok};
      wait(deadline, w);
    }
  }

  /**
   * Does @p a until it is done or its deadline passes; nothing when @p stopped().
   */
  template <class Stopped>
  std::optional<io_result> perform(const action& a, Stopped& stopped) {
    switch (a.what) {
      case action_kind::write: return transfer(a.deadline, waiting::output, stopped, [&] { return d_->write(a.out); });
      case action_kind::read: return transfer(a.deadline, waiting::input, stopped, [&] { return d_->read(a.in); });
      case action_kind::reopen:
        for (;;) {
          if (stopped()) return std::nullopt;
          if (Clock::now() >= a.deadline) break;
          wait(a.deadline, waiting::time);
        }
        if constexpr (can_reopen) return io_result{0, d_->reopen() ? io_status::ok : io_status::failed};
        return io_result{0, io_status::failed};
      case action_kind::done: break;
    }
    return io_result{};
  }

  Device* d_;
  options opt_;
  machine m_;
  std::array<std::uint8_t, 16> junk_{};  // stray bytes dropped before an exchange
};

}  // namespace rcb4::link
