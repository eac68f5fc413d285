// Your own transport: rcb4's operations driven by nothing but POSIX read/write/poll on a file
// descriptor, and the same loop over an in-memory link (a test double for your own tests). The
// link's policy (deadlines, resync after an error, retries for reads, a write sent once, a
// loopback named) is not written here: rcb4/link/device_link.hpp runs the library's public
// exchange machine over any device that can write and read bytes without waiting.
//
//   rcb4_own_loop /dev/ttyUSB0     a board at 115200 baud (8E1), or a pty from `rcb4 serve --pty`
//   rcb4_own_loop --memory         the virtual board in memory: no device, no thread
//
// It reads the config word and every servo's state (ops::read_config, ops::read_servo_states).
// Exit status: 0 done; 1 the board refused (NACK) or its answers stayed malformed; 2 usage;
// 3 an I/O error (no such device, not a terminal, unplugged); 4 the board was silent past the
// deadlines.
//
// What a device gives the link (see device_link.hpp): write() and read() that never wait (bytes
// taken or read, 0 for none now, negative when the device failed), and optionally
// idle(until, waiting), which waits for input, room to write or time until a deadline (here:
// poll()).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/board/virtual_board.hpp>
#include <rcb4/link/device_link.hpp>
#include <rcb4/link/requests.hpp>
#include <rcb4/ops/servos.hpp>
#include <rcb4/ops/system.hpp>

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <span>
#include <string>
#include <vector>

namespace {

using clock_type = std::chrono::steady_clock;

/** A serial line (or pty) as a non-blocking file descriptor: raw, 8 data bits, even parity, 1 stop bit. */
class fd_device {
 public:
  /** Opens @p path; fd() is -1 and why() says why when that failed. */
  explicit fd_device(const char* path) : fd_(::open(path, O_RDWR | O_NOCTTY | O_CLOEXEC | O_NONBLOCK)) {
    if (fd_ < 0) {
      why_ = std::strerror(errno);
      return;
    }
    termios t{};
    if (::tcgetattr(fd_, &t) != 0) {
      why_ = "not a serial port (" + std::string(std::strerror(errno)) + ")";
      ::close(fd_);
      fd_ = -1;
      return;
    }
    ::cfmakeraw(&t);
    t.c_cflag |= PARENB | CLOCAL | CREAD;  // 8E1 (protocol.md §1); 625k/1.25M need termios2 BOTHER
    t.c_cflag &= ~static_cast<tcflag_t>(PARODD | CSTOPB);
    ::cfsetspeed(&t, B115200);
    ::tcsetattr(fd_, TCSANOW, &t);
  }
  fd_device(const fd_device&) = delete;
  fd_device& operator=(const fd_device&) = delete;
  ~fd_device() {
    if (fd_ >= 0) ::close(fd_);
  }
  /** The descriptor, or -1. */
  int fd() const noexcept { return fd_; }
  /** Why opening failed. */
  const std::string& why() const noexcept { return why_; }

  /** Bytes of @p out the line took now; -1: it failed. */
  long write(std::span<const std::uint8_t> out) {
    for (;;) {
      const auto n = ::write(fd_, out.data(), out.size());
      if (n >= 0) return static_cast<long>(n);
      if (errno == EINTR) continue;
      return errno == EAGAIN || errno == EWOULDBLOCK ? 0 : -1;
    }
  }
  /** Bytes waiting, into @p in (never more than asked: no over-read); -1: hung up or failed. */
  long read(std::span<std::uint8_t> in) {
    for (;;) {
      const auto n = ::read(fd_, in.data(), in.size());
      if (n > 0) return static_cast<long>(n);
      if (n == 0) return -1;  // hung up (an unplugged adapter, a closed pty)
      if (errno == EINTR) continue;
      return errno == EAGAIN || errno == EWOULDBLOCK ? 0 : -1;
    }
  }
  /** Waits for @p w (input, room to write, or only time), until @p until at most (the link's deadline). */
  void idle(clock_type::time_point until, rcb4::link::waiting w) {
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(until - clock_type::now()).count();
    pollfd p{fd_, static_cast<short>(w == rcb4::link::waiting::output ? POLLOUT : POLLIN), 0};
    ::poll(&p, w == rcb4::link::waiting::time ? 0 : 1, static_cast<int>(std::clamp<long long>(left, 0, 1000)));
  }

