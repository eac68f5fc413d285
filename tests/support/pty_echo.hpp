// The raw pty floor for benchmarks: an Asio echo on a pty master, and a blocking client loop
// that measures round trips on any pty path (the echo's or a server's).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/ops.hpp>
#include <rcb4/transport/pty.hpp>

#include <boost/asio.hpp>

#include <chrono>
#include <future>
#include <span>
#include <string>
#include <vector>

namespace rcb4::testing {

/** Opens @p path read-write in raw mode (the caller closes it); -1 on failure. */
inline int open_raw(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY);
  termios t{};
  ::tcgetattr(fd, &t);
  ::cfmakeraw(&t);
  ::tcsetattr(fd, TCSANOW, &t);
  return fd;
}

/** Writes @p request on @p fd, then reads exactly @p reply.size() bytes into @p reply; false on failure. */
inline bool raw_round_trip(int fd, std::span<const std::uint8_t> request, std::span<std::uint8_t> reply) {
  if (::write(fd, request.data(), request.size()) != static_cast<ssize_t>(request.size())) return false;
  std::size_t got = 0;
  while (got < reply.size()) {
    const auto r = ::read(fd, reply.data() + got, reply.size() - got);
    if (r <= 0) return false;
    got += static_cast<std::size_t>(r);
  }
  return true;
}

/** Opens @p path raw and measures @p n round trips of @p request; µs per round trip. */
inline double pty_round_trips(const std::string& path, std::span<const std::uint8_t> request, std::size_t reply_size,
                              int n) {
  const int fd = open_raw(path);
  std::vector<std::uint8_t> buf(reply_size);
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < n && raw_round_trip(fd, request, buf); ++i) {
  }
  const auto us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  ::close(fd);
  return us / n;
}

/**
 * A control cycle by a bare blocking loop on @p path: ops::read_servo_states (planned for
 * @p cost) then @p write, @p n times; µs per cycle. Each exchange writes its frame and reads
 * exactly its reply's length: the least any client can spend on this line.
 */
inline double raw_cycle_us(const std::string& path, ops::link_cost cost, const command& write, int n) {
  const int fd = open_raw(path);
  std::array<std::uint8_t, max_reply_size> buf{};
  bool ok = true;
  const auto exchange = [&](const command& c) {
    const auto frame = encode(c);
    const auto shape = expected_reply(c);
    const auto reply = std::span(buf).first(shape.frame_size());
    ok = ok && raw_round_trip(fd, frame.bytes(), reply);
    const auto parsed = parse_reply(reply, shape);
    ok = ok && parsed.status == parse_status::complete;
    return parsed.value();
  };
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < n && ok; ++i) {
    ops::read_servo_states op(cost);
    while (auto c = op.next()) op.on_reply(exchange(*c));
    exchange(write);
  }
  const auto us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  ::close(fd);
  return ok ? us / n : -1.0;
}

/**
 * Round trips of @p request on @p path by the least an Asio program can do: one coroutine on
 * its own io_context thread writing and reading a stream_descriptor (no strand, no deadline);
 * µs per round trip. The yardstick for asynchronous clients.
 */
inline double asio_round_trips(const std::string& path, std::span<const std::uint8_t> request, std::size_t reply_size,
                               int n) {
  boost::asio::io_context io;
  boost::asio::posix::stream_descriptor s(io, open_raw(path));
  double us = -1.0;
  boost::asio::co_spawn(
      io,
      [&]() -> boost::asio::awaitable<void> {
        std::vector<std::uint8_t> buf(reply_size);
        const auto start = std::chrono::steady_clock::now();
        for (int i = 0; i < n; ++i) {
          co_await boost::asio::async_write(s, boost::asio::buffer(request.data(), request.size()),
                                            boost::asio::use_awaitable);
          std::size_t got = 0;
          while (got < reply_size)
            got += co_await s.async_read_some(boost::asio::buffer(buf.data() + got, reply_size - got),
                                              boost::asio::use_awaitable);
        }
        us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count() / n;
      },
      boost::asio::detached);
  io.run();
  return us;
}

/** Echoes every byte back on a new pty, on @p io (run by another thread): the floor any pty server can reach. */
class pty_echo {
 public:
  explicit pty_echo(boost::asio::io_context& io) : stream_(io, pty_.release_master()) {
    boost::asio::co_spawn(io, echo(), boost::asio::detached);
  }
  pty_echo(const pty_echo&) = delete;
  pty_echo& operator=(const pty_echo&) = delete;
  /** Closes the echo on its io thread and waits for that. */
  ~pty_echo() {
    std::promise<void> done;
    boost::asio::post(stream_.get_executor(), [&] {
      boost::system::error_code ignored;
      stream_.close(ignored);
      done.set_value();
    });
    done.get_future().wait();
  }
  /** The pty path to open. */
  const std::string& path() const noexcept { return pty_.path(); }

 private:
  boost::asio::awaitable<void> echo() {
    std::array<std::uint8_t, 512> buf{};
    for (;;) {
      boost::system::error_code ec;
      const auto n = co_await stream_.async_read_some(boost::asio::buffer(buf),
                                                      boost::asio::redirect_error(boost::asio::use_awaitable, ec));
      if (ec) co_return;
      co_await boost::asio::async_write(stream_, boost::asio::buffer(buf.data(), n),
                                        boost::asio::redirect_error(boost::asio::use_awaitable, ec));
      if (ec) co_return;
    }
  }
  transport::pty_pair pty_;
  boost::asio::posix::stream_descriptor stream_;
};

}  // namespace rcb4::testing
