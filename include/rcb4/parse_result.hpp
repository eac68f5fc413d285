// rcb4 — the answer of an incremental parser: complete, need more bytes, or an error.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/error.hpp>

#include <cstddef>
#include <cstdint>

namespace rcb4 {

/** Outcome of feeding bytes to a parser. */
enum class parse_status : std::uint8_t {
  complete,   ///< a whole frame was parsed; `consumed` bytes belong to it
  need_more,  ///< the frame is not complete yet; at least `needed` more bytes are required
  error,      ///< the bytes are not a valid frame; `error` says why
};

/**
 * What a parser made of a byte span. "Need more" is a normal answer, not a failure: the first
 * byte of every frame is its length, so a reader can always ask for exactly `needed` bytes.
 */
template <class T>
struct parse_result {
  parse_status status = parse_status::need_more;  ///< complete, need_more or error
  T value{};                                      ///< the parsed value, when complete
  std::size_t consumed = 0;                       ///< bytes of the input that make up the frame (or the bad frame)
  std::size_t needed = 0;                         ///< with need_more: bytes still missing, at least 1
  errc error{};                                   ///< with error: what was wrong
  std::uint8_t command = 0;                       ///< CMD byte of the frame, when at least 2 bytes were seen

  /** True when a whole valid frame was parsed. */
  constexpr bool ok() const noexcept { return status == parse_status::complete; }
};

}  // namespace rcb4
