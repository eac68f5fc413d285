// The exchange machine on its own (detail/exchange_machine.hpp): no stream and no clock. Each test
// plays the driver by hand, with a virtual clock and the io_result of every action, and checks
// every action the machine asks for: its kind, the bytes to write, how many bytes a read may take,
// and its deadline (DESIGN.md §4, §8). Deadlines are computed here from the options: 11 bits a byte
// at 8E1 (protocol.md §1) plus the turnaround. Golden bytes are written by hand from protocol.md
// (SUM = sum of the preceding bytes & 0xFF), never produced by the project's serializer.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/transport/detail/exchange_machine.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

using namespace rcb4;
using namespace std::chrono_literals;
namespace t = rcb4::transport;
namespace d = rcb4::transport::detail;

namespace {

using byte_vector = std::vector<std::uint8_t>;
using kind = d::action::kind;
using time_point = d::clock::time_point;

/** Bytes written by hand. */
template <class... B>
byte_vector bytes(B... b) {
  return {static_cast<std::uint8_t>(b)...};
}

/** @p a then @p b (what one read may bring). */
byte_vector join(const byte_vector& a, const byte_vector& b) {
  byte_vector out = a;
  out.insert(out.end(), b.begin(), b.end());
  return out;
}

/** "04 FE 06 08": what a failed comparison of bytes prints. */
std::string hex(std::span<const std::uint8_t> b) {
  static constexpr char digits[] = "0123456789ABCDEF";
  std::string s;
  for (const std::uint8_t x : b) {
    if (!s.empty()) s += ' ';
    s += digits[x >> 4];
    s += digits[x & 0x0F];
  }
  return s;
}

/** A duration in nanoseconds (what a failed comparison of times prints). */
std::int64_t ns(d::clock::duration x) { return std::chrono::duration_cast<std::chrono::nanoseconds>(x).count(); }

// protocol.md §4.11: the ping every library sends, its ACK and NACK; the short ping of a resync.
const byte_vector ping_frame = bytes(0x04, 0xFE, 0x06, 0x08);
const byte_vector ping_ack = bytes(0x04, 0xFE, 0x06, 0x08);
const byte_vector ping_nack = bytes(0x04, 0xFE, 0x15, 0x17);
const byte_vector short_ping = bytes(0x03, 0xFE, 0x01);
// §4.1: MOV RAM 0x0000 (config), 2 bytes → COM: [0A][00][TYPE 20][DST COM 00 00 00][SRC 00 00 02][SUM]
const byte_vector read_frame = bytes(0x0A, 0x00, 0x20, 0x00, 0x00, 0x00, 0x00, 0x00, 0x02, 0x2C);
// §2.2: its data reply [05][00][lo][hi][SUM] (here the config word 0x008B), and its NACK.
const byte_vector read_reply = bytes(0x05, 0x00, 0x8B, 0x00, 0x90);
const byte_vector read_nack = bytes(0x04, 0x00, 0x15, 0x19);
// §4.6: SINGLE, ICS 0 to 7500 (0x1D4C) in 10 frames: [07][0F][ics][speed][lo][hi][SUM]; its ACK and NACK.
const byte_vector single_frame = bytes(0x07, 0x0F, 0x00, 0x0A, 0x4C, 0x1D, 0x89);
const byte_vector single_ack = bytes(0x04, 0x0F, 0x06, 0x19);
const byte_vector single_nack = bytes(0x04, 0x0F, 0x15, 0x28);

t::request ping_request() { return t::request::of(ping{}); }
t::request read_request() { return t::request::of(move::read_ram(ram::config, 2).value()); }
t::request single_request() { return t::request::of(single_servo{0, 7500, 10}); }

/** The line rate of the tests: a byte (11 bits at 8E1) takes exactly 8.8 µs at 1.25 Mbit/s. */
constexpr std::uint32_t test_baud = 1'250'000;
/** The wire time of @p n bytes at test_baud. */
d::clock::duration wire(std::size_t n) { return std::chrono::nanoseconds(static_cast<std::int64_t>(n) * 8'800); }

/** An I/O that moved @p n bytes. */
d::io_result moved(std::size_t n) {
  d::io_result r;
  r.n = n;
  return r;
}
/** An I/O whose deadline passed first, after @p n bytes. */
d::io_result timed_out(std::size_t n = 0) {
  d::io_result r;
  r.n = n;
  r.timed_out = true;
  return r;
}
/** An I/O that failed with @p ec, after @p n bytes. */
d::io_result failed(t::error_code ec, std::size_t n = 0) {
  d::io_result r;
  r.n = n;
  r.ec = ec;
  return r;
}
/** A write action done in full. */
d::io_result wrote_all(const d::action& a) {
  REQUIRE(a.what == kind::write);
  return moved(a.out.size());
}
/** A read action that got @p b: the bytes go into its buffer, as a driver's read puts them. */
d::io_result feed(const d::action& a, std::span<const std::uint8_t> b) {
  REQUIRE(a.what == kind::read);
  REQUIRE(b.size() <= a.in.size());  // a driver never reads more than it is asked for
  std::copy(b.begin(), b.end(), a.in.begin());
  return moved(b.size());
}

/** A machine, its options and counters, and a virtual clock that moves only when told to. */
struct rig {
  t::client_options opt;
  t::client_counters n;
  d::exchange_machine m{opt, n};
  time_point now = time_point{} + 1000h;  // any time: the machine knows only what it is told

  rig() {
    opt.baud = test_baud;
    opt.turnaround = 20ms;  // not the defaults, so the deadlines show which values are used
    opt.quiet = 3ms;
  }
  /** Starts @p r now. */
  d::action start(const t::request& r, std::size_t stray = 0) { return m.start(r, now, stray); }
  /** The last action ended with @p r, @p later after the previous event. */
  d::action resume(const d::io_result& r, d::clock::duration later = 10us) {
    now += later;
    return m.resume(r, now);
  }
  /** Runs a resync that goes well from its first action @p a: the short ping, its ACK, silence. */
  d::action clean_resync(d::action a) {
    REQUIRE(a.what == kind::write);
    REQUIRE(hex(a.out) == hex(short_ping));
    a = resume(wrote_all(a), 20us);
    a = resume(feed(a, ping_ack), 100us);
    REQUIRE(a.what == kind::read);
    REQUIRE(ns(a.deadline - now) == ns(opt.quiet));
    return resume(timed_out(), opt.quiet);
  }
  /** From @p a, the config read's frame goes out and its reply comes: done, no error, 0x008B. */
  void read_answered(d::action a) {
    REQUIRE(a.what == kind::write);
    CHECK(hex(a.out) == hex(read_frame));
    a = resume(wrote_all(a));
    a = resume(feed(a, read_reply));
    REQUIRE(a.what == kind::done);
    CHECK_FALSE(a.ec);
    CHECK(m.reply().u16() == 0x008B);
  }
  /** Nothing ever answers: every write goes out, every read times out at its deadline. The writes. */
  std::vector<byte_vector> silent_line(d::action a) {
    std::vector<byte_vector> writes;
    while (a.what != kind::done) {
      REQUIRE(writes.size() < 50);
      if (a.what == kind::write) {
        writes.emplace_back(a.out.begin(), a.out.end());
        a = resume(wrote_all(a));
      } else {
        REQUIRE(a.what == kind::read);
        a = resume(timed_out(), a.deadline - now);
      }
    }
    return writes;
  }
};

}  // namespace

TEST_CASE("machine: wire time is 11 bits a byte at the line rate", "[transport][machine]") {
  CHECK(ns(t::wire_time(8, 1'250'000)) == 70'400);         // 88 bits at 1.25 Mbit/s
  CHECK(ns(t::wire_time(9, 115'200)) == 859'375);          // 99 bits at 115200 bit/s
  CHECK(ns(t::wire_time(1, 625'000)) == 17'600);           // 11 bits at 625 kbit/s
  CHECK(ns(t::wire_time(15, test_baud)) == ns(wire(15)));  // the helper of these tests agrees
}

TEST_CASE("machine: a clean exchange writes the frame, reads the reply, ends without error", "[transport][machine]") {
  struct clean_case {
    const char* name;
    t::request req;
    byte_vector frame, reply;
    reply_kind kind;
    std::uint8_t command;
    byte_vector data;
  };
  const clean_case cases[] = {
      {"ping", ping_request(), ping_frame, ping_ack, reply_kind::ack, 0xFE, {}},
      {"read", read_request(), read_frame, read_reply, reply_kind::data, 0x00, bytes(0x8B, 0x00)},
      {"write", single_request(), single_frame, single_ack, reply_kind::ack, 0x0F, {}},
  };
  for (const auto& c : cases) {
    DYNAMIC_SECTION(c.name) {
      rig r;
      const auto t0 = r.now;
      const auto wire_both = wire(c.frame.size() + c.reply.size());
      auto a = r.start(c.req);
      REQUIRE(a.what == kind::write);
      CHECK(hex(a.out) == hex(c.frame));
      CHECK(ns(a.deadline - t0) == ns(wire_both + r.opt.turnaround));
      CHECK(r.m.deadline() == a.deadline);
      CHECK_FALSE(r.m.idle());
      a = r.resume(moved(c.frame.size()), 30us);
      REQUIRE(a.what == kind::read);
      CHECK(a.in.size() == c.reply.size());
      CHECK(ns(a.deadline - t0) == ns(wire_both + r.opt.turnaround));  // one deadline for the attempt
      CHECK(ns(a.expected - t0) == ns(wire_both));                     // when the reply is due on the wire
      a = r.resume(feed(a, c.reply), 200us);
      REQUIRE(a.what == kind::done);
      CHECK_FALSE(a.ec);
      CHECK(r.m.idle());
      CHECK_FALSE(r.m.dirty());
      CHECK(r.m.reply().kind == c.kind);
      CHECK(r.m.reply().command == c.command);
      CHECK(hex(r.m.reply().data.bytes()) == hex(c.data));
      CHECK(r.n.exchanges == 1);
      CHECK(r.n.bytes_out == c.frame.size());
      CHECK(r.n.bytes_in == c.reply.size());
      CHECK(r.n.errors == 0);
      CHECK(r.n.retries == 0);
      CHECK(r.n.timeouts == 0);
      CHECK(r.n.resyncs == 0);
      CHECK(r.n.nacks == 0);
    }
  }
}

TEST_CASE("machine: the counters add up over exchanges, and a data reply reads as its word", "[transport][machine]") {
  rig r;
  const auto p = ping_request();
  const auto rd = read_request();
  const auto s = single_request();
  for (const t::request* req : {&p, &rd, &s}) {
    auto a = r.start(*req);
    a = r.resume(wrote_all(a));
    const auto& reply = req == &p ? ping_ack : req == &rd ? read_reply : single_ack;
    a = r.resume(feed(a, reply), 1ms);
    REQUIRE(a.what == kind::done);
    CHECK_FALSE(a.ec);
    if (req == &rd) CHECK(r.m.reply().u16() == 0x008B);
  }
  CHECK(r.n.exchanges == 3);
  CHECK(r.n.bytes_out == 4 + 10 + 7);
  CHECK(r.n.bytes_in == 4 + 5 + 4);
  CHECK(r.n.errors == 0);
  CHECK(r.n.retries == 0);
}

TEST_CASE("machine: a reply split anywhere is read without ever asking past its end", "[transport][machine]") {
  struct split_case {
    const char* name;
    t::request req;
    byte_vector reply;
    std::size_t first_read;  // before the length byte: the size of the reply asked for
    reply_kind kind;
  };
  const split_case cases[] = {
      {"ping ACK", ping_request(), ping_ack, 4, reply_kind::ack},
      {"ping NACK", ping_request(), ping_nack, 4, reply_kind::nack},
      {"read data", read_request(), read_reply, 5, reply_kind::data},
      {"read NACK", read_request(), read_nack, 5, reply_kind::nack},
      {"write ACK", single_request(), single_ack, 4, reply_kind::ack},
      {"write NACK", single_request(), single_nack, 4, reply_kind::nack},
  };
  for (const auto& c : cases) {
    const std::span<const std::uint8_t> reply(c.reply);
    DYNAMIC_SECTION(c.name << ", one byte at a time") {
      rig r;
      auto a = r.start(c.req);
      a = r.resume(wrote_all(a));
      const auto deadline = a.deadline;
      for (std::size_t k = 0; k < reply.size(); ++k) {
        INFO("after " << k << " bytes");
        REQUIRE(a.what == kind::read);
        // After the length byte, exactly what is left of this reply: the next one is never eaten.
        CHECK(a.in.size() == (k == 0 ? c.first_read : reply.size() - k));
        CHECK(a.deadline == deadline);
        a = r.resume(feed(a, reply.subspan(k, 1)), 9us);
      }
      REQUIRE(a.what == kind::done);
      CHECK_FALSE(a.ec);
      CHECK(r.m.reply().kind == c.kind);
      CHECK(r.n.bytes_in == reply.size());
    }
    for (std::size_t k = 1; k < reply.size(); ++k) {
      DYNAMIC_SECTION(c.name << ", split after byte " << k) {
        rig r;
        auto a = r.start(c.req);
        a = r.resume(wrote_all(a));
        REQUIRE(a.what == kind::read);
        CHECK(a.in.size() == c.first_read);
        a = r.resume(feed(a, reply.first(k)), 50us);
        REQUIRE(a.what == kind::read);
        CHECK(a.in.size() == reply.size() - k);
        a = r.resume(feed(a, reply.subspan(k)), 50us);
        REQUIRE(a.what == kind::done);
        CHECK_FALSE(a.ec);
        CHECK(r.m.reply().kind == c.kind);
        CHECK(r.n.bytes_in == reply.size());
        CHECK(r.n.exchanges == 1);
      }
    }
  }
}

TEST_CASE("machine: a partial write asks to write the rest, before the same deadline", "[transport][machine]") {
  rig r;
  const auto s = single_request();
  auto a = r.start(s);
  const auto deadline = a.deadline;
  a = r.resume(moved(2));
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == hex(std::span(single_frame).subspan(2)));
  CHECK(a.deadline == deadline);
  CHECK(r.n.bytes_out == 2);
  a = r.resume(moved(0));  // nothing went: the same rest again
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == hex(std::span(single_frame).subspan(2)));
  a = r.resume(moved(4));
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == "89");
  a = r.resume(moved(1));
  REQUIRE(a.what == kind::read);
  CHECK(a.in.size() == 4);
  CHECK(a.deadline == deadline);
  CHECK(r.n.bytes_out == 7);
  a = r.resume(feed(a, single_ack));
  REQUIRE(a.what == kind::done);
  CHECK_FALSE(a.ec);
}

TEST_CASE("machine: a malformed reply to a write ends it at once with the codec's error", "[transport][machine]") {
  struct fault {
    const char* name;
    byte_vector reply;
    rcb4::errc error;
  };
  const fault faults[] = {
      {"corrupted checksum", bytes(0x04, 0x0F, 0x06, 0x1A), rcb4::errc::bad_checksum},
      {"corrupted status byte", bytes(0x04, 0x0F, 0x07, 0x19), rcb4::errc::bad_checksum},
      {"wrong length byte", bytes(0x05, 0x0F, 0x06, 0x1A), rcb4::errc::bad_reply_length},
      {"wrong echoed command", bytes(0x04, 0xFE, 0x06, 0x08), rcb4::errc::echo_mismatch},
      {"garbage", bytes(0xAA, 0x55, 0xAA, 0x55), rcb4::errc::bad_reply_length},
      {"neither ACK nor NACK", bytes(0x04, 0x0F, 0x07, 0x1A), rcb4::errc::bad_ack_code},
  };
  for (const auto& f : faults) {
    DYNAMIC_SECTION(f.name) {
      rig r;
      const auto s = single_request();
      auto a = r.start(s);
      a = r.resume(wrote_all(a));
      a = r.resume(feed(a, f.reply));
      REQUIRE(a.what == kind::done);  // a write is not repeated: it may have reached the board
      CHECK(a.ec == f.error);
      CHECK(r.m.dirty());
      CHECK_FALSE(r.m.lost());
      CHECK(r.n.exchanges == 1);
      CHECK(r.n.errors == 1);
      CHECK(r.n.retries == 0);
      CHECK(r.n.resyncs == 0);
      CHECK(r.n.timeouts == 0);
      // The next exchange starts from a clean line: the short ping first.
      const auto p = ping_request();
      a = r.start(p);
      REQUIRE(a.what == kind::write);
      CHECK(hex(a.out) == hex(short_ping));
      CHECK(r.n.resyncs == 1);
    }
  }
}

TEST_CASE("machine: a malformed reply to an idempotent request is retried after a resync", "[transport][machine]") {
  struct fault {
    const char* name;
    t::request req;
    byte_vector frame, reply, good;
    rcb4::errc error;
  };
  const fault faults[] = {
      {"ping, corrupted checksum", ping_request(), ping_frame, bytes(0x04, 0xFE, 0x06, 0x09), ping_ack,
       rcb4::errc::bad_checksum},
      {"ping, wrong echoed command", ping_request(), ping_frame, bytes(0x04, 0xFD, 0x06, 0x07), ping_ack,
       rcb4::errc::echo_mismatch},
      {"ping, wrong length byte", ping_request(), ping_frame, bytes(0x05, 0xFE, 0x06, 0x09), ping_ack,
       rcb4::errc::bad_reply_length},
      {"read, corrupted data byte", read_request(), read_frame, bytes(0x05, 0x00, 0x8B, 0x01, 0x90), read_reply,
       rcb4::errc::bad_checksum},
      {"read, wrong length byte", read_request(), read_frame, bytes(0x06, 0x00, 0x8B, 0x00, 0x91), read_reply,
       rcb4::errc::bad_reply_length},
      {"read, wrong echoed command", read_request(), read_frame, bytes(0x05, 0x01, 0x8B, 0x00, 0x91), read_reply,
       rcb4::errc::echo_mismatch},
      {"read, ACK instead of data", read_request(), read_frame, bytes(0x04, 0x00, 0x06, 0x0A), read_reply,
       rcb4::errc::unexpected_ack},
      {"read, garbage", read_request(), read_frame, bytes(0x00, 0x00, 0x00, 0x00, 0x00), read_reply,
       rcb4::errc::bad_reply_length},
  };
  for (const auto& f : faults) {
    DYNAMIC_SECTION(f.name) {
      rig r;
      SECTION("with read_retries = 0, the fault is the outcome") {
        r.opt.read_retries = 0;
        auto a = r.start(f.req);
        a = r.resume(wrote_all(a));
        a = r.resume(feed(a, f.reply));
        REQUIRE(a.what == kind::done);
        CHECK(a.ec == f.error);
        CHECK(r.n.retries == 0);
        CHECK(r.m.dirty());
      }
      SECTION("with the default retries, a resync and the next attempt succeed") {
        auto a = r.start(f.req);
        a = r.resume(wrote_all(a));
        a = r.resume(feed(a, f.reply), 300us);
        REQUIRE(a.what == kind::write);
        CHECK(hex(a.out) == hex(short_ping));
        CHECK(ns(a.deadline - r.now) == ns(wire(3 + 4) + r.opt.turnaround));
        CHECK(r.n.retries == 1);
        a = r.clean_resync(a);
        REQUIRE(a.what == kind::write);
        CHECK(hex(a.out) == hex(f.frame));
        CHECK(ns(a.deadline - r.now) == ns(wire(f.frame.size() + f.good.size()) + r.opt.turnaround));
        a = r.resume(wrote_all(a));
        a = r.resume(feed(a, f.good));
        REQUIRE(a.what == kind::done);
        CHECK_FALSE(a.ec);
        CHECK_FALSE(r.m.dirty());
        CHECK(r.n.exchanges == 1);
        CHECK(r.n.errors == 0);
        CHECK(r.n.retries == 1);
        CHECK(r.n.resyncs == 1);
        CHECK(r.n.bytes_out == 2 * f.frame.size() + 3);
        CHECK(r.n.bytes_in == f.reply.size() + 4 + f.good.size());
      }
    }
  }
}

TEST_CASE("machine: a timeout ends a write at once, at the write or at the read", "[transport][machine]") {
  rig r;
  const auto s = single_request();
  auto a = r.start(s);
  std::size_t out = 0, in = 0;
  SECTION("the write times out with nothing written") { a = r.resume(timed_out(0), a.deadline - r.now); }
  SECTION("the write times out with part written") {
    a = r.resume(timed_out(3), a.deadline - r.now);
    out = 3;
  }
  t::error_code expected = t::transport_errc::timeout;
  SECTION("the read times out with nothing read") {
    a = r.resume(wrote_all(a));
    a = r.resume(timed_out(), a.deadline - r.now);
    out = 7;
  }
  SECTION("the read times out with part of the reply: truncated, not silent") {
    a = r.resume(wrote_all(a));
    auto io = feed(a, std::span(single_ack).first(2));
    io.timed_out = true;
    a = r.resume(io, a.deadline - r.now);
    out = 7;
    in = 2;
    expected = t::transport_errc::truncated;
  }
  REQUIRE(a.what == kind::done);
  CHECK(a.ec == expected);
  CHECK(r.m.dirty());
  CHECK(r.n.timeouts == 1);
  CHECK(r.n.retries == 0);
  CHECK(r.n.errors == 1);
  CHECK(r.n.exchanges == 1);
  CHECK(r.n.bytes_out == out);
  CHECK(r.n.bytes_in == in);
}

TEST_CASE("machine: a timed-out ping is retried, and the late reply is discarded by the resync",
          "[transport][machine]") {
  rig r;
  const auto p = ping_request();
  auto a = r.start(p);
  a = r.resume(wrote_all(a));
  auto io = feed(a, std::span(ping_ack).first(2));  // the reply starts, and stops
  io.timed_out = true;
  a = r.resume(io, a.deadline - r.now);
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == hex(short_ping));
  CHECK(ns(a.deadline - r.now) == ns(wire(7) + r.opt.turnaround));
  CHECK(r.n.timeouts == 1);
  CHECK(r.n.retries == 1);
  a = r.resume(wrote_all(a));
  a = r.resume(feed(a, bytes(0x06, 0x08, 0x04, 0xFE, 0x06, 0x08)));  // the rest of the late reply, then the ACK
  REQUIRE(a.what == kind::read);
  CHECK(ns(a.deadline - r.now) == ns(r.opt.quiet));
  a = r.resume(timed_out(), r.opt.quiet);
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == hex(ping_frame));
  a = r.resume(wrote_all(a));
  a = r.resume(feed(a, ping_ack));
  REQUIRE(a.what == kind::done);
  CHECK_FALSE(a.ec);
  CHECK(r.n.errors == 0);
  CHECK(r.n.bytes_in == 2 + 6 + 4);
}

TEST_CASE("machine: idempotent requests get read_retries more attempts, writes none unless retry_writes",
          "[transport][machine]") {
  const auto p = ping_request();
  const auto rd = read_request();
  const auto s = single_request();
  SECTION("ping, default read_retries (2): three attempts, the last two resync first") {
    rig r;
    const auto writes = r.silent_line(r.start(p));
    CHECK(writes == std::vector<byte_vector>{ping_frame, short_ping, short_ping});
    CHECK(r.n.timeouts == 3);
    CHECK(r.n.retries == 2);
    CHECK(r.n.resyncs == 2);
    CHECK(r.n.errors == 1);
    CHECK(r.n.exchanges == 1);
  }
  SECTION("read, a resync that succeeds and a reply that never comes") {
    rig r;
    auto a = r.start(rd);
    a = r.resume(wrote_all(a));
    a = r.resume(timed_out(), a.deadline - r.now);  // attempt 1
    a = r.resume(wrote_all(a));
    a = r.resume(timed_out(), a.deadline - r.now);  // attempt 2: the resync hears nothing
    a = r.clean_resync(a);                          // attempt 3
    REQUIRE(a.what == kind::write);
    CHECK(hex(a.out) == hex(read_frame));
    a = r.resume(wrote_all(a));
    a = r.resume(timed_out(), a.deadline - r.now);
    REQUIRE(a.what == kind::done);
    CHECK(a.ec == t::transport_errc::timeout);
    CHECK(r.n.timeouts == 3);
    CHECK(r.n.retries == 2);
    CHECK(r.n.resyncs == 2);
  }
  SECTION("read_retries sets the number of attempts") {
    for (const unsigned retries : {0u, 1u, 5u}) {
      rig r;
      r.opt.read_retries = retries;
      CHECK(r.silent_line(r.start(rd)).size() == 1 + retries);
      CHECK(r.n.retries == retries);
    }
  }
  SECTION("a write gets one attempt") {
    rig r;
    r.opt.read_retries = 5;
    CHECK(r.silent_line(r.start(s)) == std::vector<byte_vector>{single_frame});
    CHECK(r.n.retries == 0);
    CHECK(r.n.resyncs == 0);
  }
  SECTION("retry_writes: a write gets the retries too") {
    rig r;
    r.opt.retry_writes = true;
    CHECK(r.silent_line(r.start(s)) == std::vector<byte_vector>{single_frame, short_ping, short_ping});
    CHECK(r.n.retries == 2);
  }
  SECTION("retry_writes: a write is retried after a bad reply, and succeeds") {
    rig r;
    r.opt.retry_writes = true;
    auto a = r.start(s);
    a = r.resume(wrote_all(a));
    a = r.resume(feed(a, bytes(0x04, 0x0F, 0x06, 0x1A)));  // corrupted SUM
    a = r.clean_resync(a);
    REQUIRE(a.what == kind::write);
    CHECK(hex(a.out) == hex(single_frame));
    a = r.resume(wrote_all(a));
    a = r.resume(feed(a, single_ack));
    REQUIRE(a.what == kind::done);
    CHECK_FALSE(a.ec);
    CHECK(r.n.retries == 1);
  }
}

TEST_CASE("machine: a lost link (EOF, connection reset) at any byte ends the exchange when it cannot reopen",
          "[transport][machine]") {
  struct lost_case {
    const char* name;
    t::request req;
    byte_vector frame, reply;
  };
  const lost_case cases[] = {
      {"ping", ping_request(), ping_frame, ping_ack},
      {"read", read_request(), read_frame, read_reply},
      {"write", single_request(), single_frame, single_ack},
  };
  const t::error_code losses[] = {boost::asio::error::eof, boost::asio::error::connection_reset};
  for (const auto& c : cases) {
    for (const auto& loss : losses) {
      for (std::size_t at = 0; at < c.frame.size() + c.reply.size(); ++at) {
        DYNAMIC_SECTION(c.name << ", " << loss.message() << " after " << at << " bytes of the exchange") {
          rig r;
          auto a = r.start(c.req);
          std::size_t in = 0;
          if (at < c.frame.size()) {
            if (at > 0) a = r.resume(moved(at));
            REQUIRE(a.what == kind::write);
            a = r.resume(failed(loss));
          } else {
            a = r.resume(wrote_all(a));
            in = at - c.frame.size();
            auto io = feed(a, std::span(c.reply).first(in));
            io.ec = loss;
            a = r.resume(io);
          }
          REQUIRE(a.what == kind::done);
          if (loss == boost::asio::error::eof)
            CHECK(a.ec == t::transport_errc::closed);
          else
            CHECK(a.ec == boost::asio::error::connection_reset);
          CHECK(r.m.lost());
          CHECK(r.m.dirty());
          CHECK(r.n.retries == 0);  // nothing to retry on: the link is gone
          CHECK(r.n.errors == 1);
          CHECK(r.n.exchanges == 1);
          CHECK(r.n.bytes_out == std::min(at, c.frame.size()));
          CHECK(r.n.bytes_in == in);
          // Without a reopen, the next exchange tries the line as it is, after a resync.
          a = r.start(c.req);
          REQUIRE(a.what == kind::write);
          CHECK(hex(a.out) == hex(short_ping));
        }
      }
    }
  }
}

TEST_CASE("machine: a lost link during a resync ends the exchange", "[transport][machine]") {
  rig r;
  const auto p = ping_request();
  auto a = r.start(p, 1);
  REQUIRE(a.what == kind::write);
  SECTION("at the short ping's write") { a = r.resume(failed(boost::asio::error::eof)); }
  SECTION("while discarding") {
    a = r.resume(wrote_all(a));
    auto io = feed(a, bytes(0x04, 0xFE));
    io.ec = boost::asio::error::connection_reset;
    a = r.resume(io);
  }
  REQUIRE(a.what == kind::done);
  CHECK((a.ec == t::transport_errc::closed || a.ec == boost::asio::error::connection_reset));
  CHECK(r.m.lost());
  CHECK(r.n.retries == 0);
  CHECK(r.n.errors == 1);
}

TEST_CASE("machine: an error of the stream that is not a lost link ends the exchange as it is",
          "[transport][machine]") {
  rig r;
  r.m.set_reopen(true);
  const auto p = ping_request();
  auto a = r.start(p);
  a = r.resume(failed(t::os_error(EINVAL)));
  REQUIRE(a.what == kind::done);
  CHECK(a.ec == std::errc::invalid_argument);
  CHECK_FALSE(r.m.lost());
  CHECK(r.m.dirty());
  CHECK(r.n.retries == 0);
  a = r.start(p);  // no reopen: the link was not lost
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == hex(short_ping));
}

TEST_CASE("machine: a duplicated reply stays on the line and is discarded by a resync", "[transport][machine]") {
  rig r;
  const auto p = ping_request();
  const auto rd = read_request();
  auto a = r.start(p);
  a = r.resume(wrote_all(a));
  REQUIRE(a.in.size() == 4);  // the copy behind this reply is not read
  a = r.resume(feed(a, ping_ack));
  REQUIRE(a.what == kind::done);
  CHECK_FALSE(a.ec);
  SECTION("the driver finds the stray bytes: the next exchange resyncs first") {
    a = r.start(rd, 4);
    REQUIRE(a.what == kind::write);
    CHECK(hex(a.out) == hex(short_ping));
    a = r.resume(wrote_all(a));
    a = r.resume(feed(a, join(ping_ack, ping_ack)));  // the copy, then the resync's ACK
    REQUIRE(a.what == kind::read);
    CHECK(ns(a.deadline - r.now) == ns(r.opt.quiet));
    a = r.resume(timed_out(), r.opt.quiet);
    r.read_answered(a);
    CHECK(r.n.retries == 0);
    CHECK(r.n.errors == 0);
    CHECK(r.n.resyncs == 1);
  }
  SECTION("unnoticed: the copy is read as the next reply, fails, and the retry gets the right one") {
    a = r.start(rd);
    REQUIRE(a.what == kind::write);
    CHECK(hex(a.out) == hex(read_frame));
    a = r.resume(wrote_all(a));
    a = r.resume(feed(a, ping_ack));  // only the copy is there yet
    REQUIRE(a.what == kind::write);
    CHECK(hex(a.out) == hex(short_ping));
    a = r.resume(wrote_all(a));
    a = r.resume(feed(a, join(read_reply, ping_ack)));  // the first attempt's late reply, then the ACK
    REQUIRE(a.what == kind::read);
    a = r.resume(timed_out(), r.opt.quiet);
    r.read_answered(a);
    CHECK(r.n.retries == 1);
    CHECK(r.n.errors == 0);
  }
}

TEST_CASE("machine: a resync writes the short ping, discards to its ACK, then waits for quiet",
          "[transport][machine]") {
  rig r;
  const auto p = ping_request();
  auto a = r.start(p);
  a = r.resume(wrote_all(a));
  a = r.resume(feed(a, bytes(0x04, 0xFE, 0x06, 0x09)), 200us);  // corrupted SUM
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == hex(short_ping));
  const auto t1 = r.now;
  CHECK(ns(a.deadline - t1) == ns(wire(3 + 4) + r.opt.turnaround));
  CHECK(r.m.deadline() == a.deadline);
  a = r.resume(wrote_all(a), 20us);
  REQUIRE(a.what == kind::read);
  CHECK(a.in.size() >= 4);  // anything waiting goes into a junk buffer
  CHECK(ns(a.deadline - t1) == ns(wire(3 + 4) + r.opt.turnaround));
  CHECK(ns(a.expected - t1) == ns(wire(3 + 4)));
  a = r.resume(feed(a, ping_ack), 150us);
  REQUIRE(a.what == kind::read);
  CHECK(ns(a.deadline - r.now) == ns(r.opt.quiet));  // the ACK: now the line must stay quiet
  a = r.resume(timed_out(), r.opt.quiet);
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == hex(ping_frame));
  CHECK(ns(a.deadline - r.now) == ns(wire(8) + r.opt.turnaround));  // a new deadline for the real frame
  CHECK_FALSE(r.m.dirty());
  a = r.resume(wrote_all(a));
  a = r.resume(feed(a, ping_ack));
  REQUIRE(a.what == kind::done);
  CHECK_FALSE(a.ec);
  CHECK(r.n.resyncs == 1);
  CHECK(r.n.retries == 1);
  CHECK(r.n.timeouts == 0);  // the quiet period ending is the resync succeeding, not a missed deadline
  CHECK(r.n.errors == 0);
  CHECK(r.n.exchanges == 1);
  CHECK(r.n.bytes_out == 4 + 3 + 4);
  CHECK(r.n.bytes_in == 4 + 4 + 4);
}

