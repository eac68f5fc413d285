// Example firmware: a Cortex-M4 drives an RCB-4 over a polled UART with rcb4's codec and its
// sans-I/O operations. No heap, no exceptions, no RTTI; nothing here but the standard library
// and mps2.hpp (the board support: UART, millisecond clock, semihosting).
//
//   1. ping until the board answers (it may still be booting), 6 s at most;
//   2. read the config word (ops::read_config);
//   3. read every allocated servo's trim, position and target through the planner
//      (ops::read_servo_states_fixed: the allocation table, then the fewest reads);
//   4. move the first two allocated servos with one CONST frame (protocol.md §4.8), then read
//      again until both have arrived.
//
// Exit status (semihosting): 0 done; 1 the board fell silent (no reply by the deadline);
// 2 malformed replies (three in a row to a read, one to a write) or an operation's error (a
// nonsense allocation table); 3 the board refused (NACK); 4 the servos did not arrive within
// 2 s; 5 fewer than two servos allocated; 70 a fault.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/ops/servos.hpp>
#include <rcb4/ops/system.hpp>
#include <rcb4/rcb4.hpp>

#include "mps2.hpp"

#include <optional>
#include <variant>

namespace {

constexpr std::uint32_t reply_deadline_ms = 1500;  // QEMU may hold the first byte for about 1 s
constexpr std::uint32_t boot_deadline_ms = 6000;   // how long to ping a board that may be booting
constexpr int tries = 3;                           // a malformed reply to a read is retried after a quiet line

enum class outcome { ok = 0, silent = 1, malformed = 2, refused = 3, not_arrived = 4, too_few_servos = 5 };

[[noreturn]] void fail(outcome o, const char* what) {
  mps2::line l;
  l << "firmware: " << what << " (exit " << static_cast<long>(o) << ")";
  l.print();
  mps2::exit(static_cast<int>(o));
}

/** Drops what the line still carries until it has been quiet for 20 ms, 200 ms at most. */
void drain() {
  const std::uint32_t give_up = mps2::now_ms() + 200;
  while (static_cast<std::int32_t>(mps2::now_ms() - give_up) < 0 && mps2::uart_get(mps2::now_ms() + 20)) {
  }
}

/** Where replies are read: a parsed reply points into it, so it lives as long as the program. */
std::uint8_t g_rx[rcb4::max_reply_size];

/**
 * One exchange: the command's frame out, then the reply read as the codec asks for it (length
 * byte first, then exactly the missing bytes), each byte by the deadline. A malformed reply to a
 * read (or ping) is retried after drain(); a write is sent once (a CALL sent twice would push the
 * board's stack twice). Nothing when the board stays silent; NACK is returned as the reply (the
 * operation decides whether it is an error). The reply's bytes live in g_rx until the next call.
 */
std::optional<rcb4::reply> exchange(const rcb4::command& cmd, std::uint32_t timeout_ms = reply_deadline_ms) {
  std::uint8_t tx[rcb4::max_request_size];
  const auto n = rcb4::serialize(cmd, tx);
  if (!n) fail(outcome::malformed, "a command that does not serialize");
  const auto shape = rcb4::expected_reply(cmd);
  const bool repeatable = shape.data || std::holds_alternative<rcb4::ping>(cmd);
  for (int attempt = 0; attempt < (repeatable ? tries : 1); ++attempt) {
    for (std::size_t i = 0; i < *n; ++i)
      if (!mps2::uart_put(tx[i], mps2::now_ms() + timeout_ms)) fail(outcome::silent, "the UART does not send");
    std::size_t have = 0;
    const std::uint32_t deadline = mps2::now_ms() + timeout_ms;
    for (;;) {
      const auto p = rcb4::parse_reply({g_rx, have}, shape);
      if (p.ok()) return p.value();
      if (p.status == rcb4::parse_status::error) {
        mps2::line l;
        l << "firmware: malformed reply: " << rcb4::message(p.error);
        l.print();
        drain();
        break;
      }
      for (std::size_t k = 0; k < p.needed; ++k) {
        const auto b = mps2::uart_get(deadline);
        if (!b) return std::nullopt;
        g_rx[have++] = *b;
      }
    }
  }
  fail(outcome::malformed, repeatable ? "three malformed replies in a row" : "a malformed reply to a write");
}

/** exchange() that ends the program when the board is silent. */
rcb4::reply exchange_or_fail(const rcb4::command& cmd) {
  const auto r = exchange(cmd);
  if (!r) fail(outcome::silent, "the board did not answer in time");
  return *r;
}

/** Runs a sans-I/O operation to its end over exchange(). */
template <class Op>
void run(Op& op, const char* what) {
  while (const auto c = op.next()) op.on_reply(exchange_or_fail(*c));
  if (op.error() == rcb4::errc::nack) fail(outcome::refused, what);
  if (op.error() != rcb4::errc{}) {  // a malformed reply the operation saw, a nonsense allocation table
    mps2::line l;
    l << "firmware: " << what << ": " << rcb4::message(op.error()) << " (exit " << static_cast<long>(outcome::malformed)
      << ")";
    l.print();
    mps2::exit(static_cast<int>(outcome::malformed));
  }
}

}  // namespace

extern "C" int firmware_main() {
  using namespace rcb4;
  mps2::init();
  mps2::line out;

  // 1. ping until the board answers (it may still be booting), for boot_deadline_ms at most.
  const std::uint32_t boot = mps2::now_ms() + boot_deadline_ms;
  std::optional<reply> pong;
  while (!(pong = exchange(command{ping{}})))
    if (static_cast<std::int32_t>(mps2::now_ms() - boot) >= 0)
      fail(outcome::silent, "the board did not answer in time");
  if (!pong->is_ack()) fail(outcome::refused, "ping: NACK");
  (out << "ping: ACK").print();

  // 2. the config word.
  ops::read_config config;
  run(config, "read config");
  out << "config: ";
  out.hex(config.value().encode(), 4);
  out << " (baud " << static_cast<long>(bits_per_second(config.value().com_baud)) << ", period "
      << static_cast<long>(milliseconds(config.value().period)) << " ms)";
  out.print();

  // 3. every servo's state, planned reads (in a scope of its own: the reads in step 4 reuse its stack).
  ics_number a{}, b{};
  {
    ops::read_servo_states_fixed states;
    run(states, "read servos");
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
  if (!exchange_or_fail(command{*move}).is_ack()) fail(outcome::refused, "move: NACK");
  (out << "move: ICS " << static_cast<long>(a.value()) << " -> " << static_cast<long>(goal_a.value()) << ", ICS "
       << static_cast<long>(b.value()) << " -> " << static_cast<long>(goal_b.value()) << ", 10 frames: ACK")
      .print();

  // Read until both measured positions are within 2 counts of their goals, for at most 2 s.
  const std::uint32_t give_up = mps2::now_ms() + 2000;
  for (int round = 1;; ++round) {
    ops::read_servo_states_fixed now;
    run(now, "read servos");
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
