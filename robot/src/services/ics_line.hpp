// rcb4 — robot services, private: what the ICS service's files share (rcb4/robot/services/ics.hpp):
// texts for messages, wait times, and ics_servo::ask, the one exchange with tries and lingers.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/robot/services/ics.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>

namespace rcb4::robot::services {
namespace ics_detail {

using namespace std::chrono_literals;
using ics::field;

inline constexpr std::uint32_t discovery_order[] = {115200, 1250000, 625000};  // a new servo runs at 115200 (ics.md §1)

inline std::string baud_list(std::span<const std::uint32_t> bauds) {
  std::string s;
  for (std::size_t i = 0; i < bauds.size(); ++i)
    s += (i == 0 ? "" : i + 1 == bauds.size() ? " or " : ", ") + std::to_string(bauds[i]);
  return s;
}

inline const char* sub_name(ics::sub s) {
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

inline std::string hex(std::span<const std::uint8_t> b) {
  std::string s;
  for (auto x : b) s += fmt::format("{}{:02X}", s.empty() ? "" : " ", x);
  return s;
}

inline const std::string hint_wiring =
    "check the adapter is in ICS mode (the Dual USB Adapter HS's LED red), the servo has its own supply and was "
    "powered after the adapter was opened, and its baud (--baud, or let rcb4 try all three)";

/** The error code of a line failure: a std::system_error's own, else an I/O error. */
inline std::error_code line_code(const std::exception& e) {
  if (const auto* se = dynamic_cast<const std::system_error*>(&e)) return se->code();
  return std::make_error_code(std::errc::io_error);
}

/** A line failure in words: the error's text without the " [category:value]" that Boost appends. */
inline std::string line_text(const std::exception& e) {
  std::string_view w = e.what();
  if (const auto at = w.rfind(" ["); at != std::string_view::npos && w.ends_with(']')) w = w.substr(0, at);
  return std::string(w);
}

/** What `transact` should wait for: both directions' wire time, then the reply allowance. */
inline std::chrono::milliseconds wait_for(std::size_t bytes, std::uint32_t baud, std::chrono::milliseconds allowance) {
  return std::chrono::milliseconds(ics::wire_micros(bytes, baud) / 1000 + 1) + allowance;
}

/** Nothing came back at any of @p order, not even the echo: no ICS line (ics.md §1: an adapter in ICS mode echoes). */
inline refused no_echo(std::span<const std::uint32_t> order) {
  return refused(refusal_kind::timeout,
                 fmt::format("nothing came back at {} baud, not even the echo of the bytes sent: not an ICS line (an "
                             "adapter in ICS mode returns every byte it sends, servo or not)",
                             baud_list(order)),
                 "is the adapter switched to ICS mode (not COM mode, which reaches an RCB-4 board)? is this port an "
                 "RCB-4 board (use `rcb4 --device ...` without `ics`)? is a pty served?");
}

}  // namespace ics_detail

template <class Cmd>
typename Cmd::reply_type ics_servo::ask(const Cmd& c, std::chrono::milliseconds wait, const char* what) {
  using namespace ics_detail;
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
    echoed_ = echoed_ || !rx.empty();
    const auto p = ics::parse_exchange(c, rx);
    if (l_.last_damaged()) {  // (checked first: the bytes before the damaged one may parse as a shorter reply)
      last = fmt::format("byte {} of echo and reply failed its parity check (received {} before it)", rx.size() + 1,
                         rx.empty() ? std::string("nothing") : hex(rx));
      answered = true;
    } else if (p.ok() && rx.size() == p.consumed) {
      return p.value();
    } else if (p.ok()) {
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

}  // namespace rcb4::robot::services
