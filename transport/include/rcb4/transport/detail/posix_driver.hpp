// rcb4 — the caller-thread driver: a blocking call on an idle line runs the exchange machine on
// its own thread, with POSIX calls on the stream's descriptor (no hand-off to the executor, no
// allocation). It pays for itself: a blocking exchange then costs what a bare write + read loop
// costs (the README's performance table).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/transport/detail/exchange_machine.hpp>
#include <rcb4/transport/options.hpp>

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <functional>
#include <optional>
#include <variant>

namespace rcb4::transport::detail {

/** A socket's protocol (to assign a released descriptor back), or nothing for other streams. */
template <class Stream>
struct protocol_of {
  using type = std::monostate;
};
template <class Stream>
requires requires { typename Stream::protocol_type; }
struct protocol_of<Stream> {
  using type = std::optional<typename Stream::protocol_type>;
};

/** True when @p fd is a socket (then it is written with send(MSG_NOSIGNAL), never write()). */
inline bool is_socket_fd(int fd) noexcept {
  struct stat st {};
  return ::fstat(fd, &st) == 0 && S_ISSOCK(st.st_mode);
}

/**
 * Writes @p b to @p fd without blocking; a socket (also one wrapped as a plain descriptor) with
 * MSG_NOSIGNAL, so that a peer that has gone is EPIPE, never a SIGPIPE that kills the process.
 */
inline ssize_t write_nosignal(int fd, bool socket, std::span<const std::uint8_t> b) noexcept {
  return socket ? ::send(fd, b.data(), b.size(), MSG_NOSIGNAL) : ::write(fd, b.data(), b.size());
}

/**
 * One write of @p b to the non-blocking @p fd (see write_nosignal), both drivers' first try:
 * what it wrote or the error, or nothing when the descriptor has no room yet.
 */
inline std::optional<io_result> try_write(int fd, bool socket, std::span<const std::uint8_t> b) noexcept {
  for (;;) {
    const ssize_t n = write_nosignal(fd, socket, b);
    if (n >= 0) return io_result{static_cast<std::size_t>(n)};
    if (errno == EINTR) continue;
    if (errno == EAGAIN || errno == EWOULDBLOCK) return std::nullopt;
    return io_result{0, os_error(errno)};
  }
}

/**
 * True when @p fd is a terminal whose reads a VTIME bound limits: not a pseudo-terminal's master
 * side, whose termios settings belong to the slave (a read there would block without limit).
 */
inline bool is_bounded_tty(int fd) noexcept {
  unsigned pty_number = 0;
  return ::isatty(fd) == 1 && ::ioctl(fd, TIOCGPTN, &pty_number) != 0;
}

/**
 * True when @p fd is a terminal that marks a damaged byte and doubles an intact 0xFF (PARMRK
 * without ISTRIP: what open_serial sets, serial.hpp): its reads are decoded (line_marks.hpp).
 * Not a pseudo-terminal's master side, whose reads are the slave's output, never marked.
 */
inline bool is_marked_tty(int fd) noexcept {
  termios t{};
  return is_bounded_tty(fd) && ::tcgetattr(fd, &t) == 0 && (t.c_iflag & PARMRK) != 0 && (t.c_iflag & ISTRIP) == 0;
}

/** Runs exchanges on the calling thread over the descriptor of a @p Stream. */
template <class Stream>
class posix_driver {
 public:
  /** Streams with a descriptor (serial ports, descriptors, sockets): the only ones it can drive. */
  static constexpr bool has_descriptor = requires(Stream & s) {
    { s.native_handle() } -> std::convertible_to<int>;
  };
  /** Sockets are written with send(MSG_NOSIGNAL): a closed peer is an error, never SIGPIPE. */
  static constexpr bool is_socket = requires(Stream & s) { s.remote_endpoint(); };
  /** Streams whose descriptor can leave the reactor and come back (see park). */
  static constexpr bool can_park = has_descriptor && requires(Stream & s) {
    { s.release() } -> std::convertible_to<int>;
  };
  /** Reopens a lost link (basic_client::set_reconnect). */
  using reopen_function = std::function<void(Stream&, error_code&)>;

