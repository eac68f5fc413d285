// The link's public machine through its reference adapters (rcb4/link/device_link.hpp), against
// the virtual board, with no file descriptor, no thread and no real clock: a byte device in
// libftdi's shape (write, read, idle until a deadline) and a polled UART (a byte at a time; the
// clock moves only as it is polled). Each board here can misbehave: silent, a loopback, a reply
// lost or damaged, a late reply waiting on the line, a device that goes away.
// Golden bytes are written by hand from protocol.md, never made by the project's serializer.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/board/virtual_board.hpp>
#include <rcb4/link/device_link.hpp>
#include <rcb4/link/requests.hpp>
#include <rcb4/ops/servos.hpp>
#include <rcb4/ops/system.hpp>

#include <catch2/catch.hpp>

#include <array>
#include <chrono>
#include <cstdint>
#include <deque>
#include <vector>

using namespace rcb4;
using namespace std::chrono_literals;
namespace l = rcb4::link;

namespace {

using bytes = std::vector<std::uint8_t>;

/** A clock the test moves: microseconds from 0. */
struct sim_clock {
  using rep = std::int64_t;
  using period = std::micro;
  using duration = std::chrono::microseconds;
  using time_point = std::chrono::time_point<sim_clock>;
  static inline duration t{0};
  static time_point now() noexcept { return time_point(t); }
};

/** The virtual board behind a byte device, with the misbehaviours the tests switch on. */
struct board_line {
  board::virtual_board board;
  std::deque<std::pair<sim_clock::time_point, std::uint8_t>> to_host;  // bytes and when they arrive
  bytes seen;                                                          // every byte the host wrote, in order
  bool silent = false;                                                 // the board hears nothing
  bool loopback = false;                                               // the line returns what is written, no board
  int drop_replies = 0;                                                // replies lost on the wire
  std::uint8_t drop_command = 0;  // the replies to this command byte are lost on the wire (0: none)
  int damage_replies = 0;         // replies whose last byte (the checksum) is flipped
  bool gone = false;              // the device went away (read and write fail)
  int reopens = 0;                // reopen() calls

  void write_bytes(std::span<const std::uint8_t> out) {
    const auto now = sim_clock::now();
    seen.insert(seen.end(), out.begin(), out.end());
    // The wire: each byte arrives after its 11 bits at 115200 baud; a reply after the request.
    auto at = now + std::chrono::ceil<sim_clock::duration>(l::wire_time(out.size(), 115200));
    if (loopback) {
      for (const auto b : out) to_host.emplace_back(at, b);
      return;
    }
    if (silent) return;
    bytes reply;
    board.receive(out, std::chrono::duration_cast<board::board_time>(now.time_since_epoch()), reply);
    if (reply.empty()) return;
    if (drop_replies > 0) {
      --drop_replies;
      return;
    }
    if (drop_command != 0 && reply.size() > 1 && reply[1] == drop_command) return;
    if (damage_replies > 0) {
      --damage_replies;
      reply.back() = static_cast<std::uint8_t>(reply.back() ^ 0x5A);
    }
    for (const auto b : reply) {
      at += std::chrono::ceil<sim_clock::duration>(l::wire_time(1, 115200));
      to_host.emplace_back(at, b);
    }
  }
  std::size_t read_bytes(std::span<std::uint8_t> in) {
    std::size_t n = 0;
    while (n < in.size() && !to_host.empty() && to_host.front().first <= sim_clock::now()) {
      in[n++] = to_host.front().second;
      to_host.pop_front();
    }
    return n;
  }
};

/** libftdi's shape: write and read what can go now, idle until a deadline (the clock jumps). */
struct block_device {
  board_line* line;
  long write(std::span<const std::uint8_t> out) {
    if (line->gone) return -1;
    line->write_bytes(out);
    return static_cast<long>(out.size());
  }
  long read(std::span<std::uint8_t> in) {
    if (line->gone) return -1;
    return static_cast<long>(line->read_bytes(in));
  }
  void idle(sim_clock::time_point until, l::waiting w) {
    // To the next byte's arrival, or the deadline, 1 ms at most (a wait that wakes every millisecond).
    auto next = std::min(until, sim_clock::now() + 1ms);
    if (w == l::waiting::input && !line->to_host.empty()) next = std::min(next, line->to_host.front().first);
    sim_clock::t = std::max(sim_clock::t + 1us, next.time_since_epoch());
    ++idles;
  }
  int idles = 0;
};

/** The same with reopen(): a device that comes back. */
struct reopening_device : block_device {
  bool reopen() {
    ++line->reopens;
    line->gone = false;
    return true;
  }
};

/** A UART polled a byte at a time; every poll takes 2 µs of the clock (no idle hook). */
struct polled_uart {
  board_line* line;
  bool poll_in(std::uint8_t& b) {
    sim_clock::t += 2us;
    std::array<std::uint8_t, 1> one{};
    if (line->read_bytes(one) == 0) return false;
    b = one[0];
    return true;
  }
  bool poll_out(std::uint8_t b) {
    sim_clock::t += 2us;
    line->write_bytes(std::array<std::uint8_t, 1>{b});
    return true;
  }
};

/** Counts what the machine tells its observer. */
struct counting : l::no_observer {
  explicit counting(std::array<std::size_t, 10>* counts) : n(counts) {}
  std::array<std::size_t, 10>* n;
  void count(l::counter c, std::size_t k = 1) noexcept { (*n)[static_cast<std::size_t>(c)] += k; }
};
std::size_t of(const std::array<std::size_t, 10>& n, l::counter c) { return n[static_cast<std::size_t>(c)]; }

l::options at_115200() {
  l::options o;
  o.baud = 115200;
  o.turnaround = 20ms;
  return o;
}

// protocol.md §4.11: the ping and its ACK; §4.11 short form: the resync's ping.
const bytes ping_frame{0x04, 0xFE, 0x06, 0x08};
const bytes sync_ping{0x03, 0xFE, 0x01};

}  // namespace

