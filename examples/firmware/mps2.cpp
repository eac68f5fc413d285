// MPS2 AN386 board support: startup (vector table, .data/.bss), SysTick milliseconds, CMSDK UART0,
// semihosting. Register layouts: ARM's CMSDK APB UART and the Cortex-M4 SysTick (ARMv7-M).
// SPDX-License-Identifier: BSL-1.0
#include "mps2.hpp"

#include <cstring>

namespace {

volatile std::uint32_t& reg(std::uintptr_t address) noexcept {
  return *reinterpret_cast<volatile std::uint32_t*>(address);
}

// CMSDK APB UART0.
constexpr std::uintptr_t uart0 = 0x40004000;
constexpr std::uintptr_t uart_data = uart0 + 0x00, uart_state = uart0 + 0x04, uart_ctrl = uart0 + 0x08,
                         uart_bauddiv = uart0 + 0x10;
constexpr std::uint32_t state_tx_full = 1u << 0, state_rx_full = 1u << 1;
constexpr std::uint32_t ctrl_tx_enable = 1u << 0, ctrl_rx_enable = 1u << 1;

// SysTick on the processor clock: QEMU's MPS2 runs it at 25 MHz, so 25000 counts are 1 ms.
constexpr std::uintptr_t syst_csr = 0xE000E010, syst_rvr = 0xE000E014, syst_cvr = 0xE000E018;
constexpr std::uint32_t csr_enable = 1u << 0, csr_tickint = 1u << 1, csr_processor_clock = 1u << 2;
constexpr std::uint32_t sysclk_hz = 25'000'000;

volatile std::uint32_t g_ms = 0;  // counted by systick_handler

// Semihosting (ARM's "Semihosting for AArch32 and AArch64"): BKPT 0xAB, operation in r0, argument in r1.
constexpr int sys_write0 = 0x04, sys_exit_extended = 0x20;
constexpr std::uint32_t adp_stopped_application_exit = 0x20026;

int semihost(int op, const void* arg) noexcept {
  int result;
  asm volatile("mov r0, %1\n\tmov r1, %2\n\tbkpt 0xAB\n\tmov %0, r0"
               : "=r"(result)
               : "r"(op), "r"(arg)
               : "r0", "r1", "memory");
  return result;
}

}  // namespace

namespace mps2 {

void init() noexcept {
  reg(syst_rvr) = sysclk_hz / 1000 - 1;
  reg(syst_cvr) = 0;
  reg(syst_csr) = csr_enable | csr_tickint | csr_processor_clock;
  // QEMU ignores the divider; a real CMSDK UART wants sysclk / baud (>= 16). The RCB-4 speaks 8E1,
  // which this UART cannot: on real hardware pick a UART with even parity (e.g. an STM32 USART
  // with PCE and 9-bit words).
  reg(uart_bauddiv) = sysclk_hz / 115200;
  reg(uart_ctrl) = ctrl_tx_enable | ctrl_rx_enable;
}

std::uint32_t now_ms() noexcept { return g_ms; }

bool uart_poll_out(std::uint8_t b) noexcept {
  if (reg(uart_state) & state_tx_full) return false;
  reg(uart_data) = b;
  return true;
}

bool uart_poll_in(std::uint8_t& b) noexcept {
  if (!(reg(uart_state) & state_rx_full)) return false;
  b = static_cast<std::uint8_t>(reg(uart_data) & 0xFFu);
  return true;
}

void print(const char* text) noexcept { semihost(sys_write0, text); }

void exit(int code) noexcept {
  const std::uint32_t block[2] = {adp_stopped_application_exit, static_cast<std::uint32_t>(code)};
  semihost(sys_exit_extended, block);
  for (;;) {
  }
}

}  // namespace mps2

// --- startup: the vector table QEMU reads at address 0, then .data copied and .bss zeroed --------
extern "C" {
/** The application (main.cpp): its return value is the exit status. */
int firmware_main();
extern std::uint32_t __stack_top, __data_load, __data_start, __data_end, __bss_start, __bss_end;
extern void (*__init_array_start[])(), (*__init_array_end[])();

[[noreturn]] void reset_handler() {
  std::memcpy(&__data_start, &__data_load,
              static_cast<std::size_t>(reinterpret_cast<char*>(&__data_end) - reinterpret_cast<char*>(&__data_start)));
  std::memset(&__bss_start, 0,
              static_cast<std::size_t>(reinterpret_cast<char*>(&__bss_end) - reinterpret_cast<char*>(&__bss_start)));
  for (auto f = __init_array_start; f != __init_array_end; ++f) (*f)();
  mps2::exit(firmware_main());
}

/** One millisecond more (SysTick, exception 15). */
void systick_handler() { g_ms = g_ms + 1; }

/** Any fault (a trap from rcb4::result::value() on an error, a bad access) ends the run with 70. */
[[noreturn]] void fault_handler() {
  mps2::print("firmware: fault\n");
  mps2::exit(70);
}

__attribute__((section(".vectors"), used)) void* const vector_table[16] = {
    &__stack_top,                            // initial stack pointer
    reinterpret_cast<void*>(reset_handler),  // reset
    reinterpret_cast<void*>(fault_handler),  // NMI
    reinterpret_cast<void*>(fault_handler),  // hard fault
    reinterpret_cast<void*>(fault_handler),  // memory management
    reinterpret_cast<void*>(fault_handler),  // bus fault
    reinterpret_cast<void*>(fault_handler),  // usage fault (UDF from __builtin_trap)
    nullptr,
    nullptr,
    nullptr,
    nullptr,                                   // reserved
    reinterpret_cast<void*>(fault_handler),    // SVCall
    reinterpret_cast<void*>(fault_handler),    // debug monitor
    nullptr,                                   // reserved
    reinterpret_cast<void*>(fault_handler),    // PendSV
    reinterpret_cast<void*>(systick_handler),  // SysTick: the millisecond clock
};
}
