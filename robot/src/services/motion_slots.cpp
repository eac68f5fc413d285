// rcb4 — robot services: the ROM's motion slots (see rcb4/robot/services/motion_slots.hpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/ops/memory.hpp>
#include <rcb4/ops/motion.hpp>
#include <rcb4/ops/system.hpp>
#include <rcb4/robot/services/motion_slots.hpp>
#include <rcb4/robot/services/slot_names.hpp>

#include "rom_code.hpp"
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
using detail::rom_code;
using detail::stack_depth;

using rcb4::ops::memory;

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
  // The slot as a listing reads it now: the new bytes over the old (the fingerprint its name keeps).
  auto after = old;
  std::copy(r.bytes.begin(), r.bytes.end(), after.begin());
  r.fingerprint = code_fingerprint(after);
  // A motion file names its slot (the board keeps no names): the name goes with the code, and a
  // file without one leaves the slot unnamed. A backup's bytes show the name given with that code, if any.
  if (src.document) {
    r.name = src.document->name;
    try {
      set_slot_name(robot.name(), n, r.name, r.fingerprint);
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
      set_slot_name(robot, n, {}, std::nullopt);
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
    r.document.name = slot_name(robot, n, load_slot_labels(robot.name()), bytes);
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
