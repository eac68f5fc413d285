// rcb4 — how a client behaves (options, reconnect policy) and what it has done (counters).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/link/types.hpp>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <span>

namespace rcb4::transport {

/** The wire time of bytes at a baud, 8E1 (rcb4/link/types.hpp). */
using link::wire_time;
/** Direction of a traced frame (rcb4/link/types.hpp). */
using link::direction;

/** Called with every frame on the line: direction, monotonic time, bytes. */
using trace_function =
    std::function<void(direction, std::chrono::steady_clock::time_point, std::span<const std::uint8_t>)>;

/** Client behaviour. */
struct client_options {
  std::uint32_t baud = 115200;                ///< line rate used for deadlines (the slowest is the safe default)
  std::chrono::milliseconds turnaround{100};  ///< allowance for adapter latency, the board's reply, a busy host
  std::chrono::milliseconds quiet{5};         ///< silence that ends a resync after an error
  unsigned read_retries = 2;                  ///< extra attempts for idempotent reads (ping, VERSION, MOV → COM)
  bool retry_writes = false;  ///< also retry commands that change the board (only if you know they are safe)
  /**
   * Blocking calls on an idle line do their I/O on the calling thread (streams with a
   * descriptor); false sends every exchange through the executor's thread.
   */
  bool direct_io = true;
  /**
   * With direct_io: busy-poll for a reply within this window either side of its expected
   * arrival (the wire time of request and reply at `baud`) instead of sleeping until it comes.
   * It saves the thread's wake-up latency (tens of µs on a busy or virtual machine) at the cost
   * of a busy core for up to twice this long per exchange. 0 (the default) always sleeps.
   */
  std::chrono::microseconds busy_poll{0};
  /** Called with every frame on the line, on the thread doing the I/O (empty: no trace). */
  trace_function trace;
};

/**
 * How a client reopens a lost link (EOF, EIO, ENODEV: an unplugged adapter, a stopped server):
 * the link's own policy (rcb4/link/types.hpp); after give_up_after the exchange fails with
 * transport_errc::reconnect_failed.
 */
using link::reconnect_policy;

/** What a client has done (readable from any thread). */
struct client_counters {
  std::atomic<std::uint64_t> exchanges{0};    ///< requests completed (success or not)
  std::atomic<std::uint64_t> retries{0};      ///< extra attempts
  std::atomic<std::uint64_t> timeouts{0};     ///< deadlines missed (a resync's included)
  std::atomic<std::uint64_t> errors{0};       ///< exchanges that ended in an error (a NACK is not one)
  std::atomic<std::uint64_t> nacks{0};        ///< replies that were NACK
  std::atomic<std::uint64_t> resyncs{0};      ///< resynchronisations (ping, discard to its ACK) after an error
  std::atomic<std::uint64_t> bytes_out{0};    ///< bytes written
  std::atomic<std::uint64_t> bytes_in{0};     ///< bytes read (discarded bytes included)
  std::atomic<std::uint64_t> reconnects{0};   ///< links reopened after a loss
  std::atomic<std::uint64_t> line_errors{0};  ///< bytes that failed their parity or framing check (a marked line)
};

}  // namespace rcb4::transport
