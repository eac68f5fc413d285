// The firmware-size bench's board support: a polled UART (the MPS2's UART0 registers) and a
// millisecond counter, the least a firmware needs to talk to an RCB-4. Every job program of this
// bench uses it, so the figures compare only what the jobs add.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <cstdint>

namespace bench {

/** Milliseconds since reset (SysTick's handler counts them). */
std::uint32_t now_ms() noexcept;
/** Sends @p b, waiting for room. */
void uart_put(std::uint8_t b) noexcept;
/** The next byte received before @p deadline_ms, or -1. */
int uart_get(std::uint32_t deadline_ms) noexcept;
/** A byte received, if one is waiting (the link's polled UART). */
bool uart_poll_in(std::uint8_t& b) noexcept;
/** Sends @p b if there is room (the link's polled UART). */
bool uart_poll_out(std::uint8_t b) noexcept;
/** Reports the job's outcome (0 done) to the host and stops. */
[[noreturn]] void finish(int status) noexcept;

}  // namespace bench