TEST_CASE("link: a device in libftdi's shape drives the virtual board", "[link]") {
  sim_clock::t = 0us;
  board_line line;
  block_device dev{&line};
  std::array<std::size_t, 10> n{};
  l::device_link<block_device, sim_clock, counting> link(dev, at_115200(), {}, counting{&n});

  const auto r = link.exchange(l::request_of(ping{}));
  REQUIRE(r.has_value());
  CHECK(r->is_ack());
  CHECK(line.seen == ping_frame);  // the frame as protocol.md §4.11 writes it, once

  // An operation (the config word, then every servo's state) over the same link.
  ops::read_config cfg;
  CHECK(l::run(link, cfg) == errc{});
  ops::read_servo_states states;
  CHECK(l::run(link, states) == errc{});
  CHECK(of(n, l::counter::errors) == 0);
  CHECK(of(n, l::counter::retries) == 0);
  CHECK(of(n, l::counter::exchanges) >= 3);
}

TEST_CASE("link: a silent board ends in link_timeout after the read's retries, a write goes once", "[link]") {
  sim_clock::t = 0us;
  board_line line;
  line.silent = true;
  block_device dev{&line};
  std::array<std::size_t, 10> n{};
  l::device_link<block_device, sim_clock, counting> link(dev, at_115200(), {}, counting{&n});

  const auto r = link.exchange(l::request_of(ping{}));
  REQUIRE(!r.has_value());
  CHECK(r.error() == errc::link_timeout);
  CHECK(of(n, l::counter::retries) == 2);  // options::read_retries
  // Three attempts, each within the wire time and the turnaround (and a resync's before the 2nd and 3rd).
  CHECK(sim_clock::t < 3 * (20ms + 2ms) + 2 * (20ms + 2ms));

  // A servo move changes the board: one attempt only, so the board can never get it twice. The
  // board hears again, but the move's reply is lost on the way back.
  line.silent = false;
  line.drop_command = single_servo::command_code;
  line.seen.clear();
  const auto move = l::request_of(single_servo{3, 7500, 10});
  CHECK_FALSE(move.idempotent);
  const auto w = link.exchange(move);
  REQUIRE(!w.has_value());
  CHECK(w.error() == errc::link_timeout);
  // The line was dirty: a resync ping first (answered), then the frame once, and nothing after it.
  REQUIRE(line.seen.size() == sync_ping.size() + move.frame.size());
  CHECK(bytes(line.seen.begin(), line.seen.begin() + 3) == sync_ping);
  CHECK(bytes(line.seen.begin() + 3, line.seen.end()) == bytes(move.frame.bytes().begin(), move.frame.bytes().end()));
}

