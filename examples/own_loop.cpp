// Your own transport: rcb4's operations driven by nothing but POSIX read/write/poll on a file
// descriptor, and the same loop over an in-memory link (a test double for your own tests).
//
//   rcb4_own_loop /dev/ttyUSB0     a board at 115200 baud (8E1), or a pty from `rcb4 serve --pty`
//   rcb4_own_loop --memory         the virtual board in memory: no device, no thread, no clock
//
// It reads the config word and every servo's state (ops::read_config, ops::read_servo_states).
// Exit status: 0 done; 1 the board refused (NACK) or its answers stayed malformed; 2 usage;
// 3 an I/O error (no such device, not a terminal); 4 the board was silent past the deadline.
//
// The contract (see the README, "Your own transport"):
//   - op.next() gives the command to send, or nothing when the operation is finished;
//   - send its frame, read one reply, and give it to op.on_reply(); then ask next() again;
//   - op.error() is errc{} on success, errc::nack when the board refused, or what was wrong.
// Framing: every reply starts with its length byte; rcb4::parse_reply() says how many bytes are
// still needed, so the reader never reads into the next frame. Deadlines are yours: every wait
// here is a poll() with what is left of a deadline.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/board/virtual_board.hpp>
#include <rcb4/ops/servos.hpp>
#include <rcb4/ops/system.hpp>

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

namespace {

using clock_type = std::chrono::steady_clock;

/** How an exchange ended when no reply came: the board was silent, or the descriptor failed. */
enum class link_status { ok, silent, io_error, malformed };

/** A serial line (or pty) as a file descriptor: raw, 8 data bits, even parity, 1 stop bit. */
class fd_link {
 public:
  /** Opens @p path; fd() is -1 and why() says why when that failed. */
  explicit fd_link(const char* path) : fd_(::open(path, O_RDWR | O_NOCTTY | O_CLOEXEC)) {
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
  fd_link(const fd_link&) = delete;
  fd_link& operator=(const fd_link&) = delete;
  ~fd_link() {
    if (fd_ >= 0) ::close(fd_);
  }
  /** The descriptor, or -1. */
  int fd() const noexcept { return fd_; }
  /** Why opening failed. */
  const std::string& why() const noexcept { return why_; }

  /** Writes all of @p bytes. */
  link_status send(std::span<const std::uint8_t> bytes) {
    ::tcflush(fd_, TCIFLUSH);  // a late reply to an earlier, abandoned exchange is not this one's
    while (!bytes.empty()) {
      const auto n = ::write(fd_, bytes.data(), bytes.size());
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) return link_status::io_error;
      bytes = bytes.subspan(static_cast<std::size_t>(n));
    }
    return link_status::ok;
  }
  /** Reads exactly @p out.size() bytes, each poll() bounded by @p deadline. */
  link_status receive(std::span<std::uint8_t> out, clock_type::time_point deadline) {
    while (!out.empty()) {
      const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - clock_type::now()).count();
      if (left <= 0) return link_status::silent;
      pollfd p{fd_, POLLIN, 0};
      const int r = ::poll(&p, 1, static_cast<int>(left));
      if (r < 0 && errno == EINTR) continue;
      if (r < 0 || (p.revents & (POLLERR | POLLNVAL))) return link_status::io_error;
      if (r == 0) return link_status::silent;
      const auto n = ::read(fd_, out.data(), out.size());  // never more than asked: no over-read
      if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
      if (n <= 0) return link_status::io_error;  // 0: hung up (unplugged adapter, closed pty)
      out = out.subspan(static_cast<std::size_t>(n));
    }
    return link_status::ok;
  }
  /** Drops bytes until the line has been quiet for 20 ms, for 200 ms at most (after a malformed reply). */
  void drain() {
    std::uint8_t junk[64];
    pollfd p{fd_, POLLIN, 0};
    const auto give_up = clock_type::now() + std::chrono::milliseconds(200);
    while (clock_type::now() < give_up && ::poll(&p, 1, 20) > 0 && ::read(fd_, junk, sizeof junk) > 0) {
    }
  }

 private:
  int fd_ = -1;
  std::string why_;
};

/**
 * The same interface over memory: what is sent goes to rcb4's virtual board (sans-I/O), what it
 * answers is read back. A test double for a program's own tests; a fixed byte script would do too.
 */
