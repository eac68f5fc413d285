// rcb4 — robot services: the ROM's motion slots (see rcb4/robot/services/motion_slots.hpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/ops/memory.hpp>
#include <rcb4/ops/motion.hpp>
#include <rcb4/ops/system.hpp>
#include <rcb4/robot/services/motion_slots.hpp>
#include <rcb4/robot/services/slot_names.hpp>

#include "slot_address.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

namespace rcb4::robot::services {
namespace {

namespace mo = rcb4::motion;

/** A listing's first problem, without the disassembler's ": the board stops here" (the caller says what follows). */
std::string first_problem(const mo::listing& code) {
  std::string p = code.problems.front();
  constexpr std::string_view tail = ": the board stops here";
  if (p.size() > tail.size() && p.compare(p.size() - tail.size(), tail.size(), tail) == 0)
    p.resize(p.size() - tail.size());
  return p;
}
using rcb4::ops::memory;

/** The board's call stack (protocol.md §4: 16 deep); a motion played takes one level itself (§8.1). */
constexpr unsigned stack_depth = 16;

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
std::string chain_text(const rom_layout& layout, const std::vector<std::uint32_t>& chain) {
  std::string out;
  for (const auto a : chain) out += (out.empty() ? "" : " -> ") + name_of(layout, a);
  return out;
}

/** Writes @p bytes at @p at and reads them back; a failure is refused naming @p saved and how to put it back. */
void write_rom_checked(link& l, std::uint32_t at, std::span<const std::uint8_t> bytes, std::string_view label,
                       unsigned n, const std::string& saved) {
  const std::string undo =
      saved.empty()
          ? std::string()
          : fmt::format("the slot's old bytes are in {}: rcb4 motion push {} {} puts them back", saved, saved, n);
  rcb4::ops::write_memory op(memory::rom, at, bytes);
  try {
    while (auto c = op.next()) {
      op.on_reply(l.exchange(*c));
      l.progress(label, op.value(), bytes.size());
    }
    if (op.error() != errc{}) l.failed(op.error());
  } catch (const std::system_error& e) {
    throw refused(
        refusal_kind::line,
        fmt::format("writing ROM 0x{:06X} failed after {} of {} bytes: {}", at, op.value(), bytes.size(), e.what()),
        "the slot may now hold part of the new motion; " + undo, saved, e.code());
  }
  std::vector<std::uint8_t> back;
  try {
    back = read_rom(l, at, bytes.size(), "reading back");
  } catch (const std::system_error& e) {
    throw refused(refusal_kind::line, fmt::format("reading back ROM 0x{:06X} after the write failed: {}", at, e.what()),
                  "the slot holds what was written, unchecked; " + undo, saved, e.code());
  }
  for (std::size_t i = 0; i < bytes.size(); ++i)
    if (back[i] != bytes[i])
      throw refused(refusal_kind::board,
                    fmt::format("ROM 0x{:06X} reads back 0x{:02X}, 0x{:02X} was written", at + i, back[i], bytes[i]),
                    "the board may not accept ROM writes there; " + undo, saved);
}

}  // namespace

std::string file_stamp() {
  char stamp[32];
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  ::localtime_r(&t, &tm);
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &tm);
  return stamp;
}

std::string save_backup_file(unsigned motion, std::span<const std::uint8_t> old, const std::string& path_) {
  std::string path = path_;
  if (path.empty()) {
    const auto stamp = file_stamp();
    path = fmt::format("motion-{}-{}.bin", motion, stamp);
    for (int k = 2; std::filesystem::exists(path); ++k) path = fmt::format("motion-{}-{}-{}.bin", motion, stamp, k);
  } else if (std::filesystem::exists(path)) {
    throw refused(refusal_kind::usage, fmt::format("the backup {} exists: a backup never replaces a file", path));
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(old.data()), static_cast<std::streamsize>(old.size()));
  out.flush();
  if (!out)
    throw refused(
        refusal_kind::usage,
        fmt::format("cannot write the backup {}: {} (nothing was written to the board)", path, std::strerror(errno)),
        "name another place for the backup");
  return path;
}

std::vector<std::uint8_t> read_backup_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw refused(refusal_kind::usage, fmt::format("FILE: {} cannot be read ({})", path, std::strerror(errno)));
  std::vector<std::uint8_t> b(8193);  // a slot holds at most 2 KiB: more than 8 KiB is no backup of one
  in.read(reinterpret_cast<char*>(b.data()), static_cast<std::streamsize>(b.size()));
  b.resize(static_cast<std::size_t>(in.gcount()));
  return b;
}

