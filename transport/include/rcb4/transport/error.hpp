// rcb4 — transport errors (category "rcb4.transport"); codec errors stay rcb4::errc.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <string>
#include <system_error>

namespace rcb4::transport {

/** What can go wrong on a line, beyond a malformed reply (rcb4::errc). */
enum class errc {
  timeout = 1,       ///< no (complete) reply within the exchange's deadline
  closed,            ///< the line closed (EOF): cable unplugged, server gone
  port_busy,         ///< the serial port is used by another program (flock/TIOCEXCL)
  unsupported_baud,  ///< the rate cannot be set, or reads back different
  no_board,          ///< baud detection found no board answering at any rate
  would_deadlock,    ///< a blocking call on the thread that must run the client's executor
  cancelled,         ///< the client was closed while the exchange waited
  reconnect_failed,  ///< the link was lost and reopening it failed until the policy gave up
};

/** The category of rcb4::transport::errc; name() is "rcb4.transport". */
class error_category_impl final : public std::error_category {
 public:
  /** "rcb4.transport". */
  const char* name() const noexcept override { return "rcb4.transport"; }
  /** A message for @p ev. */
  std::string message(int ev) const override {
    switch (static_cast<errc>(ev)) {
      case errc::timeout: return "no reply from the board before the deadline";
      case errc::closed: return "the line was closed (unplugged cable or stopped server)";
      case errc::port_busy: return "the serial port is in use by another program";
      case errc::unsupported_baud: return "the serial port cannot be set to that baud rate";
      case errc::no_board: return "no RCB-4 answered at 115200, 625000 or 1250000 baud";
      case errc::would_deadlock: return "blocking call from the thread that runs the client's executor";
      case errc::cancelled: return "the client was closed";
      case errc::reconnect_failed: return "the link was lost and could not be reopened (device still unplugged?)";
    }
    return "unknown rcb4.transport error";
  }
};

/** The single instance of the transport category. */
inline const std::error_category& error_category() noexcept {
  static const error_category_impl instance;
  return instance;
}

/** Makes a std::error_code from @p e. */
inline std::error_code make_error_code(errc e) noexcept { return {static_cast<int>(e), error_category()}; }

}  // namespace rcb4::transport

template <>
struct std::is_error_code_enum<rcb4::transport::errc> : std::true_type {};