TEST_CASE("machine: the resync's ACK is found across reads and after junk", "[transport][machine]") {
  rig r;
  const auto p = ping_request();
  auto a = r.start(p, 3);
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == hex(short_ping));
  const auto sync_deadline = a.deadline;
  a = r.resume(wrote_all(a));
  SECTION("split ACK") {
    a = r.resume(feed(a, bytes(0x00, 0x8B, 0x04, 0xFE)));  // junk, then half the ACK
    REQUIRE(a.what == kind::read);
    CHECK(a.deadline == sync_deadline);
    a = r.resume(feed(a, bytes(0x06)));
    REQUIRE(a.what == kind::read);
    CHECK(a.deadline == sync_deadline);
    a = r.resume(feed(a, bytes(0x08)));
  }
  SECTION("junk and the ACK in one read") { a = r.resume(feed(a, bytes(0x8B, 0x00, 0x90, 0x04, 0xFE, 0x06, 0x08))); }
  REQUIRE(a.what == kind::read);
  CHECK(ns(a.deadline - r.now) == ns(r.opt.quiet));
  a = r.resume(timed_out(), r.opt.quiet);
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == hex(ping_frame));
}

TEST_CASE("machine: bytes after an ACK-like tail keep the resync reading", "[transport][machine]") {
  rig r;
  const auto p = ping_request();
  auto a = r.start(p, 9);  // a stale ACK and a stale data reply wait on the line
  a = r.resume(wrote_all(a));
  a = r.resume(feed(a, ping_ack));  // looks like ours
  REQUIRE(a.what == kind::read);
  CHECK(ns(a.deadline - r.now) == ns(r.opt.quiet));
  a = r.resume(feed(a, bytes(0x05)), 1ms);  // more, within `quiet`: it was not ours
  REQUIRE(a.what == kind::read);
  CHECK(ns(a.deadline - r.now) == ns(wire(2 * 4) + r.opt.turnaround));
  const auto deadline = a.deadline;
  a = r.resume(feed(a, bytes(0x00, 0x8B, 0x00, 0x90)));
  REQUIRE(a.what == kind::read);
  CHECK(a.deadline == deadline);
  a = r.resume(feed(a, ping_ack));  // the real one
  REQUIRE(a.what == kind::read);
  CHECK(ns(a.deadline - r.now) == ns(r.opt.quiet));
  a = r.resume(timed_out(), r.opt.quiet);
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == hex(ping_frame));
  CHECK(r.n.timeouts == 0);
  CHECK(r.n.resyncs == 1);
  CHECK(r.n.bytes_in == 4 + 1 + 4 + 4);
}

