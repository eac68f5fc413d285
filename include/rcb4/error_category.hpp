// rcb4 — the codec's errors as std::error_code: the "rcb4" category. Included by the transport,
// which reports codec errors through std::error_code / boost::system::error_code; the codec
// itself and firmware do not need it (<rcb4/error.hpp> has the enum and its messages).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/error.hpp>

#include <string>
#include <system_error>

namespace rcb4 {

/** The std::error_category of rcb4::errc (the codec's); its name() is "rcb4". */
class codec_category_impl final : public std::error_category {
 public:
  /** The category name, "rcb4". */
  const char* name() const noexcept override { return "rcb4"; }
  /** The message of the errc value @p ev. */
  std::string message(int ev) const override { return rcb4::message(static_cast<errc>(ev)); }
};

/** The single instance of the codec's error category. */
inline const std::error_category& codec_category() noexcept {
  static const codec_category_impl instance;
  return instance;
}

/** Makes a std::error_code from @p e (found by ADL for `std::error_code ec = errc::...`). */
inline std::error_code make_error_code(errc e) noexcept { return {static_cast<int>(e), codec_category()}; }

}  // namespace rcb4

template <>
struct std::is_error_code_enum<rcb4::errc> : std::true_type {};
