// rcb4 — the motion assembler: a program's steps into the commands and ROM bytes of a slot.
// SPDX-License-Identifier: BSL-1.0
//
// Two passes: the first lays the steps out (every step's frames have a size that does not
// depend on where its jumps go) and gives each label its address; the second builds the frames
// with the labels resolved. Checked: labels unique and defined, the code inside the slot, the
// last step a RETURN or a jump (the board would run on into whatever follows), every value in
// its range (the codec's factories), and the CALL nesting this program adds to the 16-deep stack.
#pragma once

#include <rcb4/motion/program.hpp>

#include <map>
#include <string>

namespace rcb4::motion {

namespace detail {

/** The flags-only SUB + JUMP condition of a compare: Z for (not) equal, C for below / at least. */
inline condition condition_of(compare how) noexcept {
  switch (how) {
    case compare::equal: return {true, std::nullopt};
    case compare::not_equal: return {false, std::nullopt};
    case compare::below: return {std::nullopt, false};
    case compare::at_least: return {std::nullopt, true};
    case compare::at_most: return {true, false};
  }
  return {};
}

/** "step 3 (pose): " */
inline std::string where_step(std::size_t i, const step& s) {
  static constexpr const char* names[] = {"label", "pose",        "set_counter",     "count_down", "branch_if",
                                          "go_to", "call_motion", "servo_parameter", "end"};
  return "step " + std::to_string(i) + " (" + names[s.index()] + "): ";
}

/** The commands of one step, jumps to @p target (the resolved label, or a placeholder). */
inline outcome<std::vector<command>> commands_of(const step& s, rom_address target) {
  using out = std::vector<command>;
  const auto fail = [](errc e) -> outcome<out> { return failure{message(e)}; };
  return std::visit(
      [&](const auto& x) -> outcome<out> {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, label>) {
          return out{};
        } else if constexpr (std::is_same_v<T, pose>) {
          const auto c = const_servo::make(x.targets, x.time);  // update flags set: the program waits
          if (!c) return fail(c.error());
          return out{command{*c}};
        } else if constexpr (std::is_same_v<T, set_counter>) {
          const auto c = move::make(destination::ram(x.counter), source::literal_u8(x.value));
          if (!c) return fail(c.error());
          return out{command{*c}};
        } else if constexpr (std::is_same_v<T, count_down>) {
          const auto c = arith::make(arith_op::sub, destination::ram(x.counter), source::literal_u8(1));
          if (!c) return fail(c.error());
          return out{command{*c}, command{jump{target, condition{x.when_zero, std::nullopt}}}};
        } else if constexpr (std::is_same_v<T, branch_if>) {
          if (x.size != 1 && x.size != 2) return failure{"the value is 1 or 2 bytes"};
          if (x.size == 1 && x.value > 0xFF) return failure{"a 1-byte value compares with 0-255"};
          const auto lit =
              x.size == 1 ? source::literal_u8(static_cast<std::uint8_t>(x.value)) : source::literal_u16(x.value);
          const auto c = arith::make(arith_op::sub, destination::ram(x.address), lit, store_mode::flags_only);
          if (!c) return fail(c.error());
          return out{command{*c}, command{jump{target, condition_of(x.how)}}};
        } else if constexpr (std::is_same_v<T, go_to>) {
          return out{command{jump{target}}};
        } else if constexpr (std::is_same_v<T, call_motion>) {
          return out{command{call{x.address}}};
        } else if constexpr (std::is_same_v<T, servo_parameter>) {
          const auto c = servo_params::make(x.kind, x.values);
          if (!c) return fail(c.error());
          return out{command{*c}};
        } else {
          return out{command{ret{}}};
        }
      },
      s);
}

/** The label a step jumps to, or nothing. */
inline const std::string* target_of(const step& s) noexcept {
  if (const auto* c = std::get_if<count_down>(&s)) return &c->to;
  if (const auto* b = std::get_if<branch_if>(&s)) return &b->to;
  if (const auto* g = std::get_if<go_to>(&s)) return &g->to;
  return nullptr;
}

}  // namespace detail

/** The deepest CALL nesting a motion may add: the board's stack is 16 deep, the main loop's CALL is one. */
inline constexpr unsigned max_call_depth = 15;

/**
 * The commands of @p p at @p where, labels resolved; a failure names the step and why.
 * @p callee_depth: how deep the motions it calls nest in turn (0: they call nothing), for the
 * stack check.
 */
inline outcome<std::vector<command>> compile(const program& p, slot where, unsigned callee_depth = 0) {
  if (p.steps.empty()) return failure{"an empty motion: it needs at least a RETURN (end)"};
  // Pass 1: the layout and the labels.
  std::map<std::string, std::uint32_t> labels;
  std::uint32_t at = where.address.value();
  bool calls = false;
  for (std::size_t i = 0; i < p.steps.size(); ++i) {
    const auto& s = p.steps[i];
    if (const auto* l = std::get_if<label>(&s)) {
      if (l->name.empty()) return failure{detail::where_step(i, s) + "a label needs a name"};
      if (!labels.emplace(l->name, at).second)
        return failure{detail::where_step(i, s) + "the label '" + l->name + "' is defined twice"};
      continue;
    }
    if (const auto* c = std::get_if<call_motion>(&s)) {
      if (c->address == where.address)
        return failure{detail::where_step(i, s) +
                       "the motion calls itself: every pass would take a level of the 16-deep stack (go_to loops)"};
      calls = true;
    }
    auto cs = detail::commands_of(s, where.address);
    if (!ok(cs)) return failure{detail::where_step(i, s) + std::get<failure>(cs).message};
    for (const auto& c : std::get<std::vector<command>>(cs)) at += static_cast<std::uint32_t>(wire_size(c));
  }
  const auto& last = p.steps.back();
  if (!std::holds_alternative<end>(last) && !std::holds_alternative<go_to>(last))
    return failure{
        "the last step is neither an end (RETURN) nor a go_to: the board would run on into the bytes "
        "after the motion"};
  const std::uint32_t used = at - where.address.value();
  if (used > where.size)
    return failure{"the motion takes " + std::to_string(used) + " bytes, its slot holds " + std::to_string(where.size)};
  if (calls && 1 + callee_depth > max_call_depth)
    return failure{"the calls would nest " + std::to_string(2 + callee_depth) +
                   " deep with the main loop's: the board's stack holds 16"};
  // Pass 2: the frames with their targets.
  std::vector<command> out;
  for (std::size_t i = 0; i < p.steps.size(); ++i) {
    const auto& s = p.steps[i];
    rom_address target = where.address;
    if (const auto* name = detail::target_of(s)) {
      const auto l = labels.find(*name);
      if (l == labels.end()) return failure{detail::where_step(i, s) + "no label is called '" + *name + "'"};
      target = rom_address::make(l->second).value();
    }
    auto cs = detail::commands_of(s, target);
    for (auto& c : std::get<std::vector<command>>(cs)) out.push_back(c);
  }
  return out;
}

/** The ROM bytes of @p p at @p where (every frame through the codec's encoders). */
inline outcome<std::vector<std::uint8_t>> assemble(const program& p, slot where, unsigned callee_depth = 0) {
  auto cs = compile(p, where, callee_depth);
  if (!ok(cs)) return std::get<failure>(cs);
  std::vector<std::uint8_t> bytes;
  for (const auto& c : std::get<std::vector<command>>(cs)) {
    const auto f = encode(c);
    bytes.insert(bytes.end(), f.begin(), f.end());
  }
  return bytes;
}

}  // namespace rcb4::motion
