// A byte that failed its parity check is an error, never data (line_marks.hpp, serial.hpp).
// The decoder against termios(3)'s PARMRK rules written by hand; the exchange machine on a marked
// line (no stream, no clock); then the real kernel on a pseudo-terminal: an intact 0xFF doubled
// by the line discipline and decoded, and marks injected as a UART driver hands them over.
// Golden frames by hand from protocol.md (SUM = sum of the preceding bytes & 0xFF).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/transport/client.hpp>
#include <rcb4/transport/detail/exchange_machine.hpp>
#include <rcb4/transport/ics_port.hpp>
#include <rcb4/transport/io_thread.hpp>
#include <rcb4/transport/line_marks.hpp>
#include <rcb4/transport/pty.hpp>
#include <rcb4/transport/serial.hpp>

#include <catch2/catch.hpp>

#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <functional>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

using namespace rcb4;
using namespace std::chrono_literals;
namespace t = rcb4::transport;
namespace d = rcb4::transport::detail;

namespace {
using bytes = std::vector<std::uint8_t>;

/** Decodes @p raw in chunks of @p sizes (the rest in one), returning all the data and the damage. */
bytes decode_in(t::line_marks& m, bytes raw, std::initializer_list<std::size_t> sizes, std::size_t& damaged) {
  bytes out;
  std::size_t at = 0;
  damaged = 0;
  auto take = [&](std::size_t n) {
    const auto dd = m.decode(std::span(raw).subspan(at, n));
    out.insert(out.end(), raw.begin() + static_cast<std::ptrdiff_t>(at),
               raw.begin() + static_cast<std::ptrdiff_t>(at + dd.size));
    damaged += dd.damaged;
    at += n;
  };
  for (const auto n : sizes) take(n);
  take(raw.size() - at);
  return out;
}

// protocol.md §4.1: MOV RAM 0x0000 (config), 2 bytes → COM, and its reply [05][00][lo][hi][SUM].
const bytes read_frame{0x0A, 0x00, 0x20, 0x00, 0x00, 0x00, 0x00, 0x00, 0x02, 0x2C};
const bytes read_reply{0x05, 0x00, 0x8B, 0x00, 0x90};                  // the config word 0x008B
const bytes read_reply_ff{0x05, 0x00, 0xFF, 0x00, 0x04};               // the word 0x00FF: 05+FF = 0x104
const bytes read_reply_ff_marked{0x05, 0x00, 0xFF, 0xFF, 0x00, 0x04};  // ... as a marked line reads it
// The same reply with its third byte (8B) damaged: PARMRK hands it over as FF 00 8B.
const bytes read_reply_damaged{0x05, 0x00, 0xFF, 0x00, 0x8B, 0x00, 0x90};
// §4.11: the resync's short ping and the ACK of any ping.
const bytes short_ping{0x03, 0xFE, 0x01};
const bytes ping_ack{0x04, 0xFE, 0x06, 0x08};
// §4.6: SINGLE, ICS 0 to 7500 in 10 frames, and its ACK [04][0F][06][SUM]; the ACK with 06 damaged.
const bytes single_ack_damaged{0x04, 0x0F, 0xFF, 0x00, 0x06, 0x19};
}  // namespace

