// rcb4 — the answer of an incremental parser: complete, need more bytes, or an error.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/result.hpp>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>

namespace rcb4 {
namespace detail {
/// Not constexpr: value() of a parse result still needing bytes stops a constant evaluation
/// here, naming the mistake; at run time it traps.
inline void value_read_before_the_frame_was_complete() noexcept { __builtin_trap(); }
}  // namespace detail

/** Outcome of feeding bytes to a parser. */
enum class parse_status : std::uint8_t {
  complete,   ///< a whole frame was parsed; `consumed` bytes belong to it
  need_more,  ///< the frame is not complete yet; at least `needed` more bytes are required
  error,      ///< the bytes are not a valid frame; `error` says why
};

/**
 * What a parser made of a byte span. "Need more" is a normal answer, not a failure: the first
 * byte of every frame is its length, so a reader can always ask for exactly `needed` bytes.
 * The value exists only when the frame is complete: value() before then fails to compile in a
 * constant expression and traps at run time, like result<T>::value() (check ok() first).
 */
template <class T>
class parse_result {
 public:
  parse_status status = parse_status::need_more;  ///< complete, need_more or error
  std::size_t consumed = 0;                       ///< bytes of the input that make up the frame (or the bad frame)
  std::size_t needed = 0;                         ///< with need_more: bytes still missing, at least 1
  errc error{};                                   ///< with error: what was wrong
  std::uint8_t command = 0;                       ///< CMD byte of the frame, when at least 2 bytes were seen

  /** True when a whole valid frame was parsed. */
  constexpr bool ok() const noexcept { return status == parse_status::complete; }
  /** The parsed value; only when ok(). */
  constexpr const T& value() const noexcept {
    if (!ok()) {
      if (status == parse_status::error && error != errc{}) detail::bad_result_access(error);
      detail::value_read_before_the_frame_was_complete();
    }
    return *value_;
  }
  /** The parser's last word: @p v parsed, the status complete. */
  constexpr void complete(T v) noexcept {
    value_.emplace(std::move(v));
    status = parse_status::complete;
    error = errc{};
  }

 private:
  std::optional<T> value_;  ///< engaged only once complete
};

}  // namespace rcb4
