// Heap allocations made by the whole process so far (the global operator new is replaced in
// alloc_count.cpp), for "allocations per operation" figures in benchmarks.
// SPDX-License-Identifier: BSL-1.0
#pragma once
#include <cstddef>

namespace rcb4::bench {
/** Number of calls to operator new so far. */
std::size_t allocations() noexcept;
}  // namespace rcb4::bench
