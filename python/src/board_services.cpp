// pyrcb4: the robot services (rcb4/robot/services/) on a Board: motion slots, buttons, the ROM.
// The policy is the library's, as the rcb4 tool runs it; this file only hands it the line and
// turns its refusals into pyrcb4's exceptions.
// SPDX-License-Identifier: BSL-1.0
#include "board.hpp"

#include <rcb4/ops/layout.hpp>
#include <rcb4/ops/memory.hpp>

#include <algorithm>
#include <cctype>
#include <string_view>
#include <thread>
#include <utility>

namespace pyrcb4 {

namespace t = rcb4::transport;
namespace sv = rcb4::robot::services;

namespace {
/** The client as the services see it: one exchange at a time, a failed line as std::system_error. */
class client_link final : public sv::link {
 public:
  explicit client_link(client& c) : c_(c) {}
  rcb4::reply exchange(const rcb4::command& cmd) override {
    t::error_code ec;
    last_ = c_.exchange(cmd, ec);
    if (ec) throw std::system_error(std::error_code(ec));
    return last_.view();
  }

 private:
  client& c_;
  t::response last_;
};

}  // namespace

fault fault_of(sv::refusal_kind k) {
  switch (k) {
    case sv::refusal_kind::usage: return fault::usage;
    case sv::refusal_kind::limit: return fault::limit;
    case sv::refusal_kind::timeout: return fault::timeout;
    case sv::refusal_kind::board:
    case sv::refusal_kind::line: break;
  }
  return fault::refused;
}

void raise_refusal(const sv::refused& e, const std::string& what) {
  const std::string text = python_words(what + ": " + e.what() + (e.hint.empty() ? "" : " (" + e.hint + ")"));
  if (e.kind == sv::refusal_kind::line && e.code) raise(e.code, text);
  throw board_error(fault_of(e.kind), text);
}

std::string python_words(std::string text) {
  static constexpr std::pair<std::string_view, std::string_view> words[] = {
      // IcsServo's (rcb4/robot/services/ics.hpp words its hints for `rcb4 ics`).
      {"rcb4 ics eeprom restore ", "restore() of "},
      {"rcb4 ics eeprom show", "eeprom()"},
      {"rcb4 ics id set N", "set_id(n)"},
      {"rcb4 ics id set", "set_id()"},
      {"rcb4 ics position free", "free()"},
      {"rcb4 ics scan", "pyrcb4.ics_scan()"},
      {"rcb4 ics id", "read_id()"},
      {"rcb4 ics set user_offset=N", "set(user_offset=n)"},
      {"--id N", "id=n"},
      {"rcb4 motion buttons set", "set_button()"},
      {"rcb4 motion buttons clear", "clear_button()"},
      {"rcb4 motion buttons reset", "set_button() for each entry after clearing"},
      {"rcb4 motion buttons", "buttons()"},
      {"rcb4 motion show N", "show_motion(n)"},
      {"rcb4 motion show", "show_motion()"},
      {"rcb4 motion list", "motions()"},
      {"rcb4 motion wait", "wait_motion()"},
      {"rcb4 motion stop", "stop_motion()"},
      {"rcb4 motion play N", "play_motion(n)"},
      {"rcb4 motion play", "play_motion()"},
      {"rcb4 motion push", "push_motion()"},
      {"rcb4 motion resume", "resume_motion()"},
      {"motion resume", "resume_motion()"},
      {"rcb4 rom backup", "rom_backup()"},
      {"rcb4 rom restore", "rom_restore()"},
      {"rcb4 read rom", "read(..., memory='rom')"},
      {"rcb4 scan", "scan()"},
      {"--no-check", "no_check=True"},
      {"--hold", "hold=True"},
      {"--force", "force=True"},
      {"--joints", "joints="},
      {"--baud", "baud"},
  };
  for (const auto& [tool, py] : words)
    for (auto at = text.find(tool); at != std::string::npos; at = text.find(tool, at + 1)) {
      // A method's number given in the text goes inside its parentheses: "rcb4 motion show 70".
      std::size_t end = at + tool.size(), digits = 0;
      while (end + 1 + digits < text.size() && std::isdigit(static_cast<unsigned char>(text[end + 1 + digits])))
        ++digits;
      if (py.ends_with("()") && digits > 0 && text[end] == ' ') {
        const auto n = text.substr(end + 1, digits);
        text.replace(at, end + 1 + digits - at, std::string(py.substr(0, py.size() - 1)) + n + ")");
      } else {
        text.replace(at, tool.size(), py);
      }
    }
  return text;
}

template <class F>
auto board::service(const char* what, F&& f) {
  std::shared_lock life(life_);
  client_link l(c(what));
  try {
    return f(l);
  } catch (const sv::refused& e) {
    raise_refusal(e, what);
  } catch (const std::system_error& e) {
    fail(e.code(), what);
  } catch (const rcb4::robot::profile_error& e) {
    throw board_error(fault::usage, std::string(what) + ": " + e.what());
  }
}

std::pair<std::vector<std::uint8_t>, rcb4::motion::listing> board::show_motion(unsigned n) {
  const auto& layout = this->layout();
  return service("show_motion", [&](sv::link& l) {
    const auto where = sv::slot_for(layout, n);
    auto bytes = sv::read_rom(l, where.address.value(), where.size, "reading");
    auto code = rcb4::motion::disassemble(bytes, where);
    return std::pair{std::move(bytes), std::move(code)};
  });
}

sv::pull_report board::pull_motion(unsigned n) {
  const auto& layout = this->layout();
  return service("pull_motion", [&](sv::link& l) { return sv::pull_motion(l, model_, layout, n); });
}

sv::push_report board::push_motion(const sv::push_source& src, unsigned n, const std::string& backup, bool dry_run) {
  const auto& layout = this->layout();
  return service("push_motion", [&](sv::link& l) {
    return sv::push_motion(
        l, model_, layout, n, src,
        [&](unsigned k, std::span<const std::uint8_t> old) { return sv::save_backup_file(k, old, backup); }, dry_run);
  });
}

sv::erase_report board::erase_motion(unsigned n, const std::string& backup) {
  const auto& layout = this->layout();
  return service("erase_motion", [&](sv::link& l) {
    return sv::erase_motion(
        l, layout, n,
        [&](unsigned k, std::span<const std::uint8_t> old) { return sv::save_backup_file(k, old, backup); },
        model_.name());
  });
}

sv::button_tables board::buttons() {
  return service("buttons", [](sv::link& l) { return sv::read_buttons(l); });
}

sv::table_report board::set_button(std::uint16_t word, unsigned n) {
  const auto& layout = this->layout();
  return service("set_button", [&](sv::link& l) { return sv::set_button(l, layout, word, n); });
}

sv::table_report board::clear_button(std::uint16_t word) {
  return service("clear_button", [&](sv::link& l) { return sv::clear_button(l, word); });
}

sv::press_report board::press(std::uint16_t word, bool hold) {
  const auto& layout = this->layout();
  return service("press", [&](sv::link& l) { return sv::press(l, layout, word, hold); });
}

void board::release() {
  service("release", [](sv::link& l) {
    sv::release(l);
    return 0;
  });
}

std::vector<std::uint8_t> board::rom_backup() {
  return service("rom_backup", [](sv::link& l) { return sv::backup_rom(l); });
}

sv::restore_report board::rom_restore(std::span<const std::uint8_t> image, const sv::rom_sink& save, bool force) {
  return service("rom_restore", [&](sv::link& l) { return sv::restore_rom(l, image, save, force); });
}

sv::trims_report board::set_trims(const std::vector<std::pair<std::string, double>>& trims, bool persistent) {
  return service("set_trims", [&](sv::link& l) { return sv::set_trims(l, model_, trims, persistent); });
}

std::vector<sv::trim_entry> board::trims() {
  return service("trims", [&](sv::link& l) { return sv::read_trims(l, model_, {}); });
}

namespace {
/** Sleeps until @p t in steps of at most 50 ms; false as soon as @p stop says so. */
bool sleep_until(std::chrono::steady_clock::time_point t, const std::function<bool()>& stop) {
  for (;;) {
    if (stop()) return false;
    const auto now = std::chrono::steady_clock::now();
    if (now >= t) return true;
    std::this_thread::sleep_until(std::min(t, now + std::chrono::milliseconds(50)));
  }
}
}  // namespace

board::file_play board::play_file(const rcb4::robot::motion_document& d, const std::string& name, bool rescale,
                                  double timeout_s, const std::function<bool()>& stop) {
  const auto& layout = sv::needs_layout(d) ? this->layout() : rcb4::hth4_2_2;
  const auto board_period = period();
  const auto stopped = [&] { return closing_ || stop(); };
  return service("play_motion_file", [&](sv::link& l) {
    sv::host_play play(l, model_, layout, board_period, d, name, rescale,
                       std::chrono::milliseconds(static_cast<long long>(timeout_s * 1000)));
    const auto start = std::chrono::steady_clock::now();
    const auto elapsed = [&] {
      return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start);
    };
    file_play r;
    for (auto next = play.advance(elapsed()); next; next = play.advance(elapsed()))
      if (!sleep_until(start + *next, stopped)) {
        play.stop();
        r.interrupted = true;
        break;
      }
    r.poses = play.poses();
    r.calls = play.calls();
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    r.notes = play.notes();
    return r;
  });
}

