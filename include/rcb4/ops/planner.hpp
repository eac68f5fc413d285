// rcb4 — the read planner: which MOV reads fetch a set of byte ranges in the least time.
// SPDX-License-Identifier: BSL-1.0
//
// One read of n bytes costs one exchange (adapter and board turnaround) plus its bytes on the
// wire: a 10-byte request and an (n + 3)-byte reply. Reading a gap between two ranges costs its
// bytes; a second exchange costs the overhead and 13 more bytes. The planner finds the exact
// optimum by dynamic programming over the ranges sorted by address (at most 128 bytes a read).
#pragma once

#include <rcb4/frame.hpp>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <limits>
#include <vector>

namespace rcb4::ops {

/** A byte range [address, address + size). */
struct byte_range {
  std::uint32_t address = 0;
  std::uint32_t size = 0;
  friend bool operator==(const byte_range&, const byte_range&) = default;
};

/** What a read costs on a given link. */
struct link_cost {
  std::chrono::nanoseconds byte_time{88'000};    ///< one byte on the wire (8E1: 11 bits; default 1.25 Mbaud)
  std::chrono::nanoseconds exchange{1'000'000};  ///< per-exchange overhead (FTDI low latency ≈ 1 ms)
  /** The cost of a link at @p baud with @p overhead per exchange. */
  static link_cost at(std::uint32_t baud, std::chrono::nanoseconds overhead) {
    return {std::chrono::nanoseconds(11'000'000'000LL / baud), overhead};
  }
  /** Time of one read of @p n bytes. */
  std::chrono::nanoseconds read(std::uint32_t n) const { return exchange + byte_time * (10 + n + 3); }
};

/** The reads (each ≤ @p read_limit bytes) that cover @p wanted in the least total time. */
inline std::vector<byte_range> plan_reads(std::vector<byte_range> wanted, link_cost cost,
                                          std::uint32_t read_limit = 128) {
  std::sort(wanted.begin(), wanted.end(), [](auto& a, auto& b) { return a.address < b.address; });
  // Merge overlapping or touching ranges first: reading them apart never helps.
  std::vector<byte_range> r;
  for (const auto& w : wanted) {
    if (w.size == 0) continue;
    if (!r.empty() && w.address <= r.back().address + r.back().size) {
      const auto end = std::max(r.back().address + r.back().size, w.address + w.size);
      r.back().size = end - r.back().address;
    } else {
      r.push_back(w);
    }
  }
  // Split anything longer than one read.
  std::vector<byte_range> parts;
  for (const auto& x : r)
    for (std::uint32_t off = 0; off < x.size; off += read_limit)
      parts.push_back({x.address + off, std::min(read_limit, x.size - off)});
  const std::size_t n = parts.size();
  std::vector<std::int64_t> best(n + 1, std::numeric_limits<std::int64_t>::max());
  std::vector<std::size_t> from(n + 1, 0);
  best[0] = 0;
  for (std::size_t j = 1; j <= n; ++j) {
    for (std::size_t i = j; i-- > 0;) {  // parts i..j-1 in one read
      const std::uint32_t span = parts[j - 1].address + parts[j - 1].size - parts[i].address;
      if (span > read_limit) break;
      const auto c = best[i] + cost.read(span).count();
      if (c < best[j]) {
        best[j] = c;
        from[j] = i;
      }
    }
  }
  std::vector<byte_range> plan;
  for (std::size_t j = n; j > 0; j = from[j]) {
    const std::size_t i = from[j];
    plan.push_back({parts[i].address, parts[j - 1].address + parts[j - 1].size - parts[i].address});
  }
  std::reverse(plan.begin(), plan.end());
  return plan;
}

}  // namespace rcb4::ops
