// libFuzzer harness: the link's exchange machine (rcb4/link/exchange_machine.hpp) driven by
// whatever a line hands back. The first bytes choose the request (a ping, a RAM read of some size,
// a servo move), the options (a marked line, retried writes, a driver that can reopen) and how
// much time each step takes; the rest is a script of what each action meets: bytes (any, marks
// included), a timeout, a closed or lost line, a failed reopen. Properties:
//   - the exchange ends, within a bounded number of actions (every attempt has a deadline);
//   - a write is asked for with bytes that are the request's frame or the resync's ping, never more;
//   - a read never asks for more than a reply can hold, nor for nothing;
//   - a driver that keeps the deadlines (a step that comes after one is a timeout) sees every
//     exchange end;
//   - an exchange that ends without error has a reply of the kind and size the request expects,
//     or a NACK; an error is a code with a message;
//   - a write request is written at most once unless retries of writes were asked for.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/link/exchange_machine.hpp>
#include <rcb4/link/requests.hpp>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstring>
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
  const std::uint8_t pick = data[0], flags = data[1], step_us = data[2];
  script s{data + 3, size - 3};

  link::request req;
  switch (pick % 3) {
    case 0: req = link::request_of(ping{}); break;
    case 1:
      req = link::request_of(
          move::read_ram(ram_address{0x0090}, transfer_size::make(1 + (pick >> 2) % 64).value()).value());
      break;
    default: req = link::request_of(single_servo{3, 7500, 10}); break;
  }
  link::options opt;
  opt.baud = 115200;
  opt.turnaround = std::chrono::milliseconds(5 + (flags >> 4));
  opt.retry_writes = (flags & 2) != 0;
  machine m(opt);
  m.set_marked((flags & 1) != 0);
  m.set_reopen((flags & 4) != 0);

  auto now = fuzz_clock::time_point(std::chrono::microseconds(1000));
  const auto frame = req.frame.bytes();
  static constexpr std::uint8_t sync_ping[] = {0x03, 0xFE, 0x01};
  unsigned frames_sent = 0;
  auto a = m.start(req, now, (flags & 8) ? 1 : 0);
  for (int steps = 0; a.what != kind::done; ++steps) {
    check(steps < 100'000);  // every attempt has a deadline and the attempts are bounded
    link::io_result r;
    const std::uint8_t what = s.next();
    const bool late = a.what != kind::reopen && now >= a.deadline;  // a driver keeps the deadline
    switch (a.what) {
      case kind::write: {
        check(!a.out.empty());
        const bool is_frame = a.out.size() <= frame.size() &&
                              std::equal(a.out.begin(), a.out.end(), frame.end() - static_cast<std::ptrdiff_t>(a.out.size()));
        const bool is_sync = a.out.size() <= 3 && std::equal(a.out.begin(), a.out.end(), sync_ping + (3 - a.out.size()));
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
        check(!a.in.empty() && a.in.size() <= 256);
        if (late || what % 8 == 0) {
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
    now += std::chrono::microseconds(step_us * 100);
    a = m.resume(r, now);
  }
  check(req.idempotent || opt.retry_writes || frames_sent <= 1);
  if (a.error == errc{}) {
    const reply got = m.last_reply();
    check(got.is_nack() || (req.shape.data ? got.kind() == reply_kind::data && got.bytes().size() == req.shape.data_size
                                           : got.is_ack()));
  } else {
    check(std::strlen(message(a.error)) > 0);
  }
  check(m.idle());
  return 0;
}
