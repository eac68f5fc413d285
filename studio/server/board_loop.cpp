// rcb4 ui: the board loop (see board_loop.hpp, board_loop_class.hpp): takes the pages' actions,
// paces the reads of the robot, notices what other programs changed through the studio's share.
// SPDX-License-Identifier: BSL-1.0
#include "board_loop_class.hpp"

#include <rcb4/motion/disassemble.hpp>
#include <rcb4/robot/motion_file.hpp>
#include <rcb4/robot/services/slot_names.hpp>

#include <algorithm>
#include <cmath>
#include <system_error>

namespace cli::ui {

namespace robot = rcb4::robot;
namespace ops = rcb4::ops;
using namespace std::chrono_literals;

json angle_json(std::optional<double> d) {
  if (!d || !std::isfinite(*d)) return nullptr;
  const double r = std::round(*d * 100) / 100;
  return r == 0 ? 0.0 : r;
}

std::string words_of(std::error_code ec, std::string_view what) {
  const auto f = explain(ec, what);
  std::string s = fmt::format("{}: {}", what, plain_message(ec.message()));
  if (!f.hint.empty()) s += " (" + f.hint + ")";
  return s;
}

board_loop::board_loop(session& s, const robot::model& m, hub& h, const loop_options& o)
    : s_(s), m_(m), h_(h), o_(o), studio_(s, m, o) {
  angles_.resize(m.joints().size());
  targets_.resize(m.joints().size());
  modes_.resize(m.joints().size(), "unknown");
  last_rate_at_ = clock::now();
}

void board_loop::run() {
  bool lists_sent = false;
  bool joints_next = false;
  auto poll_at = clock::now();
  while (!h_.stopped()) {
    const auto actions = h_.take();
    bool moved = false;
    for (const auto& a : actions) {
      if (h_.stopped()) return;
      moved = moved || std::holds_alternative<move_action>(a.body);
      carry_out(a);
    }
    if (h_.stopped()) return;
    notice_outside_writes();
    if (auto done = studio_.tick()) h_.tell(done->to, done->text);  // a motion played from the host
    // After a slider move the board shows it once it has taken its first step, one output period
    // on: the page hears then, not a page period later. Other work is shown at once.
    if (moved && answering_) {
      poll_at = clock::now() + std::chrono::milliseconds(rcb4::milliseconds(period_)) + 2ms;
      joints_next = true;  // that read only needs the joints
    } else if (!actions.empty()) {
      poll_at = clock::now();
      joints_next = false;
    }
    if (clock::now() >= poll_at) {
      const auto start = clock::now();
      poll(std::exchange(joints_next, false));
      if (answering_ && !lists_sent) {  // after the first state: a page shows the robot at once
        refresh_lists();
        lists_sent = true;
      }
      poll_at = start + (answering_ ? o_.period : 500ms);  // a silent board is tried twice a second
    }
    // A motion played from the host wakes the loop when its next pose is due, not a poll later.
    const auto wake = std::min(poll_at, studio_.due().value_or(poll_at));
    if (!h_.wait_until(wake)) break;
  }
}

/**
 * Another program changed the board through the studio's share of the port: once it has been
 * quiet for 300 ms (a push writes in many pieces), the lists are read again and pages told.
 */
void board_loop::notice_outside_writes() {
  if (!o_.outside_writes) return;
  const auto n = o_.outside_writes->load();
  if (n != outside_seen_) {
    outside_unseen_ += n - outside_seen_;
    outside_seen_ = n;
    outside_at_ = clock::now();
  } else if (outside_unseen_ > 0 && clock::now() - outside_at_ >= 300ms) {
    refresh_lists();
    json j;
    j["type"] = "note";
    j["text"] = fmt::format("another program (rcb4 or pyrcb4, through this studio) changed the board: {} write{}",
                            outside_unseen_, outside_unseen_ == 1 ? "" : "s");
    h_.tell(0, text_of(j));
    outside_unseen_ = 0;
  }
}

// --- actions: each to its act() (board_actions.cpp)
// -------------------------------------------------------------------------------
void board_loop::carry_out(const action& a) {
  const std::string_view op = std::visit(
      [](const auto& b) -> std::string_view {
        using B = std::decay_t<decltype(b)>;
        if constexpr (std::is_same_v<B, move_action>)
          return "move";
        else if constexpr (std::is_same_v<B, power_action>)
          return b.free ? "free" : "hold";
        else if constexpr (std::is_same_v<B, stop_action>)
          return "stop";
        else if constexpr (std::is_same_v<B, capture_action>)
          return "capture";
        else if constexpr (std::is_same_v<B, play_pose_action>)
          return "play_pose";
        else if constexpr (std::is_same_v<B, motion_play_action>)
          return "motion_play";
        else if constexpr (std::is_same_v<B, motion_stop_action>)
          return "motion_stop";
        else if constexpr (std::is_same_v<B, motion_file_action>)
          return "motion_file";
        else if constexpr (std::is_same_v<B, studio_action>)
          return b.op;
        else
          return "refresh";
      },
      a.body);
  try {
    json extra;
    if (const auto* st = std::get_if<studio_action>(&a.body)) {
      try {
        extra = studio_.act(*st, a.from);
      } catch (const studio_refusal& r) {
        throw refusal{r.what()};
      }
      if (st->op == "motion_push" || st->op == "motion_erase" || st->op == "motion_put_back") refresh_lists();
    } else {
      extra = std::visit([&](const auto& b) { return act(b); }, a.body);
    }
    // Slider moves come without an id; they are answered only when they fail.
    if (a.id || !std::holds_alternative<move_action>(a.body))
      if (a.from) h_.tell(a.from, reply_text(a.id, op, extra.is_null() ? std::string() : text_of(extra)));
  } catch (const refusal& r) {
    if (a.from) h_.tell(a.from, error_text(a.id, op, r.what));
  } catch (const std::exception& e) {  // a failure nothing above turned into words: the page hears it, the loop goes on
    answering_ = false;
    if (a.from) h_.tell(a.from, error_text(a.id, op, plain_message(e.what())));
  }
}

void board_loop::located() {
  if (reader_) return;
  t::error_code ec;
  locate(ec);
  if (ec) throw refusal{words_of(ec, "locating the joints")};
}

void board_loop::refuse_during_motion() {
  // The one rule (rcb4/robot/services/moves.hpp), on the state this loop keeps.
  if (!rom_program_) return;
  if (const auto why = rcb4::robot::services::move_refusal(motion_)) throw refusal{*why + " (stop it first)"};
}

void run_board_loop(session& s, const robot::model& m, hub& h, const loop_options& o) { board_loop(s, m, h, o).run(); }

}  // namespace cli::ui
