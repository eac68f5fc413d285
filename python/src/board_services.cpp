// pyrcb4: the robot services (rcb4/robot/services/) on a Board: motion slots, buttons, the ROM.
// The policy is the library's, as the rcb4 tool runs it; this file only hands it the line and
// turns its refusals into pyrcb4's exceptions.
// SPDX-License-Identifier: BSL-1.0
#include "board.hpp"

#include <rcb4/ops/layout.hpp>
#include <rcb4/ops/memory.hpp>

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

/** The exception a refusal is in Python. */
fault fault_of(sv::refusal_kind k) {
  switch (k) {
    case sv::refusal_kind::usage: return fault::usage;
    case sv::refusal_kind::limit: return fault::limit;
    case sv::refusal_kind::board:
    case sv::refusal_kind::line: break;
  }
  return fault::refused;
}
}  // namespace

template <class F>
auto board::service(const char* what, F&& f) {
  std::shared_lock life(life_);
  client_link l(c(what));
  try {
    return f(l);
  } catch (const sv::refused& e) {
    const std::string text = std::string(what) + ": " + e.what() + (e.hint.empty() ? "" : " (" + e.hint + ")");
    if (e.kind == sv::refusal_kind::line && e.code) raise(e.code, text);
    throw board_error(fault_of(e.kind), text);
  } catch (const std::system_error& e) {
    raise(e.code(), what);
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
    return sv::erase_motion(l, layout, n, [&](unsigned k, std::span<const std::uint8_t> old) {
      return sv::save_backup_file(k, old, backup);
    });
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

void board::check_playable(unsigned n, const char* what) {
  const auto& layout = this->layout();
  service(what, [&](sv::link& l) {
    sv::require_playable(l, layout, n, "");  // the service error is prefixed with the call's name
    return 0;
  });
}

}  // namespace pyrcb4
