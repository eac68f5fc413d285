// rcb4 — robot services: an ICS servo on its own line (ics.md §5). See rcb4/robot/services/ics.hpp.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/services/ics.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <iterator>
#include <system_error>
#include <type_traits>

namespace rcb4::robot::services {
namespace {

using namespace std::chrono_literals;
using ics::field;

constexpr std::uint32_t discovery_order[] = {115200, 1250000, 625000};  // a new servo runs at 115200 (ics.md §1)

std::string baud_list(std::span<const std::uint32_t> bauds) {
  std::string s;
  for (std::size_t i = 0; i < bauds.size(); ++i)
    s += (i == 0 ? "" : i + 1 == bauds.size() ? " or " : ", ") + std::to_string(bauds[i]);
  return s;
}

const char* sub_name(ics::sub s) {
  switch (s) {
    case ics::sub::eeprom: return "EEPROM";
    case ics::sub::stretch: return "stretch";
    case ics::sub::speed: return "speed";
    case ics::sub::current: return "current";
    case ics::sub::temperature: return "temperature";
    case ics::sub::position: return "position";
  }
  return "parameter";
}

std::string hex(std::span<const std::uint8_t> b) {
  std::string s;
  for (auto x : b) s += fmt::format("{}{:02X}", s.empty() ? "" : " ", x);
  return s;
}

const std::string hint_wiring =
    "check the adapter is in ICS mode (the Dual USB Adapter HS's LED red), the servo has its own supply and was "
    "powered after the adapter was opened, and its baud (--baud, or let rcb4 try all three)";

/** The error code of a line failure: a std::system_error's own, else an I/O error. */
std::error_code line_code(const std::exception& e) {
  if (const auto* se = dynamic_cast<const std::system_error*>(&e)) return se->code();
  return std::make_error_code(std::errc::io_error);
}

/** What `transact` should wait for: both directions' wire time, then the reply allowance. */
std::chrono::milliseconds wait_for(std::size_t bytes, std::uint32_t baud, std::chrono::milliseconds allowance) {
  return std::chrono::milliseconds(ics::wire_micros(bytes, baud) / 1000 + 1) + allowance;
}

}  // namespace

template <class Cmd>
typename Cmd::reply_type ics_servo::ask(const Cmd& c, std::chrono::milliseconds wait, const char* what) {
  const auto req = c.request();
  const std::size_t expect = req.size + Cmd::reply_size;
  std::string last;
  bool answered = false;
  // A write waits long for its answer (seconds): tried twice at most, not three times.
  const bool write = std::is_same_v<Cmd, ics::write_eeprom> || std::is_same_v<Cmd, ics::write_id>;
  const int tries = std::max(1, write ? std::min(o_.tries, 2) : o_.tries);
  int tried = 0;
  for (int attempt = 0; attempt < tries; ++attempt) {
    if (attempt > 0 && o_.interrupted && o_.interrupted()) break;  // Ctrl-C: no further try
    ++tried;
    const auto rx = l_.transact(req.view(), expect, wait_for(expect, l_.baud(), wait));
    const auto p = ics::parse_exchange(c, rx);
    if (p.ok() && rx.size() == p.consumed) return p.value;
    if (p.ok()) {
      last = fmt::format("{} bytes more than the reply came back ({}): another device answered too",
                         rx.size() - p.consumed, hex(std::span(rx).subspan(p.consumed)));
      answered = true;
    } else if (p.status == parse_status::error) {
      last = fmt::format("{} (received {})", rcb4::message(p.error), hex(rx));
      answered = true;
    } else if (rx.size() > req.size) {
      last = fmt::format("the reply stopped after {} of {} bytes (received {})", rx.size() - req.size, Cmd::reply_size,
                         hex(rx));
      answered = true;
    }
    l_.linger(std::min(wait, o_.timeout));  // let a late reply pass before the next frame (ics.md §1)
  }
  const auto who = fmt::format("ICS servo {} at {} baud", id_.value(), l_.baud());
  if (!answered)
    throw refused(refusal_kind::timeout,
                  fmt::format("{}: no answer to the {} ({} {} of {} ms)", who, what, tried,
                              tried == 1 ? "try" : "tries", wait.count()),
                  hint_wiring);
  throw refused(refusal_kind::board, fmt::format("{}: bad answer to the {}: {}", who, what, last),
                "one servo alone on the adapter, its own supply; a corrupt or garbled reply is never used");
}

ics_servo::ics_servo(ics_link& l, std::optional<ics::servo_id> id, std::optional<std::uint32_t> baud, ics_options o,
                     bool for_id_work)
    : l_(l), o_(o) {
  if (baud && !ics::baud_code(*baud))
    throw refused(refusal_kind::usage, fmt::format("--baud {}: an ICS line runs at 115200, 625000 or 1250000", *baud));
  std::vector<std::uint32_t> order;
  if (baud)
    order.push_back(*baud);
  else
    order.assign(std::begin(discovery_order), std::end(discovery_order));
  for (const auto b : order) {
    l_.set_baud(b);
    if (id) {
      id_ = *id;
      const auto saved = o_.tries;
      o_.tries = order.size() > 1 ? 1 : saved;
      try {
        (void)ask(ics::read_parameter::make(id_, ics::sub::stretch).value(), o_.timeout, "stretch read");
        o_.tries = saved;
        return;
      } catch (const refused& r) {
        o_.tries = saved;
        if (r.kind != refusal_kind::timeout) throw;
      }
      continue;
    }
    const ics::read_id c;
    const auto req = c.request();
    auto rx = l_.transact(req.view(), req.size + 1, wait_for(req.size + 1, b, o_.timeout));
    if (rx.size() <= req.size) {  // nothing at this rate: let a late answer pass before the next rate
      (void)l_.linger(o_.timeout);
      continue;
    }
    id_ = read_id(for_id_work);  // the full check: one clean answer, nothing after it
    return;
  }
  throw refused(refusal_kind::timeout,
                id ? fmt::format("ICS servo {} does not answer at {} baud", id->value(), baud_list(order))
                   : fmt::format("no ICS servo answers the ID read at {} baud", baud_list(order)),
                hint_wiring);
}

ics::servo_id ics_servo::read_id(bool for_id_write) {
  const ics::read_id c;
  const auto req = c.request();
  std::vector<std::uint8_t> rx;
  for (int attempt = 0; attempt < std::max(1, o_.tries); ++attempt) {
    rx = l_.transact(req.view(), req.size + 1, wait_for(req.size + 1, l_.baud(), o_.timeout));
    if (rx.size() > req.size) break;
  }
  // A second device answers late or garbled: within the first one's turnaround (an adapter's latency timer).
  const auto extra = l_.linger(std::clamp(o_.timeout / 4, std::chrono::milliseconds(5), std::chrono::milliseconds(50)));
  rx.insert(rx.end(), extra.begin(), extra.end());
  const auto p = ics::parse_exchange(c, rx);
  const auto where = fmt::format("the ID read (FF 00 00 00) at {} baud", l_.baud());
  if (p.status == parse_status::need_more && rx.size() <= req.size)
    throw refused(refusal_kind::timeout, fmt::format("no answer to {}", where), hint_wiring);
  const bool one_byte = rx.size() == req.size + 1 && p.error != errc::ics_line_echo_mismatch;
  if (!p.ok() && one_byte)
    throw refused(refusal_kind::board,
                  fmt::format("the answer to {} is {:02X}, not an ID reply (E0 + ID): a corrupt line, or no ICS servo",
                              where, rx.back()),
                  "one servo alone on the adapter, its own supply; a corrupt reply is never used");
  if (p.error == errc::ics_line_echo_mismatch)
    throw refused(refusal_kind::board,
                  fmt::format("the echo of {} differs from what was sent (received {}): a collision on the line, or a "
                              "port that is no ICS adapter (an adapter in ICS mode returns every byte sent)",
                              where, hex(rx)),
                  "one servo alone on an adapter in ICS mode");
  if (!p.ok() || rx.size() != p.consumed)
    throw refused(refusal_kind::board,
                  fmt::format("more than one device answers {} (received {}): the ID command talks to every "
                              "device on the line",
                              where, hex(rx)),
                  for_id_write ? "leave one servo alone on the adapter for ID work (docs/ics-servos.md)"
                               : "name the servo with --id N (`rcb4 ics scan` lists them)");
  return p.value;
}

ics::servo_id ics_servo::set_id(ics::servo_id id) {
  const auto alone = read_id(true);
  if (alone != id_)
    throw refused(
        refusal_kind::board,
        fmt::format("the one servo on the line answers as ID {}, not {}: nothing written", alone.value(), id_.value()));
  if (alone == id) return id_;  // already: nothing to write
  try {
    (void)ask(ics::write_id(id), std::max(o_.write_timeout, o_.timeout), "ID write");
  } catch (const refused& e) {
    if (e.kind != refusal_kind::timeout) throw;
    throw refused(
        e.kind, e.what(),
        fmt::format("the servo may hold ID {} already, or still {}: `rcb4 ics id` tells", id.value(), id_.value()));
  }
  const auto now = read_id(true);
  if (now != id)
    throw refused(
        refusal_kind::board,
        fmt::format("the ID write was answered, but the servo now answers as ID {}, not {}", now.value(), id.value()));
  id_ = id;
  return id_;
}

ics::eeprom_image ics_servo::read_eeprom() {
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
    if (want.get(i.f) != before.get(i.f)) r.changed.emplace_back(i.f, want.get(i.f));
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
                    e.what()),
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
    r.after = read_eeprom();
  } catch (refused& e) {
    throw refused(e.kind, fmt::format("the EEPROM was written, but reading it back failed: {}", e.what()),
                  fmt::format("the old image is in {}", r.backup), r.backup);
  } catch (const std::exception& e) {
    throw refused(refusal_kind::line,
                  fmt::format("the EEPROM was written, but the line failed reading it back ({})", e.what()),
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
    if (want.get(f) != v) (void)want.set(f, v);  // a field that holds the value keeps its bytes
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
  // A backup is checked like `set`: no field beyond its range unless the servo holds that value now.
  for (const auto& i : ics::fields) {
    if (!i.writable || i.nibbles == 0) continue;
    const long v = image.get(i.f);
    if (v == before.get(i.f)) continue;
    ics::eeprom_image probe;
    if (!probe.set(i.f, v))
      throw refused(refusal_kind::usage,
                    i.f == field::baud ? fmt::format("the backup's baud code is {} (10, 1 or 0 expected): a damaged "
                                                     "or hand-edited file; nothing written",
                                                     -v)
                                       : fmt::format("the backup's {} is {}, beyond {}..{}: a damaged or hand-edited "
                                                     "file; nothing written",
                                                     i.name, v, i.min, i.max));
  }
  for (const auto f : {field::stretch, field::stretch_1, field::stretch_2, field::stretch_3}) {
    const auto n = ics::info(f).first;  // stored doubled: an odd byte pair is no value a servo keeps
    if ((image.bytes()[n] & 1u) != 0 && image.bytes()[n] != before.bytes()[n])
      throw refused(refusal_kind::usage,
                    fmt::format("the backup's {} is stored odd (0x{:X}{:X}): a damaged or hand-edited file; nothing "
                                "written",
                                ics::info(f).name, image.bytes()[n - 1], image.bytes()[n]));
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
  return r;
}

std::uint16_t ics_servo::move(std::uint16_t counts) {
  const auto c = ics::set_position::make(id_, counts);
  if (!c)
    throw refused(refusal_kind::usage, fmt::format("position {}: out of range {}..{} (-135..135 degrees)", counts,
                                                   ics::position::min, ics::position::max));
  return ask(*c, o_.timeout, "position command");
}

std::uint16_t ics_servo::free() { return ask(ics::set_position::free(id_), o_.timeout, "free command"); }

std::uint16_t ics_servo::position() {
  try {
    const auto p = ask(ics::read_position(id_), o_.timeout, "position read (SC 5)");
    ics36_ = true;
    return p;
  } catch (const refused& r) {
    if (r.kind != refusal_kind::timeout || ics36_) throw;  // it answered SC 5 before: it stopped answering
    throw refused(refusal_kind::board,
                  fmt::format("ICS servo {} does not answer the ICS 3.6 position read (SC 5): an ICS 3.5 servo tells "
                              "its position only in reply to a move or a free",
                              id_.value()),
                  "`rcb4 ics position free` frees it and prints the angle");
  }
}

std::uint8_t ics_servo::read(ics::sub what) {
  const auto c = ics::read_parameter::make(id_, what);
  if (!c) throw refused(refusal_kind::usage, "read: stretch, speed, current or temperature");
  return ask(*c, o_.timeout, fmt::format("{} read", sub_name(what)).c_str());
}

std::uint8_t ics_servo::write(ics::sub what, long value) {
  const auto c = ics::write_parameter::make(id_, what, value);
  if (!c) {
    const auto r = ics::write_range(what);
    throw refused(refusal_kind::usage, fmt::format("{} {}: out of range {}..{}", sub_name(what), value, r.min, r.max));
  }
  return ask(*c, o_.timeout, fmt::format("{} write", sub_name(what)).c_str());
}

std::vector<ics_found> ics_scan(ics_link& l, std::span<const std::uint32_t> bauds, const ics_options& o,
                                const std::function<void(std::uint32_t)>& on_baud, std::optional<ics::servo_id> only) {
  std::vector<std::uint32_t> order(bauds.begin(), bauds.end());
  if (order.empty()) order.assign(std::begin(ics::bauds), std::end(ics::bauds));
  for (const auto b : order)
    if (!ics::baud_code(b))
      throw refused(refusal_kind::usage, fmt::format("baud {}: an ICS line runs at 115200, 625000 or 1250000", b));
  std::vector<ics_found> found;
  ics_options quick = o;
  quick.tries = 1;
  for (const auto b : order) {
    if (on_baud) on_baud(b);
    // Every device answers the ID read (ics.md §1): silence at this rate means no servo listens at it.
    l.set_baud(b);
    const auto probe = ics::read_id{}.request();
    const auto heard = l.transact(probe.view(), probe.size + 1, wait_for(probe.size + 1, b, o.timeout));
    (void)l.linger(o.timeout);
    if (heard.size() <= probe.size) continue;
    for (unsigned n = 0; n <= ics::servo_id::max; ++n) {
      if (o.interrupted && o.interrupted()) break;
      const auto id = ics::servo_id::make(n).value();
      if (only && id != *only) continue;
      l.set_baud(b);
      try {
        ics_servo s(l, id, b, quick);
        ics_found f{b, id, false, s.read(ics::sub::stretch), s.read(ics::sub::speed), {}};
        try {
          (void)s.position();
          f.ics36 = true;
        } catch (const refused&) {
        }
        found.push_back(f);
      } catch (const refused& r) {
        if (r.kind == refusal_kind::board)
          found.push_back(ics_found{b, id, false, 0, 0, r.what()});
        else if (r.kind != refusal_kind::timeout)
          throw;
      }
    }
  }
  l.set_baud(order.front());
  return found;
}

ics::line_time ics_virtual_link::now() const {
  return std::chrono::duration_cast<ics::line_time>(std::chrono::steady_clock::now() - start_);
}

std::vector<std::uint8_t> ics_virtual_link::transact(std::span<const std::uint8_t> request, std::size_t expect,
                                                     std::chrono::milliseconds) {
  pending_.clear();
  std::vector<std::uint8_t> out;
  line_.feed(request, baud_, now(), out);
  if (out.size() > expect) {
    pending_.assign(out.begin() + static_cast<std::ptrdiff_t>(expect), out.end());
    out.resize(expect);
  }
  return out;
}

std::vector<std::uint8_t> ics_virtual_link::linger(std::chrono::milliseconds) { return std::exchange(pending_, {}); }

}  // namespace rcb4::robot::services
