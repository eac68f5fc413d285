// rcb4 — opening a serial port the way the RCB-4 needs it (Linux).
// SPDX-License-Identifier: BSL-1.0
//
// 8 data bits, even parity, 1 stop bit, raw (protocol.md §1), set with termios; the rate
// (115200, 625000, 1250000: the last two are not standard termios rates) with termios2 BOTHER,
// applied last and read back. The port is taken exclusively (flock + TIOCEXCL) so a second
// program gets a clear "port busy" instead of garbled exchanges. FTDI adapters get
// ASYNC_LOW_LATENCY as a best effort; their latency timer (ms) is reported when sysfs shows it.
// The port is an Asio stream descriptor: the client can take it out of the reactor
// (release/assign) while blocking calls do their I/O on the caller's thread.
#pragma once

#include <rcb4/transport/error.hpp>

#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>

#include <fcntl.h>
#include <unistd.h>

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
 * The serial port open_serial returns: an Asio stream descriptor on the io_context's own
 * executor type (not the type-erased any_io_executor), so that the client's strand and
 * handlers allocate nothing per exchange, and with release()/assign(), so that the client can
 * take the descriptor out of the reactor while its blocking calls use it (see basic_client).
 * Its settings are termios (tcgetattr, or detail::set_custom_baud for the rate).
 */
using serial_port = boost::asio::posix::basic_stream_descriptor<boost::asio::io_context::executor_type>;

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
  serial_port port(io);
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {  // EBUSY: another program holds the terminal in exclusive mode (TIOCEXCL)
    ec = errno == EBUSY ? std::error_code(errc::port_busy) : std::error_code(errno, std::generic_category());
    return port;
  }
  const auto fail = [&](std::error_code e) {
    ec = e;
    ::close(fd);
    return std::move(port);
  };
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0)
    return fail(errno == EWOULDBLOCK ? std::error_code(errc::port_busy)
                                     : std::error_code(errno, std::generic_category()));
  ::ioctl(fd, TIOCEXCL);  // best effort: ptys and some drivers refuse it
  termios t{};
  if (::tcgetattr(fd, &t) != 0) return fail(std::error_code(errno, std::generic_category()));
  ::cfmakeraw(&t);                       // no echo, no line editing, no translations, 8 bits
  t.c_cflag |= CREAD | CLOCAL | PARENB;  // receive; ignore modem lines; even parity (PARODD off)
  t.c_cflag &= ~static_cast<tcflag_t>(PARODD | CSTOPB | CRTSCTS);  // one stop bit, no RTS/CTS
  t.c_iflag &= ~static_cast<tcflag_t>(IGNPAR | PARMRK | IXON | IXOFF);
  t.c_iflag |= INPCK;  // check parity: a bad byte reads as 0, and the frame's checksum rejects it
  t.c_cc[VMIN] = 1;    // (VMIN 0 with VTIME 0 would make an empty read return 0, as at end of file)
  t.c_cc[VTIME] = 0;
  ::cfsetispeed(&t, B115200);
  ::cfsetospeed(&t, B115200);
  if (::tcsetattr(fd, TCSANOW, &t) != 0) return fail(std::error_code(errno, std::generic_category()));
  const auto actual = detail::set_custom_baud(fd, baud);  // applied last, after the termios settings
  if (!actual || (*actual > baud ? *actual - baud : baud - *actual) > baud / 50)  // > 2 % off
    return fail(errc::unsupported_baud);
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
  boost::system::error_code bec;
  port.assign(fd, bec);
  if (bec) return fail(bec);
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
