// rcb4 — holding the CPUs' wake-up latency low while a control loop runs (Linux PM QoS).
// SPDX-License-Identifier: BSL-1.0
//
// Every exchange sleeps twice (the board's side and ours) until bytes arrive. A CPU that went
// into a deep idle state while waiting wakes some tens of µs late, on a virtual machine more:
// on the project's 2-core test machine a paced control cycle spends about 80 µs per exchange
// that way. Writing a latency bound to /dev/cpu_dma_latency and keeping the file open asks the
// kernel to keep every CPU in idle states that wake within that bound (0: poll, never sleep);
// closing it drops the request. This is what real-time tools (cyclictest, ROS 2 control setups)
// do. It costs power: hold it only while the loop runs.
#pragma once

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <system_error>
#include <utility>

namespace rcb4::transport {

/**
 * Holds a PM QoS request on the CPUs' wake-up latency for its lifetime. Needs write access to
 * /dev/cpu_dma_latency (root by default; a udev rule can grant a group). When the request
 * cannot be made, active() is false and error() says why; nothing else changes.
 */
class cpu_latency_guard {
 public:
  /** Asks for wake-ups within @p bound (0: the CPUs poll instead of sleeping). */
  explicit cpu_latency_guard(std::chrono::microseconds bound = std::chrono::microseconds(0)) {
    fd_ = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
    if (fd_ < 0) {
      error_ = std::error_code(errno, std::generic_category());
      return;
    }
    const auto us = static_cast<std::int32_t>(bound.count());
    if (::write(fd_, &us, sizeof us) != static_cast<ssize_t>(sizeof us)) {
      error_ = std::error_code(errno, std::generic_category());
      ::close(fd_);
      fd_ = -1;
    }
  }
  cpu_latency_guard(const cpu_latency_guard&) = delete;
  cpu_latency_guard& operator=(const cpu_latency_guard&) = delete;
  /** Takes over @p other's request. */
  cpu_latency_guard(cpu_latency_guard&& other) noexcept : fd_(std::exchange(other.fd_, -1)), error_(other.error_) {}
  /** Drops the request (closing the file is what ends it). */
  ~cpu_latency_guard() {
    if (fd_ >= 0) ::close(fd_);
  }
  /** Whether the kernel holds the request now. */
  bool active() const noexcept { return fd_ >= 0; }
  /** Why the request could not be made (permission_denied without root, for example). */
  std::error_code error() const noexcept { return error_; }

 private:
  int fd_ = -1;
  std::error_code error_;
};

/** The bound the kernel currently applies to CPU wake-ups, in µs (reads /dev/cpu_dma_latency; -1 when unreadable). */
inline std::int64_t cpu_latency_bound_us() {
  const int fd = ::open("/dev/cpu_dma_latency", O_RDONLY | O_CLOEXEC);
  if (fd < 0) return -1;
  std::int32_t us = -1;
  const bool ok = ::read(fd, &us, sizeof us) == static_cast<ssize_t>(sizeof us);
  ::close(fd);
  return ok ? us : -1;
}

}  // namespace rcb4::transport
