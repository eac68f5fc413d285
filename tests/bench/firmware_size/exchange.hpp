// The firmware-size bench's exchange, as a firmware author writes it from docs/codec.md: the frame
// written, the reply read until parse_reply says it is whole (its size, checksum, kind and length
// checked against the command's expected shape), 100 ms at most. One template for both jobs: a
// concrete command type (job_codec.cpp) or the rcb4::command variant (job_variant.cpp), through
// the codec's overloads of serialize() and expected_reply() for each.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/rcb4.hpp>

#include "uart.hpp"

#include <array>

namespace bench {

// One program per job: internal, as a firmware's own code is (and as the figures were measured).
namespace {

std::array<std::uint8_t, rcb4::max_reply_size> g_rx{};  // the reply (a data reply refers to it)

/** Sends @p c and reads its reply: the reply when it came whole and valid, else the error. */
template <class C>
rcb4::result<rcb4::reply> exchange(const C& c) noexcept {
  std::array<std::uint8_t, rcb4::max_request_size> tx{};
  const auto n = rcb4::serialize(c, tx);
  if (!n) return n.error();
  for (std::size_t i = 0; i < *n; ++i) uart_put(tx[i]);
  const std::uint32_t deadline = now_ms() + 100;
  std::size_t got = 0;
  for (;;) {
    const auto p = rcb4::parse_reply({g_rx.data(), got}, rcb4::expected_reply(c));
    if (p.ok()) return p.value();
    if (p.status == rcb4::parse_status::error) return p.error;
    for (std::size_t k = 0; k < p.needed; ++k) {
      const int b = uart_get(deadline);
      if (b < 0) return rcb4::errc::link_timeout;
      g_rx[got++] = static_cast<std::uint8_t>(b);
    }
  }
}

}  // namespace
}  // namespace bench
