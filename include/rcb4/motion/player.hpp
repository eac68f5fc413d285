// rcb4 — a motion program played from the host: the steps a ROM motion would run, as actions a
// driver carries out (send a frame and wait its frames, read a RAM value, play a ROM motion),
// without writing ROM. Sans-I/O: no clock, no port; the driver owns both.
// SPDX-License-Identifier: BSL-1.0
//
// What the board does and the player does the same way (motions.md §1-§2): a pose is one CONST
// and the next step waits until its frames have passed (the board fetches nothing while an update
// flag is set); set_counter / count_down keep the counter (an 8-bit value that wraps as the
// board's SUB does) in the player, and a branch_if on a counter's address compares that value; a
// branch on any other RAM value (the KRR buttons at 0x0350, an AD channel) asks the driver to read
// it from the board; call_motion asks the driver to play the ROM code at that address and wait for
// its end; end (RETURN) ends the program.
//
//   motion::player p(program);           // labels resolved, or p.error() says why not
//   for (auto a = p.next(); !std::holds_alternative<motion::finished>(a); a = p.next()) {
//     if (auto* s = std::get_if<motion::send>(&a)) { exchange(s->cmd); wait(s->frames periods); }
//     else if (auto* r = std::get_if<motion::read_value>(&a)) p.value(read_ram(r->address, r->size));
//     else if (auto* c = std::get_if<motion::play_code>(&a)) play_rom_and_wait(c->address);
//   }
#pragma once

#include <rcb4/motion/assemble.hpp>

#include <map>
#include <string>
#include <variant>

namespace rcb4::motion {

/** Send @p cmd, then let @p frames output periods pass before the next action (0: at once). */
struct send {
  command cmd;          ///< a CONST (pose) or a 0x12 (speed/stretch)
  unsigned frames = 0;  ///< what the board would wait: a pose's frames, else 0
};
/** Read the 1- or 2-byte RAM value at @p address from the board and give it to player::value(). */
struct read_value {
  ram_address address{};  ///< what a branch compares
  std::uint8_t size = 2;  ///< bytes, little-endian
};
/** Play the ROM code at @p address (another motion) and wait until it has returned. */
struct play_code {
  rom_address address{};  ///< the callee's first byte
};
/** The program has ended (its RETURN), or stopped on error(). */
struct finished {};
/** What the driver does next. */
using action = std::variant<send, read_value, play_code, finished>;

/** Steps through a program as the board would, one action at a time. */
class player {
 public:
  /** Steps without an action (a jump, a counter) that may run in a row before the player gives up. */
  static constexpr unsigned max_quiet_steps = 100000;

  /** Plays @p p: its labels must be unique and defined, its values in range (as assemble checks). */
  explicit player(program p) : p_(std::move(p)) {
    for (std::size_t i = 0; i < p_.steps.size(); ++i)
      if (const auto* l = std::get_if<label>(&p_.steps[i]))
        if (!labels_.emplace(l->name, i).second) fail("the label '" + l->name + "' is defined twice");
    for (std::size_t i = 0; i < p_.steps.size() && error_.empty(); ++i)
      if (const auto* to = detail::target_of(p_.steps[i]); to && !labels_.count(*to))
        fail("step " + std::to_string(i) + ": no label is called '" + *to + "'");
    for (std::size_t i = 0; i < p_.steps.size() && error_.empty(); ++i) {
      const auto cs = detail::commands_of(p_.steps[i], rom_address{});
      if (!ok(cs)) fail(detail::where_step(i, p_.steps[i]) + std::get<failure>(cs).message);
    }
  }

