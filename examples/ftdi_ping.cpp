// An RCB-4 through an FTDI adapter with no tty at all: libftdi (libusb) as a byte device, the
// library's link (rcb4/link/device_link.hpp) for deadlines, resync and retries, and the sans-I/O
// operations on top. What a program does where there is no serial driver, or where the adapter
// must not be handed to ftdi_sio.
//
//   rcb4_ftdi_ping [VID:PID [BAUD]]    default 165c:0008 (KONDO's DUAL USB ADAPTER HS), 115200
//
// It pings the board, reads its config word and every servo's position.
// Exit status: 0 done; 1 the board refused or answered malformed; 2 usage; 3 no such adapter, or
// it failed (unplugged); 4 the board was silent.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/link/device_link.hpp>
#include <rcb4/link/libftdi_device.hpp>
#include <rcb4/link/requests.hpp>
#include <rcb4/ops/servos.hpp>
#include <rcb4/ops/system.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace {

int exit_status(rcb4::errc e) {
  switch (e) {
    case rcb4::errc::link_timeout: return 4;
    case rcb4::errc::link_lost:
    case rcb4::errc::link_closed:
    case rcb4::errc::link_io_error:
    case rcb4::errc::link_reconnect_failed: return 3;
    default: return 1;
  }
}

bool parse_ids(const std::string& s, int& vendor, int& product) {
  const auto colon = s.find(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == s.size()) return false;
  char* end = nullptr;
  vendor = static_cast<int>(std::strtol(s.c_str(), &end, 16));
  if (end != s.c_str() + colon || vendor <= 0 || vendor > 0xFFFF) return false;
  product = static_cast<int>(std::strtol(s.c_str() + colon + 1, &end, 16));
  return *end == 0 && product > 0 && product <= 0xFFFF;
}

}  // namespace

int main(int argc, char** argv) {
  rcb4::link::libftdi_device::which w;
  std::uint32_t baud = 115200;
  if (argc > 3 || (argc >= 2 && !parse_ids(argv[1], w.vendor, w.product))) {
    std::fprintf(stderr,
                 "usage: rcb4_ftdi_ping [VID:PID [BAUD]]   (hex ids, e.g. 165c:0008; BAUD 115200, 625000, 1250000)\n");
    return 2;
  }
  if (argc == 3) {
    const std::string b = argv[2];
    if (b != "115200" && b != "625000" && b != "1250000") {
      std::fprintf(stderr, "rcb4_ftdi_ping: BAUD is 115200, 625000 or 1250000 (protocol.md §9), not %s\n", argv[2]);
      return 2;
    }
    baud = static_cast<std::uint32_t>(std::stoul(b));
  }
  rcb4::link::libftdi_device ftdi(w, baud);
  if (!ftdi.ok()) {
    std::fprintf(stderr, "rcb4_ftdi_ping: %s\n", ftdi.error().c_str());
    return 3;
  }
  rcb4::link::options opt;
  opt.baud = baud;
  opt.turnaround = std::chrono::milliseconds(100);
  rcb4::link::device_link<rcb4::link::libftdi_device, std::chrono::steady_clock> link(ftdi, opt);

  // The short ping (03 FE 01): its ACK differs from its frame, so a loopback cannot pass for a board.
  const auto pong = link.exchange(rcb4::link::request_of(rcb4::ping{rcb4::ping_form::short_}));
  if (!pong) {
    std::fprintf(stderr, "rcb4_ftdi_ping: ping: %s%s%s\n", rcb4::message(pong.error()),
                 ftdi.error().empty() ? "" : ": ", ftdi.error().c_str());
    return exit_status(pong.error());
  }
  std::printf("ping: %s\n", pong->is_ack() ? "ACK" : "NACK");
  rcb4::ops::read_config config;
  if (const auto e = rcb4::link::run(link, config); e != rcb4::errc{}) {
    std::fprintf(stderr, "rcb4_ftdi_ping: read config: %s\n", rcb4::message(e));
    return exit_status(e);
  }
  std::printf("config word 0x%04X\n", config.value().encode());
  rcb4::ops::read_servo_states servos;
  if (const auto e = rcb4::link::run(link, servos); e != rcb4::errc{}) {
    std::fprintf(stderr, "rcb4_ftdi_ping: read servos: %s\n", rcb4::message(e));
    return exit_status(e);
  }
  for (const auto& s : servos.value())
    std::printf("ICS %2u  position %5u\n", static_cast<unsigned>(s.ics.value()), static_cast<unsigned>(s.position));
  return 0;
}
