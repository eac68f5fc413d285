// rcb4 — robot services: an ICS servo on its own line (ics.md §5): found, its ID, moves and readings (see
// rcb4/robot/services/ics.hpp). SPDX-License-Identifier: BSL-1.0
#include "ics_line.hpp"

#include <iterator>

namespace rcb4::robot::services {
using namespace ics_detail;

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
  // Rounds over the rates, o.tries of them (a servo that answers late once, on a loaded host, is
  // found in the next round without making a silent rate cost three waits in the common case).
  bool echoed = false;  // anything came back: an ICS adapter returns every byte it sends (ics.md §1)
  const int rounds = std::max(1, o_.tries);
  for (int round = 0; round < rounds; ++round) {
    if (round > 0 && o_.interrupted && o_.interrupted()) break;
    for (const auto b : order) {
      l_.set_baud(b);
      if (id) {
        id_ = *id;
        const auto saved = o_.tries;
        o_.tries = 1;
        try {
          (void)ask(ics::read_parameter::make(id_, ics::sub::stretch).value(), o_.timeout, "stretch read");
          o_.tries = saved;
          return;
        } catch (const refused& r) {
          o_.tries = saved;
          if (r.kind != refusal_kind::timeout) throw;
        }
        echoed = echoed || echoed_;
        continue;
      }
      const ics::read_id c;
      const auto req = c.request();
      auto rx = l_.transact(req.view(), req.size + 1, wait_for(req.size + 1, b, o_.timeout));
      echoed = echoed || !rx.empty();
      if (rx.size() <= req.size) {  // nothing at this rate: let a late answer pass before the next rate
        const auto late = l_.linger(o_.timeout);
        echoed = echoed || !late.empty();
        continue;
      }
      id_ = read_id(for_id_work);  // the full check: one clean answer, nothing after it
      return;
    }
  }
  if (!echoed) throw no_echo(order);
  throw refused(
      refusal_kind::timeout,
      id ? fmt::format("ICS servo {} does not answer at {} baud ({} rounds)", id->value(), baud_list(order), rounds)
         : fmt::format("no ICS servo answers the ID read at {} baud ({} rounds)", baud_list(order), rounds),
      hint_wiring);
}

ics::servo_id ics_servo::read_id(bool for_id_write) {
  const ics::read_id c;
  const auto req = c.request();
  std::vector<std::uint8_t> rx;
  bool damaged = false;
  for (int attempt = 0; attempt < std::max(1, o_.tries); ++attempt) {
    rx = l_.transact(req.view(), req.size + 1, wait_for(req.size + 1, l_.baud(), o_.timeout));
    damaged = l_.last_damaged();
    if (rx.size() > req.size && !damaged) break;
    if (damaged) (void)l_.linger(o_.timeout);  // the rest of the damaged answer passes first
  }
  const auto where = fmt::format("the ID read (FF 00 00 00) at {} baud", l_.baud());
  if (damaged)
    throw refused(refusal_kind::board,
                  fmt::format("the answer to {} had a byte that failed its parity check, at the last of {} tries "
                              "(received {} before it): a noisy line, or a second device answering at once",
                              where, std::max(1, o_.tries), rx.empty() ? std::string("nothing") : hex(rx)),
                  "one servo alone on the adapter, its own supply; a damaged reply is never used");
  // A second device answers late or garbled: within the first one's turnaround (an adapter's latency timer).
  const auto extra = l_.linger(std::clamp(o_.timeout / 4, std::chrono::milliseconds(5), std::chrono::milliseconds(50)));
  rx.insert(rx.end(), extra.begin(), extra.end());
  const auto p = ics::parse_exchange(c, rx);
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
  return p.value();
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

}  // namespace rcb4::robot::services