  /** The next action; finished at the end, or when error() is set. */
  action next() {
    if (waiting_) fail("next() before value(): a read_value needs its answer");
    for (unsigned quiet = 0; error_.empty(); ++quiet) {
      if (quiet >= max_quiet_steps) {
        fail("the program ran " + std::to_string(max_quiet_steps) +
             " steps without a pose, a read or a call: it would "
             "spin for ever");
        break;
      }
      if (pc_ >= p_.steps.size()) {
        fail("the program runs past its last step (it ends with neither end nor go_to)");
        break;
      }
      const std::size_t at = pc_++;
      const auto& s = p_.steps[at];
      if (const auto* ps = std::get_if<pose>(&s)) {
        ++poses_;
        return send{command{const_servo::make(ps->targets, ps->time).value()}, ps->time.value()};
      }
      if (const auto* sp = std::get_if<servo_parameter>(&s))
        return send{command{servo_params::make(sp->kind, sp->values).value()}, 0};
      if (const auto* sc = std::get_if<set_counter>(&s)) {
        counters_[sc->counter.value()] = sc->value;
      } else if (const auto* cd = std::get_if<count_down>(&s)) {
        auto& c = counters_[cd->counter.value()];  // a counter never set: 0, as RAM the program never wrote
        c = static_cast<std::uint8_t>(c - 1);
        if ((c == 0) == cd->when_zero) pc_ = labels_.at(cd->to);
      } else if (const auto* b = std::get_if<branch_if>(&s)) {
        const auto known = b->size == 1 ? counters_.find(b->address.value()) : counters_.end();
        if (known == counters_.end()) {
          waiting_ = b;
          return read_value{b->address, b->size};
        }
        take(*b, known->second);
      } else if (const auto* g = std::get_if<go_to>(&s)) {
        pc_ = labels_.at(g->to);
      } else if (const auto* c = std::get_if<call_motion>(&s)) {
        ++calls_;
        return play_code{c->address};
      } else if (std::holds_alternative<end>(s)) {
        done_ = true;
        return finished{};
      }
    }
    return finished{};
  }

  /** The value a read_value asked for. */
  void value(std::uint16_t v) {
    if (!waiting_) {
      fail("value() without a read_value");
      return;
    }
    const branch_if* b = waiting_;
    waiting_ = nullptr;
    take(*b, b->size == 1 ? static_cast<std::uint16_t>(v & 0xFF) : v);
  }

  /** True once the program has reached its end (not on an error). */
  bool done() const noexcept { return done_; }
  /** Why the program cannot be played or stopped, or empty. */
  const std::string& error() const noexcept { return error_; }
  /** The step the next action comes from (0-based). */
  std::size_t step() const noexcept { return pc_; }
  /** Poses sent so far. */
  std::size_t poses() const noexcept { return poses_; }
  /** ROM motions called so far. */
  std::size_t calls() const noexcept { return calls_; }

 private:
  void fail(std::string why) {
    if (error_.empty()) error_ = std::move(why);
  }
  /** The branch after a flags-only SUB of b.value from @p v: Z when equal, C when no borrow. */
  void take(const branch_if& b, std::uint16_t v) {
    bool jump = false;
    switch (b.how) {
      case compare::equal: jump = v == b.value; break;
      case compare::not_equal: jump = v != b.value; break;
      case compare::below: jump = v < b.value; break;
      case compare::at_least: jump = v >= b.value; break;
      case compare::at_most: jump = v <= b.value; break;
    }
    if (jump) pc_ = labels_.at(b.to);
  }

  program p_;
  std::map<std::string, std::size_t> labels_;
  std::map<std::uint16_t, std::uint8_t> counters_;
  const branch_if* waiting_ = nullptr;
  std::size_t pc_ = 0, poses_ = 0, calls_ = 0;
  bool done_ = false;
  std::string error_;
};

/** How long a program plays, as the board runs it (play_time). */
struct play_estimate {
  unsigned long long frames = 0;  ///< interpolation frames of its poses, every loop counted
  bool endless = false;           ///< it goes round for ever (or longer than play_time looks)
  bool reads = false;             ///< a branch read RAM (buttons, AD, ...): taken as 0, nothing pressed
  std::size_t calls = 0;          ///< ROM motions it calls: their time is not counted
  std::string error;              ///< why it cannot be played (player::error), or empty
};

/**
 * The frames @p p plays as the board runs it: counters and loops counted, every RAM value a
 * branch reads taken as 0 (no button held, AD and RAM at 0), calls not followed. A program that
 * is still going after @p longest frames is endless (the default: an hour at 10 ms).
 */
inline play_estimate play_time(const program& p, unsigned long long longest = 360000) {
  play_estimate e;
  player pl(p);
  for (auto a = pl.next(); !std::holds_alternative<finished>(a); a = pl.next()) {
    if (const auto* s = std::get_if<send>(&a)) {
      e.frames += s->frames;
      if (e.frames > longest || pl.poses() > 1000000) {
        e.endless = true;
        return e;
      }
    } else if (std::holds_alternative<read_value>(a)) {
      e.reads = true;
      pl.value(0);
    } else if (std::holds_alternative<play_code>(a)) {
      ++e.calls;
    }
  }
  e.error = pl.error();
  // A loop without poses spins on the player's step guard: a program that never ends.
  if (!e.error.empty() && e.error.find("spin for ever") != std::string::npos) {
    e.endless = true;
    e.error.clear();
  }
  return e;
}

}  // namespace rcb4::motion
