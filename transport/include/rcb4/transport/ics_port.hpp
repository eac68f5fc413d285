// rcb4 — an ICS line on a serial port: KONDO's adapter in ICS mode, or `rcb4 ics serve --pty`.
// SPDX-License-Identifier: BSL-1.0
//
// The port is opened as the RCB-4's (8E1, raw, exclusive; serial.hpp) at 115200, 625000 or
// 1250000 baud (ics.md §1). An exchange is blocking, with one deadline: what the host sends
// comes back first (the one-wire echo), then the reply; a read stops when the bytes expected are
// in or the deadline passed. Input left over from an earlier exchange is dropped before a send.
// Robot services reach it through services::ics_port_link (rcb4/robot/services/ics.hpp).
#pragma once

#include <rcb4/transport/line_marks.hpp>
#include <rcb4/transport/serial.hpp>

#include <poll.h>

#include <chrono>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace rcb4::transport {

/** A serial port speaking ICS: blocking exchanges with deadlines. Movable, not copyable. */
class ics_port {
 public:
  /** Opens @p path at @p baud; throws system_error naming the port (busy, missing, not a terminal). */
  ics_port(const std::string& path, std::uint32_t baud) : path_(path), baud_(baud) {
    boost::asio::io_context io;
    auto port = open_serial(io, path, baud, &info_);
    fd_ = port.release();
    marked_ = detail::is_marked(fd_);
  }
  ics_port(ics_port&& o) noexcept
      : path_(std::move(o.path_)),
        baud_(o.baud_),
        info_(o.info_),
        fd_(o.fd_),
        marked_(o.marked_),
        marks_(o.marks_),
        damaged_(o.damaged_) {
    o.fd_ = -1;
  }
  ics_port& operator=(ics_port&&) = delete;
  ics_port(const ics_port&) = delete;
  ics_port& operator=(const ics_port&) = delete;
  ~ics_port() {
    if (fd_ < 0) return;
    if (marked_) detail::unmark(fd_);
    ::close(fd_);
  }

  /** What was opened. */
  const std::string& path() const noexcept { return path_; }
  /** The rate in use. */
  std::uint32_t baud() const noexcept { return baud_; }
  /** What opening found (parity kept, latency timer). */
  const serial_info& info() const noexcept { return info_; }

  /** Talks at @p baud from now on; throws system_error when the port does not take it. */
  void set_baud(std::uint32_t baud) {
    std::uint32_t rate = 0;
    bool parity = false;
    if (const auto ec = detail::set_rcb4_line(fd_, baud, rate, parity)) {
      if (ec.value() == EIO || ec.value() == ENXIO || ec.value() == ENODEV)  // unplugged, or the pty's server gone
        throw system_error(transport_errc::closed, path_);
      throw system_error(ec, "set baud of " + path_);
    }
    baud_ = baud;
    marked_ = detail::is_marked(fd_);
  }

  /**
   * True when the last transact() or linger() stopped at a byte that failed its parity or
   * framing check (what they returned are the bytes before it).
   */
  bool damaged() const noexcept { return damaged_; }

  /**
   * Sends @p request and reads until @p expect bytes came back (echo and reply) or @p wait passed:
   * fewer bytes mean a timeout. Throws system_error when the line closes (unplugged, server gone).
   */
  std::vector<std::uint8_t> transact(std::span<const std::uint8_t> request, std::size_t expect,
                                     std::chrono::milliseconds wait) {
    const auto deadline = std::chrono::steady_clock::now() + wait;
    ::tcflush(fd_, TCIFLUSH);
    marks_.reset();  // (a mark the flush cut in half is gone with it)
    std::size_t sent = 0;
    while (sent < request.size()) {
      if (!ready(POLLOUT, deadline)) throw system_error(transport_errc::timeout, "write to " + path_);
      const auto n = ::write(fd_, request.data() + sent, request.size() - sent);
      if (n < 0 && (errno == EIO || errno == ENXIO || errno == ENODEV))  // unplugged, or the pty's server gone
        throw system_error(transport_errc::closed, path_);
      if (n < 0 && errno != EAGAIN && errno != EINTR) throw system_error(os_error(errno), "write to " + path_);
      if (n > 0) sent += static_cast<std::size_t>(n);
    }
    std::vector<std::uint8_t> rx;
    read_until(rx, expect, deadline);
    return rx;
  }

  /** The bytes that arrive within @p wait. */
  std::vector<std::uint8_t> linger(std::chrono::milliseconds wait) {
    std::vector<std::uint8_t> rx;
    read_until(rx, static_cast<std::size_t>(-1), std::chrono::steady_clock::now() + wait);
    return rx;
  }

 private:
  bool ready(short events, std::chrono::steady_clock::time_point deadline) {
    for (;;) {
      const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      pollfd p{fd_, events, 0};
      const int r = ::poll(&p, 1, static_cast<int>(std::max<std::chrono::milliseconds::rep>(0, left.count())));
      if (r < 0 && errno == EINTR) continue;
      if (r < 0) throw system_error(os_error(errno), "poll " + path_);
      if (r == 0) return false;
      if ((p.revents & (POLLERR | POLLHUP | POLLNVAL)) && !(p.revents & events))
        throw system_error(transport_errc::closed, path_);
      return true;
    }
  }
  void read_until(std::vector<std::uint8_t>& rx, std::size_t expect, std::chrono::steady_clock::time_point deadline) {
    damaged_ = false;
    std::uint8_t buf[256];
    while (rx.size() < expect && ready(POLLIN, deadline)) {
      const auto n = ::read(fd_, buf, sizeof buf);
      if (n == 0 || (n < 0 && (errno == EIO || errno == ENXIO || errno == ENODEV)))
        throw system_error(transport_errc::closed, path_);
      if (n < 0 && errno != EAGAIN && errno != EINTR) throw system_error(os_error(errno), "read " + path_);
      if (n <= 0) continue;
      auto size = static_cast<std::size_t>(n);
      if (marked_) {
        const auto d = marks_.decode(std::span(buf, size));
        if (d.damaged > 0) {  // the bytes before the first damaged one, and no more
          damaged_ = true;
          rx.insert(rx.end(), buf, buf + d.first_damaged);
          return;
        }
        size = d.size;
      }
      rx.insert(rx.end(), buf, buf + size);
    }
  }
  std::string path_;
  std::uint32_t baud_;
  serial_info info_{};
  int fd_ = -1;
  bool marked_ = false;  // reads are PARMRK-marked (open_serial sets it; a pty's slave keeps it)
  line_marks marks_{};
  bool damaged_ = false;
};

}  // namespace rcb4::transport
