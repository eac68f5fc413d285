// rcb4 — a value-or-error result usable in constant expressions and without exceptions.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/error.hpp>

#include <memory>
#include <type_traits>
#include <utility>

namespace rcb4 {
namespace detail {
/// Deliberately not constexpr: reaching it in a constant expression is a compile error
/// naming the problem; at run time it traps (no exceptions needed in firmware).
inline void bad_result_access() noexcept { __builtin_trap(); }

/// One function per error, none constexpr: value() of a failed result in a constant expression
/// stops the compiler at the one that names the error held ("call to non-constexpr function
/// result_holds_error::ram_address_out_of_range()"). Never called at run time.
struct result_holds_error {
  static void buffer_too_small() noexcept { __builtin_trap(); }
  static void frame_too_short() noexcept { __builtin_trap(); }
  static void frame_too_long() noexcept { __builtin_trap(); }
  static void bad_frame_size() noexcept { __builtin_trap(); }
  static void bad_checksum() noexcept { __builtin_trap(); }
  static void unknown_command() noexcept { __builtin_trap(); }
  static void bad_type_byte() noexcept { __builtin_trap(); }
  static void reserved_bits_set() noexcept { __builtin_trap(); }
  static void ics_out_of_range() noexcept { __builtin_trap(); }
  static void ram_address_out_of_range() noexcept { __builtin_trap(); }
  static void rom_address_out_of_range() noexcept { __builtin_trap(); }
  static void ics_offset_out_of_range() noexcept { __builtin_trap(); }
  static void transfer_size_out_of_range() noexcept { __builtin_trap(); }
  static void literal_size_out_of_range() noexcept { __builtin_trap(); }
  static void operand_size_out_of_range() noexcept { __builtin_trap(); }
  static void ics_length_out_of_range() noexcept { __builtin_trap(); }
  static void position_out_of_range() noexcept { __builtin_trap(); }
  static void param_out_of_range() noexcept { __builtin_trap(); }
  static void frames_out_of_range() noexcept { __builtin_trap(); }
  static void shift_count_out_of_range() noexcept { __builtin_trap(); }
  static void servo_id_out_of_range() noexcept { __builtin_trap(); }
  static void motion_out_of_range() noexcept { __builtin_trap(); }
  static void empty_servo_set() noexcept { __builtin_trap(); }
  static void bad_condition() noexcept { __builtin_trap(); }
  static void unknown_parameter_kind() noexcept { __builtin_trap(); }
  static void destination_not_allowed() noexcept { __builtin_trap(); }
  static void flags_only_not_allowed() noexcept { __builtin_trap(); }
  static void bad_reply_length() noexcept { __builtin_trap(); }
  static void echo_mismatch() noexcept { __builtin_trap(); }
  static void bad_ack_code() noexcept { __builtin_trap(); }
  static void unexpected_ack() noexcept { __builtin_trap(); }
  static void nack() noexcept { __builtin_trap(); }
  static void baud_change_not_allowed() noexcept { __builtin_trap(); }
  static void unsupported_baud() noexcept { __builtin_trap(); }
  static void index_out_of_range() noexcept { __builtin_trap(); }
  static void motion_slot_empty() noexcept { __builtin_trap(); }
  static void motion_slot_not_a_frame() noexcept { __builtin_trap(); }
  static void servo_not_allocated() noexcept { __builtin_trap(); }
  static void bad_allocation_table() noexcept { __builtin_trap(); }
  static void ics_id_out_of_range() noexcept { __builtin_trap(); }
  static void ics_value_out_of_range() noexcept { __builtin_trap(); }
  static void ics_line_echo_mismatch() noexcept { __builtin_trap(); }
  static void ics_bad_reply() noexcept { __builtin_trap(); }
  static void ics_bad_eeprom() noexcept { __builtin_trap(); }
  static void link_timeout() noexcept { __builtin_trap(); }
  static void link_truncated() noexcept { __builtin_trap(); }
  static void link_echo() noexcept { __builtin_trap(); }
  static void link_line_error() noexcept { __builtin_trap(); }
  static void link_closed() noexcept { __builtin_trap(); }
  static void link_lost() noexcept { __builtin_trap(); }
  static void link_io_error() noexcept { __builtin_trap(); }
  static void link_reconnect_failed() noexcept { __builtin_trap(); }
  static void link_cancelled() noexcept { __builtin_trap(); }
};

/// Fails a value() of a result holding @p e: in a constant expression at the function named
/// after @p e; at run time a trap (one instruction: the names exist only for the compiler).
constexpr void bad_result_access(errc e) noexcept {
  if (!std::is_constant_evaluated()) return bad_result_access();
  switch (e) {
    case errc::buffer_too_small: return result_holds_error::buffer_too_small();
    case errc::frame_too_short: return result_holds_error::frame_too_short();
    case errc::frame_too_long: return result_holds_error::frame_too_long();
    case errc::bad_frame_size: return result_holds_error::bad_frame_size();
    case errc::bad_checksum: return result_holds_error::bad_checksum();
    case errc::unknown_command: return result_holds_error::unknown_command();
    case errc::bad_type_byte: return result_holds_error::bad_type_byte();
    case errc::reserved_bits_set: return result_holds_error::reserved_bits_set();
    case errc::ics_out_of_range: return result_holds_error::ics_out_of_range();
    case errc::ram_address_out_of_range: return result_holds_error::ram_address_out_of_range();
    case errc::rom_address_out_of_range: return result_holds_error::rom_address_out_of_range();
    case errc::ics_offset_out_of_range: return result_holds_error::ics_offset_out_of_range();
    case errc::transfer_size_out_of_range: return result_holds_error::transfer_size_out_of_range();
    case errc::literal_size_out_of_range: return result_holds_error::literal_size_out_of_range();
    case errc::operand_size_out_of_range: return result_holds_error::operand_size_out_of_range();
    case errc::ics_length_out_of_range: return result_holds_error::ics_length_out_of_range();
    case errc::position_out_of_range: return result_holds_error::position_out_of_range();
    case errc::param_out_of_range: return result_holds_error::param_out_of_range();
    case errc::frames_out_of_range: return result_holds_error::frames_out_of_range();
    case errc::shift_count_out_of_range: return result_holds_error::shift_count_out_of_range();
    case errc::servo_id_out_of_range: return result_holds_error::servo_id_out_of_range();
    case errc::motion_out_of_range: return result_holds_error::motion_out_of_range();
    case errc::empty_servo_set: return result_holds_error::empty_servo_set();
    case errc::bad_condition: return result_holds_error::bad_condition();
    case errc::unknown_parameter_kind: return result_holds_error::unknown_parameter_kind();
    case errc::destination_not_allowed: return result_holds_error::destination_not_allowed();
    case errc::flags_only_not_allowed: return result_holds_error::flags_only_not_allowed();
    case errc::bad_reply_length: return result_holds_error::bad_reply_length();
    case errc::echo_mismatch: return result_holds_error::echo_mismatch();
    case errc::bad_ack_code: return result_holds_error::bad_ack_code();
    case errc::unexpected_ack: return result_holds_error::unexpected_ack();
    case errc::nack: return result_holds_error::nack();
    case errc::baud_change_not_allowed: return result_holds_error::baud_change_not_allowed();
    case errc::unsupported_baud: return result_holds_error::unsupported_baud();
    case errc::index_out_of_range: return result_holds_error::index_out_of_range();
    case errc::motion_slot_empty: return result_holds_error::motion_slot_empty();
    case errc::motion_slot_not_a_frame: return result_holds_error::motion_slot_not_a_frame();
    case errc::servo_not_allocated: return result_holds_error::servo_not_allocated();
    case errc::bad_allocation_table: return result_holds_error::bad_allocation_table();
    case errc::ics_id_out_of_range: return result_holds_error::ics_id_out_of_range();
    case errc::ics_value_out_of_range: return result_holds_error::ics_value_out_of_range();
    case errc::ics_line_echo_mismatch: return result_holds_error::ics_line_echo_mismatch();
    case errc::ics_bad_reply: return result_holds_error::ics_bad_reply();
    case errc::ics_bad_eeprom: return result_holds_error::ics_bad_eeprom();
    case errc::link_timeout: return result_holds_error::link_timeout();
    case errc::link_truncated: return result_holds_error::link_truncated();
    case errc::link_echo: return result_holds_error::link_echo();
    case errc::link_line_error: return result_holds_error::link_line_error();
    case errc::link_closed: return result_holds_error::link_closed();
    case errc::link_lost: return result_holds_error::link_lost();
    case errc::link_io_error: return result_holds_error::link_io_error();
    case errc::link_reconnect_failed: return result_holds_error::link_reconnect_failed();
    case errc::link_cancelled: return result_holds_error::link_cancelled();
  }
  bad_result_access();
}
}  // namespace detail

/**
 * Either a T or an rcb4::errc. Like std::expected (C++23) but constexpr in C++20 and usable
 * with -fno-exceptions: value() on an error fails to compile in a constant expression and
 * traps at run time, so check has_value() (or use value_or()) first. T need not be
 * default-constructible: a failed result holds no T at all (the error is the discriminant).
 */
template <class T>
class [[nodiscard]] result {
  static_assert(!std::is_reference_v<T> && !std::is_same_v<std::remove_cv_t<T>, errc>,
                "result<T> holds a value type other than errc");
  // Which copies and moves stay trivial (T's are): the codec's commands keep a trivial result.
  static constexpr bool trivial_copy = std::is_trivially_copy_constructible_v<T>;
  static constexpr bool trivial_move = std::is_trivially_move_constructible_v<T>;
  static constexpr bool trivial_end = std::is_trivially_destructible_v<T>;
  static constexpr bool trivial_copy_assign = std::is_trivially_copy_assignable_v<T> && trivial_copy && trivial_end;
  static constexpr bool trivial_move_assign = std::is_trivially_move_assignable_v<T> && trivial_move && trivial_end;

