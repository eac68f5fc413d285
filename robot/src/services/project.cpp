// rcb4 — robot services: HTH4 projects on the board (see rcb4/robot/services/project.hpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/ops/memory.hpp>
#include <rcb4/ops/motion.hpp>
#include <rcb4/ops/system.hpp>
#include <rcb4/robot/services/motion_slots.hpp>
#include <rcb4/robot/services/project.hpp>
#include <rcb4/robot/services/slot_names.hpp>

#include <fmt/format.h>

#include <ctime>

namespace rcb4::robot::services {

project_import_report import_project(link& l, const rom_layout& layout, const model& robot, const hth4::project& p,
                                     const project_import_options& opt, const rom_sink& save) {
  if (&layout == &hth4_1_3)
    throw refused(refusal_kind::usage,
                  "the board's ROM has HeartToHeart4 1.3's layout (50 slots of 4864 bytes): a 2.x project's 120 "
                  "slots do not fit it (nothing written)",
                  "write the board once with HTH4 2.x, or give --layout if the ROM was told wrongly");
  project_import_report r;
  r.relocated = layout.motion_base.value() != p.layout().motion_base.value();
  const auto rom = backup_rom(l, "reading ROM");
  try {
    r.plan = hth4::plan_import(rom, p, {&layout, opt.keep_baud, true});
  } catch (const profile_error& e) {
    throw refused(refusal_kind::usage, std::string(e.what()) + " (nothing written)");
  }
  if (opt.dry_run) {
    // Say now what the real import will refuse (restore_rom's rule), rather than after the read.
    const auto st = run(l, ops::read_motion_state{});
    if (st.running || st.suspended)
      r.plan.not_written.insert(
          r.plan.not_written.begin(),
          std::string("NOTHING yet: ") +
              (st.motion ? "motion " + std::to_string(*st.motion) : std::string("the program")) +
              (st.running ? " is running" : " is stopped part way") +
              ", and the import is refused until it ends (rcb4 motion wait) or the program starts afresh");
    return r;
  }
  try {
    r.written = restore_rom(l, r.plan.image, save, false, rom);  // the ROM read above: not read twice
  } catch (refused& e) {
    if (e.hint.ends_with("then restore")) e.hint.replace(e.hint.size() - 7, 7, "import");
    throw;
  }
  // The trims act at once too, as `trim set --persist` makes them (RAM +2 of each block).
  for (const auto& [ics, counts] : r.plan.trims) {
    const auto at = static_cast<std::uint16_t>(ram::user_area.value() + 20 * ics + 2);
    const auto u = static_cast<std::uint16_t>(counts);
    const std::uint8_t bytes[] = {static_cast<std::uint8_t>(u), static_cast<std::uint8_t>(u >> 8)};
    run(l, ops::write_memory(ops::memory::ram, at, bytes));
    const auto back = run(l, ops::read_memory(ops::memory::ram, at, 2));
    if ((back[0] | (back[1] << 8)) != u)
      throw refused(refusal_kind::board,
                    fmt::format("ICS {}: trim {:+d} written to RAM, the board reads back 0x{:02X}{:02X}", ics, counts,
                                back[1], back[0]));
    ++r.ram_trims;
  }
  // The project's motions were made for its output period: the board runs at it from now on, not
  // only after a power cycle (a motion of 15 ms frames played at 10 ms is half as fast again).
  const auto period = config_word::decode(p.config).period;
  if (run(l, ops::read_config{}).period != period) {
    run(l, ops::update_config([period](config_word& c) { c.period = period; }));
    r.period_set = true;
  }
  // The motions' names, as a pushed file's name: names its slot (a name HTH4 gives an unused slot is its key).
  for (const auto& m : p.motions) {
    if (m.frames.empty()) continue;
    std::string name = m.name.substr(0, 64);
    if (name.find_first_of("\r\n") != std::string::npos) name.clear();
    const auto where = slot_for(layout, static_cast<long long>(m.number) + 1);
    set_slot_name(robot.name(), m.number + 1, name,
                  code_fingerprint(std::span(r.plan.image).subspan(where.address.value(), where.size)));
    r.names += !name.empty();
  }
  return r;
}

hth4::export_result export_project(link& l, const rom_layout& layout, const model& robot) {
  if (&layout == &hth4_1_3)
    throw refused(refusal_kind::usage, "the board's ROM has HeartToHeart4 1.3's layout: a .h4p holds 2.x's 120 slots");
  const auto rom = backup_rom(l, "reading ROM");
  std::vector<std::string> names(hth4::servo_count);
  for (const auto& j : robot.joints())
    if (j.ics.value() < names.size()) names[j.ics.value()] = j.name;
  std::vector<std::string> slots(hth4::motion_count);
  for (const auto& [n, label] : load_slot_labels(robot.name()))  // only a name given to the code each slot holds
    if (n >= 1 && n <= slots.size()) {
      const auto where = slot_for(layout, n);
      if (label.code && *label.code == code_fingerprint(std::span(rom).subspan(where.address.value(), where.size)))
        slots[n - 1] = label.name;
    }
  const auto now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  char date[40];
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%S.0000000%z", &tm);
  std::string stamp(date);  // ISO 8601's offset has a colon: +0100 -> +01:00 (as HTH4 writes it, §2.2)
  if (const auto n = stamp.size(); n > 4 && (stamp[n - 5] == '+' || stamp[n - 5] == '-'))
    stamp = fmt::format("{}:{}", std::string_view(stamp).substr(0, n - 2), std::string_view(stamp).substr(n - 2));
  try {
    return hth4::project_from_rom(rom, layout, names, slots, stamp);
  } catch (const profile_error& e) {
    throw refused(refusal_kind::board, std::string("the board's ROM does not make a project: ") + e.what());
  }
}

}  // namespace rcb4::robot::services
