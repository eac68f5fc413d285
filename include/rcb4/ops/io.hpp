// rcb4 — the board's program I/O: counters, user parameters, down-timers, PIO writes, and
// emulating a KRR receiver (protocol.md §6 RAM map). Counters and user parameters are where
// HTH4 projects keep them (rcb4::hth4_ram); timers and PIO are the firmware's own.
// SPDX-License-Identifier: BSL-1.0
//
// Reads are one MOV → COM each; writes are MOV literal → RAM frames whose bytes live in the
// command itself, so the operation can be kept and sent later.
#pragma once

#include <rcb4/ops/operation.hpp>

#include <array>

namespace rcb4::ops {

/** The 11 one-byte counters at 0x0457 (used by motions for loops). */
using counter_values = std::array<std::uint8_t, hth4_ram::counter_count>;
/** The 20 signed user parameters at 0x0462. */
using user_param_values = std::array<std::int16_t, hth4_ram::user_param_count>;
/** The 4 down-timers at 0x003C: 100 ms ticks, bit 15 set = stopped. */
using timer_values = std::array<std::uint16_t, ram::timers>;

namespace detail {
struct decode_counters {
  counter_values operator()(const reply& r) const {
    counter_values v{};
    for (std::size_t k = 0; k < v.size(); ++k) v[k] = r.bytes()[k];
    return v;
  }
};
struct decode_user_params {
  user_param_values operator()(const reply& r) const {
    user_param_values v{};
    for (std::size_t k = 0; k < v.size(); ++k) v[k] = static_cast<std::int16_t>(r.u16(2 * k));
    return v;
  }
};
struct decode_timers {
  timer_values operator()(const reply& r) const {
    timer_values v{};
    for (std::size_t k = 0; k < v.size(); ++k) v[k] = r.u16(2 * k);
    return v;
  }
};
/** One write of @p make(address) when @p index < @p count, else errc::index_out_of_range. */
template <class Make>
ack_sequence indexed_write(unsigned index, unsigned count, Make make) {
  if (index >= count) return ack_sequence({}, errc::index_out_of_range);
  return ack_sequence({make()});
}
}  // namespace detail

/** Reads the 11 counters (11 bytes at 0x0457). */
using read_counters = detail::single_read<counter_values, 0x0457, hth4_ram::counter_count, detail::decode_counters>;
/** Reads the 20 user parameters (40 bytes at 0x0462). */
using read_user_params =
    detail::single_read<user_param_values, 0x0462, 2 * hth4_ram::user_param_count, detail::decode_user_params>;
/** Reads the 4 down-timers (8 bytes at 0x003C). */
using read_timers = detail::single_read<timer_values, 0x003C, 2 * ram::timers, detail::decode_timers>;

/** Sets counter @p k (0–10) to @p value. */
inline detail::ack_sequence write_counter(unsigned k, std::uint8_t value) {
  return detail::indexed_write(k, hth4_ram::counter_count,
                               [&] { return detail::write_u8(detail::ram_at(hth4_ram::counters, k), value); });
}
/** Sets user parameter @p k (0–19) to @p value. */
inline detail::ack_sequence write_user_param(unsigned k, std::int16_t value) {
  return detail::indexed_write(k, hth4_ram::user_param_count, [&] {
    return detail::write_u16(detail::ram_at(hth4_ram::user_params, 2 * k), static_cast<std::uint16_t>(value));
  });
}
/** Sets down-timer @p k (0–3) to @p ticks (100 ms each; bit 15 = stopped). */
inline detail::ack_sequence write_timer(unsigned k, std::uint16_t ticks) {
  return detail::indexed_write(k, ram::timers,
                               [&] { return detail::write_u16(detail::ram_at(ram::timer, 2 * k), ticks); });
}

/** Sets PIO direction (bit n: PIO n+1 is an output) and output levels; 10 bits each. */
inline detail::ack_sequence write_pio(std::uint16_t direction, std::uint16_t value) {
  if ((direction | value) & ~0x03FFu) return detail::ack_sequence({}, errc::reserved_bits_set);
  return detail::ack_sequence(
      {detail::write_u16(ram::pio_direction, direction), detail::write_u16(ram::pio_value, value)});
}

/**
 * Emulates a KRR receiver: writes the button word (krr_button bits, high byte first, §11.11) and
 * PA1–PA4 (7-bit) where the board's program reads them. Undefined button bits fail with
 * errc::reserved_bits_set, an analog value over 127 with errc::param_out_of_range.
 */
inline detail::ack_sequence emulate_receiver(std::uint16_t buttons,
                                             std::array<std::uint8_t, krr::analog_channels> analog = {}) {
  if (buttons & ~krr::valid_buttons) return detail::ack_sequence({}, errc::reserved_bits_set);
  for (auto a : analog)
    if (a > 127) return detail::ack_sequence({}, errc::param_out_of_range);
  const auto b = krr::encode_buttons(buttons);
  const auto word = [](std::uint8_t lo, std::uint8_t hi) { return static_cast<std::uint16_t>(lo | (hi << 8)); };
  return detail::ack_sequence({detail::write_u16(krr::buttons, word(b[0], b[1])),
                               detail::write_u16(krr::analog, word(analog[0], analog[1])),
                               detail::write_u16(detail::ram_at(krr::analog, 2), word(analog[2], analog[3]))});
}

}  // namespace rcb4::ops
