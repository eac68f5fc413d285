// rcb4 — robot services, private: the ROM's code as the board runs it, read once per address, and
// the call graph of the motion slots walked through it (motion_calls.cpp, motion_slots.cpp).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/motion/disassemble.hpp>
#include <rcb4/robot/services/motion_slots.hpp>

#include "slot_address.hpp"

#include <fmt/format.h>

#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace rcb4::robot::services::detail {

namespace mo = rcb4::motion;

/** A listing's first problem, without the disassembler's ": the board stops here" (the caller says what follows). */
inline std::string first_problem(const mo::listing& code) {
  std::string p = code.problems.front();
  constexpr std::string_view tail = ": the board stops here";
  if (p.size() > tail.size() && p.compare(p.size() - tail.size(), tail.size(), tail) == 0)
    p.resize(p.size() - tail.size());
  return p;
}

/** The board's call stack (protocol.md §4: 16 deep); a motion played takes one level itself (§8.1). */
inline constexpr unsigned stack_depth = 16;

/** The code from @p at to the end of its slot (or 2 KiB outside the slots) as the board runs it. */
struct code_at {
  std::vector<std::uint8_t> bytes;  // the listing's commands point into these
  mo::listing code;
};

/**
 * The reachable code of the ROM from @p at, read once per address: the call graph of the slots
 * is walked through it. @p own is the code a push is about to write (its slot read from there).
 */
class rom_code {
 public:
  rom_code(link& l, const rom_layout& layout, const mo::listing* own) : l_(l), layout_(layout), own_(own) {}

  /** The code at @p at. */
  const mo::listing& at(std::uint32_t a) {
    if (own_ && a == own_->where.address.value()) return *own_;
    auto it = read_.find(a);
    if (it != read_.end()) return it->second->code;
    auto c = std::make_unique<code_at>();
    const auto n = slot_number(layout_, a);
    const std::uint32_t end = n ? layout_.motion_base.value() + *n * layout_.slot_size : a + 2048;
    const auto where = mo::slot{rom_address::make(a).value(), end - a};
    c->bytes = read_rom(l_, a, where.size, fmt::format("reading {}", name_of(layout_, a)));
    c->code = c->bytes.empty() || c->bytes[0] == 0xFF ? mo::listing{where, {}, {}, {"it is empty (erased ROM)"}, {}}
                                                      : mo::disassemble(c->bytes, where);
    return read_.emplace(a, std::move(c)).first->second->code;
  }

  /**
   * The levels of the stack the code at @p a takes when CALLed (its own and its callees'), or
   * nothing when its calls come back to a caller still on the stack (recursion); the chain of
   * the deepest path goes to @p chain. A callee that is empty or broken is refused by the caller.
   */
  std::optional<unsigned> depth(std::uint32_t a, std::vector<std::uint32_t>& chain) {
    if (auto it = depth_.find(a); it != depth_.end()) {
      chain = it->second.second;
      return it->second.first;
    }
    if (std::find(path_.begin(), path_.end(), a) != path_.end()) {
      chain.assign(std::find(path_.begin(), path_.end(), a), path_.end());
      chain.push_back(a);
      return std::nullopt;
    }
    path_.push_back(a);
    unsigned best = 0;
    std::vector<std::uint32_t> best_chain;
    for (const auto callee : at(a).calls) {
      std::vector<std::uint32_t> sub;
      const auto d = depth(callee, sub);
      if (!d) {
        path_.pop_back();
        chain = std::move(sub);
        return std::nullopt;
      }
      if (*d > best) best = *d, best_chain = std::move(sub);
    }
    path_.pop_back();
    best_chain.insert(best_chain.begin(), a);
    depth_[a] = {best + 1, best_chain};
    chain = std::move(best_chain);
    return best + 1;
  }

  /** True when the code at @p from CALLs (through any number of slots) into the slot of @p target. */
  bool reaches(std::uint32_t from, std::uint32_t target) {
    std::set<std::uint32_t> seen;
    std::vector<std::uint32_t> todo{from};
    const auto goal = slot_number(layout_, target);
    while (!todo.empty()) {
      const auto a = todo.back();
      todo.pop_back();
      if (!seen.insert(a).second) continue;
      for (const auto callee : at(a).calls) {
        if (callee == target || (goal && slot_number(layout_, callee) == goal)) return true;
        todo.push_back(callee);
      }
    }
    return false;
  }

 private:
  link& l_;
  const rom_layout& layout_;
  const mo::listing* own_;
  std::map<std::uint32_t, std::unique_ptr<code_at>> read_;
  std::map<std::uint32_t, std::pair<unsigned, std::vector<std::uint32_t>>> depth_;
  std::vector<std::uint32_t> path_;
};

/** "motion 3 (0x001B80) -> motion 4 (0x002380)" */
inline std::string chain_text(const rom_layout& layout, const std::vector<std::uint32_t>& chain) {
  std::string out;
  for (const auto a : chain) out += (out.empty() ? "" : " -> ") + name_of(layout, a);
  return out;
}

}  // namespace rcb4::robot::services::detail
