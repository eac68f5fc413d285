// rcb4 — a first-in first-out queue on a ring of slots that is reused (no allocation per push).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

namespace rcb4::transport::detail {

/**
 * A FIFO whose storage grows (doubling) when full and is otherwise reused, so that a queue
 * holding a few elements at a time never allocates in steady state (std::deque allocates a node
 * every few pushes). T needs only a move constructor: elements are constructed in place and
 * destroyed when popped, never assigned (Boost 1.81's any_completion_handler cannot be).
 */
template <class T>
class fifo {
 public:
  /** True when nothing is queued. */
  bool empty() const noexcept { return count_ == 0; }
  /** Number of queued elements. */
  std::size_t size() const noexcept { return count_; }
  /** Appends @p v at the back. */
  void push_back(T v) {
    grow_if_full();
    slots_[(head_ + count_) % slots_.size()].emplace(std::move(v));
    ++count_;
  }
  /** Inserts @p v at the front (it is popped next). */
  void push_front(T v) {
    grow_if_full();
    head_ = (head_ + slots_.size() - 1) % slots_.size();
    slots_[head_].emplace(std::move(v));
    ++count_;
  }
  /** Removes and returns the front element (the queue must not be empty). */
  T pop_front() {
    T v = std::move(*slots_[head_]);
    slots_[head_].reset();
    head_ = (head_ + 1) % slots_.size();
    --count_;
    return v;
  }
  /** Removes and returns the first element for which @p pred is true, if any (order kept). */
  template <class Pred>
  std::optional<T> take_if(Pred pred) {
    for (std::size_t i = 0; i < count_; ++i) {
      auto& slot = slots_[(head_ + i) % slots_.size()];
      if (!pred(*slot)) continue;
      std::optional<T> out(std::move(*slot));
      for (std::size_t j = i; j + 1 < count_; ++j) {  // close the gap: later elements move up
        auto& to = slots_[(head_ + j) % slots_.size()];
        auto& from = slots_[(head_ + j + 1) % slots_.size()];
        to.reset();
        to.emplace(std::move(*from));
      }
      slots_[(head_ + count_ - 1) % slots_.size()].reset();
      --count_;
      return out;
    }
    return std::nullopt;
  }

 private:
  void grow_if_full() {
    if (count_ < slots_.size()) return;
    std::vector<std::optional<T>> bigger(slots_.empty() ? 4 : slots_.size() * 2);
    for (std::size_t i = 0; i < count_; ++i) {
      auto& from = slots_[(head_ + i) % slots_.size()];
      bigger[i].emplace(std::move(*from));
      from.reset();
    }
    slots_ = std::move(bigger);
    head_ = 0;
  }
  std::vector<std::optional<T>> slots_;
  std::size_t head_ = 0, count_ = 0;
};

}  // namespace rcb4::transport::detail
