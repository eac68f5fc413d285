// rcb4 — the decoder of a PARMRK-marked serial line: rcb4/link/line_marks.hpp (std only), which
// the transport's serial lines use. This name stays for code that included it from here.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/link/line_marks.hpp>

namespace rcb4::transport {
using link::line_marks;  ///< see rcb4/link/line_marks.hpp
}  // namespace rcb4::transport
