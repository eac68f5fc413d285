// rcb4 — opening a serial port the way the RCB-4 needs it (Linux).
// SPDX-License-Identifier: BSL-1.0
//
// 8 data bits, even parity, 1 stop bit, raw (protocol.md §1) and the rate (115200, 625000,
// 1250000: the last two are not standard termios rates, so BOTHER) are set in one TCSETS2 and
// read back; glibc's tcsetattr is not used, since it reports EINVAL when a driver drops a flag
// (a pseudo-terminal always drops PARENB), which made a pty another program had configured
// impossible to open. The port is taken exclusively (flock + TIOCEXCL) so a second
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
inline constexpr tcflag_t kernel_cibaud = kernel_cbaud << 16;  // the input rate's field (IBSHIFT 16)

/**
 * The output rate set on the terminal @p fd, as termios2 reads it back (for a pty's master: the
 * rate its user set on the other end); 0 when it cannot be read.
 */
inline std::uint32_t line_rate(int fd) noexcept {
  kernel_termios2 t{};
  if (::ioctl(fd, tcgets2, &t) != 0) return 0;
  return t.c_ospeed;
}

/** True when @p got is within 2 % of @p want (what a UART's divisor can reach). */
constexpr bool rate_close(std::uint32_t got, std::uint32_t want) noexcept {
  return (got > want ? got - want : want - got) <= want / 50;
}

/**
 * The RCB-4's line (protocol.md §1) on top of @p t: 8 data bits, even parity, 1 stop bit, raw
 * (no echo, no line editing, no translations, no flow control), receiver on, modem lines
 * ignored, parity checked and a damaged byte marked (INPCK + PARMRK: FF 00 X, and an intact FF
 * doubled; line_marks.hpp decodes it: without PARMRK Linux would hand the byte over as 0x00, a
 * valid value), the rate @p baud as an arbitrary rate (BOTHER) for input and output, and reads
 * that wait for one byte (VMIN 1, VTIME 0: with VMIN 0 an empty non-blocking read returns 0, as
 * at end of file).
 */
inline void make_rcb4_line(kernel_termios2& t, std::uint32_t baud) noexcept {
  t.c_iflag &= ~static_cast<tcflag_t>(IGNBRK | BRKINT | ISTRIP | INLCR | IGNCR | ICRNL | IXON | IXOFF | IXANY | IGNPAR |
                                      IUCLC | IMAXBEL);
  t.c_iflag |= INPCK | PARMRK;
  t.c_oflag &= ~static_cast<tcflag_t>(OPOST);
  t.c_lflag &= ~static_cast<tcflag_t>(ECHO | ECHOE | ECHOK | ECHONL | ICANON | ISIG | IEXTEN);
  t.c_cflag &=
      ~static_cast<tcflag_t>(CSIZE | PARODD | CSTOPB | CRTSCTS | CMSPAR | HUPCL | kernel_cbaud | kernel_cibaud);
  t.c_cflag |= CS8 | PARENB | CREAD | CLOCAL | kernel_bother;
  t.c_ispeed = t.c_ospeed = baud;
  t.c_cc[VMIN] = 1;
  t.c_cc[VTIME] = 0;
}

/** True when input flags @p iflag mark a damaged byte and double an intact 0xFF (line_marks.hpp). */
constexpr bool iflag_marks(tcflag_t iflag) noexcept { return (iflag & PARMRK) != 0 && (iflag & ISTRIP) == 0; }

/** True when the terminal @p fd marks damaged bytes (iflag_marks): its reads go through line_marks. */
inline bool is_marked(int fd) noexcept {
  kernel_termios2 t{};
  return ::ioctl(fd, tcgets2, &t) == 0 && iflag_marks(t.c_iflag);
}

/**
 * Takes the marks off @p fd's input (PARMRK), as a program that is done with the port leaves it:
 * a terminal keeps its settings after the last close, and a program that opens it next without
 * clearing PARMRK (Python's tty.setraw does not) would read each FF twice. Best effort.
 */
inline void unmark(int fd) noexcept {
  kernel_termios2 t{};
  if (::ioctl(fd, tcgets2, &t) != 0 || (t.c_iflag & PARMRK) == 0) return;
  t.c_iflag &= ~static_cast<tcflag_t>(PARMRK);
  (void)::ioctl(fd, tcsets2, &t);
}

/**
 * Sets @p fd to the RCB-4's line at @p baud with TCSETS2 (no library layer in between that
 * could refuse a setting the driver drops), reads everything back and checks it. Returns
 * errc-free with the rate read back and whether parity was kept (a pseudo-terminal has no
 * parity and always drops PARENB: that is reported, not refused).
 */
