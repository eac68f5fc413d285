// The hardware tier: the same client against a real RCB-4 on a real serial adapter. Off by
// default; configure with -DRCB4_TEST_DEVICE=/dev/ttyUSB0 (or set RCB4_DEVICE and run this
// program). Read-only: nothing is written to the board and no servo moves.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/transport/client.hpp>
#include <rcb4/transport/detect.hpp>
#include <rcb4/transport/operations.hpp>
#include <rcb4/transport/serial.hpp>

#include <catch2/catch.hpp>

#include <termios.h>

#include <cstdlib>
#include <string>

using namespace rcb4;
namespace t = rcb4::transport;

namespace {
/** The device under test: RCB4_DEVICE, which the ctest entries set. */
std::string device() {
  const char* d = std::getenv("RCB4_DEVICE");
  if (!d || !*d) FAIL("set RCB4_DEVICE to the serial port with an RCB-4 (e.g. /dev/ttyUSB0)");
  return d;
}

/** A client on the device at the rate detect_baud finds. */
auto open_board(t::io_thread& io) {
  const auto path = device();
  t::error_code ec;
  const auto baud = t::detect_baud(io.context(), path, ec);
  INFO("detect_baud on " << path << ": " << ec.message());
  REQUIRE(baud != 0);
  t::client_options opt;
  opt.baud = baud;
  return t::make_client(t::open_serial(io.context(), path, baud), opt);
}
}  // namespace

TEST_CASE("hardware: the adapter runs 8E1 raw at the board's rate", "[hardware]") {
  t::io_thread io;
  t::error_code ec;
  const auto baud = t::detect_baud(io.context(), device(), ec);
  REQUIRE(baud != 0);
  t::serial_info info;
  auto port = t::open_serial(io.context(), device(), baud, &info);
  CHECK(info.baud == baud);
  termios tio{};
  REQUIRE(::tcgetattr(port.native_handle(), &tio) == 0);
  CHECK((tio.c_cflag & CSIZE) == CS8);
  CHECK((tio.c_cflag & PARENB) != 0);  // even parity (protocol.md §1): a real UART keeps it
  CHECK((tio.c_cflag & PARODD) == 0);
  CHECK((tio.c_cflag & CSTOPB) == 0);
  CHECK((tio.c_lflag & ICANON) == 0);
  t::open_serial(io.context(), device(), baud, ec);  // exclusive
  CHECK(ec == t::transport_errc::port_busy);
  if (info.latency_timer_ms) WARN("FTDI latency timer: " << *info.latency_timer_ms << " ms");
}

TEST_CASE("hardware: the board answers ping, VERSION and its config register", "[hardware]") {
  t::io_thread io;
  auto c = open_board(io);
  CHECK(c.execute(ping{}).kind == reply_kind::ack);
  const auto v = t::run(c, ops::read_version{});
  CHECK_FALSE(v.empty());
  WARN("VERSION: " << v);
  const auto cfg = t::run(c, ops::read_config{});
  CHECK(cfg.encode() == c.execute(move::read_ram(ram::config, 2).value()).u16());
}

TEST_CASE("hardware: servo states and sensors read back in range", "[hardware]") {
  t::io_thread io;
  auto c = open_board(io);
  for (const auto& s : t::run(c, ops::read_servo_states{})) {
    INFO("ICS " << static_cast<int>(s.ics.value()));
    CHECK(s.position <= 0x3FFF);
  }
  const auto a = t::run(c, ops::read_analog{});
  CHECK(a.battery_volts > 0.0);
  WARN("battery: " << a.battery_volts << " V");
  const auto pio = t::run(c, ops::read_pio{});
  CHECK(pio.value <= 0x03FF);
}

TEST_CASE("hardware: many exchanges in a row all match their replies", "[hardware]") {
  t::io_thread io;
  auto c = open_board(io);
  for (int i = 0; i < 1000; ++i) REQUIRE(c.execute(ping{}).kind == reply_kind::ack);
  CHECK(c.counters().errors == 0);
  CHECK(c.counters().timeouts == 0);
}
