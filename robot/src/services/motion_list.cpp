// rcb4 — robot services: the used slots as the board runs them, and their play times (see
// rcb4/robot/services/motion_slots.hpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/services/motion_slots.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "slot_address.hpp"

namespace rcb4::robot::services {
namespace {

namespace mo = rcb4::motion;

/** @p s's code as the board runs it, from the bytes the walk read (to its first RETURN or bad frame). */
mo::listing code_of(const ops::motion_slot& s, const rom_layout& layout) {
  return mo::disassemble(s.code, mo::slot{rom_address::make(s.address).value(), layout.slot_size});
}

/**
 * The slot's own problem, or "" when its code plays. The walk reads to the first RETURN: code
 * after it that a jump reaches was not read, so a slot with a RETURN whose code leads past the
 * bytes read is not called broken (its play time is unknown); one the walk ended on a byte that
 * starts no frame is broken where its code reaches that byte.
 */
std::string own_problem(const ops::motion_slot& s, const mo::listing& code) {
  if (!s.readable) return "its first frame fails its checksum (another --layout?)";
  if (code.problems.empty() || s.ends) return {};
  return code.problems.front();
}

}  // namespace

std::optional<motion::play_estimate> slot_play_time(const ops::motion_slot& s, const rom_layout& layout) {
  if (!s.readable) return std::nullopt;
  const auto code = code_of(s, layout);
  if (!code.problems.empty()) return std::nullopt;
  auto p = mo::lift(code);
  if (!mo::ok(p)) return std::nullopt;
  return mo::play_time(std::get<mo::program>(p));
}

std::vector<slot_state> slot_states(const std::vector<ops::motion_slot>& used, const rom_layout& layout) {
  std::vector<slot_state> out(used.size());
  std::vector<std::vector<std::uint32_t>> calls(used.size());
  for (std::size_t i = 0; i < used.size(); ++i) {
    const auto code = code_of(used[i], layout);
    out[i].problem = own_problem(used[i], code);
    out[i].plays = slot_play_time(used[i], layout);
    out[i].endless = out[i].plays && out[i].plays->endless;
    if (out[i].problem.empty()) calls[i] = code.calls;
  }
  const auto index_of = [&](unsigned n) -> std::optional<std::size_t> {
    const auto it = std::find_if(used.begin(), used.end(), [&](const auto& v) { return v.number == n; });
    if (it == used.end()) return std::nullopt;
    return static_cast<std::size_t>(it - used.begin());
  };
  // A call of an empty or broken slot breaks its caller, and so on up the chains: until nothing changes.
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t i = 0; i < used.size(); ++i) {
      if (!out[i].problem.empty()) continue;
      for (const auto a : calls[i]) {
        const auto n = slot_number(layout, a);
        if (!n) continue;  // outside the slots: the disassembler has said what it is
        const auto k = index_of(*n);
        if (k && out[*k].problem.empty()) continue;
        out[i].problem = k ? fmt::format("it calls motion {}, which is broken", *n)
                           : fmt::format("it calls motion {}, which holds no motion", *n);
        changed = true;
        break;
      }
    }
  }
  return out;
}

std::optional<double> play_seconds(const motion::play_estimate& e, output_period period) {
  if (e.endless || !e.error.empty() || e.calls) return std::nullopt;
  return std::round(static_cast<double>(e.frames) * rcb4::milliseconds(period) / 10.0) / 100.0;
}

std::string play_time_text(const motion::play_estimate& e, output_period period) {
  if (!e.error.empty()) return "cannot be played: " + e.error;
  if (e.endless) return "plays until stopped: it goes round for ever";
  std::string t = fmt::format("plays {:.2f} s", static_cast<double>(e.frames) * rcb4::milliseconds(period) / 1000.0);
  if (e.calls) t += fmt::format(" and {} call{} of other motions", e.calls, e.calls == 1 ? "" : "s");
  if (e.reads) t += ", no button held";
  return t;
}

}  // namespace rcb4::robot::services