TEST_CASE("line_marks: termios(3)'s PARMRK stream back to data, damage counted", "[transport][marks]") {
  t::line_marks m;
  std::size_t damaged = 0;
  SECTION("intact bytes pass; an intact FF arrives doubled and is one byte") {
    CHECK(decode_in(m, {0x01, 0xFF, 0xFF, 0x02, 0x00}, {}, damaged) == bytes{0x01, 0xFF, 0x02, 0x00});
    CHECK(damaged == 0);
  }
  SECTION("FF 00 X: X failed its check and is not data; the bytes around it are") {
    bytes raw{0x05, 0xFF, 0x00, 0x41, 0x06};
    const auto dd = m.decode(raw);
    CHECK(dd.size == 2);
    CHECK(dd.damaged == 1);
    CHECK(dd.first_damaged == 1);
    CHECK(dd.clean_from == 1);
    CHECK(raw[0] == 0x05);
    CHECK(raw[1] == 0x06);
  }
  SECTION("a break (FF 00 00) and two damaged bytes") {
    bytes raw{0x11, 0xFF, 0x00, 0x00, 0x22, 0xFF, 0x00, 0x33, 0x44};
    const auto dd = m.decode(raw);
    CHECK(dd.size == 3);
    CHECK(dd.damaged == 2);
    CHECK(dd.first_damaged == 1);  // 11 came before the first
    CHECK(dd.clean_from == 2);     // 44 came after the last
    CHECK(bytes(raw.begin(), raw.begin() + 3) == bytes{0x11, 0x22, 0x44});
  }
  SECTION("a mark or an escape split over reads is finished by the next read") {
    CHECK(decode_in(m, {0x01, 0xFF, 0xFF, 0x02}, {2}, damaged) == bytes{0x01, 0xFF, 0x02});
    CHECK(damaged == 0);
    CHECK(decode_in(m, {0x01, 0xFF, 0x00, 0x7A, 0x03}, {2}, damaged) == bytes{0x01, 0x03});
    CHECK(damaged == 1);
    CHECK(decode_in(m, {0xFF, 0x00, 0x7A, 0x03}, {1, 1}, damaged) == bytes{0x03});
    CHECK(damaged == 1);
    bytes one{0xFF};
    CHECK(m.decode(one).size == 0);
    CHECK(m.inside_mark());
    m.reset();  // a new descriptor: the half mark is forgotten
    CHECK_FALSE(m.inside_mark());
    bytes next{0x02};
    CHECK(m.decode(next).size == 1);
  }
  SECTION("FF followed by anything else is no sequence the kernel writes: damaged, not data") {
    CHECK(decode_in(m, {0x01, 0xFF, 0x41, 0x02}, {}, damaged) == bytes{0x01, 0x02});
    CHECK(damaged == 1);
  }
  SECTION("it runs in a constant expression (firmware can use it)") {
    constexpr auto n = [] {
      t::line_marks c;
      std::uint8_t raw[] = {0x01, 0xFF, 0xFF, 0xFF, 0x00, 0x09};
      return c.decode(raw).size;
    }();
    STATIC_REQUIRE(n == 2);
  }
}

namespace {
/** A machine on a marked line, played by hand with a virtual clock. */
struct marked_rig {
  t::client_options opt;
  t::client_counters n;
  d::exchange_machine m{opt, n};
  d::clock::time_point now = d::clock::time_point{} + 1000h;
  marked_rig() {
    opt.baud = 1'250'000;
    m.set_marked(true);
  }
  d::action resume(const d::io_result& r) {
    now += 10us;
    return m.resume(r, now);
  }
  d::action wrote(const d::action& a) {
    REQUIRE(a.what == d::action::kind::write);
    d::io_result r;
    r.n = a.out.size();
    return resume(r);
  }
  /** A read that brings the raw bytes @p raw (never more than the read may take). */
  d::action got(const d::action& a, const bytes& raw) {
    REQUIRE(a.what == d::action::kind::read);
    REQUIRE(raw.size() <= a.in.size());
    std::copy(raw.begin(), raw.end(), a.in.begin());
    d::io_result r;
    r.n = raw.size();
    return resume(r);
  }
  d::action quiet(const d::action& a) {
    REQUIRE(a.what == d::action::kind::read);
    d::io_result r;
    r.timed_out = true;
    return resume(r);
  }
};
}  // namespace

