// rcb4 — robot services: the call graph of the motion slots, checked before a slot is written,
// erased or played (see rcb4/robot/services/motion_slots.hpp: check_calls, require_writable,
// require_playable).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/ops/motion.hpp>
#include <rcb4/ops/system.hpp>
#include <rcb4/robot/services/motion_slots.hpp>

#include "rom_code.hpp"
#include "slot_address.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <set>

namespace rcb4::robot::services {

using detail::chain_text;
using detail::first_problem;
using detail::rom_code;
using detail::stack_depth;
namespace mo = rcb4::motion;

void check_calls(link& l, const rom_layout& layout, const mo::listing& code, const mo::program* steps,
                 const std::vector<std::string>& where_, std::string_view done) {
  rom_code rom(l, layout, &code);
  const std::uint32_t self = code.where.address.value();
  // Each call, in the order the steps make them, so the message names the step.
  std::vector<std::uint32_t> order;
  for (const auto& in : code.code)
    if (in.cmd)
      if (const auto* c = std::get_if<rcb4::call>(&*in.cmd); c && c->target().value() != self)
        if (std::find(order.begin(), order.end(), c->target().value()) == order.end())
          order.push_back(c->target().value());
  const auto step_of = [&](std::uint32_t callee) {
    if (steps)
      for (std::size_t i = 0; i < steps->steps.size(); ++i)
        if (const auto* c = std::get_if<mo::call_motion>(&steps->steps[i]); c && c->address.value() == callee)
          return fmt::format("step {}{} calls", i + 1, i < where_.size() ? fmt::format(" ({})", where_[i]) : "");
    return std::string("it calls");
  };
  for (const auto callee : order) {
    const auto& c = rom.at(callee);
    if (!c.problems.empty())
      throw refused(refusal_kind::board,
                    fmt::format("{} {}, which {}: the board's program would stop there (nothing was {})",
                                step_of(callee), name_of(layout, callee),
                                c.code.empty() ? "holds no motion" : "is broken (" + first_problem(c) + ")", done),
                    c.code.empty() ? "push that motion first; rcb4 motion list shows the used slots"
                                   : "rcb4 motion show N lists its code; push it again");
  }
  std::vector<std::uint32_t> chain;
  const auto d = rom.depth(self, chain);
  if (!d) {
    chain.erase(chain.begin(), std::find(chain.begin(), chain.end(), chain.back()));
    throw refused(refusal_kind::board,
                  fmt::format("its calls come back round ({}): every pass takes another level of the board's "
                              "{}-deep call stack until the board stops (nothing was {})",
                              chain_text(layout, chain), stack_depth, done),
                  "a motion that repeats itself loops with goto, not call");
  }
  // The play's own CALL (or the caller's) takes a level before the motion's first byte.
  if (*d > stack_depth)
    throw refused(refusal_kind::board,
                  fmt::format("its calls nest {} deep ({}): played, it needs {} levels of the board's {}-deep call "
                              "stack, so the board would stop (nothing was {})",
                              *d - 1, chain_text(layout, chain), *d, stack_depth, done),
                  "call fewer motions within each other");
  // The motions that call this slot nest deeper by what it now adds: when it is deeper than the
  // code it replaces, every used slot is looked at for a caller whose chain would overflow.
  if (!slot_number(layout, self)) return;  // played from the host: nothing in ROM calls it
  if (*d <= 1) return;                     // it calls nothing: no caller can nest deeper than before
  rom_code before(l, layout, nullptr);
  std::vector<std::uint32_t> unused;
  const auto was = before.depth(self, unused);
  if (was && *d <= *was) return;
  for (unsigned k = 1; k <= layout.motion_count; ++k) {
    const std::uint32_t a = layout.motion_base.value() + (k - 1) * layout.slot_size;
    if (a == self) continue;
    l.progress("looking for motions that call it", k, layout.motion_count);
    if (run(l, rcb4::ops::read_memory(rcb4::ops::memory::rom, a, 1))[0] == 0xFF) continue;  // empty
    if (!rom.reaches(a, self)) continue;
    std::vector<std::uint32_t> via;
    const auto caller = rom.depth(a, via);
    if (!caller)
      throw refused(refusal_kind::board,
                    fmt::format("{} calls it, and with the new code the calls come back round ({}): the board's "
                                "{}-deep call stack would overflow (nothing was {})",
                                name_of(layout, a), chain_text(layout, via), stack_depth, done),
                    "a motion that repeats itself loops with goto, not call");
    if (*caller > stack_depth)
      throw refused(refusal_kind::board,
                    fmt::format("{} calls it, and with the new code its calls nest {} deep ({}): played, it needs {} "
                                "levels of the board's {}-deep call stack, so the board would stop (nothing was {})",
                                name_of(layout, a), *caller - 1, chain_text(layout, via), *caller, stack_depth, done),
                    "call fewer motions within each other");
  }
}

void require_writable(link& l, const rom_layout& layout, unsigned n, std::span<const std::uint8_t> old,
                      std::string_view doing) {
  const auto st = run(l, rcb4::ops::read_motion_state(layout));
  if (!st.running && !st.suspended) return;
  const auto where = slot_for(layout, n);
  const std::uint32_t base = where.address.value();
  const std::string state = st.running ? "is running" : "is stopped part way";
  const std::string pc_name = name_of(layout, st.program_counter);
  const std::string hint = st.running ? "rcb4 motion wait, or rcb4 motion stop and then rcb4 motion play N (any "
                                        "motion), which starts the program afresh; then try again"
                                      : "rcb4 motion play N (any motion) starts the program afresh; then try again";
  if (st.motion && *st.motion == n)
    throw refused(
        refusal_kind::board,
        fmt::format("motion {} {} (program counter 0x{:06X}): {} in the middle of the bytes being {}", n, state,
                    st.program_counter, st.running ? "the board would run on" : "motion resume would continue", doing),
        hint);
  mo::listing own{where, {}, {}, {}, {}};
  if (!old.empty() && old[0] != 0xFF) own = mo::disassemble(old, where);
  rom_code rom(l, layout, &own);
  // A CALL of this slot's on the stack: the callee's RETURN would land in the new bytes.
  if (st.depth >= 2 && rom.reaches(base, st.program_counter))
    throw refused(refusal_kind::board,
                  fmt::format("the board's program {} in {}, which motion {} called: a return into motion {} is on "
                              "the board's call stack ({} levels), so {} would return into the bytes being {}",
                              state, pc_name, n, n, st.depth, st.running ? "the program" : "motion resume", doing),
                  hint);
  // A running motion that calls this slot would run it while it is written.
  const auto pc_slot = slot_number(layout, st.program_counter);
  if (st.running && pc_slot) {
    const std::uint32_t pc_base = layout.motion_base.value() + (*pc_slot - 1) * layout.slot_size;
    if (rom.reaches(pc_base, base))
      throw refused(refusal_kind::board,
                    fmt::format("motion {} is running and calls motion {}: the board could run the bytes being {}",
                                *pc_slot, n, doing),
                    hint);
  }
}

void require_playable(link& l, const rom_layout& layout, unsigned n, std::string_view what) {
  const auto where = slot_for(layout, n);
  rom_code rom(l, layout, nullptr);
  const auto& c = rom.at(where.address.value());
  if (c.problems.empty()) {
    // Its calls, through any number of slots: an empty or broken one stops the board's program
    // when the play reaches it (after the robot has moved), so the play is refused before it starts.
    std::map<std::uint32_t, std::uint32_t> via;  // callee -> the code that calls it
    std::vector<std::uint32_t> todo(c.calls.begin(), c.calls.end());
    for (const auto a : todo) via.emplace(a, where.address.value());
    while (!todo.empty()) {
      const auto a = todo.back();
      todo.pop_back();
      const auto& k = rom.at(a);
      if (!k.problems.empty()) {
        std::string chain = name_of(layout, a);
        for (auto at = via.at(a); at != where.address.value(); at = via.at(at))
          chain = name_of(layout, at) + " → " + chain;
        throw refused(refusal_kind::board,
                      fmt::format("{}motion {} calls {}, which {}: a play would stop the board's program there",
                                  what.empty() ? std::string() : std::string(what) + ": ", n, chain,
                                  k.code.empty() ? "holds no motion" : "is broken (" + first_problem(k) + ")"),
                      "push that motion (again), or push the caller without the call");
      }
      for (const auto b : k.calls)
        if (via.emplace(b, a).second) todo.push_back(b);
    }
    return;
  }
  throw refused(refusal_kind::board,
                fmt::format("{}motion {} (0x{:06X}) {}: a play would stop the board's program there",
                            what.empty() ? std::string() : std::string(what) + ": ", n, where.address.value(),
                            c.code.empty() ? "holds no motion" : "is broken (" + first_problem(c) + ")"),
                c.code.empty() ? "rcb4 motion list shows the used slots"
                               : fmt::format("rcb4 motion show {} lists its code; push it again", n));
}

}  // namespace rcb4::robot::services
