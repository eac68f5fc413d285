// rcb4 — a vector of at most N values stored inline: what the heap-free operations hold (servo
// slots, planned reads) so that firmware without a heap can run them.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <array>
#include <cstddef>
#include <span>

namespace rcb4::ops {

/**
 * Up to N values of T inline, no heap; push_back() on a full vector returns false and changes
 * nothing. T must be default-constructible and copyable (the operations' small value types).
 */
template <class T, std::size_t N>
class fixed_vector {
 public:
  static constexpr std::size_t capacity = N;  ///< the most values it can hold
  /** Appends @p v; false (nothing changed) when full. */
  constexpr bool push_back(const T& v) noexcept {
    if (size_ == N) return false;
    items_[size_++] = v;
    return true;
  }
  /** Removes every value. */
  constexpr void clear() noexcept { size_ = 0; }
  /** Keeps the first @p n values (n ≤ N; values past the old size are whatever the storage holds). */
  constexpr void resize(std::size_t n) noexcept { size_ = n < N ? n : N; }
  /** How many values are held. */
  constexpr std::size_t size() const noexcept { return size_; }
  /** True when none is held. */
  constexpr bool empty() const noexcept { return size_ == 0; }
  /** Value @p i (unchecked, i < size()). */
  constexpr const T& operator[](std::size_t i) const noexcept { return items_[i]; }
  /** Writable value @p i (unchecked, i < size()). */
  constexpr T& operator[](std::size_t i) noexcept { return items_[i]; }
  /** The first value's address. */
  constexpr const T* data() const noexcept { return items_.data(); }
  /** The first value's address, writable. */
  constexpr T* data() noexcept { return items_.data(); }
  /** Iterator to the first value. */
  constexpr const T* begin() const noexcept { return items_.data(); }
  /** Iterator past the last value. */
  constexpr const T* end() const noexcept { return items_.data() + size_; }
  /** Writable iterator to the first value. */
  constexpr T* begin() noexcept { return items_.data(); }
  /** Writable iterator past the last value. */
  constexpr T* end() noexcept { return items_.data() + size_; }
  /** The values held. */
  constexpr std::span<const T> view() const noexcept { return {items_.data(), size_}; }

 private:
  std::array<T, N> items_{};
  std::size_t size_ = 0;
};

}  // namespace rcb4::ops
