// rcb4 — reaching a board through TCP, e.g. a serial port exported by ser2net.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/transport/error.hpp>

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>

#include <string>
#include <system_error>

namespace rcb4::transport {

/**
 * The socket connect returns: Asio's TCP socket on the io_context's own executor type (not the
 * type-erased any_io_executor), so that the client allocates nothing per exchange. It converts
 * to boost::asio::ip::tcp::socket (by move) if you need that type.
 */
using tcp_socket = boost::asio::basic_stream_socket<boost::asio::ip::tcp, boost::asio::io_context::executor_type>;

/**
 * Connects to "HOST:PORT" (names resolved; IPv6 as "[::1]:3333"), with TCP_NODELAY set. A
 * missing or non-numeric port, or one above 65535, is std::errc::invalid_argument.
 */
inline tcp_socket connect(boost::asio::io_context& io, const std::string& where, error_code& ec) {
  tcp_socket socket(io);
  const auto colon = where.rfind(':');
  const auto port = colon == std::string::npos ? std::string() : where.substr(colon + 1);
  const bool numeric = !port.empty() && port.size() <= 5 && port.find_first_not_of("0123456789") == std::string::npos;
  if (!numeric || std::stoul(port) > 65535) {
    ec = std::make_error_code(std::errc::invalid_argument);
    return socket;
  }
  std::string host = where.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  boost::asio::ip::tcp::resolver resolver(io);
  boost::system::error_code bec;
  const auto endpoints = resolver.resolve(host, where.substr(colon + 1), bec);
  if (!bec) boost::asio::connect(socket, endpoints, bec);
  if (!bec) socket.set_option(boost::asio::ip::tcp::no_delay(true), bec);
  ec = bec;
  return socket;
}

/** connect() that throws system_error. */
inline tcp_socket connect(boost::asio::io_context& io, const std::string& where) {
  error_code ec;
  auto s = connect(io, where, ec);
  if (ec) throw system_error(ec, "connect " + where);
  return s;
}

}  // namespace rcb4::transport
