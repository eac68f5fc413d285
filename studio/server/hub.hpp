// rcb4 ui: where the web server's thread and the board loop's thread meet (one mutex).
// SPDX-License-Identifier: BSL-1.0
//
// The server calls join/leave/receive from its io thread; the controller's letters go out
// through `send` (which posts to the server's io thread), its actions wait in a queue for the
// board loop, which takes them, observes the board and broadcasts the state. Every wait has a
// deadline and ends early when work arrives or the hub stops.
#pragma once

#include "controller.hpp"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace cli::ui {

/** The meeting point of the server and the board loop. */
class hub {
 public:
  /** Sends one text to one page (0: to every page). Must not block (it posts). */
  using sender = std::function<void(client_id, std::string)>;

  /** For robot @p m under @p s; letters go through @p send. */
  hub(const rcb4::robot::model& m, settings s, sender send) : controller_(m, s), send_(std::move(send)) {}

  /** A page connected: it gets the hello, the lists, the last state and its role. */
  void join(client_id c) {
    std::vector<letter> out;
    {
      std::lock_guard lock(mutex_);
      for (const auto* t : {&hello_, &lists_, &state_})
        if (!t->empty()) out.push_back({c, *t});
      absorb(controller_.join(c), out);
    }
    deliver(out);
  }
  /** A page went away. */
  void leave(client_id c) {
    std::vector<letter> out;
    {
      std::lock_guard lock(mutex_);
      absorb(controller_.leave(c), out);
    }
    deliver(out);
  }
  /** A page sent @p text. */
  void receive(client_id c, std::string_view text) {
    std::vector<letter> out;
    {
      std::lock_guard lock(mutex_);
      absorb(controller_.receive(c, text, clock::now()), out);
    }
    cv_.notify_all();  // a slider move may be due now
    deliver(out);
  }

  /** The board loop's work: queued actions, then the due slider move. */
  std::vector<action> take() {
    std::lock_guard lock(mutex_);
    std::vector<action> out(std::make_move_iterator(queue_.begin()), std::make_move_iterator(queue_.end()));
    queue_.clear();
    if (auto mv = controller_.due_move(clock::now())) out.push_back(std::move(*mv));
    return out;
  }
  /**
   * Waits until @p deadline, or less: when an action is queued, a slider move falls due (a drag's
   * first move at once, then one a move interval) or the hub stops. Returns false once stopped.
   */
  bool wait_until(clock::time_point deadline) {
    std::unique_lock lock(mutex_);
    for (;;) {
      if (stopped_ || !queue_.empty()) break;
      const auto due = controller_.move_due_at();
      const auto until = due ? std::min(deadline, *due) : deadline;
      if (clock::now() >= until) break;
      cv_.wait_until(lock, until);  // receive() wakes it when a page sends
    }
    return !stopped_;
  }
  /** The board's targets and angles, per model joint, and its longest move (see controller::observe). */
  void observe(std::span<const std::optional<double>> targets, std::span<const std::optional<double>> angles,
               std::chrono::milliseconds longest) {
    std::lock_guard lock(mutex_);
    controller_.observe(targets, angles, longest);
  }
  /** Sends @p text to page @p to. */
  void tell(client_id to, std::string text) { send_(to, std::move(text)); }
  /** Sets what every page gets first (the robot) and sends it to those connected. */
  void set_hello(std::string text) { remember(hello_, std::move(text)); }
  /** Sets and broadcasts the pose and motion lists. */
  void set_lists(std::string text) { remember(lists_, std::move(text)); }
  /** Sets and broadcasts the latest state. */
  void set_state(std::string text) { remember(state_, std::move(text)); }
  /** Ends every wait; the board loop returns. */
  void stop() {
    {
      std::lock_guard lock(mutex_);
      stopped_ = true;
    }
    cv_.notify_all();
  }
  /** True once stop() was called. */
  bool stopped() const {
    std::lock_guard lock(mutex_);
    return stopped_;
  }
  /** The settings the controller enforces. */
  const settings& limits() const noexcept { return controller_.limits(); }

 private:
  void absorb(effects e, std::vector<letter>& out) {
    for (auto& l : e.letters) out.push_back(std::move(l));
    const bool work = !e.actions.empty();
    for (auto& a : e.actions) {
      if (std::holds_alternative<stop_action>(a.body)) {  // before anything still waiting
        queue_.push_front(std::move(a));
      } else if (std::holds_alternative<refresh_action>(a.body) &&
                 std::any_of(queue_.begin(), queue_.end(),
                             [](const action& q) { return std::holds_alternative<refresh_action>(q.body); })) {
        // One refresh waiting is enough: its lists go to every page.
      } else if (queue_.size() >= max_queued) {
        out.push_back({a.from, error_text(a.id, {}, "the board is busy with earlier requests: try again")});
      } else {
        queue_.push_back(std::move(a));
      }
    }
    if (work) cv_.notify_all();
  }
  void deliver(std::vector<letter>& out) {
    for (auto& l : out) send_(l.to, std::move(l.text));
  }
  void remember(std::string& slot, std::string text) {
    {
      std::lock_guard lock(mutex_);
      slot = text;
    }
    send_(0, std::move(text));
  }

  static constexpr std::size_t max_queued = 32;  ///< actions waiting for the board, at most
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  controller controller_;
  sender send_;
  std::deque<action> queue_;
  std::string hello_, lists_, state_;
  bool stopped_ = false;
};

}  // namespace cli::ui
