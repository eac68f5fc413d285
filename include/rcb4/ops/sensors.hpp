// rcb4 — sensors and I/O in one read each: AD channels and battery, PIO, KRR receiver.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/ops/operation.hpp>

#include <array>

namespace rcb4::ops {

/** The 11 AD measurements (raw − reference) and the supply voltage from AD0. */
struct analog_inputs {
  std::array<std::uint16_t, ram::ad_channels> values{};  ///< AD0 … AD10
  double battery_volts = 0;                              ///< AD0 × 25 / 1024 (DOC-FW)
};

/** PIO direction and levels. */
struct pio_state {
  std::uint16_t direction = 0;  ///< bit n: PIO n+1 is an output
  std::uint16_t value = 0;      ///< levels (10 bits)
};

/** What a KRR receiver (or a program emulating one) reports. */
struct receiver_state {
  std::uint16_t buttons = 0;                                ///< krr_button bits
  std::array<std::uint8_t, krr::analog_channels> analog{};  ///< PA1–PA4, 7-bit
};

namespace detail {
struct decode_analog {
  analog_inputs operator()(const reply& r) const {
    analog_inputs a;
    for (unsigned k = 0; k < ram::ad_channels; ++k) a.values[k] = r.u16(2 * k);
    a.battery_volts = battery_volts(a.values[0]);
    return a;
  }
};
struct decode_pio {
  pio_state operator()(const reply& r) const { return {r.u16(0), static_cast<std::uint16_t>(r.u16(2) & 0x03FFu)}; }
};
struct decode_receiver {
  receiver_state operator()(const reply& r) const {
    receiver_state s;
    s.buttons = krr::decode_buttons(r.bytes()[0], r.bytes()[1]);
    for (unsigned i = 0; i < krr::analog_channels; ++i) s.analog[i] = r.bytes()[2 + i];
    return s;
  }
};
}  // namespace detail

/** Reads AD0–AD10 (22 bytes at 0x0022) and the battery voltage. */
using read_analog = detail::single_read<analog_inputs, 0x0022, 22, detail::decode_analog>;
/** Reads PIO direction and levels (4 bytes at 0x0038). */
using read_pio = detail::single_read<pio_state, 0x0038, 4, detail::decode_pio>;
/** Reads the KRR button word and PA1–PA4 (6 bytes at 0x0350). */
using read_receiver = detail::single_read<receiver_state, 0x0350, 6, detail::decode_receiver>;

}  // namespace rcb4::ops
