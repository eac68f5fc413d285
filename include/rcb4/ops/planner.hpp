// rcb4 — the read planner: which MOV reads fetch a set of byte ranges in the least time.
// SPDX-License-Identifier: BSL-1.0
//
// One read of n bytes costs one exchange (adapter and board turnaround) plus its bytes on the
// wire: a 10-byte request and an (n + 3)-byte reply. Reading a gap between two ranges costs its
// bytes; a second exchange costs the overhead and 13 more bytes. The planner finds the exact
// optimum by dynamic programming over the ranges sorted by address (at most 128 bytes a read).
// plan_reads_fixed makes the same plan without the heap, for firmware.
#pragma once

#include <rcb4/frame.hpp>
#include <rcb4/ops/fixed_vector.hpp>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
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
  /** The cost of a link at @p baud with @p overhead per exchange; a baud of 0 (unknown) is taken as 115200, the
   * slowest. */
  static link_cost at(std::uint32_t baud, std::chrono::nanoseconds overhead) {
    return {std::chrono::nanoseconds(11'000'000'000LL / (baud ? baud : 115200u)), overhead};
  }
  /** Time of one read of @p n bytes. */
  std::chrono::nanoseconds read(std::uint32_t n) const { return exchange + byte_time * (10 + n + 3); }
};

namespace detail {
/**
 * Sorts @p wanted by address (in place), merges overlapping or touching ranges (reading them
 * apart never helps) and splits the result into parts of at most @p limit bytes, written to
 * @p out. Returns how many parts, or nothing when @p out is too small for them.
 */
inline std::optional<std::size_t> plan_parts(std::span<byte_range> wanted, std::uint32_t limit,
                                             std::span<byte_range> out) noexcept {
  // Insertion sort: a few dozen ranges, no recursion (a firmware's worst stack stays a number).
  for (std::size_t i = 1; i < wanted.size(); ++i)
    for (std::size_t j = i; j > 0 && wanted[j].address < wanted[j - 1].address; --j)
      std::swap(wanted[j], wanted[j - 1]);
  std::size_t n = 0;
  bool overflow = false;
  const auto emit = [&](byte_range x) {
    for (std::uint32_t off = 0; off < x.size; off += limit) {
      if (n == out.size()) {
        overflow = true;
        return;
      }
      out[n++] = {x.address + off, std::min(limit, x.size - off)};
    }
  };
  std::optional<byte_range> cur;
  for (const auto& w : wanted) {
    if (w.size == 0) continue;
    if (cur && w.address <= cur->address + cur->size) {
      cur->size = std::max(cur->address + cur->size, w.address + w.size) - cur->address;
    } else {
      if (cur) emit(*cur);
      cur = w;
    }
  }
  if (cur) emit(*cur);
  if (overflow) return std::nullopt;
  return n;
}

/**
 * The exact optimum over @p parts (sorted, apart, each ≤ @p limit): dynamic programming over
 * which consecutive parts share one read. @p best and @p from are scratch of parts.size() + 1;
 * the reads go to @p out (parts.size() at least). Returns how many reads.
 */
inline std::size_t choose_reads(std::span<const byte_range> parts, link_cost cost, std::uint32_t limit,
                                std::span<std::int64_t> best, std::span<std::size_t> from,
                                std::span<byte_range> out) noexcept {
  const std::size_t n = parts.size();
  std::fill(best.begin(), best.begin() + static_cast<std::ptrdiff_t>(n + 1), std::numeric_limits<std::int64_t>::max());
  best[0] = 0;
  for (std::size_t j = 1; j <= n; ++j) {
    for (std::size_t i = j; i-- > 0;) {  // parts i..j-1 in one read
      const std::uint32_t span = parts[j - 1].address + parts[j - 1].size - parts[i].address;
      if (span > limit) break;
      const auto c = best[i] + cost.read(span).count();
      if (c < best[j]) {
        best[j] = c;
        from[j] = i;
      }
    }
  }
  std::size_t count = 0;
  for (std::size_t j = n; j > 0; j = from[j]) ++count;
  std::size_t k = count;
  for (std::size_t j = n; j > 0; j = from[j]) {
    const std::size_t i = from[j];
    out[--k] = {parts[i].address, parts[j - 1].address + parts[j - 1].size - parts[i].address};
  }
  return count;
}
}  // namespace detail

/** The reads (each ≤ @p read_limit bytes, 1–128) that cover @p wanted in the least total time. */
inline std::vector<byte_range> plan_reads(std::vector<byte_range> wanted, link_cost cost,
                                          std::uint32_t read_limit = 128) {
  std::size_t bound = 0;  // merging never needs more parts than splitting each range alone
  for (const auto& w : wanted) bound += (w.size + read_limit - 1) / read_limit;
  std::vector<byte_range> parts(bound);
  const std::size_t n = detail::plan_parts(wanted, read_limit, parts).value_or(0);
  std::vector<std::int64_t> best(n + 1);
  std::vector<std::size_t> from(n + 1);
  std::vector<byte_range> plan(n);
  plan.resize(detail::choose_reads({parts.data(), n}, cost, read_limit, best, from, plan));
  return plan;
}

/**
 * plan_reads without the heap, written into @p out in place (for firmware): @p wanted is sorted
 * in place, and the scratch on the stack is about 20 bytes a range. False (out empty) when more
 * than N ranges are wanted or the plan needs more than N parts before merging reads.
 */
template <std::size_t N>
bool plan_reads_into(std::span<byte_range> wanted, link_cost cost, fixed_vector<byte_range, N>& out,
                     std::uint32_t read_limit = 128) noexcept {
  out.clear();
  if (wanted.size() > N) return false;
  std::array<byte_range, N> parts{};
  const auto n = detail::plan_parts(wanted, read_limit, parts);
  if (!n) return false;
  std::array<std::int64_t, N + 1> best{};
  std::array<std::size_t, N + 1> from{};
  out.resize(N);
  out.resize(detail::choose_reads({parts.data(), *n}, cost, read_limit, best, from, {out.data(), N}));
  return true;
}

/**
 * plan_reads without the heap (for firmware): the same reads, held inline; nothing when more
 * than N ranges are wanted or the plan needs more than N parts before merging reads.
 */
template <std::size_t N>
std::optional<fixed_vector<byte_range, N>> plan_reads_fixed(std::span<const byte_range> wanted, link_cost cost,
                                                            std::uint32_t read_limit = 128) noexcept {
  if (wanted.size() > N) return std::nullopt;
  std::array<byte_range, N> sorted{};
  std::copy(wanted.begin(), wanted.end(), sorted.begin());
  fixed_vector<byte_range, N> plan;
  if (!plan_reads_into<N>({sorted.data(), wanted.size()}, cost, plan, read_limit)) return std::nullopt;
  return plan;
}

}  // namespace rcb4::ops