  /** Runs @p req to its end on this thread, which owns the line; the reply is in @p m. */
  error_code run(Stream& s, exchange_machine& m, const client_options& opt, const request& req,
                 const reopen_function& reopen) {
    park(s);
    m.set_marked(marked(s));
    const auto stray = bytes_waiting(s);
    auto a = m.start(req, clock::now(), stray);
    for (;;) {
      io_result r;  // (performed first, then the time read: argument order is unspecified)
      switch (a.what) {
        case action::kind::write: r = write_before(s, a); break;
        case action::kind::read: r = read_before(s, a, opt); break;
        case action::kind::reopen:
          r = reopen_line(s, a.deadline, reopen);
          if (!r.ec) m.set_marked(marked(s));
          break;
        case action::kind::done: return a.ec;
      }
      a = m.resume(r, clock::now());
    }
  }

  /** Whether the stream's reads are marked (a serial line open_serial set up): once per descriptor. */
  bool marked(Stream& s) {
    if constexpr (has_descriptor) {
      return line_fd(s) >= 0 && fd_.marked;
    } else {
      (void)s;
      return false;
    }
  }

  /** Bytes already waiting on the line (0 when the stream cannot tell). */
  std::size_t bytes_waiting(Stream& s) {
    if constexpr (has_descriptor) {
      int n = 0;
      return ::ioctl(line_fd(s), FIONREAD, &n) == 0 && n > 0 ? static_cast<std::size_t>(n) : 0;
    } else if constexpr (requires(boost::system::error_code & e) { s.available(e); }) {
      boost::system::error_code e;
      return s.available(e);
    } else {
      return 0;
    }
  }

  /**
   * Takes the descriptor out of the reactor while a calling thread owns the line. Asio watches
   * a descriptor from the moment its stream opens it; left there, every reply a caller's
   * blocking read takes would also wake the executor's thread in epoll_wait (edge triggered,
   * for nothing): on a fast line that costs about as much as the client's own work. The stream
   * releases it (the number stays) and unpark() assigns it back before the worker uses it.
   */
  void park(Stream& s) {
    if constexpr (can_park) {
      if (parked_ >= 0 || !s.is_open()) return;
      boost::system::error_code e;
      if constexpr (is_socket) protocol_.emplace(s.local_endpoint(e).protocol());
      if (e) return;  // it stays in the stream: the exchange reports what is wrong with it
      if constexpr (requires { s.release(e); })
        parked_ = s.release(e);  // (a socket's; it fails on no POSIX system)
      else
        parked_ = s.release();
      if (e) parked_ = -1;
    }
  }
  /** Gives a parked descriptor back to the stream (and the reactor), non-blocking as Asio needs it. */
  void unpark(Stream& s) {
    if (fd_.blocking) {  // a bounded tty read left it blocking
      ::fcntl(fd_.fd, F_SETFL, fd_.flags);
      fd_.blocking = false;
    }
    if constexpr (can_park) {
      if (parked_ < 0) return;
      boost::system::error_code e;
      if constexpr (is_socket)
        s.assign(*protocol_, parked_, e);
      else
        s.assign(parked_, e);
      if (e) ::close(parked_);  // the stream stays closed: the next exchange reports it
      parked_ = -1;
    }
  }
  /** The stream's descriptor may have been replaced: its settings are checked again before use. */
  void forget() noexcept { fd_ = descriptor{}; }

