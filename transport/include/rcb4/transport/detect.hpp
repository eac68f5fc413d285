// rcb4 — finding the baud rate a board listens at, and saying why when none answers.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/transport/client.hpp>
#include <rcb4/transport/serial.hpp>

namespace rcb4::transport {

/** How detect_baud tries each rate. */
struct detect_options {
  std::chrono::milliseconds turnaround{50};  ///< the deadline's allowance per ping
  unsigned pings = 2;                        ///< attempts per rate
  trace_function trace;                      ///< sees every frame of the detection (rcb4 --trace)
};

/**
 * Tries 1250000, 115200 and 625000 on @p path with the short ping (03 FE 01, whose ACK a
 * loopback cannot fake) and returns the first rate a board ACKs at. When none does, @p ec says
 * the most telling thing that happened, not just "nothing answered":
 * - the port could not be opened: the OS's error (no such device, not a terminal, permission)
 *   or transport_errc::port_busy; nothing more is tried;
 * - transport_errc::echo: the line returned our own bytes (a loopback plug or an echoing pty);
 * - rcb4::errc::nack: something answered NACK;
 * - a malformed reply (rcb4::errc::bad_checksum, bad_reply_length, echo_mismatch ...): something
 *   answers, but not in the board's framing (wrong rate or parity, another device);
 * - transport_errc::no_board: silence at every rate.
 * @p io must be run by another thread (e.g. io_thread), or not at all: the pings run on this
 * thread. A pseudo-terminal answers at any rate, so there the first rate wins.
 */
inline std::uint32_t detect_baud(boost::asio::io_context& io, const std::string& path, error_code& ec,
                                 const detect_options& how = {}) {
  error_code telling;  // the most informative failure so far
  const auto rank = [](const error_code& e) {
    if (e == transport_errc::echo) return 4;
    if (e == rcb4::errc::nack) return 3;
    if (std::error_code(e).category() == rcb4::codec_category()) return 2;  // (Boost wraps std categories)
    return e == transport_errc::timeout ? 0 : 1;
  };
  for (const std::uint32_t baud : board_bauds) {
    auto port = open_serial(io, path, baud, ec);
    if (ec == transport_errc::rate_not_set) continue;  // this adapter cannot do this rate; others may
    if (ec) return 0;                                  // no rate will open it: the real cause
    client_options opt;
    opt.baud = baud;
    opt.turnaround = how.turnaround;
    opt.read_retries = how.pings > 0 ? how.pings - 1 : 0;
    opt.trace = how.trace;
    basic_client<serial_port> c(std::move(port), opt);
    error_code pe;
    const auto r = c.exchange(ping{ping_form::short_}, pe);
    if (!pe && r.kind == reply_kind::ack) {
      ec.clear();
      return baud;  // the client closes the port; open it again at this rate
    }
    if (!pe) pe = rcb4::errc::nack;
    if (!telling || rank(pe) > rank(telling)) telling = pe;
  }
  ec = !telling || telling == transport_errc::timeout ? error_code(transport_errc::no_board) : telling;
  return 0;
}

/** The old form: @p turnaround per ping, no trace. */
inline std::uint32_t detect_baud(boost::asio::io_context& io, const std::string& path, error_code& ec,
                                 std::chrono::milliseconds turnaround) {
  detect_options how;
  how.turnaround = turnaround;
  return detect_baud(io, path, ec, how);
}

}  // namespace rcb4::transport
