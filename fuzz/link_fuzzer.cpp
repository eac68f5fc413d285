// libFuzzer harness: the link's exchange machine (rcb4/link/exchange_machine.hpp) driven by
// whatever a line hands back, for up to three exchanges on one machine (the line's state carries
// over). The first bytes choose the options (a marked line, retried writes, a driver that can
// reopen, one that keeps deadlines or not) and how much time each step takes; then, for each
// exchange, the request (a ping, a RAM read of some size, a servo move) and a script of what each
// action meets: bytes (any, marks included), a timeout, a closed or lost line, a failed reopen, a
// stop. Properties:
//   - each exchange ends within a bound of steps (the script's length and a few attempts), also
//     with a driver that hands over bytes past the deadlines;
//   - a write is asked for with bytes that are the request's frame or the resync's ping, never more;
//   - a read never asks for more than a reply can hold, nor for nothing;
//   - an exchange has a reply exactly when it ended without error, of the kind and size the
//     request expects, or a NACK; a stop ends it with link_cancelled;
//   - a write request is written at most once unless retries of writes were asked for.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/link/exchange_machine.hpp>
#include <rcb4/link/requests.hpp>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <span>

namespace {
void check(bool ok) {
  if (!ok) __builtin_trap();
}

struct fuzz_clock {
  using rep = std::int64_t;
  using period = std::micro;
  using duration = std::chrono::microseconds;
  using time_point = std::chrono::time_point<fuzz_clock>;
  static time_point now() noexcept { return time_point(duration(0)); }
};

struct script {
  const std::uint8_t* p;
  std::size_t n;
  std::uint8_t next() noexcept {
    if (n == 0) return 0;
    --n;
    return *p++;
  }
};
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 3) return 0;
  using namespace rcb4;
  using machine = link::exchange_machine<fuzz_clock>;
  using kind = machine::action::kind;
  const std::uint8_t flags = data[0], step_us = data[1];
  script s{data + 2, size - 2};
  // A driver that checks each deadline before it reads (as a driver must), or one that hands over
  // whatever the line has, deadline or not: the machine must end the exchange either way.
  const bool keeps_deadlines = (flags & 0x20) == 0;

  link::options opt;
  opt.baud = 115200;
  opt.turnaround = std::chrono::milliseconds(5 + (flags >> 6));
  opt.retry_writes = (flags & 2) != 0;
  machine m(opt);
  m.set_marked((flags & 1) != 0);
  m.set_reopen((flags & 4) != 0);
  static constexpr std::uint8_t sync_ping[] = {0x03, 0xFE, 0x01};

  auto now = fuzz_clock::time_point(std::chrono::microseconds(1000));
  std::size_t steps = 0;
  for (int exchanges = 0; exchanges < 3 && s.n > 0; ++exchanges) {  // the line's state carries over
    link::request req;
    const std::uint8_t pick = s.next();
    switch (pick % 3) {
      case 0: req = link::request_of(ping{}); break;
      case 1:
        req = link::request_of(
            move::read_ram(ram_address{0x0090}, transfer_size::make(1 + (pick >> 2) % 64).value()).value());
        break;
      default: req = link::request_of(single_servo{3, 7500, 10}); break;
    }
    const auto frame = req.frame.bytes();
    unsigned frames_sent = 0;
    auto a = m.start(req, now, (flags & 8) ? 1 : 0);
    while (a.what != kind::done) {
      // Each step takes a byte of the script while it lasts; once it is spent every step is a
      // timeout, and the machine must end within a few attempts of a few steps each.
      check(++steps <= size + 64);
      link::io_result r;
      const std::uint8_t what = s.next();
      if (what == 0xC3) {  // a stop
        a = m.cancel();
        check(a.what == kind::done && a.error == errc::link_cancelled);
        break;
      }
      const bool late = a.what != kind::reopen && keeps_deadlines && now >= a.deadline;
      switch (a.what) {
        case kind::write: {
          check(!a.out.empty());
          const bool is_frame =
              a.out.size() <= frame.size() &&
              std::equal(a.out.begin(), a.out.end(), frame.end() - static_cast<std::ptrdiff_t>(a.out.size()));
          const bool is_sync =
              a.out.size() <= 3 && std::equal(a.out.begin(), a.out.end(), sync_ping + (3 - a.out.size()));
          check(is_frame || is_sync);
          if (is_frame && a.out.size() == frame.size()) ++frames_sent;
          if (late || what % 16 == 0) {
            r = {0, link::io_status::timed_out};
          } else if (what % 16 == 1) {
            r = {0, link::io_status::lost};
          } else {
            r = {std::min<std::size_t>(a.out.size(), 1 + what % a.out.size()), link::io_status::ok};
          }
          break;
        }
        case kind::read: {
          // Never nothing, never more than a reply's frame (258) or the resync's buffer.
          check(!a.in.empty() && a.in.size() <= 258);
          if (late || what % 8 == 0 || s.n == 0) {
            r = {0, link::io_status::timed_out};
          } else if (what % 32 == 1) {
            r = {0, (what & 0x40) ? link::io_status::closed : link::io_status::failed};
          } else {
            const std::size_t k = std::min<std::size_t>(a.in.size(), 1 + what % 7);
            for (std::size_t i = 0; i < k; ++i) a.in[i] = s.next();
            r = {k, link::io_status::ok};
          }
          break;
        }
        case kind::reopen:
          now = std::max(now, a.deadline);  // not before the deadline
          r = {0, (what & 1) ? link::io_status::ok : link::io_status::failed};
          break;
        case kind::done: break;
      }
      // Time moves on (a driver that ignores deadlines still lives in time: 100 µs a step at least).
      now += std::chrono::microseconds(keeps_deadlines ? step_us * 100 : 100 + step_us * 100);
      a = m.resume(r, now);
    }
    check(m.idle());
    check(req.idempotent || opt.retry_writes || frames_sent <= 1);  // a write goes once
    const auto got = m.last_reply();
    check(got.has_value() == (a.error == errc{}));  // a reply exactly when no error
    if (got)
      check(got->is_nack() ||
            (req.shape.data ? got->kind() == reply_kind::data && got->bytes().size() == req.shape.data_size
                            : got->is_ack()));
  }
  return 0;
}