sv::record_report board::record(const std::vector<std::string>& words, double every_s, double seconds, double threshold,
                                bool free, const std::function<bool()>& stop) {
  if (!(every_s >= 0.02 && every_s <= 2)) throw board_error(fault::usage, "every: 0.02 to 2 seconds");
  if (!(seconds >= 0 && seconds <= 3600)) throw board_error(fault::usage, "seconds: 0 (until stopped) to 3600");
  if (!(threshold >= 0.1 && threshold <= 45)) throw board_error(fault::usage, "threshold: 0.1 to 45 degrees");
  const auto js = joints_named(words);
  const auto cost = link("record");
  const auto stopped = [&] { return closing_ || stop(); };
  return service("record", [&](sv::link& l) {
    sv::recording rec(l, model_, js,
                      {.threshold = threshold, .free = free, .lead_in = std::chrono::seconds(1), .cost = cost});
    const auto start = std::chrono::steady_clock::now();
    const auto every =
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(every_s));
    const auto until =
        start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
    for (auto next = start;;) {
      try {
        rec.sample(std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start));
      } catch (const std::system_error& e) {  // the board went away: what was recorded is kept and said
        auto r = rec.finish(true);
        r.lost = e.code();
        return r;
      }
      next += every;
      if (seconds > 0 && next > until) break;
      if (!sleep_until(next, stopped)) break;
    }
    return rec.finish();
  });
}

void board::check_playable(unsigned n, const char* what) {
  const auto& layout = this->layout();
  service(what, [&](sv::link& l) {
    sv::require_playable(l, layout, n, "");  // the service error is prefixed with the call's name
    return 0;
  });
}

}  // namespace pyrcb4