TEST_CASE("machine: a resync that never sees the ACK is a failed attempt", "[transport][machine]") {
  rig r;
  const auto p = ping_request();
  const auto s = single_request();
  SECTION("ping: bytes in no framing, the next attempt resyncs again") {
    auto a = r.start(p, 2);
    const auto deadline = a.deadline;
    a = r.resume(wrote_all(a));
    a = r.resume(feed(a, bytes(0x12, 0x34)));
    REQUIRE(a.what == kind::read);
    CHECK(a.deadline == deadline);  // junk does not move the deadline
    a = r.resume(timed_out(), a.deadline - r.now);
    REQUIRE(a.what == kind::write);
    CHECK(hex(a.out) == hex(short_ping));
    CHECK(ns(a.deadline - r.now) == ns(wire(7) + r.opt.turnaround));
    CHECK(r.n.timeouts == 0);  // the line answered, in no framing the board uses: not a timeout
    CHECK(r.n.retries == 1);
    CHECK(r.n.resyncs == 2);
  }
  SECTION("an ACK that comes with the deadline was not followed by quiet") {
    auto a = r.start(p, 2);
    a = r.resume(wrote_all(a));
    auto io = feed(a, ping_ack);
    io.timed_out = true;
    a = r.resume(io, a.deadline - r.now);
    REQUIRE(a.what == kind::write);
    CHECK(hex(a.out) == hex(short_ping));  // the next attempt, not the frame
    CHECK(r.n.timeouts == 1);
    CHECK(r.n.retries == 1);
  }
  SECTION("write: the exchange ends, its frame never written") {
    auto a = r.start(s, 2);
    a = r.resume(wrote_all(a));
    a = r.resume(timed_out(), a.deadline - r.now);
    REQUIRE(a.what == kind::done);
    CHECK(a.ec == t::transport_errc::timeout);
    CHECK(r.n.bytes_out == 3);
    CHECK(r.n.timeouts == 1);
  }
  SECTION("a line that keeps talking after the ACK does not settle") {
    auto a = r.start(p, 1);
    a = r.resume(wrote_all(a));
    int reads = 0;
    while (a.what == kind::read && reads < 200) {
      a = r.resume(feed(a, ping_ack), 1ms);
      if (a.what != kind::read) break;
      a = r.resume(feed(a, bytes(0x00)), 1ms);
      reads += 2;
    }
    CHECK(reads > 2);  // a byte after an ACK-like tail alone does not end the resync
    REQUIRE(a.what == kind::write);
    CHECK(hex(a.out) == hex(short_ping));  // the next attempt
    CHECK(r.n.timeouts == 1);
  }
}