 public:
  using value_type = T;
  /** A successful result holding @p v. */
  constexpr result(T v) noexcept : value_(std::move(v)) {}  // NOLINT(google-explicit-constructor)
  /** A successful result whose value is built in place from @p args (no copy of a large T). */
  template <class... Args>
  constexpr explicit result(std::in_place_t, Args&&... args) noexcept : value_(std::forward<Args>(args)...) {}
  /** A failed result; @p e must not be errc{}. */
  constexpr result(errc e) noexcept : none_(), error_(e) {  // NOLINT(google-explicit-constructor)
    if (e == errc{}) detail::bad_result_access();
  }

  // Copies and moves: trivial where T's are (the codec's commands), else member-wise.
  constexpr result(const result&) noexcept requires trivial_copy = default;
  constexpr result(const result& o) noexcept : none_(), error_(o.error_) {
    if (has_value()) std::construct_at(&value_, o.value_);
  }
  constexpr result(result&&) noexcept requires trivial_move = default;
  constexpr result(result&& o) noexcept : none_(), error_(o.error_) {
    if (has_value()) std::construct_at(&value_, std::move(o.value_));
  }
  constexpr result& operator=(const result&) noexcept requires trivial_copy_assign = default;
  constexpr result& operator=(const result& o) noexcept {
    if (this == &o) return *this;
    if (o.has_value())
      assign_value(o.value_);
    else
      assign_error(o.error_);
    return *this;
  }
  constexpr result& operator=(result&&) noexcept requires trivial_move_assign = default;
  constexpr result& operator=(result&& o) noexcept {
    if (this == &o) return *this;
    if (o.has_value())
      assign_value(std::move(o.value_));
    else
      assign_error(o.error_);
    return *this;
  }
  constexpr ~result() requires trivial_end = default;
  constexpr ~result() {
    if (has_value()) value_.~T();
  }

