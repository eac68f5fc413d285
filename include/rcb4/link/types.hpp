// rcb4 — what a link driver and the exchange machine (exchange_machine.hpp) say to each other:
// the request, the options and reconnect policy the machine reads, the observer's calls, the
// driver's I/O results and the machine's actions. std only.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/commands/common.hpp>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <span>

namespace rcb4::link {

/**
 * The wire time of @p bytes at @p baud with 8E1 framing: 11 bits a byte (protocol.md §1). What
 * deadlines and a served board's pacing are made of.
 */
constexpr std::chrono::nanoseconds wire_time(std::size_t bytes, std::uint32_t baud) noexcept {
  return std::chrono::nanoseconds(static_cast<std::int64_t>(bytes) * 11 * 1'000'000'000 / (baud > 0 ? baud : 1));
}

/** A command ready for the line: its frame, the shape of its reply, whether it may be repeated. */
struct request {
  request_frame frame;      ///< the bytes to send
  reply_shape shape;        ///< the reply a success has
  bool idempotent = false;  ///< may be sent again without changing the board (ping, VERSION, MOV → COM)
};

/**
 * What the machine reads of its options (any type with these members will do: the Asio client's
 * client_options has them). Read as it goes: change them only while no exchange runs.
 */
struct options {
  std::uint32_t baud = 115200;                ///< line rate used for deadlines (the slowest is the safe default)
  std::chrono::milliseconds turnaround{100};  ///< allowance for adapter latency, the board's reply, a busy host
  std::chrono::milliseconds quiet{5};         ///< silence that ends a resync after an error
  unsigned read_retries = 2;                  ///< extra attempts for idempotent requests
  bool retry_writes = false;                  ///< also retry requests that change the board
};

/**
 * How a lost link is reopened: attempts spaced by a delay that starts at first_delay and doubles
 * up to max_delay; after give_up_after without success the exchange ends with
 * errc::link_reconnect_failed, and the next exchange starts trying again.
 */
struct reconnect_policy {
  std::chrono::milliseconds first_delay{50};      ///< wait after the first failed attempt
  std::chrono::milliseconds max_delay{1000};      ///< the longest wait between attempts
  std::chrono::milliseconds give_up_after{5000};  ///< total time one exchange spends reconnecting
};

/** Direction of traced bytes. */
enum class direction : std::uint8_t { tx, rx };

/** What an observer is told to count. */
enum class counter : std::uint8_t {
  exchanges,    ///< an exchange ended (success or not)
  errors,       ///< an exchange ended in an error (a NACK is not one)
  retries,      ///< an extra attempt
  timeouts,     ///< a deadline missed (a resync's included)
  nacks,        ///< a reply was a NACK
  resyncs,      ///< a resynchronisation (ping, discard to its ACK) after an error
  reconnects,   ///< the link was reopened after a loss
  bytes_out,    ///< bytes written (the count is the second argument)
  bytes_in,     ///< bytes read, the resync's discarded ones included (not stray bytes a driver drains first)
  line_errors,  ///< bytes that failed their parity or framing check
};

/**
 * The observer that observes nothing: every call compiles to nothing. An observer of your own
 * derives from it and writes the members it wants.
 */
struct no_observer {
  /** @p bytes went out or came in at @p t. */
  template <class TimePoint>
  constexpr void trace(direction, TimePoint, std::span<const std::uint8_t>) noexcept {}
  /** @p c happened @p n times. */
  constexpr void count(counter, std::size_t = 1) noexcept {}
  /** An attempt failed with @p e (another may follow: counter::retries says so). */
  constexpr void attempt_failed(errc) noexcept {}
};

/** How the driver's last action ended. */
enum class io_status : std::uint8_t {
  ok,         ///< done (a read may have returned fewer bytes than asked: what arrived first)
  timed_out,  ///< the deadline passed first (n says what was done before it)
  closed,     ///< the line closed (end of file)
  lost,       ///< the link is gone (EIO, ENODEV, a reset connection, an unplugged adapter)
  failed,     ///< another failure (the driver keeps its details): the exchange ends with link_io_error
};

/** How the last action ended: bytes written or read (also with a timeout), and the status. */
struct io_result {
  std::size_t n = 0;               ///< bytes written or read
  io_status status = io_status::ok;  ///< how it ended
};

/** What a driver must do next (@p TimePoint: its clock's). */
template <class TimePoint>
struct basic_action {
  /** The kinds of action. */
  enum class kind : std::uint8_t {
    write,   ///< write `out` (all of it, or report what was written) before `deadline`
    read,    ///< read at most `in.size()` bytes into `in` before `deadline` (what arrives first)
    reopen,  ///< reopen the link, not before `deadline`
    done,    ///< the exchange has ended with `error` (the reply is machine.last_reply())
  };
  kind what = kind::done;               ///< what to do
  std::span<const std::uint8_t> out{};  ///< write: the bytes still to write
  std::span<std::uint8_t> in{};         ///< read: where the bytes go
  TimePoint deadline{};                 ///< write/read: give up then; reopen: not before then
  TimePoint expected{};                 ///< read: when the reply is due on the wire (for busy polling)
  errc error{};                         ///< done: the outcome (errc{}: a reply, ACK, NACK or data)
};

}  // namespace rcb4::link