TEST_CASE("link: a lost or damaged reply is resynchronised and retried, a late one drained", "[link]") {
  sim_clock::t = 0us;
  board_line line;
  block_device dev{&line};
  std::array<std::size_t, 10> n{};
  l::device_link<block_device, sim_clock, counting> link(dev, at_115200(), {}, counting{&n});

  line.drop_replies = 1;
  auto r = link.exchange(l::request_of(ping{}));
  REQUIRE(r.has_value());
  CHECK(r->is_ack());
  CHECK(of(n, l::counter::retries) == 1);
  CHECK(of(n, l::counter::resyncs) == 1);
  // ping (lost reply), then the resync's ping, then the ping again
  CHECK(line.seen == bytes{0x04, 0xFE, 0x06, 0x08, 0x03, 0xFE, 0x01, 0x04, 0xFE, 0x06, 0x08});

  line.damage_replies = 1;
  r = link.exchange(l::request_of(ping{}));
  REQUIRE(r.has_value());
  CHECK(of(n, l::counter::retries) == 2);

  // A write whose reply came back damaged is not sent again: the caller hears the checksum.
  line.damage_replies = 1;
  const auto w = link.exchange(l::request_of(single_servo{3, 7500, 10}));
  REQUIRE(!w.has_value());
  CHECK(w.error() == errc::bad_checksum);

  // A reply nobody read (the board answered after the host gave up) waits on the line: drained, resync
  // first. The line is clean before it (a ping went through).
  REQUIRE(link.exchange(l::request_of(ping{})).has_value());
  REQUIRE_FALSE(link.state().dirty());
  line.to_host.emplace_back(sim_clock::now(), 0x04);
  line.to_host.emplace_back(sim_clock::now(), 0xFE);
  const auto resyncs = of(n, l::counter::resyncs);
  r = link.exchange(l::request_of(ping{}));
  REQUIRE(r.has_value());
  CHECK(of(n, l::counter::resyncs) == resyncs + 1);
}

TEST_CASE("link: a loopback is named, never taken for a board", "[link]") {
  sim_clock::t = 0us;
  board_line line;
  line.loopback = true;
  block_device dev{&line};
  l::device_link<block_device, sim_clock> link(dev, at_115200());
  const auto r = link.exchange(l::request_of(version{}));
  REQUIRE(!r.has_value());
  CHECK(r.error() == errc::link_echo);
}

TEST_CASE("link: a device that goes away is lost, or reopened when it can be", "[link]") {
  sim_clock::t = 0us;
  board_line line;
  {
    block_device dev{&line};
    l::device_link<block_device, sim_clock> link(dev, at_115200());
    STATIC_REQUIRE_FALSE(l::device_link<block_device, sim_clock>::can_reopen);
    line.gone = true;
    const auto r = link.exchange(l::request_of(ping{}));
    REQUIRE(!r.has_value());
    CHECK(r.error() == errc::link_lost);
  }
  line.gone = false;
  reopening_device dev{{&line}};
  std::array<std::size_t, 10> n{};
  l::device_link<reopening_device, sim_clock, counting> link(dev, at_115200(), {}, counting{&n});
  STATIC_REQUIRE(l::device_link<reopening_device, sim_clock, counting>::can_reopen);
  REQUIRE(link.exchange(l::request_of(ping{})).has_value());
  line.gone = true;
  const auto r = link.exchange(l::request_of(ping{}));
  REQUIRE(r.has_value());  // reopened, then the ping retried
  CHECK(line.reopens == 1);
  CHECK(of(n, l::counter::reconnects) == 1);
}

TEST_CASE("link: a stop cancels the exchange while it waits, and the next one resynchronises first", "[link]") {
  sim_clock::t = 0us;
  board_line line;
  line.silent = true;
  block_device dev{&line};
  std::array<std::size_t, 10> n{};
  l::device_link<block_device, sim_clock, counting> link(dev, at_115200(), {}, counting{&n});
  // A servo move (one attempt only), stopped 5 ms into the wait for its reply: cancelled, not timed out.
  const auto r = link.exchange(l::request_of(single_servo{3, 7500, 10}), [] { return sim_clock::t >= 5ms; });
  REQUIRE(!r.has_value());
  CHECK(r.error() == errc::link_cancelled);
  CHECK(sim_clock::t < 20ms);  // before the attempt's deadline
  CHECK(of(n, l::counter::timeouts) == 0);
  CHECK(of(n, l::counter::retries) == 0);
  CHECK(of(n, l::counter::resyncs) == 0);
  CHECK(link.state().dirty());
  CHECK_FALSE(link.state().last_reply().has_value());
  // A ping stopped the same way: no retry is begun after the stop.
  const auto start = sim_clock::t;
  const auto p = link.exchange(l::request_of(ping{}), [&] { return sim_clock::t >= start + 3ms; });
  REQUIRE(!p.has_value());
  CHECK(p.error() == errc::link_cancelled);
  CHECK(of(n, l::counter::retries) == 0);
  line.silent = false;
  line.seen.clear();
  REQUIRE(link.exchange(l::request_of(ping{})).has_value());
  CHECK(bytes(line.seen.begin(), line.seen.begin() + 3) == sync_ping);
}