inline error_code set_rcb4_line(int fd, std::uint32_t baud, std::uint32_t& rate, bool& parity) {
  kernel_termios2 t{};
  if (::ioctl(fd, tcgets2, &t) != 0) return os_error(errno);
  make_rcb4_line(t, baud);
  if (::ioctl(fd, tcsets2, &t) != 0) return os_error(errno);
  kernel_termios2 back{};
  if (::ioctl(fd, tcgets2, &back) != 0) return os_error(errno);
  rate = back.c_ospeed;
  parity = (back.c_cflag & PARENB) != 0 && (back.c_cflag & PARODD) == 0;
  if (!rate_close(back.c_ospeed, baud)) return transport_errc::rate_not_set;
  const bool raw = (back.c_lflag & (ICANON | ECHO | ISIG | IEXTEN)) == 0 && (back.c_oflag & OPOST) == 0 &&
                   (back.c_iflag & (IXON | IXOFF | ICRNL | INLCR | IGNCR | ISTRIP | IGNPAR)) == 0 &&
                   iflag_marks(back.c_iflag);
  const bool frame = (back.c_cflag & CSIZE) == CS8 && (back.c_cflag & CSTOPB) == 0 && (back.c_cflag & CRTSCTS) == 0;
  if (!raw || !frame || back.c_cc[VMIN] != 1 || back.c_cc[VTIME] != 0) return transport_errc::settings_not_kept;
  return {};
}

/** Sets an arbitrary rate with termios2, everything else unchanged; the rate read back. */
inline std::optional<std::uint32_t> set_custom_baud(int fd, std::uint32_t baud) {
  kernel_termios2 t{};
  if (::ioctl(fd, tcgets2, &t) != 0) return std::nullopt;
  t.c_cflag &= ~static_cast<tcflag_t>(kernel_cbaud | kernel_cibaud);
  t.c_cflag |= kernel_bother;
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
 * Its settings are termios2 (detail::set_custom_baud for the rate).
 */
using serial_port = boost::asio::posix::basic_stream_descriptor<boost::asio::io_context::executor_type>;

/** What open_serial found out about the port. */
struct serial_info {
  std::uint32_t baud = 0;                    ///< rate read back from the driver
  bool parity = false;                       ///< even parity kept (false on a pseudo-terminal, which has none)
  bool low_latency = false;                  ///< ASYNC_LOW_LATENCY was set
  std::optional<unsigned> latency_timer_ms;  ///< FTDI latency timer, when sysfs shows one
};

/**
 * Opens @p path at @p baud (115200, 625000 or 1250000; others are allowed if the driver takes
 * them) with 8E1, raw, exclusive, whatever state another program left the terminal in (cooked,
 * raw, another rate, BOTHER). On failure @p ec says why: transport_errc::port_busy when another
 * program holds it, rate_not_set when the rate does not read back, settings_not_kept when the
 * driver drops raw mode or 8N1 framing, or the OS error (ENOENT: no such device; ENOTTY: not a
 * terminal; EACCES: permission; EISDIR ...). A port that cannot keep parity (a pseudo-terminal)
 * opens, with serial_info::parity false.
 */
inline serial_port open_serial(boost::asio::io_context& io, const std::string& path, std::uint32_t baud, error_code& ec,
                               serial_info* info = nullptr) {
  serial_port port(io);
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {  // EBUSY: another program holds the terminal in exclusive mode (TIOCEXCL)
    ec = errno == EBUSY ? error_code(transport_errc::port_busy) : os_error(errno);
    return port;
  }
  const auto fail = [&](error_code e) {
    ec = e;
    ::close(fd);
    return std::move(port);
  };
  if (::isatty(fd) != 1) return fail(os_error(ENOTTY));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0)
    return fail(errno == EWOULDBLOCK ? error_code(transport_errc::port_busy) : os_error(errno));
  ::ioctl(fd, TIOCEXCL);  // best effort: some drivers refuse it
  serial_info si;
  if (const auto e = detail::set_rcb4_line(fd, baud, si.baud, si.parity)) return fail(e);
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

/** open_serial that throws system_error. */
inline serial_port open_serial(boost::asio::io_context& io, const std::string& path, std::uint32_t baud,
                               serial_info* info = nullptr) {
  error_code ec;
  auto p = open_serial(io, path, baud, ec, info);
  if (ec) throw system_error(ec, "open " + path);
  return p;
}

}  // namespace rcb4::transport
