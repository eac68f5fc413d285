// Heap allocations made by the process so far (minus excluded threads) (the global operator new is replaced in
// alloc_count.cpp), for "allocations per operation" figures in benchmarks.
// SPDX-License-Identifier: BSL-1.0
#pragma once
#include <cstddef>

namespace rcb4::bench {
/** Number of calls to operator new so far (on threads not excluded). */
std::size_t allocations() noexcept;
/** Stops counting this thread's allocations (e.g. an in-process server's thread). */
void exclude_this_thread() noexcept;
}  // namespace rcb4::bench