TEST_CASE("machine: stray bytes found before the exchange make its first attempt resync", "[transport][machine]") {
  rig r;
  const auto s = single_request();
  auto a = r.start(s, 1);
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == hex(short_ping));
  CHECK(ns(a.deadline - r.now) == ns(wire(7) + r.opt.turnaround));
  CHECK(r.n.resyncs == 1);
  CHECK(r.n.retries == 0);  // a resync is not a retry
  a = r.clean_resync(a);
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == hex(single_frame));
  a = r.resume(wrote_all(a));
  a = r.resume(feed(a, single_ack));
  REQUIRE(a.what == kind::done);
  CHECK_FALSE(a.ec);
  // And with nothing stray on a clean line, no resync.
  a = r.start(s, 0);
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == hex(single_frame));
  CHECK(r.n.resyncs == 1);
}

TEST_CASE("machine: the reported error is the first one more telling than a timeout", "[transport][machine]") {
  rig r;
  const auto p = ping_request();
  auto a = r.start(p);
  a = r.resume(wrote_all(a));
  SECTION("a bad checksum, then silence") {
    a = r.resume(feed(a, bytes(0x04, 0xFE, 0x06, 0x09)));
    a = r.resume(wrote_all(a));                     // attempt 2: resync
    a = r.resume(timed_out(), a.deadline - r.now);  // no ACK
    a = r.resume(wrote_all(a));                     // attempt 3: resync
    a = r.resume(timed_out(), a.deadline - r.now);  // no ACK
    REQUIRE(a.what == kind::done);
    CHECK(a.ec == rcb4::errc::bad_checksum);
    CHECK(r.n.timeouts == 2);
  }
  SECTION("silence, then a wrong echo, then silence") {
    a = r.resume(timed_out(), a.deadline - r.now);
    a = r.clean_resync(a);  // attempt 2
    a = r.resume(wrote_all(a));
    a = r.resume(feed(a, bytes(0x04, 0xFD, 0x06, 0x07)));
    a = r.resume(wrote_all(a));  // attempt 3
    a = r.resume(timed_out(), a.deadline - r.now);
    REQUIRE(a.what == kind::done);
    CHECK(a.ec == rcb4::errc::echo_mismatch);
  }
  SECTION("a bad checksum, then a bad length byte: the first stays") {
    a = r.resume(feed(a, bytes(0x04, 0xFE, 0x06, 0x09)));
    a = r.clean_resync(a);  // attempt 2
    a = r.resume(wrote_all(a));
    a = r.resume(feed(a, bytes(0x05, 0xFE, 0x06, 0x09)));
    a = r.resume(wrote_all(a));  // attempt 3
    a = r.resume(timed_out(), a.deadline - r.now);
    REQUIRE(a.what == kind::done);
    CHECK(a.ec == rcb4::errc::bad_checksum);
  }
  SECTION("only silence: a timeout") {
    a = r.resume(timed_out(), a.deadline - r.now);
    CHECK(r.silent_line(a).size() == 2);
    CHECK(r.n.errors == 1);
  }
  CHECK(r.n.exchanges == 1);
  CHECK(r.n.retries == 2);
}

