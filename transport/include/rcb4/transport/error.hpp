// rcb4 — the transport's error model: one error-code type, and the transport's own codes.
// SPDX-License-Identifier: BSL-1.0
//
// Every transport API, blocking and asynchronous, reports errors as rcb4::transport::error_code,
// which is boost::system::error_code (see the README's "Errors"). Why that one: Asio's completion
// tokens (use_awaitable, use_future) throw only for it, every Asio call a user makes already
// returns it, and since Boost 1.81 it carries std::error_category values losslessly: it is
// built from, compares with and converts back to std::error_code. So
//   ec == rcb4::errc::nack                      (a codec code: rcb4::errc, category "rcb4")
//   ec == rcb4::transport::transport_errc::timeout   (a line code: category "rcb4.transport")
//   ec == std::errc::no_such_file_or_directory  (the OS's)
// all hold on the same value, and `std::error_code s = ec;` works for std-only code.
#pragma once

#include <rcb4/error_category.hpp>

#include <boost/asio/error.hpp>
#include <boost/system/error_code.hpp>
#include <boost/system/system_error.hpp>

#include <cerrno>
#include <string>
#include <system_error>

namespace rcb4::transport {

/** The error-code type of every transport API (sync and async). */
using error_code = boost::system::error_code;
/** What the throwing functions throw (a std::runtime_error). */
using system_error = boost::system::system_error;

/** What can go wrong on a line, beyond a malformed or refused reply (rcb4::errc). */
enum class transport_errc {
  timeout = 1,           ///< no (complete) reply within the exchange's deadline
  closed,                ///< the line closed (EOF): cable unplugged, server gone
  port_busy,             ///< the serial port is used by another program (flock/TIOCEXCL)
  rate_not_set,          ///< the port cannot be set to the rate, or it reads back different
  settings_not_kept,     ///< the port did not keep raw mode or 8-bit framing (not a usable serial port)
  no_board,              ///< baud detection found no board answering at any rate
  would_deadlock,        ///< a blocking call on the thread that must run the client's executor
  cancelled,             ///< the client was destroyed while the exchange waited
  reconnect_failed,      ///< the link was lost and reopening it failed until the policy gave up
  executor_not_running,  ///< a blocking call waited for the executor, and nobody ran it
  echo,                  ///< the line echoes what is sent (a loopback plug, not a board)
  truncated,             ///< a reply began but stopped short of its length before the deadline
  line_error,            ///< a byte of the reply failed its parity or framing check (noise, wrong rate, a break)
};

}  // namespace rcb4::transport

template <>
struct std::is_error_code_enum<rcb4::transport::transport_errc> : std::true_type {};

namespace rcb4::transport {

/** The category of transport_errc; name() is "rcb4.transport". */
class transport_category_impl final : public std::error_category {
 public:
  /** "rcb4.transport". */
  const char* name() const noexcept override { return "rcb4.transport"; }
  /** A message for @p ev. */
  std::string message(int ev) const override {
    switch (static_cast<transport_errc>(ev)) {
      case transport_errc::timeout: return "no reply from the board before the deadline";
      case transport_errc::closed: return "the line was closed (unplugged cable or stopped server)";
      case transport_errc::port_busy: return "the serial port is in use by another program";
      case transport_errc::rate_not_set: return "the serial port cannot be set to that baud rate";
      case transport_errc::settings_not_kept:
        return "the serial port did not keep raw mode and 8-bit framing (is it a serial port?)";
      case transport_errc::no_board: return "no RCB-4 answered at 1250000, 115200 or 625000 baud";
      case transport_errc::would_deadlock: return "blocking call from the thread that runs the client's executor";
      case transport_errc::cancelled: return "the client was closed";
      case transport_errc::reconnect_failed:
        return "the link was lost and could not be reopened (device still unplugged?)";
      case transport_errc::executor_not_running:
        return "nobody runs the client's executor (run it on another thread, e.g. io_thread)";
      case transport_errc::echo: return "the line echoes what is sent: a loopback, not an RCB-4";
      case transport_errc::truncated: return "the board's reply stopped short of its length before the deadline";
      case transport_errc::line_error:
        return "a byte of the reply failed its parity or framing check (a noisy line, a wrong rate, or a break)";
    }
    return "unknown rcb4.transport error";
  }
};

/** The single instance of the transport's category. */
inline const std::error_category& transport_category() noexcept {
  static const transport_category_impl instance;
  return instance;
}

/** Makes a std::error_code from @p e (an error_code converts from it too). */
inline std::error_code make_error_code(transport_errc e) noexcept {
  return {static_cast<int>(e), transport_category()};
}

/** True for errors that mean the link itself is gone (as opposed to a bad or missing reply). */
inline bool is_link_lost(const error_code& ec) noexcept {
  using std::errc;
  return ec == transport_errc::closed || ec == boost::asio::error::eof || ec == errc::io_error ||
         ec == errc::no_such_device || ec == errc::no_such_device_or_address || ec == errc::bad_file_descriptor ||
         ec == errc::broken_pipe || ec == errc::connection_reset || ec == errc::connection_aborted ||
         ec == errc::not_connected || ec == boost::asio::error::shut_down;
}

/** An OS error number as an error_code. */
inline error_code os_error(int e) noexcept { return error_code(e, boost::system::generic_category()); }

}  // namespace rcb4::transport
