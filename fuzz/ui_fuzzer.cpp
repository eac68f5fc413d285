// libFuzzer harness: rcb4 ui's page messages (studio/policy: parse_message and the controller).
// The input is split at newlines into messages from two pages (even lines: page 1, which
// controls first; odd: page 2, which watches until it takes control), each 10 ms after the last.
// Properties:
//   - parse_message never throws and gives a message or a parse_error with a reason;
//   - every letter the controller writes is one valid JSON object with a "type";
//   - a page that does not control causes no action but a refresh;
//   - every move sent is to a joint of the model, within its limits, over 40..6375 ms;
//   - once both pages left, nothing more moves.
// SPDX-License-Identifier: BSL-1.0
#include "controller.hpp"
#include "messages.hpp"

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace {
void check(bool ok) {
  if (!ok) __builtin_trap();
}

const rcb4::robot::model& robot() {
  static const rcb4::robot::model m = [] {
    using rcb4::robot::joint;
    std::vector<joint> js(3);
    const char* names[] = {"head_yaw", "left_knee", "right_knee"};
    for (unsigned i = 0; i < 3; ++i) {
      js[i].name = names[i];
      js[i].ics = rcb4::ics_number::make(i * 2).value();
      js[i].lower = -90.0 - i * 10;
      js[i].upper = 90.0 + i * 10;
    }
    return std::get<rcb4::robot::model>(rcb4::robot::model::make("FUZZ", js, {{"legs", {"left_knee", "right_knee"}}}));
  }();
  return m;
}

void check_letters(const cli::ui::effects& e) {
  for (const auto& l : e.letters) {
    const auto j = nlohmann::json::parse(l.text, nullptr, false);
    check(j.is_object() && j.contains("type") && j["type"].is_string());
  }
}

void check_moves(const std::optional<cli::ui::action>& a) {
  if (!a) return;
  for (const auto& t : std::get<cli::ui::move_action>(a->body).targets) {
    const auto* j = robot().find(t.joint);
    check(j != nullptr);
    check(t.degrees >= j->lower && t.degrees <= j->upper);
    check(t.time && t.time->count() >= 40 && t.time->count() <= 6375);
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cli::ui;
  const std::string_view all(reinterpret_cast<const char*>(data), size);
  // The whole input as one message.
  const auto whole = parse_message(all);
  if (const auto* bad = std::get_if<parse_error>(&whole)) check(!bad->what.empty());

  controller c(robot());
  check_letters(c.join(1));
  check_letters(c.join(2));
  auto now = clock::time_point{} + std::chrono::hours(1);
  std::size_t line = 0;
  for (std::size_t start = 0; start <= all.size();) {
    auto end = all.find('\n', start);
    if (end == std::string_view::npos) end = all.size();
    const client_id from = line % 2 == 0 ? 1 : 2;
    const bool controlled = c.controlling() == from;
    const auto e = c.receive(from, all.substr(start, end - start), now);
    check_letters(e);
    // A page that did not control when it spoke causes no action but a reading one, or a stop
    // (every page keeps Stop: it only ever holds the joints and stops a motion).
    if (!controlled)
      for (const auto& a : e.actions) {
        const auto* st = std::get_if<studio_action>(&a.body);
        check(std::holds_alternative<refresh_action>(a.body) || std::holds_alternative<motion_file_action>(a.body) ||
              std::holds_alternative<stop_action>(a.body) || std::holds_alternative<motion_stop_action>(a.body) ||
              (st && studio_reads(st->op)));
      }
    now += std::chrono::milliseconds(10);
    check_moves(c.due_move(now));
    start = end + 1;
    ++line;
  }
  check_letters(c.leave(1));
  check_letters(c.leave(2));
  check(!c.due_move(now + std::chrono::hours(1)));  // nobody left: nothing moves
  return 0;
}
