// The client's building blocks: its request queue and its operations' memory pool.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/transport/detail/fifo.hpp>
#include <rcb4/transport/detail/handler_memory.hpp>

#include <catch2/catch.hpp>

#include <memory>
#include <set>
#include <string>
#include <vector>

using rcb4::transport::detail::fifo;
using rcb4::transport::detail::handler_allocator;
using rcb4::transport::detail::handler_memory;

TEST_CASE("fifo: first in, first out, through growth and wrap-around", "[transport][detail]") {
  fifo<std::unique_ptr<int>> q;  // move-only, as the client's pending requests are
  CHECK(q.empty());
  int next_in = 0, next_out = 0;
  // Interleave pushes and pops so the ring wraps around several times and grows twice.
  for (int round = 0; round < 50; ++round) {
    for (int i = 0; i < round % 13; ++i) q.push_back(std::make_unique<int>(next_in++));
    for (int i = 0; i < round % 7 && !q.empty(); ++i) CHECK(*q.pop_front() == next_out++);
  }
  CHECK(q.size() == static_cast<std::size_t>(next_in - next_out));
  while (!q.empty()) CHECK(*q.pop_front() == next_out++);
  CHECK(next_out == next_in);
}

TEST_CASE("fifo: push_front goes out next, also when it makes the ring grow", "[transport][detail]") {
  fifo<std::string> q;
  q.push_back("b");
  q.push_back("c");
  q.push_back("d");
  q.push_back("e");   // full (4 slots)
  q.push_front("a");  // grows, then goes first
  std::vector<std::string> out;
  while (!q.empty()) out.push_back(q.pop_front());
  CHECK(out == std::vector<std::string>{"a", "b", "c", "d", "e"});
}

TEST_CASE("handler_memory: blocks are reused, and too many or too big go to the heap", "[transport][detail]") {
  handler_memory m;
  void* first = m.allocate(100);
  m.deallocate(first);
  CHECK(m.allocate(200) == first);  // the same block again: no allocation in steady state
  std::set<void*> held{first};
  for (std::size_t i = 1; i < handler_memory::blocks; ++i) held.insert(m.allocate(handler_memory::block_size));
  CHECK(held.size() == handler_memory::blocks);  // distinct blocks
  void* extra = m.allocate(8);                   // all blocks taken: from the heap
  CHECK(held.count(extra) == 0);
  void* big = m.allocate(handler_memory::block_size + 1);  // too big for a block: from the heap
  CHECK(held.count(big) == 0);
  m.deallocate(extra);
  m.deallocate(big);
  for (void* p : held) m.deallocate(p);
  CHECK(m.allocate(1) != nullptr);
}

TEST_CASE("handler_allocator: copies share the pool and keep it alive", "[transport][detail]") {
  auto pool = std::make_shared<handler_memory>();
  handler_allocator<int> a(pool);
  handler_allocator<double> b(a);
  CHECK(a == b);
  CHECK_FALSE(a == handler_allocator<int>(std::make_shared<handler_memory>()));
  int* p = a.allocate(4);
  pool.reset();  // the client has gone; an operation still holds memory
  CHECK(b.memory().use_count() == 2);
  p[3] = 7;
  CHECK(p[3] == 7);
  a.deallocate(p, 4);
}