TEST_CASE("machine on a marked line: a damaged byte fails the attempt at once and a read is retried",
          "[transport][marks][machine]") {
  marked_rig r;
  auto a = r.m.start(t::request::of(move::read_ram(ram::config, 2).value()), r.now);
  a = r.wrote(a);
  REQUIRE(a.in.size() == 5);
  a = r.got(a, bytes(read_reply_damaged.begin(), read_reply_damaged.begin() + 5));  // 05 00 FF 00 8B
  REQUIRE(a.what == d::action::kind::write);  // at once: the resync's ping, no wait for a deadline
  CHECK(bytes(a.out.begin(), a.out.end()) == short_ping);
  CHECK(r.n.line_errors == 1);
  a = r.wrote(a);
  a = r.got(a, {0x00, 0x90});  // the rest of the damaged reply, then the ACK: discarded to it
  a = r.got(a, ping_ack);
  a = r.quiet(a);
  REQUIRE(a.what == d::action::kind::write);
  CHECK(bytes(a.out.begin(), a.out.end()) == read_frame);
  a = r.wrote(a);
  a = r.got(a, read_reply);
  REQUIRE(a.what == d::action::kind::done);
  CHECK_FALSE(a.ec);
  CHECK(r.m.reply().u16() == 0x008B);
  CHECK(r.n.retries == 1);
  CHECK(r.n.errors == 0);
}

TEST_CASE("machine on a marked line: every try damaged ends in line_error and a write is never repeated",
          "[transport][marks][machine]") {
  SECTION("a read, read_retries = 0") {
    marked_rig r;
    r.opt.read_retries = 0;
    auto a = r.m.start(t::request::of(move::read_ram(ram::config, 2).value()), r.now);
    a = r.wrote(a);
    a = r.got(a, bytes(read_reply_damaged.begin(), read_reply_damaged.begin() + 5));
    REQUIRE(a.what == d::action::kind::done);
    CHECK(a.ec == t::transport_errc::line_error);
    CHECK(r.m.dirty());  // the rest of it is on the line: the next exchange resyncs first
  }
  SECTION("a write (SINGLE): its damaged ACK is an error, the frame went once") {
    marked_rig r;
    auto a = r.m.start(t::request::of(single_servo{0, 7500, 10}), r.now);
    a = r.wrote(a);
    REQUIRE(a.in.size() == 4);
    a = r.got(a, bytes(single_ack_damaged.begin(), single_ack_damaged.begin() + 4));  // 04 0F FF 00
    a = r.got(a, {0x06});                                                             // the damaged byte itself
    REQUIRE(a.what == d::action::kind::done);
    CHECK(a.ec == t::transport_errc::line_error);
    CHECK(r.n.retries == 0);
    CHECK(r.n.bytes_out == 7);
  }
}

TEST_CASE("machine on a marked line: an intact FF is data, read without asking past the reply",
          "[transport][marks][machine]") {
  marked_rig r;
  auto a = r.m.start(t::request::of(move::read_ram(ram::config, 2).value()), r.now);
  a = r.wrote(a);
  REQUIRE(a.in.size() == 5);
  a = r.got(a, bytes(read_reply_ff_marked.begin(), read_reply_ff_marked.begin() + 5));  // 05 00 FF FF 00
  REQUIRE(a.what == d::action::kind::read);
  CHECK(a.in.size() == 1);  // four data bytes in: one more
  a = r.got(a, {0x04});
  REQUIRE(a.what == d::action::kind::done);
  CHECK_FALSE(a.ec);
  CHECK(r.m.reply().u16() == 0x00FF);
  CHECK(r.n.line_errors == 0);

  SECTION("an unmarked line (TCP, a pty master) takes FF and 00 as they come") {
    marked_rig u;
    u.m.set_marked(false);
    a = u.m.start(t::request::of(move::read_ram(ram::config, 2).value()), u.now);
    a = u.wrote(a);
    a = u.got(a, read_reply_ff);
    REQUIRE(a.what == d::action::kind::done);
    CHECK_FALSE(a.ec);
    CHECK(u.m.reply().u16() == 0x00FF);
  }
}

TEST_CASE("machine on a marked line: an ACK with a damaged byte does not end a resync", "[transport][marks][machine]") {
  marked_rig r;
  auto a = r.m.start(t::request::of(move::read_ram(ram::config, 2).value()), r.now, 3);  // stray bytes: resync first
  a = r.wrote(a);
  a = r.got(a, {0x04, 0xFE, 0xFF, 0x00, 0x06, 0x08});  // an ACK whose 06 failed its check: 04 FE 08
  REQUIRE(a.what == d::action::kind::read);
  CHECK(a.deadline - r.now > r.opt.quiet);  // still looking for the ACK, not waiting for quiet
  a = r.got(a, ping_ack);
  a = r.quiet(a);
  REQUIRE(a.what == d::action::kind::write);
  CHECK(bytes(a.out.begin(), a.out.end()) == read_frame);
}

