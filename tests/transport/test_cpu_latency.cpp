// The PM QoS guard: the kernel applies the request while the guard lives, and drops it after.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/transport/cpu_latency.hpp>

#include <catch2/catch.hpp>

#include <unistd.h>

namespace t = rcb4::transport;
using namespace std::chrono_literals;

TEST_CASE("cpu_latency_guard: holds the request while it lives, or says why it cannot", "[transport]") {
  const auto before = t::cpu_latency_bound_us();
  {
    t::cpu_latency_guard g(7us);
    if (::access("/dev/cpu_dma_latency", W_OK) != 0) {  // no permission (or no such file): nothing changes
      CHECK_FALSE(g.active());
      CHECK(g.error());
    } else {
      REQUIRE(g.active());
      CHECK_FALSE(g.error());
      // The kernel applies the smallest request of all holders: ours, unless another is smaller.
      CHECK(t::cpu_latency_bound_us() <= 7);
      CHECK(t::cpu_latency_bound_us() >= 0);
      t::cpu_latency_guard moved(std::move(g));
      CHECK(moved.active());
      CHECK_FALSE(g.active());  // NOLINT(bugprone-use-after-move): the moved-from guard holds nothing
    }
  }
  CHECK(t::cpu_latency_bound_us() == before);  // dropped with the guard
}
