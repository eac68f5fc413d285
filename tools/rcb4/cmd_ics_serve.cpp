// rcb4 command-line tool: `rcb4 ics serve --pty`, virtual ICS servos on a pseudo-terminal
// (rcb4/ics/virtual_servo.hpp), to try `rcb4 ics` and pyrcb4's IcsServo without a servo. Prints the
// /dev/pts/N path, then serves until SIGINT or SIGTERM. A client's frames are understood only at
// the servos' rate, as on a real line (the pty carries the rate its user set).
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/ics/virtual_servo.hpp>
#include <rcb4/transport/pty.hpp>
#include <rcb4/transport/serial.hpp>

#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>

namespace cli {
namespace {

namespace ics = rcb4::ics;

struct serve_options {
  bool pty = false;
  long long id = 0;
  long long servos = 1;
  std::uint32_t baud = 115200;
  bool silent = false;
  bool corrupt = false;
  bool ics35 = false;
  long long seed = 1;
};

int serve(const serve_options& o) {
  if (!o.pty) throw usage_error("ics serve: give --pty");
  if (o.id + o.servos - 1 > ics::servo_id::max)
    throw usage_error(fmt::format("--servo-id {} with --servos {}: the IDs run past 31", o.id, o.servos));
  std::vector<ics::virtual_servo> servos;
  for (long long k = 0; k < o.servos; ++k)
    servos.emplace_back(ics::servo_id::make(o.id + k).value(), o.baud, static_cast<std::uint32_t>(o.seed + k),
                        !o.ics35);
  ics::virtual_line wire(std::move(servos), ics::line_faults{o.silent, o.corrupt});
  rcb4::transport::pty_pair pty;
  const int fd = pty.release_master();
  fmt::print("{}\n", pty.path());
  std::fflush(stdout);
  signal_catcher signals;
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::uint8_t> out;
  std::uint8_t buf[512];
  int result = exit_ok;
  while (!signal_catcher::caught()) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, -1) < 0) {
      if (errno == EINTR) continue;
      result = exit_io;
      break;
    }
    const auto n = ::read(fd, buf, sizeof buf);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n <= 0) {
      result = exit_io;
      break;
    }
    const auto t = std::chrono::duration_cast<ics::line_time>(std::chrono::steady_clock::now() - start);
    out.clear();
    wire.feed(std::span(buf, static_cast<std::size_t>(n)), rcb4::transport::detail::line_rate(fd), t, out);
    for (std::size_t sent = 0; sent < out.size();) {
      const auto w = ::write(fd, out.data() + sent, out.size() - sent);
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) break;
      sent += static_cast<std::size_t>(w);
    }
  }
  ::close(fd);
  return signal_catcher::caught() ? exit_ok : result;
}

}  // namespace

void add_ics_serve_command(CLI::App* ics_cmd, context& ctx) {
  auto o = std::make_shared<serve_options>();
  auto* cmd = ics_cmd->add_subcommand("serve", "virtual ICS servos on a pseudo-terminal (prints its path)");
  cmd->add_flag("--pty", o->pty, "serve on a new pseudo-terminal")->required();
  cmd->add_option("--servo-id", o->id, "the first servo's ID (default 0)")->check(int_range(0, 31));
  cmd->add_option("--servos", o->servos, "servos on the one wire, IDs counting up (all answer an ID command)")
      ->check(int_range(1, 32));
  cmd->add_option("--servo-baud", o->baud, "the servos' rate: 115200 (default), 625000, 1250000")
      ->check(CLI::IsMember({115200u, 625000u, 1250000u}));
  cmd->add_flag("--silent", o->silent, "no servo answers (the echo still comes back)");
  cmd->add_flag("--corrupt", o->corrupt, "one bit of every reply flipped");
  cmd->add_flag("--ics35", o->ics35, "ICS 3.5 servos: no answer to the 3.6 position read (SC 5)");
  cmd->add_option("--seed", o->seed, "seed of the first servo's factory bytes (default 1)")
      ->check(int_range(1, 1 << 30));
  on_run(cmd, ctx, [o] { return serve(*o); });
}

}  // namespace cli