TEST_CASE("machine: the request's own bytes coming back are a loopback, never retried", "[transport][machine]") {
  rig r;
  const auto s = single_request();
  const auto rd = read_request();
  // What comes back is fed in the pieces the machine asks for; it confirms a loopback by reading
  // the rest of our frame (a reply that only starts like it is the malformed reply it is).
  const auto echo_back = [&r](d::action a, std::span<const std::uint8_t> frame, std::size_t first) {
    std::size_t at = 0;
    while (a.what == kind::read && at < frame.size()) {
      const std::size_t k = std::min({at == 0 ? first : a.in.size(), a.in.size(), frame.size() - at});
      a = r.resume(feed(a, frame.subspan(at, k)));
      at += k;
    }
    return a;
  };
  SECTION("write, its first 4 bytes in one read") {
    r.opt.retry_writes = true;  // no retry cures a loopback
    auto a = r.start(s);
    a = r.resume(wrote_all(a));
    REQUIRE(a.in.size() == 4);
    a = r.resume(feed(a, bytes(0x07, 0x0F, 0x00, 0x0A)));
    REQUIRE(a.what == kind::read);
    CHECK(a.in.size() == 3);  // the rest of our 7-byte frame
    a = r.resume(feed(a, bytes(0x4C, 0x1D, 0x89)));
    REQUIRE(a.what == kind::done);
    CHECK(a.ec == t::transport_errc::echo);
  }
  for (const std::size_t k : {1u, 2u, 3u}) {
    DYNAMIC_SECTION("write, a first read of " << k << " bytes") {
      auto a = r.start(s);
      a = r.resume(wrote_all(a));
      a = echo_back(a, single_frame, k);
      REQUIRE(a.what == kind::done);
      CHECK(a.ec == t::transport_errc::echo);
    }
  }
  SECTION("read, idempotent but not retried") {
    auto a = r.start(rd);
    a = r.resume(wrote_all(a));
    REQUIRE(a.in.size() == 5);
    a = r.resume(feed(a, bytes(0x0A, 0x00, 0x20, 0x00, 0x00)));
    REQUIRE(a.what == kind::read);
    a = r.resume(feed(a, bytes(0x00, 0x00, 0x00, 0x02, 0x2C)));  // the rest of 0A 00 20 00 00 00 00 00 02 2C
    REQUIRE(a.what == kind::done);
    CHECK(a.ec == t::transport_errc::echo);
  }
  CHECK(r.n.retries == 0);
  CHECK(r.n.resyncs == 0);
  CHECK(r.m.dirty());
  CHECK(r.n.errors == r.n.exchanges);
}