// --- the real kernel: a pseudo-terminal ---------------------------------------------------------

namespace {
/**
 * A board on a pty's master: reads each frame (its first byte is its length) and writes what
 * @p answer returns for it, as raw bytes. Counts the frames it saw.
 */
class scripted_board {
 public:
  using answer_fn = std::function<bytes(const bytes& frame, int nth)>;
  scripted_board(int master, answer_fn answer) : master_(master), answer_(std::move(answer)) {
    thread_ = std::thread([this] { run(); });
  }
  ~scripted_board() {
    stop_ = true;
    thread_.join();
    ::close(master_);
  }
  int frames() const { return frames_; }
  /** Clears PARMRK on the slave (termios calls on a master act on its slave). */
  void stop_marking() {
    termios tio{};
    ::tcgetattr(master_, &tio);
    tio.c_iflag &= ~static_cast<tcflag_t>(PARMRK);
    ::tcsetattr(master_, TCSANOW, &tio);
  }
  /** Frames seen, as written. */
  std::vector<bytes> seen() {
    std::lock_guard lock(m_);
    return seen_;
  }

 private:
  void run() {
    bytes frame;
    while (!stop_) {
      pollfd p{master_, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      std::uint8_t b = 0;
      if (::read(master_, &b, 1) != 1) return;
      frame.push_back(b);
      if (frame.size() < 2 || frame.size() < frame[0]) continue;
      {
        std::lock_guard lock(m_);
        seen_.push_back(frame);
      }
      const auto out = answer_(frame, frames_++);
      if (!out.empty() && ::write(master_, out.data(), out.size()) != static_cast<ssize_t>(out.size())) return;
      frame.clear();
    }
  }
  int master_;
  answer_fn answer_;
  std::atomic<bool> stop_{false};
  std::atomic<int> frames_{0};
  std::mutex m_;
  std::vector<bytes> seen_;
  std::thread thread_;
};

t::response run(t::basic_client<t::serial_port>& c, const command& cmd, bool blocking, t::error_code& ec) {
  if (blocking) return c.execute(cmd, ec);
  std::promise<std::pair<t::error_code, t::response>> done;
  c.async_execute(cmd, [&](t::error_code e, t::response r) { done.set_value({e, std::move(r)}); });
  auto [e, r] = done.get_future().get();
  ec = e;
  return r;
}
}  // namespace

TEST_CASE("a pty line: an intact FF in a reply, doubled by the kernel, is read as FF", "[transport][marks][line]") {
  const bool blocking = GENERATE(true, false);
  CAPTURE(blocking);
  t::pty_pair pty;
  t::io_thread io;
  t::serial_info info;
  auto c = t::make_client(t::open_serial(io.context(), pty.path(), 1250000, &info));
  scripted_board board(pty.release_master(), [](const bytes&, int) { return read_reply_ff; });
  t::error_code ec;
  const auto r = run(c, move::read_ram(ram::config, 2).value(), blocking, ec);
  REQUIRE_FALSE(ec);
  CHECK(r.u16() == 0x00FF);
  CHECK(c.counters().line_errors == 0);
}

TEST_CASE("a pty line: a damaged byte as a UART marks it fails the try, the read is retried, never read as data",
          "[transport][marks][line]") {
  const bool blocking = GENERATE(true, false);
  CAPTURE(blocking);
  t::pty_pair pty;
  t::io_thread io;
  auto c = t::make_client(t::open_serial(io.context(), pty.path(), 1250000));
  // The first reply is clean (the client learns the line is marked), the second damaged, then clean.
  // After the first, the board writes the bytes a UART driver hands over (so PARMRK is cleared on
  // the slave: the kernel passes them as they are, and the board escapes any FF itself).
  scripted_board board(pty.release_master(), [](const bytes& frame, int nth) {
    if (frame == short_ping) return ping_ack;
    return nth == 1 ? read_reply_damaged : read_reply;
  });
  t::error_code ec;
  auto r = run(c, move::read_ram(ram::config, 2).value(), blocking, ec);
  REQUIRE_FALSE(ec);
  board.stop_marking();
  r = run(c, move::read_ram(ram::config, 2).value(), blocking, ec);
  REQUIRE_FALSE(ec);
  CHECK(r.u16() == 0x008B);  // the retry's answer: never 0x0000 (what Linux made of it unmarked)
  CHECK(c.counters().line_errors == 1);
  CHECK(c.counters().retries == 1);
  CHECK(c.counters().resyncs == 1);
}

TEST_CASE("a pty line: a write whose ACK is damaged fails with line_error, sent once", "[transport][marks][line]") {
  const bool blocking = GENERATE(true, false);
  CAPTURE(blocking);
  t::pty_pair pty;
  t::io_thread io;
  auto c = t::make_client(t::open_serial(io.context(), pty.path(), 1250000));
  scripted_board board(pty.release_master(), [](const bytes& frame, int nth) {
    if (frame == short_ping) return ping_ack;
    if (nth == 0) return read_reply;
    return single_ack_damaged;
  });
  t::error_code ec;
  (void)run(c, move::read_ram(ram::config, 2).value(), blocking, ec);
  REQUIRE_FALSE(ec);
  board.stop_marking();
  (void)run(c, single_servo{0, 7500, 10}, blocking, ec);
  CHECK(ec == t::transport_errc::line_error);
  CHECK(ec.message().find("parity") != std::string::npos);
  const auto frames = board.seen();
  CHECK(std::count_if(frames.begin(), frames.end(), [](const bytes& f) { return f.size() == 7 && f[1] == 0x0F; }) == 1);
}

TEST_CASE("ics_port: a damaged byte ends the read there and is reported, and FF of an intact echo is FF",
          "[ics][marks]") {
  t::pty_pair pty;
  const int master = pty.release_master();
  t::ics_port port(pty.path(), 115200);
  std::atomic<int> stage{0};
  std::thread servo([master, &stage] {
    std::uint8_t buf[8];
    // 1: the ID read FF 00 00 00 (ics.md §2.5) echoed, and the reply E0 + ID 5: the kernel doubles
    // each FF the slave receives, the port undoes it.
    std::size_t got = 0;
    while (got < 4) got += static_cast<std::size_t>(std::max<ssize_t>(0, ::read(master, buf + got, 4 - got)));
    const std::uint8_t echo_and_id[] = {0xFF, 0x00, 0x00, 0x00, 0xE5};
    (void)!::write(master, echo_and_id, sizeof echo_and_id);
    while (stage.load() < 1) std::this_thread::yield();
    // 2: PARMRK cleared (as a UART driver hands marks over): the echo, then the reply's first byte damaged.
    got = 0;
    while (got < 2) got += static_cast<std::size_t>(std::max<ssize_t>(0, ::read(master, buf + got, 2 - got)));
    const std::uint8_t damaged[] = {0xAC, 0x04, 0xFF, 0x00, 0x2C, 0x04, 0x4B};
    (void)!::write(master, damaged, sizeof damaged);
  });
  const std::uint8_t id_read[] = {0xFF, 0x00, 0x00, 0x00};
  const auto rx = port.transact(id_read, 5, 1000ms);
  CHECK(rx == std::vector<std::uint8_t>{0xFF, 0x00, 0x00, 0x00, 0xE5});
  CHECK_FALSE(port.damaged());
  termios tio{};
  ::tcgetattr(master, &tio);
  tio.c_iflag &= ~static_cast<tcflag_t>(PARMRK);
  ::tcsetattr(master, TCSANOW, &tio);
  stage = 1;
  const std::uint8_t req[] = {0xAC, 0x04};
  const auto rx2 = port.transact(req, 5, 1000ms);
  servo.join();
  CHECK(rx2 == std::vector<std::uint8_t>{0xAC, 0x04});  // the bytes before the damaged one, and no more
  CHECK(port.damaged());
  ::close(master);
}
