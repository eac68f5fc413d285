// rcb4 — reading a motion slot back: the code as the board would run it, and the program it is.
// SPDX-License-Identifier: BSL-1.0
//
// disassemble() follows the code from the slot's first byte as the board fetches it (motions.md
// §7.5): each frame's SIZE byte and checksum (protocol.md §2), both ways of a conditional JUMP,
// past a CALL, never past a RETURN or an unconditional JUMP. Bytes after a RETURN that nothing
// reaches are leftovers of an older, longer motion (a slot is not erased before a write), not
// code, so a straight read from the start would show made-up instructions.
//
// lift() turns a listing into a program where the code is one the steps can express (what
// assemble() makes, and HTH4's own patterns of motions.md §1: poses, SetCounter, Loop,
// CmpButton, MotionJump, ServoParam); otherwise it names the first instruction it cannot.
// assemble(lift(disassemble(assemble(p)))) gives back the same bytes.
#pragma once

#include <rcb4/motion/assemble.hpp>

#include <algorithm>
#include <cstdio>
#include <set>
#include <span>

namespace rcb4::motion {

/** One frame of a slot as the board would fetch it. */
struct instruction {
  std::uint32_t address = 0;        ///< its first byte in ROM
  std::vector<std::uint8_t> bytes;  ///< the frame (or the bytes that are not one)
  std::optional<command> cmd;       ///< what it is; nothing when it is not a valid frame
  errc error{};                     ///< why it is not (erased ROM reads as 0xFF: frame_too_long)
};

/** The reachable code of a slot. */
struct listing {
  slot where;                        ///< the slot read
  std::vector<instruction> code;     ///< every reachable frame, by address
  std::vector<std::uint32_t> calls;  ///< the addresses it CALLs or JUMPs to outside the slot (other motions), ascending
  std::vector<std::string> problems;  ///< what stops the board: a bad frame, a jump out of the slot, ...
  std::vector<std::string> notes;     ///< what runs but may not be meant: a jump to itself, a call of itself
};

/** "0x000BB8" */
inline std::string hex_address(std::uint32_t a) {
  char b[12];
  std::snprintf(b, sizeof b, "0x%06X", static_cast<unsigned>(a));
  return b;
}

/**
 * The code of @p where, from @p bytes (the slot's contents from its first byte; fewer than
 * where.size is fine, more are ignored), followed as the board runs it. The commands reference
 * @p bytes (a MOV's literal): keep them alive while the listing is used.
 */
inline listing disassemble(std::span<const std::uint8_t> bytes, slot where, const codec_options& opt = {}) {
  listing out{where, {}, {}, {}, {}};
  const std::uint32_t base = where.address.value();
  const std::size_t have = std::min<std::size_t>(bytes.size(), where.size);
  std::set<std::uint32_t> seen, calls;
  std::vector<std::uint32_t> todo{base};
  while (!todo.empty()) {
    const std::uint32_t at = todo.back();
    todo.pop_back();
    if (!seen.insert(at).second) continue;
    const std::size_t off = at - base;
    if (off >= have) {
      out.problems.push_back("the code runs on to " + hex_address(at) + ", past the " + std::to_string(have) +
                             " bytes read");
      continue;
    }
    const auto rest = bytes.subspan(off, have - off);
    const auto r = parse_command(rest, opt);
    instruction in{at, {}, std::nullopt, errc{}};
    if (!r.ok()) {
      in.error = r.status == parse_status::need_more ? errc::frame_too_short : r.error;
      in.bytes.assign(rest.begin(), rest.begin() + static_cast<std::ptrdiff_t>(std::min<std::size_t>(
                                                       rest.size(), std::max<std::size_t>(rest[0], 1))));
      out.problems.push_back(hex_address(at) + ": not a frame (" + message(in.error) + "): the board stops here");
      out.code.push_back(std::move(in));
      continue;
    }
    in.bytes.assign(rest.begin(), rest.begin() + static_cast<std::ptrdiff_t>(r.consumed));
    in.cmd = r.value();
    const std::uint32_t next = at + static_cast<std::uint32_t>(r.consumed);
    const auto follow = [&](std::uint32_t target) {
      if (target < base || target >= base + where.size)
        out.problems.push_back(hex_address(at) + ": jumps out of the slot, to " + hex_address(target));
      else
        todo.push_back(target);
    };
    if (const auto* j = std::get_if<jump>(&r.value())) {
      const auto t = j->target().value();
      const bool other_slot_start = (t < base ? base - t : t - base) % where.size == 0;
      if ((t < base || t >= base + where.size) && other_slot_start) {
        // HTH4's terminal MotionJump (hth4-files.md §4, §5.5): the board goes on in another
        // motion (a slot's first byte, slots being where.size apart) and does not come back. Its target is checked as a
        // call's is (callers treat it as one: an empty or broken slot is refused, and it counts towards the nesting
        // depth).
        calls.insert(t);
        out.notes.push_back(hex_address(at) + ": jumps to " + hex_address(t) +
                            " (another motion): the board goes on there and does not come back");
      } else {
        follow(t);
      }
      if (j->cond() != condition::always())
        todo.push_back(next);
      else if (j->target().value() == at)
        out.notes.push_back(hex_address(at) + ": jumps to itself: the motion never ends (until it is stopped)");
    } else if (const auto* c = std::get_if<call>(&r.value())) {
      calls.insert(c->target().value());
      if (c->target().value() == base)
        out.notes.push_back(hex_address(at) + ": calls its own slot: every pass takes a level of the 16-deep stack");
      todo.push_back(next);
    } else if (!std::holds_alternative<ret>(r.value())) {
      todo.push_back(next);
    }
    out.code.push_back(std::move(in));
  }
  std::sort(out.code.begin(), out.code.end(), [](const auto& a, const auto& b) { return a.address < b.address; });
  out.calls.assign(calls.begin(), calls.end());
  return out;
}

namespace detail {
/** The label name of address @p a: "L0BD0". */
inline std::string label_at(std::uint32_t a) {
  char b[12];
  std::snprintf(b, sizeof b, "L%04X", static_cast<unsigned>(a));
  return b;
}
/** The 1- or 2-byte literal of a source as a number. */
inline std::uint16_t literal_value(const source& s) {
  const auto b = s.literal_bytes();
  return static_cast<std::uint16_t>(b[0] | (b.size() > 1 ? b[1] << 8 : 0));
}
/** The compare a JUMP condition after a flags-only SUB tests, if it is one of the four. */
inline std::optional<compare> compare_of(const condition& c) {
  for (auto how : {compare::equal, compare::not_equal, compare::below, compare::at_least, compare::at_most})
    if (condition_of(how) == c) return how;
  return std::nullopt;
}
}  // namespace detail

/**
 * The program of @p l where its code is contiguous from the slot's start and every instruction
 * belongs to a step; a failure names the first address that does not. With @p starts, the ROM
 * address of each step's first frame (a label's: the frame after it) is put there, a step each.
 */
inline outcome<program> lift(const listing& l, std::vector<std::uint32_t>* starts = nullptr) {
  if (!l.problems.empty()) return failure{l.problems.front()};
  const std::uint32_t base = l.where.address.value();
  std::set<std::uint32_t> targets;
  std::uint32_t expect = base;
  for (const auto& in : l.code) {
    if (in.address != expect)
      return failure{"the code is not one block: " + hex_address(in.address) + " follows " + hex_address(expect) +
                     " with a gap (the steps lay code out without one)"};
    expect += static_cast<std::uint32_t>(in.bytes.size());
    if (const auto* j = std::get_if<jump>(&*in.cmd)) targets.insert(j->target().value());
  }
  program p;
  for (std::size_t i = 0; i < l.code.size(); ++i) {
    const auto& in = l.code[i];
    const command& c = *in.cmd;
    if (targets.count(in.address)) p.steps.push_back(label{detail::label_at(in.address)});
    const jump* then = i + 1 < l.code.size() ? std::get_if<jump>(&*l.code[i + 1].cmd) : nullptr;
    const auto cannot = [&](const std::string& why) -> outcome<program> {
      return failure{hex_address(in.address) + ": " + why + " (no step says that; the listing shows it)"};
    };
    if (const auto* cs = std::get_if<const_servo>(&c)) {
      if (cs->flags() != update_flags::replace) return cannot("a CONST that leaves the update flags");
      p.steps.push_back(pose{cs->targets(), cs->speed()});
    } else if (const auto* m = std::get_if<move>(&c)) {
      if (m->dst().kind() != dst_kind::ram || m->src().kind() != src_kind::literal || m->src().size() != 1)
        return cannot("a MOV other than a 1-byte literal into RAM");
      p.steps.push_back(set_counter{ram_address::make(m->dst().address()).value(), m->src().literal_bytes()[0]});
    } else if (const auto* a = std::get_if<arith>(&c)) {
      if (a->op() != arith_op::sub || a->dst().kind() != dst_kind::ram || a->src().kind() != src_kind::literal || !then)
        return cannot("arithmetic other than a SUB of a literal from RAM followed by a JUMP");
      if (targets.count(l.code[i + 1].address)) return cannot("a jump into the middle of a step");
      const auto to = detail::label_at(then->target().value());
      const auto at = ram_address::make(a->dst().address()).value();
      if (a->mode() == store_mode::store) {
        const auto& cond = then->cond();
        if (a->src().size() != 1 || detail::literal_value(a->src()) != 1 || !cond.zero || cond.carry)
          return cannot("a SUB that counts other than down by 1 and tests Z");
        p.steps.push_back(count_down{at, to, *cond.zero});
      } else {
        const auto how = detail::compare_of(then->cond());
        if (!how)
          return cannot("a compare with a condition that is not one of equal, not equal, below, at least, at most");
        p.steps.push_back(branch_if{at, a->src().size(), detail::literal_value(a->src()), *how, to});
      }
      ++i;  // the JUMP belongs to this step
    } else if (const auto* j = std::get_if<jump>(&c)) {
      if (j->cond() != condition::always()) return cannot("a conditional JUMP after no compare");
      p.steps.push_back(go_to{detail::label_at(j->target().value())});
    } else if (const auto* k = std::get_if<call>(&c)) {
      if (k->cond() != condition::always()) return cannot("a conditional CALL");
      p.steps.push_back(call_motion{k->target()});
    } else if (const auto* sp = std::get_if<servo_params>(&c)) {
      p.steps.push_back(servo_parameter{sp->kind(), sp->values()});
    } else if (std::holds_alternative<ret>(c)) {
      p.steps.push_back(end{});
    } else {
      return cannot("a command motions do not use");
    }
    if (starts)
      while (starts->size() < p.steps.size()) starts->push_back(in.address);
  }
  return p;
}

}  // namespace rcb4::motion
