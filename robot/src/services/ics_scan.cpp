// rcb4 — robot services: every ICS servo on a line, and the in-process virtual line (see rcb4/robot/services/ics.hpp).
// SPDX-License-Identifier: BSL-1.0
#include "ics_line.hpp"

#include <iterator>
#include <utility>

namespace rcb4::robot::services {
using namespace ics_detail;

std::vector<ics_found> ics_scan(ics_link& l, std::span<const std::uint32_t> bauds, const ics_options& o,
                                const std::function<void(std::uint32_t)>& on_baud, std::optional<ics::servo_id> only) {
  std::vector<std::uint32_t> order(bauds.begin(), bauds.end());
  if (order.empty()) order.assign(std::begin(ics::bauds), std::end(ics::bauds));
  for (const auto b : order)
    if (!ics::baud_code(b))
      throw refused(refusal_kind::usage, fmt::format("baud {}: an ICS line runs at 115200, 625000 or 1250000", b));
  std::vector<ics_found> found;
  bool echoed = false;  // anything came back at any rate: an ICS adapter returns every byte it sends (ics.md §1)
  ics_options quick = o;
  quick.tries = 1;
  for (const auto b : order) {
    if (on_baud) on_baud(b);
    // Every device answers the ID read (ics.md §1): silence at this rate means no servo listens at it.
    l.set_baud(b);
    const auto probe = ics::read_id{}.request();
    bool heard = false;
    for (int t = 0; t < std::max(1, o.tries) && !heard; ++t) {  // tried as every exchange is (docs/ics-servos.md)
      const auto rx = l.transact(probe.view(), probe.size + 1, wait_for(probe.size + 1, b, o.timeout));
      const bool damaged = l.last_damaged();  // something answered, damaged: its IDs are asked one by one
      const auto late = l.linger(o.timeout);
      heard = rx.size() > probe.size || damaged || !late.empty();
      echoed = echoed || !rx.empty() || !late.empty();
    }
    if (!heard) continue;
    for (unsigned n = 0; n <= ics::servo_id::max; ++n) {
      if (o.interrupted && o.interrupted()) break;
      const auto id = ics::servo_id::make(n).value();
      if (only && id != *only) continue;
      // One ID: its stretch, speed and whether it answers the 3.6 position read; a timeout: nobody.
      const auto ask_id = [&](const ics_options& with) {
        l.set_baud(b);
        ics_servo s(l, id, b, with);
        ics_found f{b, id, false, s.read(ics::sub::stretch), s.read(ics::sub::speed), {}};
        try {
          (void)s.position();
          f.ics36 = true;
        } catch (const refused&) {
        }
        return f;
      };
      try {
        found.push_back(ask_id(quick));
      } catch (const refused& r) {
        if (r.kind != refusal_kind::board && r.kind != refusal_kind::timeout) throw;
        if (r.kind == refusal_kind::timeout) continue;
        // A wrong answer is asked again, with every try, once the line is quiet: a late echo or
        // reply of the previous ID (a loaded host, a slow pty) is no device of its own.
        (void)l.linger(o.timeout * 2);
        try {
          found.push_back(ask_id(o));
        } catch (const refused& again) {
          if (again.kind == refusal_kind::board)
            found.push_back(ics_found{b, id, false, 0, 0, again.what()});
          else if (again.kind != refusal_kind::timeout)
            throw;
        }
      }
    }
  }
  l.set_baud(order.front());
  if (!echoed) throw no_echo(order);
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