class memory_link {
 public:
  /** Passes @p bytes to the board; its replies queue up. */
  link_status send(std::span<const std::uint8_t> bytes) {
    now_ += std::chrono::milliseconds(1);  // board time: each exchange 1 ms later
    board_.receive(bytes, now_, queued_);
    return link_status::ok;
  }
  /** Takes exactly @p out.size() queued bytes; silent when fewer are queued (no clock needed). */
  link_status receive(std::span<std::uint8_t> out, clock_type::time_point) {
    if (queued_.size() < out.size()) return link_status::silent;
    std::copy_n(queued_.begin(), out.size(), out.begin());
    queued_.erase(queued_.begin(), queued_.begin() + static_cast<std::ptrdiff_t>(out.size()));
    return link_status::ok;
  }
  /** Drops what is queued. */
  void drain() { queued_.clear(); }

 private:
  rcb4::board::virtual_board board_;
  rcb4::board::board_time now_{};
  std::vector<std::uint8_t> queued_;
};

/**
 * One exchange: @p cmd out, its reply in, by @p timeout, read into @p rx. The reply returned
 * points into @p rx (a parsed reply references its bytes, it does not copy them): keep @p rx
 * alive until the operation has taken the reply. A malformed reply (bad checksum, wrong length
 * or echo) to a read is retried up to twice after draining the line; a write is not repeated (a
 * CALL sent twice would push the board's stack twice). Silence and I/O errors end it.
 */
template <class Link>
std::optional<rcb4::reply> exchange(Link& link, const rcb4::command& cmd, link_status& status,
                                    std::span<std::uint8_t, rcb4::max_reply_size> rx,
                                    std::chrono::milliseconds timeout = std::chrono::milliseconds(500)) {
  rcb4::request_frame frame;
  const auto n = rcb4::serialize(cmd, frame.storage());
  if (!n) {
    std::fprintf(stderr, "the command does not serialize (%s)\n", rcb4::message(n.error()));
    status = link_status::malformed;
    return std::nullopt;
  }
  frame.commit(*n);
  const auto shape = rcb4::expected_reply(cmd);
  const bool repeatable = shape.data || std::holds_alternative<rcb4::ping>(cmd);  // reads and ping only
  for (int attempt = 0; attempt < (repeatable ? 3 : 1); ++attempt) {
    if ((status = link.send(frame.bytes())) != link_status::ok) return std::nullopt;
    std::size_t have = 0;
    const auto deadline = clock_type::now() + timeout;
    for (;;) {
      const auto p = rcb4::parse_reply(rx.first(have), shape);
      if (p.ok()) return p.value();  // ACK, NACK or data: the operation decides what NACK means
      if (p.status == rcb4::parse_status::error) {
        const bool again = repeatable && attempt + 1 < 3;
        std::fprintf(stderr, "malformed reply (%s)%s\n", rcb4::message(p.error), again ? ", retrying" : "");
        link.drain();
        status = link_status::malformed;
        break;
      }
      if ((status = link.receive(rx.subspan(have, p.needed), deadline)) != link_status::ok) {
        if (status == link_status::silent && have > 0) {  // it began to answer, then stopped
          std::fprintf(stderr, "the reply stopped short after %zu bytes\n", have);
          status = link_status::malformed;
        }
        return std::nullopt;
      }
      have += p.needed;
    }
  }
  return std::nullopt;
}

/** Runs @p op to its end; the exit status of the first failure, or 0. */
template <class Link, class Op>
int run(Link& link, Op& op, const char* what) {
  std::array<std::uint8_t, rcb4::max_reply_size> rx{};  // outlives each reply given to op.on_reply()
  while (const auto c = op.next()) {
    link_status status{};
    const auto r = exchange(link, *c, status, std::span(rx));
    if (!r) {
      std::fprintf(stderr, "%s: %s\n", what,
                   status == link_status::silent     ? "the board did not answer within 500 ms"
                   : status == link_status::io_error ? "the line failed (unplugged?)"
                                                     : "malformed replies (named above), given up");
      return status == link_status::silent ? 4 : status == link_status::io_error ? 3 : 1;
    }
    op.on_reply(*r);
  }
  if (op.error() != rcb4::errc{}) {
    std::fprintf(stderr, "%s: %s\n", what, rcb4::message(op.error()));
    return 1;
  }
  return 0;
}

template <class Link>
int read_board(Link& link) {
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
    memory_link link;
    return read_board(link);
  }
  fd_link link(argv[1]);
  if (link.fd() < 0) {
    std::fprintf(stderr, "%s: %s\n", argv[1], link.why().c_str());
    return 3;
  }
  return read_board(link);
}
