// The board support of the example firmware: ARM's MPS2 AN386 (Cortex-M4) as Debian's
// qemu-system-arm emulates it. Everything the firmware touches outside the rcb4 codec is here:
// a polled UART, a millisecond clock and the debugger's semihosting calls (text out, exit status).
// Porting to another microcontroller means rewriting this file only.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>

namespace mps2 {

/** Starts the clock and UART0 (CMSDK APB UART at 0x40004000, TX and RX on, no interrupts). */
void init() noexcept;

/** Milliseconds since init(), counted by the SysTick interrupt. */
std::uint32_t now_ms() noexcept;

/**
 * The millisecond clock as a std::chrono clock (what rcb4's link reads), widened to 64 bits so that
 * it never wraps: now_ms() wraps after 49.7 days, and a deadline across the wrap would otherwise
 * lie 49 days ahead. Call now() at least once every 49 days (the link does, every exchange).
 */
struct clock {
  using rep = std::int64_t;                                     ///< ticks
  using period = std::milli;                                    ///< a millisecond each
  using duration = std::chrono::duration<rep, period>;          ///< a span of ticks
  using time_point = std::chrono::time_point<clock, duration>;  ///< ticks since init()
  /** Now (from the main thread only: it keeps the high word). */
  static time_point now() noexcept {
    static std::uint32_t last = 0;
    static std::int64_t wraps = 0;
    const std::uint32_t t = now_ms();
    if (t < last) wraps += std::int64_t{1} << 32;
    last = t;
    return time_point(duration(wraps + t));
  }
};

/** Sends @p b when the transmit register has room: true when it took it (never waits). */
bool uart_poll_out(std::uint8_t b) noexcept;

/** Takes a received byte into @p b: true when one was waiting (never waits). */
bool uart_poll_in(std::uint8_t& b) noexcept;

/** Writes @p text on the host's standard output (semihosting SYS_WRITE0). */
void print(const char* text) noexcept;

/** Ends the program with exit status @p code on the host (semihosting SYS_EXIT_EXTENDED). */
[[noreturn]] void exit(int code) noexcept;

/** A line of text built without printf (newlib's printf wants a heap): text, decimal, hex. */
class line {
 public:
  /** Appends @p s. */
  line& operator<<(const char* s) noexcept {
    while (*s && n_ + 1 < sizeof buf_) buf_[n_++] = *s++;
    buf_[n_] = 0;
    return *this;
  }
  /** Appends @p v in decimal. */
  line& operator<<(long v) noexcept {
    char d[21];  // a 64-bit long too
    int k = 0;
    const bool neg = v < 0;
    unsigned long u = neg ? 0UL - static_cast<unsigned long>(v) : static_cast<unsigned long>(v);
    do d[k++] = static_cast<char>('0' + u % 10);
    while ((u /= 10) != 0);
    if (neg) d[k++] = '-';
    char s[22];
    for (int i = 0; i < k; ++i) s[i] = d[k - 1 - i];
    s[k] = 0;
    return *this << static_cast<const char*>(s);
  }
  /** Appends @p v as 0x and @p digits hex digits. */
  line& hex(unsigned long v, int digits) noexcept {
    if (digits > 8) digits = 8;
    char s[11] = "0x";
    for (int i = 0; i < digits && i < 8; ++i) s[2 + i] = "0123456789ABCDEF"[(v >> (4 * (digits - 1 - i))) & 0xF];
    s[2 + (digits < 8 ? digits : 8)] = 0;
    return *this << static_cast<const char*>(s);
  }
  /** Prints the line and a newline. */
  void print() noexcept {
    *this << "\n";
    mps2::print(buf_);
    n_ = 0;
    buf_[0] = 0;
  }

 private:
  char buf_[320] = {};  // the longest codec message and a prefix
  std::size_t n_ = 0;
};

}  // namespace mps2