TEST_CASE("link: a line that never stops talking cannot hold an attempt open", "[link]") {
  sim_clock::t = 0us;
  board_line line;
  line.silent = true;
  block_device dev{&line};
  l::device_link<block_device, sim_clock> link(dev, at_115200());
  // Noise: a byte ready at every microsecond for a second (never an ACK, never a reply).
  for (int i = 0; i < 1'000'000; i += 50)
    line.to_host.emplace_back(sim_clock::time_point(std::chrono::microseconds(i)), 0x55);
  const auto r = link.exchange(l::request_of(ping{}));
  REQUIRE(!r.has_value());
  CHECK((r.error() == errc::link_timeout || r.error() == errc::bad_reply_length || r.error() == errc::link_truncated));
  CHECK(sim_clock::t < 200ms);  // three attempts' deadlines, not the noise's second
}

TEST_CASE("link: a request no reply can fit is refused before anything is sent", "[link]") {
  sim_clock::t = 0us;
  board_line line;
  block_device dev{&line};
  l::device_link<block_device, sim_clock> link(dev, at_115200());
  l::request r = l::request_of(ping{});
  r.shape = reply_shape{0x00, true, 255};  // 258 bytes: more than a reply holds (protocol.md §2)
  const auto got = link.exchange(r);
  REQUIRE(!got.has_value());
  CHECK(got.error() == errc::frame_too_long);
  CHECK(line.seen.empty());
}

TEST_CASE("link: a polled UART (a byte at a time, no idle hook) drives the virtual board", "[link]") {
  sim_clock::t = 0us;
  board_line line;
  polled_uart uart{&line};
  l::polled_uart_device<polled_uart> dev(uart);
  l::device_link<l::polled_uart_device<polled_uart>, sim_clock> link(dev, at_115200());
  const auto r = link.exchange(l::request_of(ping{}));
  REQUIRE(r.has_value());
  CHECK(line.seen == ping_frame);
  ops::read_servo_states states;
  CHECK(l::run(link, states) == errc{});

  line.silent = true;
  const auto s = link.exchange(l::request_of(ping{}));
  REQUIRE(!s.has_value());
  CHECK(s.error() == errc::link_timeout);
}

TEST_CASE("link: a control loop with no file descriptor: read the servos, move two, 50 times", "[link]") {
  sim_clock::t = 0us;
  board_line line;
  block_device dev{&line};
  std::array<std::size_t, 10> n{};
  l::device_link<block_device, sim_clock, counting> link(dev, at_115200(), {}, counting{&n});
  int arrived = 0;
  for (int k = 0; k < 50; ++k) {
    ops::read_servo_states_fixed states;
    REQUIRE(l::run(link, states) == errc{});
    REQUIRE(states.value().size() >= 2);
    const auto a = states.value()[0].ics, b = states.value()[1].ics;
    // Each round the two servos are sent to one side of the centre or the other, in one CONST frame.
    const auto goal = servo_position::make(k % 2 == 0 ? 8000 : 7000).value();
    servo_set<servo_position> targets;
    targets.insert(a, goal);
    targets.insert(b, goal);
    const auto moved = link.exchange(l::request_of(const_servo::make(targets, frames{0}).value()));
    REQUIRE(moved.has_value());
    REQUIRE(moved->is_ack());
    sim_clock::t += 20ms;  // the board's output periods pass: the servos get there
    line.board.advance_to(std::chrono::duration_cast<board::board_time>(sim_clock::t));
    if (k > 0)
      for (const auto& s : states.value())
        if (s.ics == a && s.position == (k % 2 == 0 ? 7000 : 8000)) ++arrived;  // last round's goal
  }
  CHECK(arrived == 49);  // each read saw where the move before it sent the servo
  CHECK(of(n, l::counter::errors) == 0);
  CHECK(of(n, l::counter::retries) == 0);
}

TEST_CASE("link: the machine counts in the ticks of a millisecond clock, its deadlines never early", "[link]") {
  struct ms_clock {
    using duration = std::chrono::milliseconds;
    using time_point = std::chrono::time_point<ms_clock>;
    static time_point now() noexcept { return time_point(0ms); }
  };
  const l::options o = at_115200();
  l::exchange_machine<ms_clock> m(o);
  using kind = l::exchange_machine<ms_clock>::action::kind;
  auto a = m.start(l::request_of(ping{}), ms_clock::time_point(10ms));
  REQUIRE(a.what == kind::write);
  CHECK(bytes(a.out.begin(), a.out.end()) == ping_frame);
  // The ping and its ACK, 8 bytes at 115200 baud, 11 bits each: 764 µs, rounded up: 1 ms; the
  // turnaround 20 ms; and one tick more, since a tick clock's now() is rounded down.
  CHECK(a.deadline == ms_clock::time_point(32ms));
  a = m.resume(l::io_result{4, l::io_status::ok}, ms_clock::time_point(10ms));
  REQUIRE(a.what == kind::read);
  CHECK(a.in.size() == 4);  // exactly the ACK: never a byte of the next reply
  CHECK(a.expected == ms_clock::time_point(11ms));
  CHECK(a.deadline == ms_clock::time_point(32ms));
}