 private:
  int fd_ = -1;
  std::string why_;
};

/**
 * The same over memory: what is written goes to rcb4's virtual board (sans-I/O), what it answers
 * is read back at once. A test double for a program's own tests; a fixed byte script would do too.
 */
class memory_device {
 public:
  /** Gives @p out to the board; its replies queue up. */
  long write(std::span<const std::uint8_t> out) {
    now_ += std::chrono::milliseconds(1);  // board time: each write 1 ms later
    board_.receive(out, now_, queued_);
    return static_cast<long>(out.size());
  }
  /** What the board answered, into @p in. */
  long read(std::span<std::uint8_t> in) {
    const auto n = std::min(in.size(), queued_.size());
    std::copy_n(queued_.begin(), n, in.begin());
    queued_.erase(queued_.begin(), queued_.begin() + static_cast<std::ptrdiff_t>(n));
    return static_cast<long>(n);
  }

 private:
  rcb4::board::virtual_board board_;
  rcb4::board::board_time now_{};
  std::vector<std::uint8_t> queued_;
};

/** Says on stderr what went wrong with each attempt, and that another follows. */
struct stderr_observer : rcb4::link::no_observer {
  void count(rcb4::link::counter c, std::size_t = 1) noexcept {
    if (c == rcb4::link::counter::retries) std::fprintf(stderr, "  retrying\n");
  }
  void attempt_failed(rcb4::errc e) noexcept { std::fprintf(stderr, "  attempt failed: %s\n", rcb4::message(e)); }
};

/** The exit status for a failure (see the top of this file). */
int exit_status(rcb4::errc e) {
  switch (e) {
    case rcb4::errc::link_timeout: return 4;
    case rcb4::errc::link_closed:
    case rcb4::errc::link_lost:
    case rcb4::errc::link_io_error:
    case rcb4::errc::link_reconnect_failed: return 3;
    default: return 1;
  }
}

/** Runs @p op to its end over @p link; the exit status of a failure, or 0. */
template <class Link, class Op>
int run(Link& link, Op& op, const char* what) {
  const auto e = rcb4::link::run(link, op);
  if (e == rcb4::errc{}) return 0;
  std::fprintf(stderr, "%s: %s\n", what, rcb4::message(e));
  return exit_status(e);
}

template <class Device>
int read_board(Device& device) {
  rcb4::link::options opt;
  opt.baud = 115200;
  opt.turnaround = std::chrono::milliseconds(500);  // each attempt's deadline: the wire time and this
  rcb4::link::device_link<Device, clock_type, stderr_observer> link(device, opt);
  rcb4::ops::read_config config;
  if (const int rc = run(link, config, "read config")) return rc;
  std::printf("config word 0x%04X: COM %u baud, output period %u ms\n", config.value().encode(),
              static_cast<unsigned>(rcb4::bits_per_second(config.value().com_baud)),
              rcb4::milliseconds(config.value().period));
  rcb4::ops::read_servo_states servos;
  if (const int rc = run(link, servos, "read servos")) return rc;
  std::printf("%zu servos in %zu planned reads after the allocation table\n", servos.value().size(),
              servos.plan().size());
  for (const auto& s : servos.value())
    std::printf("  ICS %2u  position %5u  target %5u\n", static_cast<unsigned>(s.ics.value()),
                static_cast<unsigned>(s.position), static_cast<unsigned>(s.target));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: rcb4_own_loop DEVICE | --memory\n");
    return 2;
  }
  if (std::string(argv[1]) == "--memory") {
    memory_device device;
    return read_board(device);
  }
  fd_device device(argv[1]);
  if (device.fd() < 0) {
    std::fprintf(stderr, "%s: %s\n", argv[1], device.why().c_str());
    return 3;
  }
  return read_board(device);
}
