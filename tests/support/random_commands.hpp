// Random valid command values for property tests (round trips) and benchmarks.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/rcb4.hpp>

#include <deque>
#include <random>
#include <vector>

namespace rcb4::testing {

/** A deterministic generator of valid commands of each kind. */
class command_generator {
 public:
  explicit command_generator(std::uint32_t seed) : rng_(seed) {}

  int uniform(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  bool coin() { return uniform(0, 1) == 1; }

  ics_number ics() { return ics_number::make(uniform(0, 35)).value(); }
  servo_position position() {
    switch (uniform(0, 9)) {
      case 0: return servo_position::free();
      case 1: return servo_position::hold();
      default: return servo_position::make(uniform(0, 16383)).value();
    }
  }
  frames speed() { return frames::make(uniform(0, 255)).value(); }
  update_flags flags() { return coin() ? update_flags::leave : update_flags::replace; }
  store_mode mode() { return coin() ? store_mode::flags_only : store_mode::store; }

  /** A source of at most @p max_size bytes. */
  source src(int max_size = 128) {
    const int size = uniform(1, max_size);
    switch (uniform(0, 3)) {
      case 0:
        return source::ram(ram_address::make(uniform(0, 0x0490 - size)).value(), transfer_size::make(size).value())
            .value();
      case 1:
        return source::ics(ics(), static_cast<std::uint8_t>(uniform(0, 256 - size)), transfer_size::make(size).value())
            .value();
      case 2: {
        // Literals are views: the generator keeps the bytes alive for its whole life.
        auto& b = literals_.emplace_back(static_cast<std::size_t>(std::min(size, 121)));
        for (auto& x : b) x = static_cast<std::uint8_t>(uniform(0, 255));
        if (b.size() == 1 && coin()) return source::literal_u8(b[0]);
        return source::literal(b).value();
      }
      default:
        return source::rom(rom_address::make(uniform(0, 0x40000 - size)).value(), transfer_size::make(size).value())
            .value();
    }
  }
  /** A destination that can hold @p size bytes, COM allowed if @p com. */
  destination dst(std::size_t size, bool com) {
    const int s = static_cast<int>(size);
    switch (uniform(com ? 0 : 1, 4)) {
      case 0: return destination::com();
      case 1: return destination::ram(ram_address::make(uniform(0, 0x0490 - s)).value());
      case 2: return destination::ics(ics(), static_cast<std::uint8_t>(uniform(0, 256 - s)));
      default: return destination::rom(rom_address::make(uniform(0, 0x40000 - s)).value());
    }
  }
  template <class T>
  servo_set<T> set_of(auto make_value) {
    servo_set<T> s;
    const int n = uniform(1, 36);
    for (int i = 0; i < n; ++i) s.insert(ics(), make_value());
    return s;
  }

  template <class T>
  T make();

 private:
  std::mt19937 rng_;
  std::deque<std::vector<std::uint8_t>> literals_;
};

template <>
inline ping command_generator::make<ping>() {
  return ping(coin() ? ping_form::ack : ping_form::short_);
}
template <>
inline version command_generator::make<version>() {
  return {};
}
template <>
inline ret command_generator::make<ret>() {
  return {};
}
template <>
inline move command_generator::make<move>() {
  auto s = src();
  return move::make(dst(s.size(), true), s).value();
}
template <>
inline logic command_generator::make<logic>() {
  auto s = src();
  return logic::make(static_cast<logic_op>(uniform(1, 3)), dst(s.size(), false), s, mode()).value();
}
template <>
inline arith command_generator::make<arith>() {
  auto s = src(2);
  return arith::make(static_cast<arith_op>(uniform(6, 10)), dst(s.size(), false), s, mode()).value();
}
template <>
inline bit_not command_generator::make<bit_not>() {
  auto size = transfer_size::make(uniform(1, 128)).value();
  return bit_not::make(dst(size.value(), false), size, mode()).value();
}
template <>
inline shift command_generator::make<shift>() {
  auto size = transfer_size::make(uniform(1, 128)).value();
  return shift::make(dst(size.value(), false), shift_count::make(uniform(-127, 127)).value(), size,
                     coin() ? shift_encoding::measured_2015 : shift_encoding::kondo_manual, mode())
      .value();
}
template <>
inline jump command_generator::make<jump>() {
  condition c;
  if (coin()) c.zero = coin();
  if (coin()) c.carry = coin();
  return jump{rom_address::make(uniform(0, 0x3FFFF)).value(), c};
}
template <>
inline call command_generator::make<call>() {
  auto j = make<jump>();
  return call{j.target(), j.cond()};
}
template <>
inline ics_exchange command_generator::make<ics_exchange>() {
  const int len = uniform(1, 64);
  return ics_exchange::make(ics(), static_cast<std::uint8_t>(len), ram_address::make(uniform(0, 0x0490 - len)).value(),
                            ram_address::make(uniform(0, 0x048F)).value())
      .value();
}
template <>
inline single_servo command_generator::make<single_servo>() {
  return single_servo{ics(), position(), speed(), flags()};
}
template <>
inline const_servo command_generator::make<const_servo>() {
  return const_servo::make(set_of<servo_position>([this] { return position(); }), speed(), flags()).value();
}
template <>
inline series_servo command_generator::make<series_servo>() {
  return series_servo::make(series_opt_in, set_of<timed_position>([this] {
                              return timed_position{position(), speed()};
                            }),
                            flags())
      .value();
}
template <>
inline servo_params command_generator::make<servo_params>() {
  return servo_params::make(coin() ? param_kind::speed : param_kind::stretch,
                            set_of<servo_param>([this] { return servo_param::make(uniform(1, 127)).value(); }))
      .value();
}

/** The codec options a value of @p c needs to parse back (only SHIFT carries one). */
inline codec_options options_for(const command& c) {
  codec_options o;
  if (auto* s = std::get_if<shift>(&c)) o.shift = s->encoding();
  o.allow_arith_to_com = true;
  return o;
}

}  // namespace rcb4::testing