TEST_CASE("machine: a reply that only starts like our frame is the malformed reply it is", "[transport][machine]") {
  rig r;
  r.opt.read_retries = 0;
  const auto s = single_request();  // (the request outlives its exchange)
  auto a = r.start(s);
  a = r.resume(wrote_all(a));
  a = r.resume(feed(a, bytes(0x07, 0x0F)));  // like our frame so far
  REQUIRE(a.what == kind::read);
  a = r.resume(feed(a, bytes(0x01)));  // our frame has 00 here
  REQUIRE(a.what == kind::done);
  CHECK(a.ec == rcb4::errc::bad_reply_length);
  CHECK(r.m.dirty());
}

TEST_CASE("machine: a NACK is a reply, not an error", "[transport][machine]") {
  struct nack_case {
    const char* name;
    t::request req;
    byte_vector nack;
    std::uint8_t command;
  };
  const nack_case cases[] = {
      {"ping", ping_request(), ping_nack, 0xFE},
      {"read", read_request(), read_nack, 0x00},
      {"write", single_request(), single_nack, 0x0F},
  };
  for (const auto& c : cases) {
    DYNAMIC_SECTION(c.name) {
      rig r;
      r.opt.retry_writes = true;
      auto a = r.start(c.req);
      a = r.resume(wrote_all(a));
      a = r.resume(feed(a, c.nack));
      REQUIRE(a.what == kind::done);
      CHECK_FALSE(a.ec);
      CHECK(r.m.reply().kind == reply_kind::nack);
      CHECK(r.m.reply().command == c.command);
      CHECK(r.m.reply().data.size() == 0);
      CHECK(r.n.nacks == 1);
      CHECK(r.n.errors == 0);
      CHECK(r.n.retries == 0);
      CHECK(r.n.exchanges == 1);
      CHECK_FALSE(r.m.dirty());
    }
  }
}

