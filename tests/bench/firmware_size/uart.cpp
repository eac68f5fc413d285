// The firmware-size bench's board support (uart.hpp): the MPS2 AN386's UART0 and SysTick.
// SPDX-License-Identifier: BSL-1.0
#include "uart.hpp"

namespace {
struct uart_regs {
  volatile std::uint32_t data;
  volatile std::uint32_t state;  // bit 0: TX full, bit 1: RX full
  volatile std::uint32_t ctrl;
};
uart_regs& uart0() noexcept { return *reinterpret_cast<uart_regs*>(0x40004000u); }
volatile std::uint32_t g_ms = 0;
}  // namespace

extern "C" void SysTick_Handler() { g_ms = g_ms + 1; }

namespace bench {
std::uint32_t now_ms() noexcept { return g_ms; }
void uart_put(std::uint8_t b) noexcept {
  while (uart0().state & 1u) {
  }
  uart0().data = b;
}
int uart_get(std::uint32_t deadline_ms) noexcept {
  while (!(uart0().state & 2u))
    if (static_cast<std::int32_t>(now_ms() - deadline_ms) >= 0) return -1;
  return static_cast<int>(uart0().data & 0xFFu);
}
bool uart_poll_in(std::uint8_t& b) noexcept {
  if (!(uart0().state & 2u)) return false;
  b = static_cast<std::uint8_t>(uart0().data & 0xFFu);
  return true;
}
bool uart_poll_out(std::uint8_t b) noexcept {
  if (uart0().state & 1u) return false;
  uart0().data = b;
  return true;
}
void finish(int status) noexcept {
  *reinterpret_cast<volatile std::uint32_t*>(0x40000000u) = static_cast<std::uint32_t>(status);
  for (;;) {
  }
}
}  // namespace bench
