// Replaces the global operator new/delete to count allocations (see alloc_count.hpp).
// SPDX-License-Identifier: BSL-1.0
#include "alloc_count.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

namespace {
std::atomic<std::size_t> g_allocations{0};
thread_local bool t_excluded = false;
}  // namespace

void rcb4::bench::exclude_this_thread() noexcept { t_excluded = true; }

std::size_t rcb4::bench::allocations() noexcept { return g_allocations.load(std::memory_order_relaxed); }

void* operator new(std::size_t n) {
  if (!t_excluded) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
