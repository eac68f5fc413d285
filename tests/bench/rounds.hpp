// Shared by the pty benchmarks: measurements taken in turns, in short rounds with a rotating
// order, summarised by medians (a noisy 2-core machine drifts from second to second), and the
// whole run done twice, the second time holding a 0 µs PM QoS request when the process may.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/transport/cpu_latency.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <vector>

namespace rcb4::bench {

/** The median of @p v. */
inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/**
 * Runs the measurements @p m (each returns µs per operation) for @p rounds rounds, rotating
 * their order every round; per measurement, its times.
 */
inline std::vector<std::vector<double>> take_turns(const std::vector<std::function<double()>>& m, int rounds) {
  std::vector<std::vector<double>> us(m.size());
  for (int r = 0; r < rounds; ++r)
    for (std::size_t k = 0; k < m.size(); ++k) {
      const std::size_t i = (k + static_cast<std::size_t>(r)) % m.size();
      us[i].push_back(m[i]());
    }
  return us;
}

/** The median over rounds of a[r] / b[r]: how fast b is next to a (times in µs). */
inline double ratio(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double> r;
  for (std::size_t i = 0; i < a.size(); ++i) r.push_back(a[i] / b[i]);
  return median(r);
}

/**
 * Runs @p pass with the CPUs' idle states as configured, then again holding a 0 µs PM QoS
 * request (cpu_latency_guard, as a control loop would; says why when it cannot). Returns 0.
 */
inline int two_passes(const std::function<void()>& pass) {
  std::printf("CPU idle states as configured (wake-up latency bound %lld us):\n",
              static_cast<long long>(transport::cpu_latency_bound_us()));
  pass();
  transport::cpu_latency_guard low(std::chrono::microseconds(0));
  if (!low.active()) {
    std::printf("\n(no second pass: a PM QoS request needs write access to /dev/cpu_dma_latency: %s)\n",
                low.error().message().c_str());
    return 0;
  }
  std::printf("\nholding the CPUs' wake-up latency at 0 us (cpu_latency_guard, as a control loop would):\n");
  pass();
  return 0;
}

}  // namespace rcb4::bench
