// Example firmware: a Cortex-M4 drives an RCB-4 over a polled UART with rcb4's codec, its
// sans-I/O operations and its link. No heap, no exceptions, no RTTI; nothing here but the
// standard library and mps2.hpp (the board support: UART, millisecond clock, semihosting).
//
//   1. ping until the board answers (it may still be booting): pings begun within 6 s;
//   2. read the config word (ops::read_config);
//   3. read every allocated servo's trim, position and target through the planner
//      (ops::read_servo_states_fixed: the allocation table, then the fewest reads);
//   4. move the first two allocated servos with one CONST frame (protocol.md §4.8), then read
//      again until both have arrived.
//
// The link's policy (deadlines, a resync after an error, reads tried three times, a write sent
// once, a loopback named) is the library's public exchange machine (rcb4/link/device_link.hpp)
// over the polled UART: this file writes none of it.
//
// Exit status (semihosting): 0 done; 1 the board fell silent (no reply by the deadline);
// 2 malformed replies (to each of a read's three attempts, or to a write's one) or an operation's
// error (a nonsense allocation table); 3 the board refused (NACK); 4 the servos did not arrive
// within 2 s; 5 fewer than two servos allocated; 70 a fault.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/link/device_link.hpp>
#include <rcb4/link/requests.hpp>
#include <rcb4/ops/servos.hpp>
#include <rcb4/ops/system.hpp>

#include "mps2.hpp"

namespace {

constexpr std::chrono::milliseconds reply_allowance{1500};  // QEMU may hold the first byte for about 1 s
constexpr std::uint32_t boot_deadline_ms = 6000;            // how long to ping a board that may be booting

enum class outcome { ok = 0, silent = 1, malformed = 2, refused = 3, not_arrived = 4, too_few_servos = 5 };

[[noreturn]] void fail(outcome o, const char* what, const char* why = nullptr) {
  mps2::line l;
  l << "firmware: " << what;
  if (why) l << ": " << why;
  l << " (exit " << static_cast<long>(o) << ")";
  l.print();
  mps2::exit(static_cast<int>(o));
}

/** The MPS2's UART as the link polls it. */
struct uart {
  bool poll_in(std::uint8_t& b) noexcept { return mps2::uart_poll_in(b); }
  bool poll_out(std::uint8_t b) noexcept { return mps2::uart_poll_out(b); }
};

/** Names each failed attempt on the host's console. */
struct console_observer : rcb4::link::no_observer {
  void attempt_failed(rcb4::errc e) noexcept {
    mps2::line l;
    l << "firmware: attempt failed: " << rcb4::message(e);
    l.print();
  }
};

using device = rcb4::link::polled_uart_device<uart>;
using board_link = rcb4::link::device_link<device, mps2::clock, console_observer>;

/** What a failed exchange or operation ends the program with. */
[[noreturn]] void fail_with(rcb4::errc e, const char* what) {
  if (e == rcb4::errc::link_timeout) fail(outcome::silent, what, "the board did not answer in time");
  if (e == rcb4::errc::nack) fail(outcome::refused, what, "NACK");
  fail(outcome::malformed, what, rcb4::message(e));
}

/** Runs a sans-I/O operation to its end over the link. */
template <class Op>
void run(board_link& link, Op& op, const char* what) {
  if (const auto e = rcb4::link::run(link, op); e != rcb4::errc{}) fail_with(e, what);
}

}  // namespace

extern "C" int firmware_main() {
  using namespace rcb4;
  mps2::init();
  mps2::line out;
  uart u;
  device d(u);
  link::options opt;
  opt.baud = 115200;
  opt.turnaround = reply_allowance;
  board_link board(d, opt);

  // 1. ping until the board answers (it may still be booting), for boot_deadline_ms at most.
  // A concrete command: its request is made without the command variant. The short ping
  // (03 FE 01): its ACK differs from its frame, so a loopback cannot pass for a board.
  const std::uint32_t boot = mps2::now_ms() + boot_deadline_ms;
  const auto hello = link::request_of(ping{ping_form::short_});
  auto pong = board.exchange(hello);
  while (!pong && pong.error() == errc::link_timeout && static_cast<std::int32_t>(mps2::now_ms() - boot) < 0)
    pong = board.exchange(hello);
  if (!pong) fail_with(pong.error(), "ping");
  if (!pong->is_ack()) fail(outcome::refused, "ping", "NACK");
  (out << "ping: ACK").print();

  // 2. the config word.
  ops::read_config config;
  run(board, config, "read config");
  out << "config: ";
  out.hex(config.value().encode(), 4);
  out << " (baud " << static_cast<long>(bits_per_second(config.value().com_baud)) << ", period "
      << static_cast<long>(milliseconds(config.value().period)) << " ms)";
  out.print();

  // 3. every servo's state, planned reads (in a scope of its own: the reads in step 4 reuse its stack).
  ics_number a{}, b{};
  {
    ops::read_servo_states_fixed states;
    run(board, states, "read servos");
    (out << "servos: " << static_cast<long>(states.value().size()) << " allocated, read in "
         << static_cast<long>(states.plan().size()) << " planned reads")
        .print();
    for (const auto& s : states.value()) {
      out << "  ICS " << static_cast<long>(s.ics.value()) << ": position " << static_cast<long>(s.position)
          << " target " << static_cast<long>(s.target);
      out.print();
    }
    if (states.value().size() < 2) fail(outcome::too_few_servos, "fewer than two servos allocated");
    a = states.value()[0].ics;
    b = states.value()[1].ics;
  }

  // 4. two servos, one CONST frame: the first to +1000 counts from centre, the second to -1000.
  const auto goal_a = servo_position::make(servo_position::centre_value + 1000).value();
  const auto goal_b = servo_position::make(servo_position::centre_value - 1000).value();
  servo_set<servo_position> targets;
  targets.insert(a, goal_a);
  targets.insert(b, goal_b);
  const auto move = const_servo::make(targets, frames{10});
  if (!move) fail(outcome::malformed, "the CONST frame does not build");
  const auto moved = board.exchange(link::request_of(*move));
  if (!moved) fail_with(moved.error(), "move");
  if (!moved->is_ack()) fail(outcome::refused, "move", "NACK");
  (out << "move: ICS " << static_cast<long>(a.value()) << " -> " << static_cast<long>(goal_a.value()) << ", ICS "
       << static_cast<long>(b.value()) << " -> " << static_cast<long>(goal_b.value()) << ", 10 frames: ACK")
      .print();

  // Read until both measured positions are within 2 counts of their goals, for at most 2 s.
  const std::uint32_t give_up = mps2::now_ms() + 2000;
  for (int round = 1;; ++round) {
    ops::read_servo_states_fixed now;
    run(board, now, "read servos");
    long at_a = -1, at_b = -1;
    for (const auto& s : now.value()) {
      if (s.ics == a) at_a = s.position;
      if (s.ics == b) at_b = s.position;
    }
    const auto near = [](long at, servo_position goal) { return at >= goal.value() - 2 && at <= goal.value() + 2; };
    if (near(at_a, goal_a) && near(at_b, goal_b)) {
      (out << "arrived: ICS " << static_cast<long>(a.value()) << " at " << at_a << ", ICS "
           << static_cast<long>(b.value()) << " at " << at_b << " after " << static_cast<long>(round) << " reads")
          .print();
      break;
    }
    if (static_cast<std::int32_t>(mps2::now_ms() - give_up) >= 0)
      fail(outcome::not_arrived, "the servos did not reach their targets within 2 s");
  }
  (out << "firmware: done").print();
  return 0;
}
