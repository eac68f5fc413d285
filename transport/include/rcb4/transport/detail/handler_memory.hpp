// rcb4 — a small pool for the client's asynchronous operations, so that a steady stream of
// exchanges allocates nothing (Asio's own per-thread cache keeps only two blocks).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <mutex>
#include <new>

namespace rcb4::transport::detail {

/**
 * A few fixed blocks handed out to the operations of one client (its timer wait, its posts, the
 * queued handlers), reused as they finish. Bigger requests, or more at once than there are
 * blocks, go to operator new. Thread-safe.
 */
class handler_memory {
 public:
  static constexpr std::size_t block_size = 512;  ///< bytes per block (an Asio operation, a handler)
  static constexpr std::size_t blocks = 8;        ///< operations in flight at once, at most

  handler_memory() = default;
  handler_memory(const handler_memory&) = delete;
  handler_memory& operator=(const handler_memory&) = delete;

  /** Memory for @p n bytes. */
  void* allocate(std::size_t n) {
    if (n <= block_size) {
      std::lock_guard lock(m_);
      for (std::size_t i = 0; i < blocks; ++i)
        if (!used_[i]) {
          used_[i] = true;
          return storage_[i].bytes;
        }
    }
    return ::operator new(n);
  }
  /** Gives back what allocate() returned. */
  void deallocate(void* p) noexcept {
    auto* b = static_cast<unsigned char*>(p);
    if (b >= storage_[0].bytes && b < storage_[0].bytes + sizeof storage_) {
      std::lock_guard lock(m_);
      used_[static_cast<std::size_t>(b - storage_[0].bytes) / sizeof(block)] = false;
      return;
    }
    ::operator delete(p);
  }

 private:
  struct block {
    alignas(std::max_align_t) unsigned char bytes[block_size];
  };
  std::mutex m_;
  std::array<block, blocks> storage_{};
  std::array<bool, blocks> used_{};
};

/**
 * A standard allocator on a shared handler_memory (an Asio associated allocator). Each copy
 * shares the pool, so the pool outlives every operation still holding memory from it (a
 * completion that runs after its client has gone).
 */
template <class T>
class handler_allocator {
 public:
  using value_type = T;  ///< what it allocates
  /** An allocator on @p mem. */
  explicit handler_allocator(std::shared_ptr<handler_memory> mem) noexcept : mem_(std::move(mem)) {}
  /** The same pool, for another type. */
  template <class U>
  handler_allocator(const handler_allocator<U>& other) noexcept : mem_(other.memory()) {}
  /** Memory for @p n objects. */
  T* allocate(std::size_t n) { return static_cast<T*>(mem_->allocate(n * sizeof(T))); }
  /** Gives back @p p (from allocate(@p n)). */
  void deallocate(T* p, std::size_t /*n*/) noexcept { mem_->deallocate(p); }
  /** The pool. */
  const std::shared_ptr<handler_memory>& memory() const noexcept { return mem_; }
  /** Same pool, same allocator. */
  template <class U>
  bool operator==(const handler_allocator<U>& other) const noexcept {
    return mem_ == other.memory();
  }

 private:
  std::shared_ptr<handler_memory> mem_;
};

}  // namespace rcb4::transport::detail