TEST_CASE("machine: a lost link is reopened at once, and the frame written without a resync", "[transport][machine]") {
  rig r;
  r.m.set_reopen(true, t::reconnect_policy{10ms, 80ms, 500ms});
  const auto p = ping_request();
  const auto rd = read_request();
  SECTION("ping, end of file at the write") {
    auto a = r.start(p);
    a = r.resume(failed(boost::asio::error::eof), 40us);
    REQUIRE(a.what == kind::reopen);
    CHECK(a.deadline == r.now);
    CHECK(r.m.lost());
    CHECK(r.n.retries == 1);
    a = r.resume(moved(0), 2ms);  // reopened
    REQUIRE(a.what == kind::write);
    CHECK(hex(a.out) == hex(ping_frame));
    CHECK(ns(a.deadline - r.now) == ns(wire(8) + r.opt.turnaround));
    CHECK(r.n.reconnects == 1);
    CHECK_FALSE(r.m.lost());
    CHECK_FALSE(r.m.dirty());
    a = r.resume(wrote_all(a));
    a = r.resume(feed(a, ping_ack));
    REQUIRE(a.what == kind::done);
    CHECK_FALSE(a.ec);
    CHECK(r.n.resyncs == 0);
    CHECK(r.n.errors == 0);
  }
  SECTION("read, connection reset with part of the reply") {
    auto a = r.start(rd);
    a = r.resume(wrote_all(a));
    auto io = feed(a, std::span(read_reply).first(2));
    io.ec = boost::asio::error::connection_reset;
    a = r.resume(io, 100us);
    REQUIRE(a.what == kind::reopen);
    CHECK(a.deadline == r.now);
    a = r.resume(failed(t::os_error(ENODEV)));  // still unplugged
    REQUIRE(a.what == kind::reopen);
    CHECK(ns(a.deadline - r.now) == ns(10ms));
    a = r.resume(failed(t::os_error(ENODEV)), a.deadline - r.now);
    REQUIRE(a.what == kind::reopen);
    CHECK(ns(a.deadline - r.now) == ns(20ms));
    a = r.resume(moved(0), a.deadline - r.now);  // back
    r.read_answered(a);
    CHECK(r.n.reconnects == 1);
    CHECK(r.n.resyncs == 0);
  }
}

TEST_CASE("machine: reopening backs off from first_delay, doubling to max_delay, and gives up",
          "[transport][machine]") {
  rig r;
  r.m.set_reopen(true, t::reconnect_policy{10ms, 80ms, 500ms});
  const auto p = ping_request();
  auto a = r.start(p);
  a = r.resume(wrote_all(a));
  a = r.resume(failed(boost::asio::error::eof), 300us);
  const auto t0 = r.now;
  // 10, 20, 40, 80, 80 ... ms apart; the last attempt at give_up_after exactly.
  const int at_ms[] = {0, 10, 30, 70, 150, 230, 310, 390, 470, 500};
  for (const int ms : at_ms) {
    INFO("reopen at " << ms << " ms");
    REQUIRE(a.what == kind::reopen);
    CHECK(ns(a.deadline - t0) == ns(std::chrono::milliseconds(ms)));
    a = r.resume(failed(t::os_error(ENODEV)), a.deadline - r.now);  // tried on time, still unplugged
  }
  REQUIRE(a.what == kind::done);
  CHECK(a.ec == t::transport_errc::reconnect_failed);
  CHECK(r.m.lost());
  CHECK(r.n.reconnects == 0);
  CHECK(r.n.errors == 1);
  CHECK(r.n.exchanges == 1);
  // The next exchange starts trying again, at once.
  r.now += 1s;
  a = r.start(p);
  REQUIRE(a.what == kind::reopen);
  CHECK(a.deadline == r.now);
  CHECK(r.n.retries == 1);  // only the first exchange's second attempt
}

TEST_CASE("machine: a reopen that ends after give_up_after has passed gives up", "[transport][machine]") {
  rig r;
  r.m.set_reopen(true, t::reconnect_policy{10ms, 80ms, 100ms});
  const auto p = ping_request();
  auto a = r.start(p);
  a = r.resume(failed(boost::asio::error::eof));
  REQUIRE(a.what == kind::reopen);
  a = r.resume(failed(t::os_error(ENODEV)), 120ms);  // a reopen that took its time
  REQUIRE(a.what == kind::done);
  CHECK(a.ec == t::transport_errc::reconnect_failed);
}

TEST_CASE("machine: a write that meets a lost link fails, and the next exchange reopens first",
          "[transport][machine]") {
  rig r;
  r.m.set_reopen(true, t::reconnect_policy{10ms, 80ms, 500ms});
  const auto s = single_request();
  auto a = r.start(s);
  a = r.resume(wrote_all(a));
  a = r.resume(failed(boost::asio::error::eof));
  REQUIRE(a.what == kind::done);  // not repeated: it may have reached the board
  CHECK(a.ec == t::transport_errc::closed);
  CHECK(r.m.lost());
  r.now += 5ms;
  a = r.start(s);
  REQUIRE(a.what == kind::reopen);
  CHECK(a.deadline == r.now);
  a = r.resume(moved(0), 1ms);
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == hex(single_frame));  // a new link: no resync
  CHECK(ns(a.deadline - r.now) == ns(wire(11) + r.opt.turnaround));
  a = r.resume(wrote_all(a));
  a = r.resume(feed(a, single_ack));
  REQUIRE(a.what == kind::done);
  CHECK_FALSE(a.ec);
  CHECK(r.n.reconnects == 1);
  CHECK(r.n.resyncs == 0);
  CHECK(r.n.retries == 0);
}

TEST_CASE("machine: the stream's error is reported, never a failed reopen's", "[transport][machine]") {
  rig r;
  r.m.set_reopen(true, t::reconnect_policy{10ms, 80ms, 500ms});
  const auto s = single_request();
  auto a = r.start(s);
  a = r.resume(wrote_all(a));
  a = r.resume(failed(boost::asio::error::eof));  // lost: the next exchange reopens first
  REQUIRE(a.what == kind::done);
  r.now += 5ms;
  a = r.start(s);
  REQUIRE(a.what == kind::reopen);
  a = r.resume(failed(t::os_error(ENODEV)), 1ms);  // the adapter is not back yet
  REQUIRE(a.what == kind::reopen);
  r.now = a.deadline;
  a = r.resume(moved(0), 1ms);  // back
  REQUIRE(a.what == kind::write);
  a = r.resume(failed(t::os_error(EPIPE)));  // and gone again at the write: a write goes once
  REQUIRE(a.what == kind::done);
  CHECK(a.ec == t::os_error(EPIPE));  // what ended it, not the reopen's ENODEV
}

TEST_CASE("machine: without a reopen, a lost link is tried again as it is", "[transport][machine]") {
  rig r;
  const auto p = ping_request();
  SECTION("never set") {}
  SECTION("set, then unset") { r.m.set_reopen(false); }
  auto a = r.start(p);
  a = r.resume(wrote_all(a));
  a = r.resume(failed(boost::asio::error::eof));
  REQUIRE(a.what == kind::done);
  CHECK(a.ec == t::transport_errc::closed);
  CHECK(r.m.lost());
  CHECK(r.n.retries == 0);
  a = r.start(p);
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == hex(short_ping));
  a = r.clean_resync(a);
  a = r.resume(wrote_all(a));
  a = r.resume(feed(a, ping_ack));
  REQUIRE(a.what == kind::done);
  CHECK_FALSE(a.ec);
  CHECK_FALSE(r.m.lost());  // the line works after all
  CHECK(r.n.reconnects == 0);
}

TEST_CASE("machine: a link replaced from outside starts clean", "[transport][machine]") {
  rig r;
  const auto p = ping_request();
  auto a = r.start(p);
  a = r.resume(failed(boost::asio::error::eof));
  REQUIRE(a.what == kind::done);
  REQUIRE(r.m.dirty());
  REQUIRE(r.m.lost());
  r.m.replaced();
  CHECK_FALSE(r.m.dirty());
  CHECK_FALSE(r.m.lost());
  a = r.start(p);
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == hex(ping_frame));
}

