// rcb4 — robot services: an ICS servo's EEPROM: verified reads, writes read back, set and restore (ics.md §4-§5) (see
// rcb4/robot/services/ics.hpp). SPDX-License-Identifier: BSL-1.0
#include "ics_line.hpp"

#include <vector>

namespace rcb4::robot::services {
using namespace ics_detail;

ics::eeprom_image ics_servo::read_eeprom_once() {
  auto e = ask(ics::read_eeprom(id_), o_.timeout + 100ms, "EEPROM read");
  if (e.get(field::id) != id_.value())
    throw refused(refusal_kind::board,
                  fmt::format("ICS servo {}: its EEPROM's ID field says {}: not a consistent image, nothing used",
                              id_.value(), e.get(field::id)));
  if (e.get(field::baud) < 0)
    throw refused(refusal_kind::board,
                  fmt::format("ICS servo {}: its EEPROM's baud code is {} (10, 1 or 0 expected): nothing used",
                              id_.value(), -e.get(field::baud)));
  return e;
}

namespace {
/** The bytes and fields where @p a and @p b differ, for a message. */
std::string image_difference(const ics::eeprom_image& a, const ics::eeprom_image& b) {
  std::string fields, bytes;
  for (const auto& i : ics::fields)
    if (a.get(i.f) != b.get(i.f))
      fields += fmt::format("{}{} {} / {}", fields.empty() ? "" : ", ", i.name, a.get(i.f), b.get(i.f));
  for (std::size_t n = 0; n < ics::eeprom_image::size; ++n)
    if (a.bytes()[n] != b.bytes()[n])
      bytes += fmt::format("{}byte {}: {:X} / {:X}", bytes.empty() ? "" : ", ", n + 1, a.bytes()[n], b.bytes()[n]);
  return fields.empty() ? bytes : fmt::format("{} ({})", fields, bytes);
}
}  // namespace

ics::eeprom_image ics_servo::read_eeprom() {
  // An ICS image has no checksum (ics.md §4.1): a byte the UART flagged as a parity error reaches
  // the program as 0x00 (termios INPCK without PARMRK), a valid nibble. Only two reads that agree
  // are trusted: a wrong byte would otherwise be written back, and into the backup, as a setting.
  constexpr int reads =
      4;  // two that agree within four: one garbled read is retried, a line that garbles every read is refused
  auto last = read_eeprom_once();
  std::vector<ics::eeprom_image> seen{last};
  for (int n = 1; n < reads; ++n) {
    if (n > 1 && o_.interrupted && o_.interrupted()) break;  // Ctrl-C: stop asking, nothing is trusted
    const auto again = read_eeprom_once();
    for (const auto& earlier : seen)
      if (earlier == again) return again;
    seen.push_back(again);
    last = again;
  }
  throw refused(
      refusal_kind::board,
      fmt::format("ICS servo {}: {} EEPROM reads never agreed twice (the line garbles bytes): nothing used; "
                  "the first two differ in {}\n  read 1: {}\n  read 2: {}",
                  id_.value(), seen.size(), image_difference(seen[0], seen[1]), hex(seen[0].bytes()),
                  hex(seen[1].bytes())),
      "check the cable and the servo's supply (a noisy line garbles bytes); a garbled image is never written back");
}

ics_eeprom_report ics_servo::write_image(const ics::eeprom_image& before, ics::eeprom_image want,
                                         const ics_backup& save, bool dry_run) {
  // The rules of ics.md §5.3: check mark, factory bytes, ID and the baud byte's high nibble as read.
  want = want.with_factory_of(before);
  want.set_id(id_);
  (void)want.set_raw(1, before.bytes()[0]);
  (void)want.set_raw(2, before.bytes()[1]);
  (void)want.set_raw(27, before.bytes()[26]);
  // Byte 16: bit 2 (fixed, ics.md §4.3) and bit 1 (FREE, a status) as read; PWMINH and reverse as asked.
  (void)want.set_raw(16, static_cast<std::uint8_t>((want.bytes()[15] & 0x9u) | (before.bytes()[15] & 0x6u)));
  ics_eeprom_report r;
  r.before = before;
  for (const auto& i : ics::fields)
    if (want.get(i.f) != before.get(i.f) || want.stored_odd(i.f) != before.stored_odd(i.f))
      r.changed.emplace_back(i.f, want.get(i.f));
  // A smaller temperature limit lets the servo run hotter (ics.md §3: 30 is about 100 °C on the
  // ICS 3.5 manual's scale; KONDO ships 70-75): a limit lowered below 60 is said, whoever asked.
  if (const long t = want.get(field::temperature_limit); t < 60 && t < before.get(field::temperature_limit))
    r.notes.push_back(
        fmt::format("temperature_limit {}: a smaller number lets the servo run hotter (75 is about 70 "
                    "°C, 30 about 100 °C on the ICS 3.5 manual's scale; ics.md §3): its protection "
                    "acts late; KONDO ships 70-75",
                    t));
  if (want == before || dry_run) {
    r.after = want;
    return r;
  }
  r.backup = save(before);
  const auto old_baud = l_.baud();
  try {
    (void)ask(ics::write_eeprom(id_, want), std::max(o_.write_timeout, o_.timeout), "EEPROM write");
  } catch (refused& e) {
    throw refused(e.kind, fmt::format("{}; the servo may or may not have taken the new image", e.what()),
                  fmt::format("read it with `rcb4 ics eeprom show`; the old image is in {} (`rcb4 ics eeprom "
                              "restore {}`)",
                              r.backup, r.backup),
                  r.backup);
  } catch (
      const std::exception& e) {  // the line failed (unplugged): say what may have happened, and where the backup is
    throw refused(
        refusal_kind::line,
        fmt::format("the line failed during the EEPROM write ({}); the servo may or may not have taken the "
                    "new image",
                    line_text(e)),
        fmt::format("the old image is in {} (`rcb4 ics eeprom restore {}` once the servo answers)", r.backup, r.backup),
        r.backup, line_code(e));
  }
  r.written = true;
  if (want.get(field::slave) != 0) {  // it no longer answers: nothing can be read back
    r.after = want;
    r.notes.push_back(
        "the servo is a slave now: it never answers; only the other servo of its back-to-back pair "
        "(same ID, reverse) answers for it");
    return r;
  }
  const auto new_baud = static_cast<std::uint32_t>(want.get(field::baud));
  if (new_baud != old_baud) {
    l_.set_baud(new_baud);
    r.notes.push_back(fmt::format(
        "the servo now talks at {} baud (was {}): rcb4 finds the new rate by itself (--baud {} skips the search); "
        "an RCB-4 reaches its servos at its own ICS rate (`rcb4 config set ics-baud={} --persist`): change both "
        "together",
        new_baud, old_baud, new_baud, new_baud));
  }
  try {
    r.after = read_eeprom_once();  // compared with what was written below: one read is enough
  } catch (refused& e) {
    throw refused(e.kind, fmt::format("the EEPROM was written, but reading it back failed: {}", e.what()),
                  fmt::format("the old image is in {}", r.backup), r.backup);
  } catch (const std::exception& e) {
    throw refused(refusal_kind::line,
                  fmt::format("the EEPROM was written, but the line failed reading it back ({})", line_text(e)),
                  fmt::format("the old image is in {}", r.backup), r.backup, line_code(e));
  }
  if (r.after != want) {
    std::string diff;
    for (const auto& i : ics::fields)
      if (r.after.get(i.f) != want.get(i.f))
        diff += fmt::format(" {} {} not {};", i.name, r.after.get(i.f), want.get(i.f));
    for (std::size_t n = 0; n < ics::eeprom_image::size; ++n)
      if (r.after.bytes()[n] != want.bytes()[n])
        diff += fmt::format(" byte {}: {:X} not {:X};", n + 1, r.after.bytes()[n], want.bytes()[n]);
    throw refused(refusal_kind::board,
                  fmt::format("ICS servo {}: the EEPROM read back differs from what was written:{}", id_.value(), diff),
                  fmt::format("the old image is in {}", r.backup), r.backup);
  }
  r.verified = true;
  return r;
}

namespace {
/** Refuses an image that would make the servo stop answering, unless @p force. */
void check_silence(const ics::eeprom_image& before, const ics::eeprom_image& want, bool force) {
  if (force || want.get(field::slave) == 0 || before.get(field::slave) != 0) return;
  throw refused(refusal_kind::usage,
                "slave=on makes the servo never answer again: no tool could read or change it alone (it is for the "
                "second servo of a back-to-back pair); nothing written",
                "--force writes it anyway");
}
}  // namespace

ics_eeprom_report ics_servo::set_fields(const std::vector<std::pair<ics::field, long>>& changes, const ics_backup& save,
                                        bool force, bool dry_run) {
  if (changes.empty()) throw refused(refusal_kind::usage, "nothing to set: give FIELD=VALUE");
  for (std::size_t i = 0; i < changes.size(); ++i) {
    const auto& inf = ics::info(changes[i].first);
    for (std::size_t k = 0; k < i; ++k)
      if (changes[k].first == changes[i].first)
        throw refused(refusal_kind::usage, fmt::format("{} is given twice", inf.name));
    ics::eeprom_image probe;
    if (!inf.writable || !probe.set(changes[i].first, changes[i].second))
      throw refused(refusal_kind::usage,
                    fmt::format("{}={}: out of range {}..{}", inf.name, changes[i].second, inf.min, inf.max));
  }
  const auto before = read_eeprom();
  auto want = before;
  for (const auto& [f, v] : changes)
    if (want.get(f) != v || want.stored_odd(f)) (void)want.set(f, v);  // a field that holds the value keeps its bytes
  check_silence(before, want, force);
  auto r = write_image(before, want, save, dry_run);
  if (want.get(field::dead_band) > 5 && want.get(field::dead_band) != before.get(field::dead_band))
    r.notes.push_back("KONDO's manual gives the dead band as 0-5 in one place and 0-10 in another: above 5 is untried");
  return r;
}

ics_eeprom_report ics_servo::restore(const ics::eeprom_image& image, bool force, const ics_backup& save, bool dry_run) {
  const auto before = read_eeprom();
  if (!before.same_unit(image) && !force)
    throw refused(refusal_kind::board,
                  fmt::format("the backup comes from another servo: its factory-correction bytes (25-26, 33-50, "
                              "55-56) differ from ICS servo {}'s; nothing written",
                              id_.value()),
                  "--force writes its settings but keeps this servo's own factory bytes");
  // A backup is checked like `set`: no field beyond rcb4's ranges, no stretch stored odd, unless the
  // servo holds that value now or --force (another tool can write such values; the user's own
  // backup of such a servo must go back byte for byte: it is then written as it is, and said).
  std::vector<std::string> beyond;
  for (const auto& i : ics::fields) {
    if (!i.writable || i.nibbles == 0) continue;
    const long v = image.get(i.f);
    if (v == before.get(i.f) && image.stored_odd(i.f) == before.stored_odd(i.f)) continue;
    ics::eeprom_image probe;
    if (!probe.set(i.f, v))
      beyond.push_back(i.f == field::baud ? fmt::format("baud code {} (10, 1 or 0 expected)", -v)
                                          : fmt::format("{} {} (rcb4's range {}..{})", i.name, v, i.min, i.max));
    else if (image.stored_odd(i.f))
      beyond.push_back(fmt::format("{} stored odd (0x{:02X}: {}.5, which no ICS command writes)", i.name,
                                   image.bytes()[i.first - 1u] * 16u + image.bytes()[i.first], v));
  }
  if (!beyond.empty() && image.get(field::baud) < 0)
    throw refused(refusal_kind::usage,
                  fmt::format("the backup's baud code is {} (10, 1 or 0 expected): the servo would talk at no rate "
                              "anyone can reach; nothing written",
                              -image.get(field::baud)));
  if (!beyond.empty() && !force) {
    std::string list;
    for (const auto& b : beyond) list += (list.empty() ? "" : "; ") + b;
    throw refused(refusal_kind::usage,
                  fmt::format("the backup holds values outside rcb4's documented ranges: {}; nothing written", list),
                  "written by another tool, or a damaged file: `rcb4 ics eeprom show FILE` shows every field; "
                  "--force writes it as it is");
  }
  check_silence(before, image, force);
  auto want = image;
  const bool stranger = !before.same_unit(image);
  if (stranger && want.get(field::user_offset) != before.get(field::user_offset))
    (void)want.set(field::user_offset, before.get(field::user_offset));  // factory-adjusted for each unit
  auto r = write_image(before, want, save, dry_run);
  if (stranger && image.get(field::user_offset) != before.get(field::user_offset))
    r.notes.push_back(
        fmt::format("this servo keeps its own user_offset {} (the backup's {}: set per unit at the "
                    "factory); `rcb4 ics set user_offset=N` changes it",
                    before.get(field::user_offset), image.get(field::user_offset)));
  if (image.get(field::id) != id_.value())
    r.notes.push_back(
        fmt::format("the backup was taken from ID {}: the servo keeps ID {} (`rcb4 ics id set` changes it)",
                    image.get(field::id), id_.value()));
  if (!before.same_unit(image))
    r.notes.push_back("the backup is another servo's: its factory bytes were not written, this servo's were kept");
  for (const auto& b : beyond)
    r.notes.push_back(fmt::format("--force: written as the backup holds it, outside rcb4's ranges: {}", b));
  return r;
}

}  // namespace rcb4::robot::services