  /**
   * The client is going away: a terminal's exclusive mode (TIOCEXCL, which open_serial sets)
   * is cleared, since it outlives this descriptor while anyone else holds the terminal open (a
   * pty's server) and would turn the next open by a user without root into EBUSY; then the
   * stream, or its parked descriptor, is closed.
   */
  void let_go(Stream& s) {
    if constexpr (has_descriptor) {
      const int fd = line_fd(s);
      if (fd >= 0 && ::isatty(fd) == 1) ::ioctl(fd, TIOCNXCL);
      // Reads as open_serial left them (VMIN 1), not as the bounded reads set them; and unmarked:
      // a terminal keeps its settings after the last close, and a program that opens it next
      // without clearing PARMRK (Python's tty.setraw does not) would read each FF twice.
      termios t{};
      if (fd >= 0 && fd_.fd == fd && (fd_.vtime != 0 || fd_.marked) && ::tcgetattr(fd, &t) == 0) {
        if (fd_.vtime != 0) {
          t.c_cc[VMIN] = 1;
          t.c_cc[VTIME] = 0;
        }
        if (fd_.marked) t.c_iflag &= ~static_cast<tcflag_t>(PARMRK);
        ::tcsetattr(fd, TCSANOW, &t);  // (best effort: the descriptor is going)
      }
    }
    if constexpr (can_park) {
      if (parked_ >= 0) ::close(parked_);
      parked_ = -1;
    }
    fd_ = descriptor{};
    boost::system::error_code ignored;
    s.close(ignored);
  }

 private:
  /** The settings of the descriptor this driver relies on, checked once per descriptor. */
  struct descriptor {
    int fd = -1;
    int flags = 0;          // file status flags, O_NONBLOCK included
    bool tty = false;       // a terminal: reads can block with a VTIME bound
    bool socket = false;    // a socket (maybe wrapped as a plain descriptor): written with send()
    cc_t vtime = 0;         // the VTIME last set (VMIN is 0 once any is set)
    bool blocking = false;  // O_NONBLOCK is off (left so by bounded reads until unpark)
    bool marked = false;    // reads are PARMRK-marked (is_marked_tty)
  };

  /** The line's descriptor, parked or in the stream; made non-blocking once per descriptor. */
  int line_fd(Stream& s) {
    int fd = -1;
    if constexpr (can_park)
      if (parked_ >= 0) fd = parked_;
    if (fd < 0) fd = s.native_handle();
    if (fd >= 0 && fd != fd_.fd) {
      fd_ = descriptor{fd, ::fcntl(fd, F_GETFL), !is_socket && is_bounded_tty(fd), is_socket || is_socket_fd(fd)};
      fd_.marked = !fd_.socket && is_marked_tty(fd);
      if (fd_.flags >= 0 && (fd_.flags & O_NONBLOCK) == 0) ::fcntl(fd, F_SETFL, fd_.flags | O_NONBLOCK);
      fd_.flags |= O_NONBLOCK;
    }
    return fd;
  }

  /** Waits until @p fd is ready for @p events: false when @p deadline passes first. Polls without sleeping in
   * [spin_from, spin_until). */
  static bool ready_before(int fd, short events, clock::time_point deadline, error_code& ec,
                           clock::time_point spin_from = {}, clock::time_point spin_until = {}) {
    for (;;) {
      const auto now = clock::now();
      if (now >= deadline) return false;
      const auto until = now < spin_from ? std::min(spin_from, deadline) : now < spin_until ? now : deadline;
      const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(until - now).count();
      const timespec ts{static_cast<time_t>(left / 1'000'000'000), static_cast<long>(left % 1'000'000'000)};
      pollfd p{fd, events, 0};
      const int r = ::ppoll(fd >= 0 ? &p : nullptr, fd >= 0 ? 1 : 0, &ts, nullptr);
      if (r > 0) {
        if (p.revents & POLLNVAL) ec = os_error(EBADF);
        return true;  // ready, or an error/hang-up that the read or write reports
      }
      if (r < 0 && errno != EINTR) {
        ec = os_error(errno);
        return true;
      }
    }
  }

  io_result write_before(Stream& s, const action& a) {
    const int fd = line_fd(s);
    if (fd < 0) return {0, os_error(EBADF)};
    for (;;) {
      if (auto r = try_write(fd, fd_.socket, a.out)) return *r;
      error_code ec;
      if (!ready_before(fd, POLLOUT, a.deadline, ec)) return {0, {}, true};
      if (ec) return {0, ec};
    }
  }

