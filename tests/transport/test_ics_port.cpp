// rcb4::transport::ics_port on a pseudo-terminal: exchanges end at their deadline, a line that
// closes part way is an error (never a hang), the rate is set, the port is taken exclusively.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/transport/ics_port.hpp>
#include <rcb4/transport/pty.hpp>

#include <catch2/catch.hpp>

#include <unistd.h>

#include <thread>

using namespace std::chrono_literals;
namespace t = rcb4::transport;

TEST_CASE("ics_port: a reply in time, a silent line ends at the deadline", "[ics]") {
  t::pty_pair pty;
  const int master = pty.release_master();
  t::ics_port port(pty.path(), 115200);
  CHECK(port.baud() == 115200);
  // No Catch assertion inside the thread (Catch is not thread-safe): its results are checked after join.
  ssize_t wrote_first = 0, wrote_rest = 0;
  std::thread servo([master, &wrote_first, &wrote_rest] {  // echo and a reply, written in two pieces
    std::uint8_t buf[8];
    std::size_t got = 0;
    while (got < 2) got += static_cast<std::size_t>(std::max<ssize_t>(0, ::read(master, buf + got, 2 - got)));
    const std::uint8_t first[] = {0xAC, 0x04, 0x2C};
    const std::uint8_t rest[] = {0x04, 0x4B};
    wrote_first = ::write(master, first, 3);
    wrote_rest = ::write(master, rest, 2);
  });
  const std::uint8_t req[] = {0xAC, 0x04};
  const auto rx = port.transact(req, 5, 1000ms);
  servo.join();
  CHECK(wrote_first == 3);
  CHECK(wrote_rest == 2);
  CHECK(rx == std::vector<std::uint8_t>{0xAC, 0x04, 0x2C, 0x04, 0x4B});

  const auto start = std::chrono::steady_clock::now();
  const auto none = port.transact(req, 5, 50ms);  // nobody answers
  const auto took = std::chrono::steady_clock::now() - start;
  CHECK(none.empty());
  CHECK(took >= 50ms);
  CHECK(took < 2s);
  port.set_baud(1250000);
  CHECK(port.baud() == 1250000);
  CHECK(t::detail::line_rate(master) == 1250000);
  ::close(master);
}

TEST_CASE("ics_port: the other end going away is an error, not a hang", "[ics]") {
  auto pty = std::make_unique<t::pty_pair>();
  const int master = pty->release_master();
  t::ics_port port(pty->path(), 115200);
  pty.reset();  // the pty's own slave descriptor goes: only the port holds the line now
  ssize_t heard = 0;
  std::thread unplug([master, &heard] {
    std::uint8_t b;
    heard = ::read(master, &b, 1);  // the request arrived: now unplug
    ::close(master);
  });
  const std::uint8_t req[] = {0xFF, 0x00, 0x00, 0x00};
  const auto start = std::chrono::steady_clock::now();
  try {
    (void)port.transact(req, 5, 5000ms);
    FAIL("no error");
  } catch (const t::system_error& e) {
    CHECK(e.code() == t::transport_errc::closed);
  }
  CHECK(std::chrono::steady_clock::now() - start < 4s);
  unplug.join();
  CHECK(heard == 1);
}

TEST_CASE("ics_port: a port another program holds is refused", "[ics]") {
  t::pty_pair pty;
  t::ics_port first(pty.path(), 115200);
  try {
    t::ics_port second(pty.path(), 115200);
    FAIL("opened twice");
  } catch (const t::system_error& e) {
    CHECK(e.code() == t::transport_errc::port_busy);
  }
  CHECK_THROWS_AS(t::ics_port("/dev/nonexistent-ics-port", 115200), t::system_error);
}