mo::slot slot_for(const rom_layout& layout, long long n) {
  const auto where = n >= 1 ? mo::slot_of(layout, static_cast<unsigned>(n)) : std::nullopt;
  if (!where || n > layout.motion_count)
    throw refused(refusal_kind::usage,
                  fmt::format("N: {} is outside 1..{} ({} layout)", n, layout.motion_count, layout.name));
  return *where;
}

std::vector<std::uint8_t> read_rom(link& l, std::uint32_t at, std::size_t size, std::string_view label) {
  rcb4::ops::read_memory op(memory::rom, at, size);
  std::size_t done = 0;
  while (auto c = op.next()) {
    op.on_reply(l.exchange(*c));
    l.progress(label, done = std::min(size, done + rcb4::ops::max_read), size);
  }
  if (op.error() != errc{}) l.failed(op.error());
  return op.value();
}

std::size_t code_size(const mo::listing& code) {
  if (code.code.empty()) return 0;
  return code.code.back().address + code.code.back().bytes.size() - code.where.address.value();
}

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

namespace {
/** The board's output period (config bits 4-5). */
output_period board_period(link& l) { return run(l, rcb4::ops::read_config{}).period; }
}  // namespace

push_report push_motion(link& l, const model& robot, const rom_layout& layout, unsigned n, const push_source& src,
                        const backup_sink& backup, bool dry_run) {
  const auto where = slot_for(layout, n);
  push_report r;
  r.motion = n;
  r.address = where.address.value();
  r.layout = layout.name;
  r.dry_run = dry_run;
  mo::listing code;
  if (!src.document) {  // a backup's bytes, as they are
    const auto& b = src.bin;
    if (b.empty() || b.size() > where.size)
      throw refused(refusal_kind::usage,
                    fmt::format("FILE: {} holds {} bytes; a slot takes 1..{}", src.name, b.size(), where.size));
    code = mo::disassemble(b, where);
    if (b[0] != 0xFF && !code.problems.empty())
      throw refused(refusal_kind::usage, fmt::format("{} is not motion code for 0x{:06X}: {}", src.name,
                                                     where.address.value(), code.problems.front()));
    r.summary = b[0] == 0xFF ? "an empty slot" : fmt::format("{} reachable frames", code.code.size());
    r.bytes = b;
    if (b[0] != 0xFF) check_calls(l, layout, code, nullptr, {}, "written");
  } else {
    const auto& d = *src.document;
    const auto c = to_program(d, robot, layout, board_period(l), src.rescale);
    if (!ok(c))
      throw refused(refusal_kind::usage,
                    fmt::format("{}: {} (nothing was written)", src.name, std::get<problem>(c).message));
    const auto& cm = std::get<compiled_motion>(c);
    // A call of its own slot is recursion, refused as any call loop is (the assembler refuses it
    // too, but as a file's mistake: it is the board's stack that cannot take it).
    for (std::size_t i = 0; i < cm.program.steps.size(); ++i)
      if (const auto* call = std::get_if<mo::call_motion>(&cm.program.steps[i]); call && call->address == where.address)
        throw refused(refusal_kind::board,
                      fmt::format("step {}{} calls motion {}, itself: its calls come back round, every pass taking "
                                  "another level of the board's {}-deep call stack until the board stops (nothing "
                                  "was written)",
                                  i + 1, i < d.where.size() ? fmt::format(" ({})", d.where[i]) : "", n, stack_depth),
                      "a motion that repeats itself loops with goto, not call");
    auto b = mo::assemble(cm.program, where);
    if (!mo::ok(b))
      throw refused(refusal_kind::usage,
                    fmt::format("{}: {} (nothing was written)", src.name, std::get<mo::failure>(b).message));
    r.bytes = std::move(std::get<std::vector<std::uint8_t>>(b));
    r.notes = cm.notes;
    code = mo::disassemble(r.bytes, where);
    check_calls(l, layout, code, &cm.program, d.where, "written");
    require_servo_slots(l, robot, cm.program, "written");
    std::size_t poses = 0;
    for (const auto& st : cm.program.steps)
      if (std::holds_alternative<mo::pose>(st)) ++poses;
    const auto steps = cm.program.steps.size();
    r.summary = fmt::format("{} step{}, {} pose{} ({})", steps, steps == 1 ? "" : "s", poses, poses == 1 ? "" : "s",
                            play_time_text(mo::play_time(cm.program), cm.period));
  }
  if (dry_run) return r;
  const auto old = read_rom(l, r.address, where.size, fmt::format("backing up motion {}", n));
  require_writable(l, layout, n, old, "written");
  if (std::equal(r.bytes.begin(), r.bytes.end(), old.begin())) {
    r.unchanged = true;
  } else {
    r.backup = backup(n, old);
    write_rom_checked(l, r.address, r.bytes, fmt::format("writing motion {}", n), n, r.backup);
  }
  // A motion file names its slot (the board keeps no names): the name goes with the code, and a
  // file without one leaves the slot unnamed. A backup's bytes keep whatever name the slot had.
  if (src.document) {
    r.name = src.document->name;
    try {
      set_slot_name(robot.name(), n, r.name);
    } catch (const refused& e) {
      r.notes.push_back(fmt::format("the slot's name was not kept: {}", e.what()));
    }
  }
  return r;
}

