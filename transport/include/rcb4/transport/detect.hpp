// rcb4 — finding the baud rate a board listens at.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/transport/client.hpp>
#include <rcb4/transport/serial.hpp>

namespace rcb4::transport {

/**
 * Tries 1250000, 115200 and 625000 on @p path: at each, two pings with a @p turnaround deadline.
 * Returns the first rate a board ACKs at, or 0 with errc::no_board (or the error that makes
 * trying pointless: port busy, no such device, permission). @p io must be run by another thread
 * (e.g. io_thread). A pseudo-terminal answers at any rate, so there the first rate wins.
 */
inline std::uint32_t detect_baud(boost::asio::io_context& io, const std::string& path, std::error_code& ec,
                                 std::chrono::milliseconds turnaround = std::chrono::milliseconds(50)) {
  for (const std::uint32_t baud : board_bauds) {
    auto port = open_serial(io, path, baud, ec);
    if (ec == errc::port_busy || ec == std::errc::no_such_file_or_directory || ec == std::errc::permission_denied)
      return 0;
    if (ec) continue;
    client_options opt;
    opt.baud = baud;
    opt.turnaround = turnaround;
    opt.read_retries = 1;
    basic_client<serial_port> c(std::move(port), opt);
    std::error_code pe;
    const auto r = c.execute(ping{}, pe);
    if (!pe && r.kind == reply_kind::ack) {
      ec.clear();
      return baud;  // the client closes the port; open it again at this rate
    }
  }
  ec = errc::no_board;
  return 0;
}

}  // namespace rcb4::transport
