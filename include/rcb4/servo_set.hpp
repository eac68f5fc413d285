// rcb4 — sets of servos: the 36-slot bitmask and per-servo values in ascending ICS order.
// SPDX-License-Identifier: BSL-1.0
//
// The 5-byte mask of CONST/SERIES/SPEED-STRETCH (protocol.md §4.7):
//   [M0][M1][M2][M3][M4]   bit k of the 40-bit little-endian value selects ICS k (0–35);
//   M4 bits 4-6 are zero; M4 bit 7 is the update-flag control (rcb4::update_flags).
// The values that follow are in ascending ICS order, whatever order the caller added them in.
#pragma once

#include <rcb4/commands/common.hpp>
#include <rcb4/values.hpp>

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <iterator>
#include <span>

namespace rcb4 {

/** Number of ICS slots (0–35). */
inline constexpr std::size_t ics_slots = 36;

/** A set of ICS slots as a 36-bit mask. */
class servo_mask {
 public:
  static constexpr std::uint64_t all_bits = (std::uint64_t{1} << ics_slots) - 1;  ///< ICS 0–35

  /** Empty. */
  constexpr servo_mask() noexcept = default;
  /** From raw bits; bits above 35 are refused (errc::ics_out_of_range). */
  static constexpr result<servo_mask> from_bits(std::uint64_t bits) noexcept {
    if ((bits & ~all_bits) != 0) return errc::ics_out_of_range;
    servo_mask m;
    m.bits_ = bits;
    return m;
  }
  /** Adds @p n. */
  constexpr void insert(ics_number n) noexcept { bits_ |= bit(n); }
  /** Removes @p n. */
  constexpr void erase(ics_number n) noexcept { bits_ &= ~bit(n); }
  /** True when @p n is in the set. */
  constexpr bool contains(ics_number n) const noexcept { return (bits_ & bit(n)) != 0; }
  /** Number of slots selected (popcount). */
  constexpr std::size_t size() const noexcept { return static_cast<std::size_t>(std::popcount(bits_)); }
  /** True when nothing is selected. */
  constexpr bool empty() const noexcept { return bits_ == 0; }
  /** How many selected slots come before @p n: its index in the value list. */
  constexpr std::size_t rank(ics_number n) const noexcept {
    return static_cast<std::size_t>(std::popcount(bits_ & (bit(n) - 1)));
  }
  /** The raw bits (bit k = ICS k). */
  constexpr std::uint64_t bits() const noexcept { return bits_; }

  /** The 5 wire bytes, with M4 bit 7 set for update_flags::leave. */
  constexpr std::array<std::uint8_t, 5> encode(update_flags f) const noexcept {
    std::array<std::uint8_t, 5> out{};
    for (std::size_t i = 0; i < 5; ++i) out[i] = static_cast<std::uint8_t>((bits_ >> (8 * i)) & 0xFFu);
    if (f == update_flags::leave) out[4] = static_cast<std::uint8_t>(out[4] | 0x80u);
    return out;
  }
  /** A decoded mask and its update-flag bit. */
  struct decoded;
  /** Decodes 5 wire bytes; M4 bits 4-6 must be zero (errc::reserved_bits_set). */
  static constexpr result<decoded> decode(std::span<const std::uint8_t, 5> b) noexcept;

  /** Iterates the selected ICS numbers in ascending order. */
  class iterator {
   public:
    using value_type = ics_number;                        ///< what *it gives
    using difference_type = std::ptrdiff_t;               ///< for std::ranges (a forward range)
    using iterator_category = std::forward_iterator_tag;  ///< for the standard algorithms
    constexpr iterator() noexcept = default;
    constexpr explicit iterator(std::uint64_t rest) noexcept : rest_(rest) {}
    constexpr ics_number operator*() const noexcept { return ics_number::make(std::countr_zero(rest_)).value(); }
    constexpr iterator& operator++() noexcept {
      rest_ &= rest_ - 1;
      return *this;
    }
    constexpr iterator operator++(int) noexcept {
      auto c = *this;
      ++*this;
      return c;
    }
    friend constexpr bool operator==(iterator, iterator) noexcept = default;

   private:
    std::uint64_t rest_ = 0;
  };
  /** First selected slot. */
  constexpr iterator begin() const noexcept { return iterator(bits_); }
  /** Past the last selected slot. */
  constexpr iterator end() const noexcept { return iterator(0); }

  friend constexpr bool operator==(servo_mask, servo_mask) noexcept = default;

