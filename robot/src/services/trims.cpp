// rcb4 — robot services: trims (see rcb4/robot/services/trims.hpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/ops/memory.hpp>
#include <rcb4/robot/services/trims.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <system_error>

namespace rcb4::robot::services {
namespace {

using rcb4::ops::memory;

std::int16_t word_at(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::int16_t>(static_cast<std::uint16_t>(b[at] | (b[at + 1] << 8)));
}

}  // namespace

std::vector<trim_entry> read_trims(link& l, const model& robot, const std::vector<const joint*>& joints) {
  const auto map = run(l, locate_joints(robot));
  std::vector<trim_entry> out;
  for (const auto& j : robot.joints()) {
    if (!joints.empty() && std::find(joints.begin(), joints.end(), &j) == joints.end()) continue;
    trim_entry e;
    e.j = &j;
    if (const auto block = map.block_of(j)) {
      e.allocated = true;
      const auto at = static_cast<std::uint16_t>(*block + 2u);
      e.ram = word_at(run(l, rcb4::ops::read_memory(memory::ram, at, 2)), 0);
      // The servo image covers the user area only (protocol.md §8): a block elsewhere has no ROM copy.
      if (at >= rcb4::ram::user_area.value()) {
        // Erased ROM (0xFFFF) holds no trim: power-on loads 0 for it.
        const auto w = word_at(run(l, rcb4::ops::read_memory(memory::rom, hth4_rom::servo_image_of(at).value(), 2)), 0);
        e.rom = w == -1 ? std::int16_t{0} : w;
      }
    }
    out.push_back(e);
  }
  return out;
}

trims_report set_trims(link& l, const model& robot, const std::vector<std::pair<std::string, double>>& items,
                       bool persistent) {
  std::vector<joint_trim> trims;
  for (const auto& [name, degrees] : items) {
    const auto* j = robot.find(name);
    if (!j) throw refused(refusal_kind::usage, fmt::format("no joint is called '{}' (nothing written)", name));
    if (std::any_of(trims.begin(), trims.end(), [&](const joint_trim& x) { return x.j == j; }))
      throw refused(refusal_kind::usage, fmt::format("{} is given twice (nothing written)", name));
    auto t = trim_of(*j, degrees);
    if (!ok(t)) throw refused(refusal_kind::limit, std::get<problem>(t).message + " (nothing written)");
    trims.push_back(std::get<joint_trim>(t));
  }
  if (trims.empty()) throw refused(refusal_kind::usage, "no trim given (nothing written)");
  write_trims op(trims, persistent);
  try {
    while (auto c = op.next()) op.on_reply(l.exchange(*c));
  } catch (const std::system_error& e) {
    if (op.in_ram() == 0) throw;
    // Some writes landed before the failure: say which, so nobody believes nothing changed.
    const auto first = [&](std::size_t n) {
      std::vector<std::string> out;
      for (std::size_t i = 0; i < n; ++i) out.push_back(fmt::format("{} {:+d}", trims[i].j->name, trims[i].counts));
      return out.empty() ? std::string("none") : fmt::format("{}", fmt::join(out, ", "));
    };
    throw refused(refusal_kind::line,
                  fmt::format("{} (already written: RAM {}{})", e.what(), first(op.in_ram()),
                              persistent ? "; ROM " + first(op.in_rom()) : std::string()),
                  {}, {}, e.code());
  }
  if (op.error() == errc::servo_not_allocated && op.unallocated()) {
    const auto* j = op.unallocated();
    throw refused(
        refusal_kind::board,
        fmt::format("the board has no servo allocated for {} (ICS {}): nothing written", j->name, j->ics.value()),
        fmt::format("is this a {}? rcb4 scan shows the board's slots", robot.name()));
  }
  if (op.error() != errc{}) l.failed(op.error());
  // Read back: a board that acknowledged and kept something else is a failure, not a success.
  std::vector<const joint*> js;
  for (const auto& t : trims) js.push_back(t.j);
  for (const auto& e : read_trims(l, robot, js)) {
    const auto& t = *std::find_if(trims.begin(), trims.end(), [&](const joint_trim& x) { return x.j == e.j; });
    // (A trim of -1 count kept in ROM is 0xFFFF, erased ROM: it reads back, and loads, as 0.)
    if (e.ram != t.counts || (persistent && e.rom && *e.rom != t.counts && t.counts != -1))
      throw refused(refusal_kind::board,
                    fmt::format("{}: trim {:+d} written, but the board reads back {:+d} (RAM){}", e.j->name, t.counts,
                                e.ram, e.rom ? fmt::format(", {:+d} (ROM)", *e.rom) : std::string()));
  }
  return {std::move(trims), persistent};
}

ics_trims_report set_ics_trims(link& l, const std::vector<std::pair<unsigned, std::int16_t>>& trims, bool persistent) {
  std::vector<unsigned> seen;
  for (const auto& [ics, counts] : trims) {
    if (ics >= 36)
      throw refused(refusal_kind::usage, fmt::format("ICS {} does not exist (0..35; nothing written)", ics));
    if (std::find(seen.begin(), seen.end(), ics) != seen.end())
      throw refused(refusal_kind::usage, fmt::format("ICS {} is given twice (nothing written)", ics));
    if (counts < -4000 || counts > 4000)
      throw refused(
          refusal_kind::limit,
          fmt::format("ICS {}: a trim of {:+d} counts ({:+.1f} deg) is beyond a servo's travel (+-4000 counts, "
                      "135 deg; nothing written)",
                      ics, counts, counts * 135.0 / 4000.0));
    seen.push_back(ics);
  }
  const auto table = run(l, rcb4::ops::read_memory(memory::ram, rcb4::ram::ics_allocation.value(), 72));
  ics_trims_report r;
  r.persistent = persistent;
  try {
    for (const auto& [ics, counts] : trims) {
      const auto block = static_cast<std::uint16_t>(table[2 * ics] | (table[2 * ics + 1] << 8));
      if (block == rcb4::ram::no_allocation || block < rcb4::ram::user_area.value()) {
        r.skipped.push_back({ics, counts});
        continue;
      }
      const auto at = static_cast<std::uint16_t>(block + 2);
      const auto u = static_cast<std::uint16_t>(counts);
      const std::uint8_t bytes[] = {static_cast<std::uint8_t>(u), static_cast<std::uint8_t>(u >> 8)};
      run(l, rcb4::ops::write_memory(memory::ram, at, bytes));
      if (persistent) run(l, rcb4::ops::write_memory(memory::rom, hth4_rom::servo_image_of(at).value(), bytes));
      const auto ram = word_at(run(l, rcb4::ops::read_memory(memory::ram, at, 2)), 0);
      const auto rom =
          persistent ? word_at(run(l, rcb4::ops::read_memory(memory::rom, hth4_rom::servo_image_of(at).value(), 2)), 0)
                     : counts;
      if (ram != counts || rom != counts)
        throw refused(refusal_kind::board,
                      fmt::format("ICS {}: trim {:+d} written, but the board reads back {:+d} (RAM){}", ics, counts,
                                  ram, persistent ? fmt::format(", {:+d} (ROM)", rom) : std::string()));
      r.written.push_back({ics, counts});
    }
  } catch (const std::system_error& e) {
    if (r.written.empty()) throw;
    std::vector<std::string> done;
    for (const auto& [ics, counts] : r.written) done.push_back(fmt::format("ICS {} {:+d}", ics, counts));
    throw refused(refusal_kind::line, fmt::format("{} (already written: {})", e.what(), fmt::join(done, ", ")), {}, {},
                  e.code());
  }
  return r;
}

}  // namespace rcb4::robot::services