TEST_CASE("machine: cancel ends the exchange, and the next one resyncs first", "[transport][machine]") {
  rig r;
  const auto rd = read_request();
  auto a = r.start(rd);
  SECTION("during the write") {}
  SECTION("during the read") {
    a = r.resume(wrote_all(a));
    a = r.resume(feed(a, std::span(read_reply).first(2)));
    REQUIRE(a.what == kind::read);
  }
  SECTION("during a resync") {
    a = r.resume(wrote_all(a));
    a = r.resume(timed_out(), a.deadline - r.now);
    REQUIRE(a.what == kind::write);
    CHECK(hex(a.out) == hex(short_ping));
  }
  a = r.m.cancel();
  REQUIRE(a.what == kind::done);
  CHECK(a.ec == boost::asio::error::operation_aborted);
  CHECK(r.m.idle());
  CHECK(r.m.dirty());
  CHECK(r.n.exchanges == 1);
  CHECK(r.n.errors == 1);
  const auto resyncs = r.n.resyncs.load();
  a = r.start(rd);
  REQUIRE(a.what == kind::write);
  CHECK(hex(a.out) == hex(short_ping));
  CHECK(r.n.resyncs == resyncs + 1);
}

TEST_CASE("machine: cancel with a code, when idle, and while reopening", "[transport][machine]") {
  rig r;
  const auto p = ping_request();
  SECTION("the exchange ends with the code given") {
    auto a = r.start(p);
    a = r.m.cancel(t::transport_errc::cancelled);
    REQUIRE(a.what == kind::done);
    CHECK(a.ec == t::transport_errc::cancelled);
  }
  SECTION("nothing runs: done with the code, nothing counted") {
    auto a = r.m.cancel();
    REQUIRE(a.what == kind::done);
    CHECK(a.ec == boost::asio::error::operation_aborted);
    CHECK(r.n.exchanges == 0);
    CHECK_FALSE(r.m.dirty());
  }
  SECTION("while reopening: the next exchange reopens") {
    r.m.set_reopen(true, t::reconnect_policy{10ms, 80ms, 500ms});
    auto a = r.start(p);
    a = r.resume(failed(boost::asio::error::eof));
    REQUIRE(a.what == kind::reopen);
    a = r.m.cancel();
    REQUIRE(a.what == kind::done);
    CHECK(a.ec == boost::asio::error::operation_aborted);
    r.now += 1ms;
    a = r.start(p);
    REQUIRE(a.what == kind::reopen);
    CHECK(a.deadline == r.now);
  }
  SECTION("resume with nothing running ends with cancelled") {
    auto a = r.m.resume(moved(4), r.now);
    REQUIRE(a.what == kind::done);
    CHECK(a.ec == t::transport_errc::cancelled);
  }
}

TEST_CASE("machine: deadlines are values computed from the times it is given", "[transport][machine]") {
  const time_point origins[] = {time_point{}, time_point{} + 1ns, time_point{} - 5h, time_point{} + 20000h};
  for (const auto origin : origins) {
    rig r;
    r.now = origin;
    const auto p = ping_request();
    auto a = r.start(p);
    CHECK(ns(a.deadline - origin) == ns(wire(8) + 20ms));
    a = r.resume(wrote_all(a), 3ms);
    CHECK(ns(a.deadline - origin) == ns(wire(8) + 20ms));  // the attempt's, not the write's end + budget
    CHECK(ns(a.expected - origin) == ns(wire(8)));
    a = r.resume(timed_out(), 17ms);  // the driver says the deadline passed: the machine believes it
    REQUIRE(a.what == kind::write);
    CHECK(ns(a.deadline - (origin + 20ms)) == ns(wire(7) + 20ms));  // the retry's from when it began
    CHECK(r.m.deadline() == a.deadline);
  }
  SECTION("the options are read at each start") {
    rig r;
    const auto p = ping_request();
    auto a = r.start(p);
    a = r.resume(wrote_all(a));
    a = r.resume(feed(a, ping_ack));
    REQUIRE(a.what == kind::done);
    r.opt.baud = 625'000;  // 17.6 µs a byte
    r.opt.turnaround = 7ms;
    a = r.start(p);
    CHECK(ns(a.deadline - r.now) == ns(8 * 17'600ns + 7ms));
  }
  SECTION("the default options: 115200 baud and 100 ms") {
    t::client_options opt;
    t::client_counters n;
    d::exchange_machine m(opt, n);
    const auto p = ping_request();
    const auto t0 = time_point{} + 42s;
    const auto a = m.start(p, t0);
    const auto wire_ns = ns(a.deadline - t0) - ns(100ms);
    CHECK((wire_ns == 763'888 || wire_ns == 763'889));  // 88 bits at 115200 bit/s = 763 888.9 ns
  }
}

// A line that keeps sending 04 FE 06 08 faster than `quiet` (a late burst of ACKs, a misbehaving
// adapter or board) must not keep the resync reading forever (DESIGN.md §4: every wait has a deadline).
TEST_CASE("machine: a line that keeps sending ACKs does not hold a resync forever", "[transport][machine]") {
  rig r;
  const auto p = ping_request();
  auto a = r.start(p, 1);
  a = r.resume(wrote_all(a));
  int reads = 0;
  while (a.what == kind::read && reads < 200) {
    a = r.resume(feed(a, ping_ack), 1ms);  // within `quiet` (3 ms) every time
    ++reads;
  }
  CHECK(a.what != kind::read);
  CHECK(r.n.timeouts == 1);
}

TEST_CASE("machine: a byte read after a short NACK marks the line for a resync", "[transport][machine]") {
  // A read's first read asks for the whole data frame (5 bytes for 2 data bytes); a NACK is 4, so
  // a stray byte behind it lands in the same read: it must not be forgotten.
  rig r;
  const auto rd = read_request();  // (the request outlives its exchange)
  auto a = r.start(rd);
  a = r.resume(wrote_all(a));
  REQUIRE(a.in.size() == 5);
  a = r.resume(feed(a, bytes(0x04, 0x00, 0x15, 0x19, 0x55)));  // NACK to MOV (§2.2), then 55
  REQUIRE(a.what == kind::done);
  CHECK_FALSE(a.ec);
  CHECK(r.m.reply().kind == reply_kind::nack);
  CHECK(r.m.dirty());
  a = r.start(rd);
  CHECK(hex(a.out) == hex(bytes(0x03, 0xFE, 0x01)));  // the next exchange resyncs first
}

TEST_CASE("machine: a failed resync says what the line answered", "[transport][machine]") {
  struct answer {
    const char* name;
    byte_vector bytes;
    t::error_code ec;
  };
  const answer answers[] = {
      {"silence", {}, t::transport_errc::timeout},
      {"our ping coming back", bytes(0x03, 0xFE, 0x01), t::transport_errc::echo},
      {"a NACK to the ping", bytes(0x04, 0xFE, 0x15, 0x17), rcb4::errc::nack},
      {"an ACK with a bad checksum", bytes(0x04, 0xFE, 0x06, 0x5A), rcb4::errc::bad_checksum},
      {"garbage", bytes(0x55, 0xAA, 0x13), rcb4::errc::bad_reply_length},
  };
  for (const auto& x : answers) {
    DYNAMIC_SECTION(x.name) {
      rig r;
      r.opt.read_retries = 0;
      const auto p = ping_request();
      auto a = r.start(p, 1);  // stray bytes: a resync first
      REQUIRE(hex(a.out) == hex(short_ping));
      a = r.resume(wrote_all(a));
      if (!x.bytes.empty()) a = r.resume(feed(a, x.bytes));
      REQUIRE(a.what == kind::read);
      a = r.resume(timed_out(), a.deadline - r.now);
      REQUIRE(a.what == kind::done);
      CHECK(a.ec == x.ec);
    }
  }
}
