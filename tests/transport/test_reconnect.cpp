// Reconnect with backoff, the baud switch followed on the host, and waiting for a motion, over
// an in-memory stream and over real pseudo-terminals.
// SPDX-License-Identifier: BSL-1.0
#include "fake_stream.hpp"
#include "served_board.hpp"

#include <rcb4/transport/operations.hpp>
#include <rcb4/transport/serial.hpp>

#include <catch2/catch.hpp>

using namespace rcb4;
using namespace std::chrono_literals;
namespace t = rcb4::transport;
using rcb4::testing::fake_stream;

TEST_CASE("reconnect: a lost link is reopened with backoff and a read is retried on it", "[transport][reconnect]") {
  board::virtual_board b;
  t::io_thread io;
  t::client_options opt;
  opt.turnaround = 50ms;
  // The first operation (the ping's write) meets end of file: the cable was pulled.
  t::basic_client<fake_stream> c(fake_stream(io.context().get_executor(), b, 1, boost::asio::error::eof), opt);
  int attempts = 0;
  c.set_reconnect(
      [&](fake_stream& s, t::error_code& ec) {
        if (++attempts < 3) {
          ec = t::os_error(ENODEV);  // still unplugged
          return;
        }
        s = fake_stream(io.context().get_executor(), b);
      },
      {1ms, 4ms, 2s});
  t::error_code ec;
  const auto r = c.execute(ping{}, ec);
  CHECK_FALSE(ec);
  CHECK(r.kind == reply_kind::ack);
  CHECK(attempts == 3);
  CHECK(c.counters().reconnects == 1);
  CHECK(c.execute(move::read_ram(ram::config, 2).value()).u16() == board::default_config);
}

TEST_CASE("reconnect: a write that meets the loss fails, the next exchange reconnects", "[transport][reconnect]") {
  board::virtual_board b;
  t::io_thread io;
  t::basic_client<fake_stream> c(fake_stream(io.context().get_executor(), b, 1, boost::asio::error::eof));
  c.set_reconnect([&](fake_stream& s, t::error_code&) { s = fake_stream(io.context().get_executor(), b); });
  t::error_code ec;
  c.execute(single_servo{0, 8000, 0}, ec);
  CHECK(ec == t::transport_errc::closed);  // not repeated: it may or may not have reached the board
  CHECK(c.counters().reconnects == 0);
  CHECK(c.execute(single_servo{0, 8000, 0}).kind == reply_kind::ack);
  CHECK(c.counters().reconnects == 1);
}

TEST_CASE("reconnect: a link that stays lost ends with reconnect_failed, every call returns",
          "[transport][reconnect]") {
  board::virtual_board b;
  t::io_thread io;
  t::basic_client<fake_stream> c(fake_stream(io.context().get_executor(), b, 1, boost::asio::error::eof));
  int attempts = 0;
  c.set_reconnect(
      [&](fake_stream&, t::error_code& ec) {
        ++attempts;
        ec = t::os_error(ENODEV);
      },
      {1ms, 8ms, 100ms});
  t::error_code ec;
  c.execute(ping{}, ec);
  CHECK(ec == t::transport_errc::reconnect_failed);
  CHECK(attempts >= 2);
  const int first = attempts;
  c.execute(ping{}, ec);  // the next exchange tries again
  CHECK(ec == t::transport_errc::reconnect_failed);
  CHECK(attempts > first);
}

TEST_CASE("reconnect: a pty whose board went away, then came back", "[transport][reconnect][pty]") {
  t::io_thread io;
  auto first = std::make_unique<rcb4::testing::served_board>();
  std::string path = first->server->where();
  t::client_options opt;
  opt.baud = 1250000;
  opt.turnaround = 100ms;
  auto c = t::make_client(t::open_serial(io.context(), path, 1250000), opt);
  CHECK(c.execute(ping{}).kind == reply_kind::ack);

  first.reset();  // the board is gone: the pty's other side is closed
  t::error_code ec;
  c.execute(ping{}, ec);
  INFO(ec.message());
  CHECK(t::is_link_lost(ec));  // EIO on a pty (a USB adapter gives EIO or EOF alike)

  rcb4::testing::served_board second;
  path = second.server->where();
  c.set_reconnect([&](t::serial_port& s, t::error_code& e) { s = t::open_serial(io.context(), path, 1250000, e); });
  CHECK(c.execute(ping{}).kind == reply_kind::ack);
  CHECK(c.counters().reconnects == 1);
}

TEST_CASE("switch_baud: the board and the host move to the new rate together", "[transport][baud]") {
  t::serve_options so;
  so.pace = true;  // replies at the board's own current rate
  rcb4::testing::served_board sb(so);
  t::io_thread io;
  t::client_options opt;
  opt.baud = 1250000;
  auto c = t::make_client(t::open_serial(io.context(), sb.server->where(), 1250000), opt);
  // (The board is checked through the line only: its thread owns it.)
  t::switch_baud(c, 115200);
  CHECK(c.options().baud == 115200);
  CHECK(t::run(c, ops::read_config{}).com_baud == baud_code::b115200);
  t::error_code ec;
  t::switch_baud(c, 9600, ec);
  CHECK(ec == rcb4::errc::unsupported_baud);
  CHECK(t::run(c, ops::read_config{}).com_baud == baud_code::b115200);
  t::switch_baud(c, 1250000);
  CHECK(t::run(c, ops::read_config{}).com_baud == baud_code::b1250000);
}

TEST_CASE("wait_motion: returns when the motion ends, or at its deadline", "[transport][motion]") {
  rcb4::testing::served_board sb;
  t::io_thread io;
  auto c = t::make_client(t::open_serial(io.context(), sb.server->where(), 1250000));
  t::run(c, ops::play_motion(2));
  t::error_code ec;
  auto st = t::wait_motion(c, 50ms, ec);  // motion 2 takes about 1.5 s
  CHECK(ec == t::transport_errc::timeout);
  CHECK(st.running);
  int progress_calls = 0;
  st = t::wait_motion(c, 10s, ec, [&](const ops::motion_state& s) {
    ++progress_calls;
    CHECK((s.motion == 2u || !s.running));
  });
  CHECK_FALSE(ec);
  CHECK_FALSE(st.running);
  CHECK(progress_calls >= 2);
}