  /** True when a value is held. */
  constexpr bool has_value() const noexcept { return error_ == errc{}; }
  /** Same as has_value(). */
  constexpr explicit operator bool() const noexcept { return has_value(); }
  /** The value; must hold one. */
  constexpr const T& value() const& noexcept {
    if (!has_value()) detail::bad_result_access(error_);
    return value_;
  }
  /** The value; must hold one. */
  constexpr T& value() & noexcept {
    if (!has_value()) detail::bad_result_access(error_);
    return value_;
  }
  /** The value, moved out; must hold one. */
  constexpr T&& value() && noexcept {
    if (!has_value()) detail::bad_result_access(error_);
    return std::move(value_);
  }
  /** The value, or @p fallback on error. */
  constexpr T value_or(T fallback) const& noexcept { return has_value() ? value_ : std::move(fallback); }
  /** The error, errc{} when a value is held. */
  constexpr errc error() const noexcept { return error_; }
  /** Access to the value; must hold one. */
  constexpr const T& operator*() const noexcept { return value(); }
  /** Access to the value's members; must hold one. */
  constexpr const T* operator->() const noexcept { return &value(); }

  /**
   * @p f(value) when a value is held (f returns a result of its own), else this error: chains steps
   * that can each fail, as std::expected::and_then.
   */
  template <class F>
  constexpr auto and_then(F&& f) const& noexcept {
    using R = std::remove_cvref_t<decltype(std::declval<F>()(std::declval<const T&>()))>;
    if (!has_value()) return R(error_);
    return std::forward<F>(f)(value_);
  }
  /** @p f(value), as a result, when a value is held, else this error (std::expected::transform). */
  template <class F>
  constexpr auto transform(F&& f) const& noexcept {
    using U = std::remove_cvref_t<decltype(std::declval<F>()(std::declval<const T&>()))>;
    if constexpr (std::is_void_v<U>) {
      if (has_value()) std::forward<F>(f)(value_);
      return result<void>(error_);
    } else {
      if (!has_value()) return result<U>(error_);
      return result<U>(std::forward<F>(f)(value_));
    }
  }
  /** This result when a value is held, else @p f(error) (a result of T): recovery from a failure. */
  template <class F>
  constexpr result or_else(F&& f) const& noexcept {
    if (has_value()) return *this;
    return std::forward<F>(f)(error_);
  }

