// rcb4 — a value-or-error result usable in constant expressions and without exceptions.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/error.hpp>

#include <type_traits>
#include <utility>

namespace rcb4 {
namespace detail {
/// Deliberately not constexpr: reaching it in a constant expression is a compile error
/// naming the problem; at run time it traps (no exceptions needed in firmware).
inline void bad_result_access() noexcept { __builtin_trap(); }
}  // namespace detail

/**
 * Either a T or an rcb4::errc. Like std::expected (C++23) but constexpr in C++20 and usable
 * with -fno-exceptions: value() on an error fails to compile in a constant expression and
 * traps at run time, so check has_value() (or use value_or()) first.
 */
template <class T>
class [[nodiscard]] result {
  static_assert(std::is_default_constructible_v<T>, "result<T> needs a default-constructible T");

 public:
  using value_type = T;
  /** A successful result holding @p v. */
  constexpr result(T v) noexcept : value_(std::move(v)) {}  // NOLINT(google-explicit-constructor)
  /** A successful result whose value is built in place from @p args (no copy of a large T). */
  template <class... Args>
  constexpr explicit result(std::in_place_t, Args&&... args) noexcept : value_(std::forward<Args>(args)...) {}
  /** A failed result; @p e must not be errc{}. */
  constexpr result(errc e) noexcept : error_(e) {  // NOLINT(google-explicit-constructor)
    if (e == errc{}) detail::bad_result_access();
  }
  /** True when a value is held. */
  constexpr bool has_value() const noexcept { return error_ == errc{}; }
  /** Same as has_value(). */
  constexpr explicit operator bool() const noexcept { return has_value(); }
  /** The value; must hold one. */
  constexpr const T& value() const& noexcept {
    if (!has_value()) detail::bad_result_access();
    return value_;
  }
  /** The value; must hold one. */
  constexpr T& value() & noexcept {
    if (!has_value()) detail::bad_result_access();
    return value_;
  }
  /** The value, moved out; must hold one. */
  constexpr T&& value() && noexcept {
    if (!has_value()) detail::bad_result_access();
    return std::move(value_);
  }
  /** The value, or @p fallback on error. */
  constexpr T value_or(T fallback) const noexcept { return has_value() ? value_ : fallback; }
  /** The error, errc{} when a value is held. */
  constexpr errc error() const noexcept { return error_; }
  /** Access to the value; must hold one. */
  constexpr const T& operator*() const noexcept { return value(); }
  /** Access to the value's members; must hold one. */
  constexpr const T* operator->() const noexcept { return &value(); }

 private:
  T value_{};
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
