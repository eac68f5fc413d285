// rcb4 — robot services: a motion file played from the host (see rcb4/robot/services/host_play.hpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/motion/assemble.hpp>
#include <rcb4/ops/memory.hpp>
#include <rcb4/ops/servos.hpp>
#include <rcb4/robot/services/host_play.hpp>
#include <rcb4/robot/services/motion_slots.hpp>
#include <rcb4/robot/services/moves.hpp>

#include <fmt/format.h>

#include <algorithm>

namespace rcb4::robot::services {
namespace {

namespace mo = rcb4::motion;
using namespace std::chrono_literals;
using rcb4::ops::memory;

/** How often a called ROM motion's end is looked for (the board refreshes its state about as often). */
constexpr std::chrono::milliseconds callee_poll = 50ms;
/** How long after its time the last pose may take to be reached on the board before a note says so. */
constexpr std::chrono::milliseconds settle_limit = 1000ms;

compiled_motion checked(link& l, const model& robot, const rom_layout& layout, output_period period,
                        const motion_document& d, const std::string& file, bool rescale, servo_mask& on_board) {
  auto c = to_program(d, robot, layout, period, rescale);
  if (!ok(c))
    throw refused(refusal_kind::usage, fmt::format("{}: {} (nothing was sent)", file, std::get<problem>(c).message));
  auto cm = std::get<compiled_motion>(std::move(c));
  {
    const mo::player probe(cm.program);
    if (!probe.error().empty()) throw refused(refusal_kind::usage, fmt::format("{}: {}", file, probe.error()));
  }
  require_no_motion(l, layout);
  on_board = require_servo_slots(l, robot, cm.program, "sent");
  // Its calls checked as a push checks them (the host plays the poses; the board runs each call).
  const auto whole = mo::slot{rcb4::rom_address{}, 0x40000};
  if (const auto code = mo::assemble(cm.program, whole); mo::ok(code))
    check_calls(l, layout, mo::disassemble(std::get<std::vector<std::uint8_t>>(code), whole), &cm.program, d.where,
                "sent");
  return cm;
}

}  // namespace

servo_mask require_servo_slots(link& l, const model& robot, const motion::program& p, std::string_view done) {
  const auto table = run(l, rcb4::ops::read_memory(memory::ram, rcb4::ram::ics_allocation.value(), 70));
  const auto slots = rcb4::ops::parse_allocation_table(table);
  if (!slots) l.failed(slots.error());
  servo_mask on_board;
  for (const auto& k : *slots) on_board.insert(k.ics);
  for (const auto& st : p.steps)
    if (const auto* pose = std::get_if<mo::pose>(&st))
      for (const auto& e : pose->targets)
        if (!on_board.contains(e.ics)) {
          const auto* j = robot.on(e.ics);
          throw refused(refusal_kind::board,
                        fmt::format("{} (ICS {}) has no slot on the board: its poses would not move it, so nothing "
                                    "was {}",
                                    j ? j->name : "a servo", e.ics.value(), done),
                        "rcb4 scan shows the board's slots");
        }
  return on_board;
}

host_play::host_play(link& l, const model& robot, const rom_layout& layout, output_period period,
                     const motion_document& d, std::string file, bool rescale, std::chrono::milliseconds callee_limit)
    : l_(l),
      layout_(layout),
      period_(period),
      file_(std::move(file)),
      callee_limit_(callee_limit),
      compiled_(checked(l, robot, layout, period, d, file_, rescale, slots_)),
      player_(compiled_.program) {}

std::optional<std::chrono::milliseconds> host_play::advance(std::chrono::milliseconds now) {
  if (callee_since_) {
    // Its end, polled as the board refreshes the state; it may not run past its limit.
    if (run(l_, rcb4::ops::read_motion_state(layout_)).running) {
      if (now - *callee_since_ < callee_limit_) return now + callee_poll;
      run(l_, rcb4::ops::stop_motion{});
      callee_since_.reset();
      throw refused(refusal_kind::timeout,
                    fmt::format("{}: motion {}, called at step {}, still ran after {:g} s: stopped", file_, *callee_,
                                player_.step(), std::chrono::duration<double>(callee_limit_).count()),
                    "a motion that loops for ever ends only when it is stopped; allow it longer");
    }
    callee_since_.reset();
    ready_ = now;
  }
  if (now < ready_) return ready_;
  if (finished_) return settled(now);
  const auto frame = std::chrono::milliseconds(rcb4::milliseconds(period_));
  for (;;) {
    const auto a = player_.next();
    if (std::holds_alternative<mo::finished>(a)) {
      finished_ = true;
      if (!player_.error().empty())
        throw refused(refusal_kind::usage,
                      fmt::format("{}: stopped at step {}: {}", file_, player_.step(), player_.error()));
      if (ready_ > now) return ready_;
      return settled(now);
    }
    if (const auto* snd = std::get_if<mo::send>(&a)) {
      if (const auto* c = std::get_if<rcb4::const_servo>(&snd->cmd))
        for (const auto e : c->targets()) moved_.insert(e.ics), last_.insert(e.ics, e.value);
      run(l_, rcb4::ops::detail::ack_sequence({snd->cmd}));
      ready_ = std::max(ready_, now) + snd->frames * frame;
      if (ready_ > now) return ready_;
    } else if (const auto* r = std::get_if<mo::read_value>(&a)) {
      const auto v = run(l_, rcb4::ops::read_memory(memory::ram, r->address.value(), r->size));
      player_.value(static_cast<std::uint16_t>(v[0] | (r->size > 1 ? v[1] << 8 : 0)));
    } else if (const auto* k = std::get_if<mo::play_code>(&a)) {
      const std::uint32_t at = k->address.value(), base = layout_.motion_base.value();
      if (!(at >= base && (at - base) % layout_.slot_size == 0 &&
            (at - base) / layout_.slot_size < layout_.motion_count))
        throw refused(refusal_kind::usage,
                      fmt::format("{}: step {} calls 0x{:06X}, which starts no motion slot ({} layout): from the "
                                  "host only whole motions are played",
                                  file_, player_.step(), at, layout_.name));
      callee_ = (at - base) / layout_.slot_size + 1;
      run(l_, rcb4::ops::play_motion(*callee_, layout_));
      callee_since_ = now;
      return now + callee_poll;
    }
  }
}

std::optional<std::chrono::milliseconds> host_play::settled(std::chrono::milliseconds now) {
  // The host's clock says the last pose is due; the board began it at its first frame after the
  // command arrived (the link's latency and up to one period later), so it is asked.
  if (last_.empty()) return std::nullopt;
  if (!settle_since_) settle_since_ = now;
  const auto states = run(l_, rcb4::ops::read_servo_states());
  bool there = true;
  for (const auto& st : states)
    if (const auto* want = last_.find(st.ics); want && st.target != want->value()) there = false;
  if (there) return std::nullopt;
  if (now - *settle_since_ >= settle_limit) {
    compiled_.notes.push_back(
        fmt::format("{}: the board had not reached the last pose {} ms after it was due (another "
                    "program moved the servos?)",
                    file_, settle_limit.count()));
    return std::nullopt;
  }
  return now + std::max(std::chrono::milliseconds(1), std::chrono::milliseconds(rcb4::milliseconds(period_)));
}

void host_play::stop() {
  if (callee_since_) {
    callee_since_.reset();
    run(l_, rcb4::ops::stop_motion{});
  }
  // A pose under way would go on to its end: every servo the play moved holds where it is now,
  // and after a call every servo on the board (the called motion's last pose may still be under way).
  auto hold = moved_;
  if (player_.calls() > 0)
    for (const auto ics : slots_) hold.insert(ics);
  if (!hold.empty()) run(l_, rcb4::ops::set_servo_power(rcb4::ops::power_state::hold, hold));
}

}  // namespace rcb4::robot::services
