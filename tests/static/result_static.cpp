// Compile-time checks of result<T> and parse_result<T> (issue 42 R2, R6): a T with no default
// constructor, a T that owns memory, the chaining members, and parse results whose value exists
// only complete. Compiling is the test (linked into rcb4_static_tests; its main is values_static.cpp's).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/ics/commands.hpp>
#include <rcb4/rcb4.hpp>

#include <array>
#include <ranges>
#include <vector>

namespace {
using namespace rcb4;

// A value type with no default constructor, as an acting command is.
struct only_made {
  constexpr explicit only_made(int value) noexcept : v(value) {}
  int v;
};
static_assert(!std::is_default_constructible_v<only_made>);
constexpr result<only_made> made(int v) noexcept {
  if (v < 0) return errc::param_out_of_range;
  return only_made(v);
}
static_assert(made(3).value().v == 3 && made(-1).error() == errc::param_out_of_range);
static_assert(std::is_trivially_copyable_v<result<only_made>>);  // a small T stays trivially copied
static_assert(!std::is_default_constructible_v<result<single_servo>>);
static_assert(!std::is_default_constructible_v<const_servo> && !std::is_default_constructible_v<servo_params> &&
              !std::is_default_constructible_v<series_servo> && !std::is_default_constructible_v<single_servo> &&
              !std::is_default_constructible_v<logic> && !std::is_default_constructible_v<jump> &&
              !std::is_default_constructible_v<call> && !std::is_default_constructible_v<ics::write_eeprom> &&
              !std::is_default_constructible_v<ics::write_id> && !std::is_default_constructible_v<ics::set_position>);

// Chaining: and_then passes the value on or keeps the first error; transform maps the value.
static_assert(made(4).and_then([](const only_made& m) { return made(m.v - 10); }).error() == errc::param_out_of_range);
static_assert(made(-4).and_then([](const only_made&) -> result<int> { return 1; }).error() == errc::param_out_of_range);
static_assert(made(4).transform([](const only_made& m) { return m.v * 2; }).value() == 8);
static_assert(made(-4).or_else([](errc) -> result<only_made> { return only_made(0); }).value().v == 0);
static_assert(servo_position::make(7500)
                  .and_then([](servo_position p) { return servo_position::make(p.value() + 9000); })
                  .error() == errc::position_out_of_range);

// A T that owns memory: copied, moved, reassigned between value and error (constexpr allocation).
constexpr bool owning_round_trip() {
  result<std::vector<int>> a(std::vector<int>{1, 2, 3});
  result<std::vector<int>> b(errc::nack);
  b = a;           // error -> value
  a = errc::nack;  // value -> error
  if (a.has_value() || b.value().size() != 3) return false;
  result<std::vector<int>> c(std::move(b));
  b = result<std::vector<int>>(std::vector<int>{7});
  return c.value()[2] == 3 && b.value()[0] == 7;
}
static_assert(owning_round_trip());

// A parse result has a value only when complete: need_more and error hold none.
constexpr std::array<std::uint8_t, 4> ack{0x04, 0x0F, 0x06, 0x19};
static_assert(parse_reply(ack, reply_shape{0x0F, false, 0}).value().is_ack());
static_assert(!parse_reply(std::span(ack).first(2), reply_shape{0x0F, false, 0}).ok());
static_assert(parse_reply(std::span(ack).first(2), reply_shape{0x0F, false, 0}).needed == 2);

// Masks and sets are forward ranges (review R10): std::views and std::ranges algorithms take them.
static_assert(std::ranges::forward_range<servo_mask> && std::ranges::forward_range<servo_set<servo_position>>);
constexpr int even_servos() {
  const auto m = servo_mask::from_bits(0b10'0001'1001).value();  // ICS 0, 3, 4 and 9
  return static_cast<int>(std::ranges::count_if(m, [](ics_number n) { return n.value() % 2 == 0; }));
}
static_assert(even_servos() == 2);
}  // namespace