 private:
  template <class V>
  constexpr void assign_value(V&& v) noexcept {
    if (has_value()) {
      value_ = std::forward<V>(v);
    } else {
      std::construct_at(&value_, std::forward<V>(v));
      error_ = errc{};
    }
  }
  constexpr void assign_error(errc e) noexcept {
    if (has_value()) {
      value_.~T();
      std::construct_at(&none_);
    }
    error_ = e;
  }

  struct empty {};
  union {
    empty none_;  ///< active while an error is held
    T value_;     ///< active while error_ == errc{}
  };
  errc error_{};
};

/** A result with no value: success or an errc. */
template <>
class [[nodiscard]] result<void> {
 public:
  /** Success. */
  constexpr result() noexcept = default;
  /** Failure with @p e (errc{} means success). */
  constexpr result(errc e) noexcept : error_(e) {}  // NOLINT(google-explicit-constructor)
  /** True on success. */
  constexpr bool has_value() const noexcept { return error_ == errc{}; }
  /** Same as has_value(). */
  constexpr explicit operator bool() const noexcept { return has_value(); }
  /** The error, errc{} on success. */
  constexpr errc error() const noexcept { return error_; }

 private:
  errc error_{};
};

}  // namespace rcb4

/// Propagates the error of a result-returning expression, else binds its value to @p var.
#define RCB4_TRY(var, expr)                                     \
  auto var##_result_ = (expr);                                  \
  if (!var##_result_.has_value()) return var##_result_.error(); \
  auto var = std::move(var##_result_).value()
