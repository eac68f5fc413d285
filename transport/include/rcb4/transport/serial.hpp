// rcb4 — opening a serial port the way the RCB-4 needs it (Linux).
// SPDX-License-Identifier: BSL-1.0
//
// 8 data bits, even parity, 1 stop bit (protocol.md §1). Asio sets 8E1 and standard rates; for
// 625000 and 1250000 (which Asio rejects) termios2 BOTHER is applied last and read back. The
// port is taken exclusively (flock + TIOCEXCL) so a second program gets a clear "port busy"
// instead of garbled exchanges. FTDI adapters get ASYNC_LOW_LATENCY as a best effort; their
// latency timer (ms) is reported when sysfs shows it.
#pragma once

#include <rcb4/transport/error.hpp>

#include <boost/asio/io_context.hpp>
#include <boost/asio/serial_port.hpp>

#include <linux/serial.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <cerrno>
#include <cstdint>
#include <fstream>
#include <optional>
#include <string>

namespace rcb4::transport {

namespace detail {
// The kernel's struct termios2 (asm-generic layout, x86 and ARM), declared here because
// <asm/termbits.h> cannot be included together with <termios.h>.
struct kernel_termios2 {
  tcflag_t c_iflag, c_oflag, c_cflag, c_lflag;
  cc_t c_line;
  cc_t c_cc[19];
  speed_t c_ispeed, c_ospeed;
};
inline constexpr unsigned long tcgets2 = _IOR('T', 0x2A, kernel_termios2);
inline constexpr unsigned long tcsets2 = _IOW('T', 0x2B, kernel_termios2);
inline constexpr tcflag_t kernel_cbaud = 0010017;
inline constexpr tcflag_t kernel_bother = 0010000;

/** Sets an arbitrary rate with termios2 and returns the rate the driver reports back. */
inline std::optional<std::uint32_t> set_custom_baud(int fd, std::uint32_t baud) {
  kernel_termios2 t{};
  if (::ioctl(fd, tcgets2, &t) != 0) return std::nullopt;
  t.c_cflag &= ~kernel_cbaud;
  t.c_cflag |= kernel_bother;
  t.c_cflag &= ~static_cast<tcflag_t>(kernel_cbaud << 16);  // input rate follows the output rate
  t.c_ispeed = t.c_ospeed = baud;
  if (::ioctl(fd, tcsets2, &t) != 0) return std::nullopt;
  kernel_termios2 back{};
  if (::ioctl(fd, tcgets2, &back) != 0) return std::nullopt;
  return back.c_ospeed;
}
}  // namespace detail

/**
 * The serial port open_serial returns: Asio's, on the io_context's own executor type (not the
 * type-erased any_io_executor), so that the client's strand and handlers allocate nothing per
 * exchange. It converts to boost::asio::serial_port (by move) if you need that type.
 */
using serial_port = boost::asio::basic_serial_port<boost::asio::io_context::executor_type>;

/** What open_serial found out about the port. */
struct serial_info {
  std::uint32_t baud = 0;                    ///< rate read back from the driver
  bool low_latency = false;                  ///< ASYNC_LOW_LATENCY was set
  std::optional<unsigned> latency_timer_ms;  ///< FTDI latency timer, when sysfs shows one
};

/**
 * Opens @p path at @p baud (115200, 625000 or 1250000; others are allowed if the driver takes
 * them) with 8E1, raw, exclusive. On failure @p ec says why: transport::errc::port_busy when
 * another program holds it, unsupported_baud when the rate does not read back, or the OS error.
 */
inline serial_port open_serial(boost::asio::io_context& io, const std::string& path, std::uint32_t baud,
                               std::error_code& ec, serial_info* info = nullptr) {
  namespace asio = boost::asio;
  serial_port port(io);
  boost::system::error_code bec;
  port.open(path, bec);
  if (bec) {
    ec = bec;
    return port;
  }
  const int fd = port.native_handle();
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    ec = errno == EWOULDBLOCK ? std::error_code(errc::port_busy) : std::error_code(errno, std::generic_category());
    port.close(bec);
    return port;
  }
  ::ioctl(fd, TIOCEXCL);  // best effort: ptys and some drivers refuse it
  port.set_option(asio::serial_port_base::character_size(8), bec);
  if (!bec) port.set_option(asio::serial_port_base::parity(asio::serial_port_base::parity::even), bec);
  if (!bec) port.set_option(asio::serial_port_base::stop_bits(asio::serial_port_base::stop_bits::one), bec);
  if (!bec) port.set_option(asio::serial_port_base::flow_control(asio::serial_port_base::flow_control::none), bec);
  if (!bec) port.set_option(asio::serial_port_base::baud_rate(115200), bec);
  if (bec) {
    ec = bec;
    port.close(bec);
    return port;
  }
  const auto actual = detail::set_custom_baud(fd, baud);  // applied last, after Asio's settings
  if (!actual || (*actual > baud ? *actual - baud : baud - *actual) > baud / 50) {  // > 2 % off
    ec = errc::unsupported_baud;
    port.close(bec);
    return port;
  }
  serial_info si;
  si.baud = *actual;
  serial_struct ss{};
  if (::ioctl(fd, TIOCGSERIAL, &ss) == 0) {
    ss.flags = static_cast<int>(static_cast<unsigned>(ss.flags) | ASYNC_LOW_LATENCY);
    si.low_latency = ::ioctl(fd, TIOCSSERIAL, &ss) == 0;
  }
  const auto slash = path.rfind('/');
  std::ifstream timer("/sys/bus/usb-serial/devices/" + path.substr(slash + 1) + "/latency_timer");
  unsigned ms = 0;
  if (timer >> ms) si.latency_timer_ms = ms;
  ::tcflush(fd, TCIOFLUSH);
  if (info) *info = si;
  ec.clear();
  return port;
}

/** The rates the RCB-4 speaks, in the order detection tries them (HTH4 projects favour 1.25 M). */
inline constexpr std::uint32_t board_bauds[] = {1250000, 115200, 625000};

/** open_serial that throws std::system_error. */
inline serial_port open_serial(boost::asio::io_context& io, const std::string& path, std::uint32_t baud,
                               serial_info* info = nullptr) {
  std::error_code ec;
  auto p = open_serial(io, path, baud, ec, info);
  if (ec) throw std::system_error(ec, "open " + path);
  return p;
}

}  // namespace rcb4::transport
