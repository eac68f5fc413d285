// The ICS hardware tier: rcb4's ICS service against one real KONDO servo on an adapter in ICS
// mode. Off by default; configure with -DRCB4_TEST_ICS_DEVICE=/dev/ttyUSB0 (or set
// RCB4_ICS_DEVICE and run this program). Read-only: nothing is written and the servo does not move.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/services/ics.hpp>
#include <rcb4/transport/ics_port.hpp>

#include <catch2/catch.hpp>

#include <cstdlib>
#include <string>

using namespace rcb4;
namespace sv = rcb4::robot::services;

namespace {
std::string device() {
  const char* d = std::getenv("RCB4_ICS_DEVICE");
  if (!d || !*d) FAIL("set RCB4_ICS_DEVICE to the adapter's port with one ICS servo (e.g. /dev/ttyUSB0)");
  return d;
}
}  // namespace

TEST_CASE("ics hardware: the lone servo is found and its EEPROM reads the same twice", "[ics]") {
  transport::ics_port port(device(), 115200);
  sv::ics_port_link<transport::ics_port> line(port);
  sv::ics_servo s(line, {}, {});
  INFO("found ID " << int(s.id().value()) << " at " << s.baud() << " baud");
  CHECK(s.read_id() == s.id());
  const auto a = s.read_eeprom();
  const auto b = s.read_eeprom();
  CHECK(a == b);
  CHECK(a.get(ics::field::id) == s.id().value());
  CHECK(a.get(ics::field::baud) == static_cast<long>(s.baud()));
  CHECK(s.read(ics::sub::stretch) == a.get(ics::field::stretch));
  const auto t = s.read(ics::sub::temperature);
  CHECK((t >= 1 && t <= 127));
}

TEST_CASE("ics hardware: a scan finds it at its rate only", "[ics]") {
  transport::ics_port port(device(), 115200);
  sv::ics_port_link<transport::ics_port> line(port);
  sv::ics_options o;
  o.timeout = std::chrono::milliseconds(30);
  const auto found = sv::ics_scan(line, {}, o);
  REQUIRE(found.size() == 1);
  CHECK(found[0].problem.empty());
}