  io_result read_before(Stream& s, const action& a, const client_options& opt) {
    const int fd = line_fd(s);
    if (fd < 0) return {0, os_error(EBADF)};
    clock::time_point spin_from{}, spin_until{};  // none: sleep until the reply comes
    if (opt.busy_poll.count() > 0) {
      spin_from = a.expected - opt.busy_poll;
      spin_until = a.expected + opt.busy_poll;
    }
    for (;;) {
      // A tty with whole tenths of a second left blocks in read() for at most those tenths (a
      // blocking read wakes sooner than ppoll + read); the last fraction goes to ppoll.
      const auto tenths =
          fd_.tty && opt.busy_poll.count() == 0
              ? std::min<std::int64_t>(255, (a.deadline - clock::now()) / std::chrono::milliseconds(100))
              : 0;
      ssize_t n;
      if (tenths > 0) {
        n = bounded_tty_read(a.in, static_cast<cc_t>(tenths));
        if (n == -2) continue;  // its tenths passed with nothing: the rest of the time goes to ppoll
        if (n == -3) return {0, transport_errc::settings_not_kept};  // another program cooked the line
      } else {
        error_code ec;
        if (!ready_before(fd, POLLIN, a.deadline, ec, spin_from, spin_until)) return {0, {}, true};
        if (ec) return {0, ec};
        n = ::read(fd, a.in.data(), a.in.size());
      }
      if (n > 0) return {static_cast<std::size_t>(n)};
      if (n == 0) return {0, boost::asio::error::eof};  // the other side has gone
      if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) return {0, os_error(errno)};
    }
  }

  /**
   * A tty read that blocks for at most @p tenths of a second, the terminal's own timer (VMIN 0,
   * VTIME): -2 when that passed with nothing read, -3 when the line is cooked (ICANON: another
   * program changed it), else read()'s result. The descriptor stays
   * blocking for the next exchanges on this thread (their writes cannot block: the previous
   * request has left, since its reply came); unpark() makes it non-blocking for the worker.
   */
  ssize_t bounded_tty_read(std::span<std::uint8_t> buf, cc_t tenths) {
    const int fd = fd_.fd;
    // The terminal's settings are read every time: another program (stty, a terminal, pyserial)
    // may have changed them, and a read on a line no longer set as this one expects would block
    // for ever (VMIN 1) or until a newline (a cooked line). A cooked line is reported (-3).
    termios t{};
    if (::tcgetattr(fd, &t) != 0) return -1;
    if ((t.c_lflag & ICANON) != 0) return -3;
    if (t.c_cc[VMIN] != 0 || t.c_cc[VTIME] != tenths || fd_.vtime != tenths) {
      t.c_cc[VMIN] = 0;
      t.c_cc[VTIME] = tenths;
      if (::tcsetattr(fd, TCSANOW, &t) != 0) return -1;
      fd_.vtime = tenths;
    }
    if (!fd_.blocking) {
      if (::fcntl(fd, F_SETFL, fd_.flags & ~O_NONBLOCK) != 0) return -1;
      fd_.blocking = true;
    }
    const auto began = clock::now();
    const ssize_t n = ::read(fd, buf.data(), buf.size());
    if (n != 0) return n;
    // Nothing: the timer ran out, or the terminal hung up (then read returns 0 at once).
    return clock::now() - began >= std::chrono::milliseconds(100 * tenths - 20) ? -2 : 0;
  }

  /** Waits until @p not_before (a backoff), then reopens the link with @p reopen. */
  io_result reopen_line(Stream& s, clock::time_point not_before, const reopen_function& reopen) {
    error_code ec;
    while (clock::now() < not_before) ready_before(-1, 0, not_before, ec);  // no descriptor: a bounded wait
    unpark(s);  // the stream owns its descriptor again: the reopen replaces it
    fd_ = descriptor{};
    ec.clear();
    reopen(s, ec);
    if (!ec) park(s);
    return {0, ec};
  }

  int parked_ = -1;  // the descriptor while out of the reactor, else -1
  [[no_unique_address]] typename protocol_of<Stream>::type protocol_{};  // a parked socket's
  descriptor fd_{};
};

}  // namespace rcb4::transport::detail