erase_report erase_motion(link& l, const rom_layout& layout, unsigned n, const backup_sink& backup,
                          const std::string& robot) {
  const auto where = slot_for(layout, n);
  erase_report r{n, where.address.value(), where.size, false, {}, {}};
  const auto forget = [&] {
    if (robot.empty()) return;
    try {
      set_slot_name(robot, n, {});
    } catch (const refused&) {  // an unreadable names file: the erase itself is done
    }
  };
  const auto old = read_rom(l, r.address, where.size, fmt::format("backing up motion {}", n));
  require_writable(l, layout, n, old, "erased");
  if (std::all_of(old.begin(), old.end(), [](std::uint8_t b) { return b == 0xFF; })) {
    r.unchanged = true;
    forget();
    return r;
  }
  r.backup = backup(n, old);
  const std::vector<std::uint8_t> erased(where.size, 0xFF);
  write_rom_checked(l, r.address, erased, fmt::format("erasing motion {}", n), n, r.backup);
  forget();
  // The motions that call it now stop the board's program where they do: said, so a play of
  // them is not a surprise (plays and buttons refuse them from now on).
  rom_code rom(l, layout, nullptr);
  for (unsigned k = 1; k <= layout.motion_count; ++k) {
    const std::uint32_t a = layout.motion_base.value() + (k - 1) * layout.slot_size;
    if (k == n) continue;
    l.progress("looking for motions that call it", k, layout.motion_count);
    if (run(l, rcb4::ops::read_memory(rcb4::ops::memory::rom, a, 1))[0] == 0xFF) continue;  // empty
    const auto& calls = rom.at(a).calls;
    if (std::find(calls.begin(), calls.end(), r.address) != calls.end()) r.callers.push_back(k);
  }
  return r;
}

pull_report pull_motion(link& l, const model& robot, const rom_layout& layout, unsigned n) {
  const auto where = slot_for(layout, n);
  pull_report r;
  r.motion = n;
  r.address = where.address.value();
  r.layout = layout.name;
  const auto bytes = read_rom(l, r.address, where.size, fmt::format("reading motion {}", n));
  if (bytes.empty() || bytes[0] == 0xFF)
    throw refused(refusal_kind::board, fmt::format("motion {} (0x{:06X}) is empty: erased ROM", n, r.address),
                  "rcb4 motion list shows the used slots");
  const auto code = mo::disassemble(bytes, where);
  if (!code.problems.empty())
    throw refused(refusal_kind::board, fmt::format("motion {}: {}", n, code.problems.front()),
                  fmt::format("rcb4 motion show {} lists the code the board reaches", n));
  r.bytes = code_size(code);
  const auto p = mo::lift(code);
  if (!mo::ok(p))
    throw refused(
        refusal_kind::board,
        fmt::format("motion {} is code a motion file cannot say: {}", n, std::get<mo::failure>(p).message),
        fmt::format("rcb4 motion show {} lists it; rcb4 read rom 0x{:06X} {} saves its bytes", n, r.address, r.bytes));
  r.period = board_period(l);
  r.document = from_program(std::get<mo::program>(p), robot, layout, r.period);
  r.plays = play_time_text(mo::play_time(std::get<mo::program>(p)), r.period);
  try {
    r.document.name = slot_name(robot, n, load_slot_names(robot.name()));
  } catch (const refused&) {  // an unreadable names file: the profile's name
    r.document.name = std::string(robot.motion(n));
  }
  // Checked as a push will check it: a pose beyond a limit pulls, but does not push back as it is.
  const auto again = to_program(r.document, robot, layout, r.period);
  if (!ok(again)) r.beyond = std::get<problem>(again).message;
  for (const auto& st : r.document.steps)
    if (const auto* mp = std::get_if<motion_pose>(&st)) ++r.poses, r.pose_ms += mp->time.count();
  return r;
}

}  // namespace rcb4::robot::services