 private:
  static constexpr std::uint64_t bit(ics_number n) noexcept { return std::uint64_t{1} << n.value(); }
  std::uint64_t bits_ = 0;
};

struct servo_mask::decoded {
  servo_mask mask;
  update_flags flags = update_flags::replace;
};

constexpr result<servo_mask::decoded> servo_mask::decode(std::span<const std::uint8_t, 5> b) noexcept {
  if ((b[4] & 0x70u) != 0) return errc::reserved_bits_set;
  std::uint64_t bits = 0;
  for (std::size_t i = 0; i < 5; ++i) bits |= std::uint64_t{b[i]} << (8 * i);
  bits &= all_bits;  // drops M4 bit 7, the flag
  servo_mask m;
  m.bits_ = bits;
  return decoded{m, (b[4] & 0x80u) ? update_flags::leave : update_flags::replace};
}

/**
 * One value per selected servo, kept in ascending ICS order (the wire order), no heap.
 * Inserting an ICS that is already present replaces its value.
 */
template <class T>
class servo_set {
 public:
  /** One member: an ICS number and its value. */
  struct entry {
    ics_number ics;
    T value;
    friend constexpr bool operator==(const entry&, const entry&) noexcept = default;
  };

  /** Empty. */
  constexpr servo_set() noexcept = default;
  /** From entries in any order; a repeated ICS keeps the last value. */
  constexpr servo_set(std::initializer_list<entry> entries) noexcept {
    for (const auto& e : entries) insert(e.ics, e.value);
  }

  /** Sets the value of @p n, adding it if absent (keeps ascending order). */
  constexpr void insert(ics_number n, T value) noexcept {
    if ((mask_.bits() >> n.value()) == 0) {  // above every member: append (the common case)
      mask_.insert(n);
      values_[count_++] = value;
      return;
    }
    const std::size_t i = mask_.rank(n);
    if (!mask_.contains(n)) {
      for (std::size_t j = count_; j > i; --j) values_[j] = values_[j - 1];
      mask_.insert(n);
      ++count_;
    }
    values_[i] = value;
  }
  /** Removes @p n if present. */
  constexpr void erase(ics_number n) noexcept {
    if (!mask_.contains(n)) return;
    const std::size_t i = mask_.rank(n);
    for (std::size_t j = i; j + 1 < count_; ++j) values_[j] = values_[j + 1];
    mask_.erase(n);
    --count_;
  }
  /** True when @p n has a value. */
  constexpr bool contains(ics_number n) const noexcept { return mask_.contains(n); }
  /** The value of @p n, or nullptr when absent. */
  constexpr const T* find(ics_number n) const noexcept { return mask_.contains(n) ? &values_[mask_.rank(n)] : nullptr; }
  /** Number of servos (kept equal to the popcount of the mask). */
  constexpr std::size_t size() const noexcept { return count_; }
  /** True when empty. */
  constexpr bool empty() const noexcept { return mask_.empty(); }
  /** The selected slots. */
  constexpr servo_mask mask() const noexcept { return mask_; }
  /** The values in ascending ICS order. */
  constexpr std::span<const T> values() const noexcept { return {values_.data(), size()}; }

  /** Iterates entries in ascending ICS order. */
  class iterator {
   public:
    using value_type = entry;                             ///< what *it gives (ICS number and value)
    using difference_type = std::ptrdiff_t;               ///< for std::ranges (a forward range)
    using iterator_category = std::forward_iterator_tag;  ///< for the standard algorithms
    constexpr iterator() noexcept = default;
    constexpr iterator(servo_mask::iterator m, const T* v) noexcept : m_(m), v_(v) {}
    constexpr entry operator*() const noexcept { return {*m_, *v_}; }
    constexpr iterator& operator++() noexcept {
      ++m_;
      ++v_;
      return *this;
    }
    constexpr iterator operator++(int) noexcept {
      auto c = *this;
      ++*this;
      return c;
    }
    friend constexpr bool operator==(const iterator& a, const iterator& b) noexcept { return a.m_ == b.m_; }

   private:
    servo_mask::iterator m_{};
    const T* v_ = nullptr;
  };
  /** First entry. */
  constexpr iterator begin() const noexcept { return {mask_.begin(), values_.data()}; }
  /** Past the last entry. */
  constexpr iterator end() const noexcept { return {mask_.end(), values_.data() + size()}; }

  /** Same servos with the same values. */
  friend constexpr bool operator==(const servo_set& a, const servo_set& b) noexcept {
    if (a.mask_ != b.mask_) return false;
    for (std::size_t i = 0; i < a.count_; ++i)
      if (!(a.values_[i] == b.values_[i])) return false;
    return true;
  }

 private:
  servo_mask mask_{};
  std::uint8_t count_ = 0;
  std::array<T, ics_slots> values_{};
};

}  // namespace rcb4
