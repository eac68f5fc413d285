// Commands: every alternative round-trips; golden frames split at every byte; every rejection.
// SPDX-License-Identifier: BSL-1.0
#include "golden.hpp"
#include "random_commands.hpp"

#include <rcb4/fmt.hpp>

#include <catch2/catch.hpp>

#include <vector>

using namespace rcb4;

namespace {
using all_command_types = command;  // an alias: the variant's commas would split the macro

/// The index of @p T among the variant's alternatives (most commands have no default to build one).
template <class T, class V>
struct alternative_index;
template <class T, class... Ts>
struct alternative_index<T, std::variant<Ts...>> {
  static constexpr std::uint32_t value = [] {
    constexpr bool same[] = {std::is_same_v<T, Ts>...};
    std::uint32_t i = 0;
    while (!same[i]) ++i;
    return i;
  }();
};
}  // namespace

TEMPLATE_LIST_TEST_CASE("every command round-trips: serialize, board-side parse, equal value", "[command]",
                        all_command_types) {
  testing::command_generator gen(0xC0DE + alternative_index<TestType, command>::value);
  for (int i = 0; i < 2000; ++i) {
    const TestType value = gen.make<TestType>();
    const command c{value};
    const auto frame = encode(c);
    INFO(fmt::format("{} :: {}", c, hex(frame.bytes())));
    REQUIRE(frame.size() == wire_size(c));
    REQUIRE(frame.size() <= max_request_size);
    REQUIRE(frame[0] == frame.size());
    REQUIRE(checksum_ok(frame.bytes()));
    const auto parsed = parse_command(frame.bytes(), testing::options_for(c));
    REQUIRE(parsed.ok());
    REQUIRE(parsed.consumed == frame.size());
    REQUIRE(std::holds_alternative<TestType>(parsed.value()));
    REQUIRE(std::get<TestType>(parsed.value()) == value);
    REQUIRE(encode(parsed.value()) == frame);
  }
}

TEMPLATE_LIST_TEST_CASE("serialize refuses a buffer one byte short", "[command]", all_command_types) {
  testing::command_generator gen(7);
  const TestType value = gen.make<TestType>();
  std::vector<std::uint8_t> buf(wire_size(value) - 1);
  auto r = serialize(value, buf);
  REQUIRE_FALSE(r.has_value());
  REQUIRE(r.error() == errc::buffer_too_small);
}

TEST_CASE("golden request frames parse identically when fed in pieces", "[command][golden]") {
  for (const auto& g : golden::requests) {
    INFO(g.name);
    for (std::size_t have = 0; have < g.frame.size(); ++have) {
      auto partial = parse_command(g.frame.first(have), g.options);
      REQUIRE(partial.status == parse_status::need_more);
      REQUIRE(partial.needed >= 1);
      REQUIRE(have + partial.needed <= g.frame.size());                 // never asks for more than the frame
      if (have >= 1) REQUIRE(have + partial.needed == g.frame.size());  // length known from byte 0
    }
    // Trailing bytes of the next frame are not consumed.
    std::vector<std::uint8_t> two(g.frame.begin(), g.frame.end());
    two.insert(two.end(), golden::ping_ack, golden::ping_ack + 4);
    auto first = parse_command(two, g.options);
    REQUIRE(first.ok());
    REQUIRE(first.consumed == g.frame.size());
    REQUIRE(first.value() == g.value);
    auto second = parse_command(std::span(two).subspan(first.consumed), g.options);
    REQUIRE(second.ok());
    REQUIRE(std::holds_alternative<ping>(second.value()));
  }
}

namespace {
struct bad_frame {
  const char* why;
  std::vector<std::uint8_t> body;  // SIZE..last payload byte; the test appends the right SUM
  errc expected;
  codec_options options{};
};

std::vector<std::uint8_t> with_sum(std::vector<std::uint8_t> b) {
  b.push_back(checksum(b));
  return b;
}
}  // namespace

TEST_CASE("board-side parse rejects every malformed command with the reason", "[command][errors]") {
  const std::vector<bad_frame> cases = {
      {"ping of 5 bytes", {0x05, 0xFE, 0x06, 0x00}, errc::bad_frame_size},
      {"ping with 07", {0x04, 0xFE, 0x07}, errc::reserved_bits_set},
      {"version of 4 bytes", {0x04, 0xFD, 0x00}, errc::bad_frame_size},
      {"unknown command 0x13", {0x03, 0x13}, errc::unknown_command},
      {"ARMH7-only 0xFB is not RCB-4", {0x04, 0xFB, 0x00}, errc::unknown_command},
      {"MOV with the S bit", {0x0A, 0x00, 0xA0, 0, 0, 0, 0x00, 0x00, 0x02}, errc::flags_only_not_allowed},
      {"MOV TYPE bit 6", {0x0A, 0x00, 0x60, 0, 0, 0, 0x00, 0x00, 0x02}, errc::bad_type_byte},
      {"MOV TYPE bit 2", {0x0A, 0x00, 0x24, 0, 0, 0, 0x00, 0x00, 0x02}, errc::bad_type_byte},
      {"MOV RAM destination, third byte set",
       {0x09, 0x00, 0x02, 0x00, 0x00, 0x01, 0x80, 0x00},
       errc::reserved_bits_set},
      {"MOV COM destination not zero", {0x0A, 0x00, 0x20, 0x01, 0, 0, 0x00, 0x00, 0x02}, errc::reserved_bits_set},
      {"MOV read past the end of RAM", {0x0A, 0x00, 0x20, 0, 0, 0, 0x80, 0x04, 0x20}, errc::ram_address_out_of_range},
      {"MOV RAM address 0x0490", {0x0A, 0x00, 0x20, 0, 0, 0, 0x90, 0x04, 0x02}, errc::ram_address_out_of_range},
      {"MOV size 0", {0x0A, 0x00, 0x20, 0, 0, 0, 0x00, 0x00, 0x00}, errc::transfer_size_out_of_range},
      {"MOV size 129", {0x0A, 0x00, 0x20, 0, 0, 0, 0x00, 0x00, 0x81}, errc::transfer_size_out_of_range},
      {"MOV ICS 36", {0x0A, 0x00, 0x21, 0, 0, 0, 0x04, 0x24, 0x02}, errc::ics_out_of_range},
      {"MOV ICS offset 255 + 2", {0x0A, 0x00, 0x21, 0, 0, 0, 0xFF, 0x03, 0x02}, errc::ics_offset_out_of_range},
      {"MOV RAM source in 11 bytes", {0x0B, 0x00, 0x20, 0, 0, 0, 0x00, 0x00, 0x02, 0x00}, errc::bad_frame_size},
      {"MOV ROM source in 10 bytes", {0x0A, 0x00, 0x23, 0, 0, 0, 0x00, 0x00, 0x02}, errc::bad_frame_size},
      {"MOV ROM 0x040000", {0x0B, 0x00, 0x23, 0, 0, 0, 0x00, 0x00, 0x04, 0x10}, errc::rom_address_out_of_range},
      {"MOV literal past RAM end", {0x09, 0x00, 0x02, 0x8F, 0x04, 0x00, 0x01, 0x02}, errc::ram_address_out_of_range},
      {"MOV ROM destination past the end",
       {0x09, 0x00, 0x32, 0xFF, 0xFF, 0x03, 0x01, 0x02},
       errc::rom_address_out_of_range},
      {"MOV with no source", {0x07, 0x00, 0x02, 0x00, 0x00, 0x00}, errc::bad_frame_size},
      {"AND to COM", {0x08, 0x01, 0x22, 0, 0, 0, 0x0F}, errc::destination_not_allowed},
      {"XOR to COM", {0x08, 0x03, 0x22, 0, 0, 0, 0x0F}, errc::destination_not_allowed},
      {"ADD of 3 bytes", {0x0A, 0x06, 0x00, 0x90, 0x00, 0x00, 0x62, 0x04, 0x03}, errc::operand_size_out_of_range},
      {"ADD to COM without opt-in", {0x09, 0x06, 0x22, 0, 0, 0, 0x01, 0x00}, errc::destination_not_allowed},
      {"NOT byte 7 set", {0x0A, 0x04, 0x00, 0x90, 0, 0, 0x00, 0x01, 0x02}, errc::reserved_bits_set},
      {"NOT with SRC bits", {0x0A, 0x04, 0x01, 0x90, 0, 0, 0x00, 0x00, 0x02}, errc::bad_type_byte},
      {"NOT to COM", {0x0A, 0x04, 0x20, 0, 0, 0, 0x00, 0x00, 0x02}, errc::destination_not_allowed},
      {"NOT in 9 bytes", {0x09, 0x04, 0x00, 0x90, 0, 0, 0x00, 0x00}, errc::bad_frame_size},
      {"NOT size 0", {0x0A, 0x04, 0x00, 0x90, 0, 0, 0x00, 0x00, 0x00}, errc::transfer_size_out_of_range},
      {"SHIFT count byte 128", {0x0A, 0x05, 0x00, 0x90, 0, 0, 0x00, 0x80, 0x01}, errc::shift_count_out_of_range},
      {"SHIFT byte 6 set", {0x0A, 0x05, 0x00, 0x90, 0, 0, 0x01, 0x03, 0x01}, errc::reserved_bits_set},
      {"SHIFT to COM", {0x0A, 0x05, 0x20, 0, 0, 0, 0x00, 0x03, 0x01}, errc::destination_not_allowed},
      {"JUMP COND bit 4", {0x07, 0x0B, 0x80, 0x0B, 0x00, 0x10}, errc::bad_condition},
      {"JUMP Z value without compare bit", {0x07, 0x0B, 0x80, 0x0B, 0x00, 0x01}, errc::bad_condition},
      {"CALL C value without compare bit", {0x07, 0x0C, 0x80, 0x0B, 0x00, 0x02}, errc::bad_condition},
      {"CALL ROM 0x040000", {0x07, 0x0C, 0x00, 0x00, 0x04, 0x00}, errc::rom_address_out_of_range},
      {"CALL in 8 bytes", {0x08, 0x0C, 0x80, 0x0B, 0x00, 0x00, 0x00}, errc::bad_frame_size},
      {"RETURN in 4 bytes", {0x04, 0x0D, 0x00}, errc::bad_frame_size},
      {"SINGLE ICS 36", {0x07, 0x0F, 0x24, 0x0A, 0x4C, 0x1D}, errc::ics_out_of_range},
      {"SINGLE ICS byte bit 6", {0x07, 0x0F, 0x40, 0x0A, 0x4C, 0x1D}, errc::reserved_bits_set},
      {"SINGLE position 0x4000", {0x07, 0x0F, 0x00, 0x0A, 0x00, 0x40}, errc::position_out_of_range},
      {"SINGLE in 6 bytes", {0x06, 0x0F, 0x00, 0x0A, 0x4C}, errc::bad_frame_size},
      {"CONST with no servo", {0x09, 0x10, 0, 0, 0, 0, 0, 0x0A}, errc::empty_servo_set},
      {"CONST mask of 2, one position", {0x0B, 0x10, 0x03, 0, 0, 0, 0, 0x0A, 0x4C, 0x1D}, errc::bad_frame_size},
      {"CONST mask bit 36", {0x0B, 0x10, 0, 0, 0, 0, 0x10, 0x0A, 0x4C, 0x1D}, errc::reserved_bits_set},
      {"CONST position 20000", {0x0B, 0x10, 0x01, 0, 0, 0, 0, 0x0A, 0x20, 0x4E}, errc::position_out_of_range},
      {"CONST shorter than its header", {0x05, 0x10, 0x01, 0x00}, errc::bad_frame_size},
      {"SERIES 10 bytes for one servo", {0x0A, 0x11, 0x01, 0, 0, 0, 0, 0x1E, 0x4C}, errc::bad_frame_size},
      {"SERIES with no servo", {0x08, 0x11, 0, 0, 0, 0, 0}, errc::empty_servo_set},
      {"PARAM SUB 3 (ARMH7 current limit)", {0x0A, 0x12, 0x01, 0, 0, 0, 0, 0x03, 0x64}, errc::unknown_parameter_kind},
      {"PARAM value 0", {0x0A, 0x12, 0x01, 0, 0, 0, 0, 0x02, 0x00}, errc::param_out_of_range},
      {"PARAM value 128", {0x0A, 0x12, 0x01, 0, 0, 0, 0, 0x02, 0x80}, errc::param_out_of_range},
      {"PARAM with the update-flag bit", {0x0A, 0x12, 0x01, 0, 0, 0, 0x80, 0x02, 0x64}, errc::reserved_bits_set},
      {"ICS 0x0E length 0", {0x09, 0x0E, 0x02, 0x00, 0x00, 0x04, 0x10, 0x04}, errc::ics_length_out_of_range},
      {"ICS 0x0E length 65", {0x09, 0x0E, 0x02, 0x41, 0x00, 0x04, 0x10, 0x04}, errc::ics_length_out_of_range},
      {"ICS 0x0E answer address 0x0490",
       {0x09, 0x0E, 0x02, 0x03, 0x00, 0x04, 0x90, 0x04},
       errc::ram_address_out_of_range},
      {"ICS 0x0E ICS 36", {0x09, 0x0E, 0x24, 0x03, 0x00, 0x04, 0x10, 0x04}, errc::ics_out_of_range},
  };
  for (const auto& c : cases) {
    INFO(c.why);
    const auto frame = with_sum(c.body);
    auto r = parse_command(frame, c.options);
    REQUIRE(r.status == parse_status::error);
    REQUIRE(r.error == c.expected);
    REQUIRE(r.consumed == frame.size());  // the board can skip the whole bad frame
    REQUIRE(r.command == frame[1]);       // and NACK the right command
  }
}

TEST_CASE("board-side parse: framing errors", "[command][errors]") {
  const std::uint8_t bad_sum[] = {0x04, 0xFE, 0x06, 0x09};
  auto r = parse_command(bad_sum);
  CHECK(r.error == errc::bad_checksum);
  CHECK(r.consumed == 4);
  const std::uint8_t tiny[] = {0x02, 0xFE};
  CHECK(parse_command(tiny).error == errc::frame_too_short);
  CHECK(parse_command(tiny).consumed == 1);
  const std::uint8_t huge[] = {0x81, 0x00};
  CHECK(parse_command(huge).error == errc::frame_too_long);
  CHECK(parse_command(std::span<const std::uint8_t>{}).status == parse_status::need_more);
}

TEST_CASE("disputed behaviours follow the options", "[command][disputed]") {
  // Arithmetic to COM (§11.6): refused by default, accepted with the opt-in, both directions.
  const auto add_com = with_sum({0x09, 0x06, 0x22, 0, 0, 0, 0x01, 0x00});
  CHECK(parse_command(add_com).error == errc::destination_not_allowed);
  auto ok = parse_command(add_com, codec_options{.allow_arith_to_com = true});
  REQUIRE(ok.ok());
  auto one = source::literal_u16(1);
  CHECK_FALSE(arith::make(arith_op::add, destination::com(), one).has_value());
  auto built = arith::make(arith_op::add, destination::com(), one, store_mode::store, arith::com_output::allow);
  REQUIRE(built.has_value());
  CHECK(encode(*built).bytes().size() == add_com.size());
  CHECK(std::equal(add_com.begin(), add_com.end(), encode(*built).begin()));

  // SHIFT (§11.5): the same byte means opposite directions under the two encodings.
  const auto shift_ff = with_sum({0x0A, 0x05, 0x00, 0x90, 0, 0, 0x00, 0xFF, 0x01});
  auto measured = parse_command(shift_ff);
  auto manual = parse_command(shift_ff, codec_options{.shift = shift_encoding::kondo_manual});
  REQUIRE(measured.ok());
  REQUIRE(manual.ok());
  CHECK(std::get<shift>(measured.value()).count().value() == -1);
  CHECK(std::get<shift>(manual.value()).count().value() == 1);
  for (int n = -127; n <= 127; ++n) {
    for (auto enc : {shift_encoding::measured_2015, shift_encoding::kondo_manual}) {
      auto c = shift_count::make(n).value();
      CHECK(shift::decode(shift::encode(c, enc), enc).value() == c);
    }
  }
}

TEST_CASE("host-side factories refuse what the board would refuse", "[command][errors]") {
  std::vector<std::uint8_t> big(122, 0xAB);
  CHECK(move::write_ram(0x0090, big).error() == errc::literal_size_out_of_range);
  CHECK(move::write_ram(0x0090, std::span(big).first(121)).has_value());
  CHECK(move::write_ram(0x0090, std::span(big).first(0)).error() == errc::literal_size_out_of_range);
  CHECK(wire_size(move::write_ram(0x0090, std::span(big).first(121)).value()) == 128);
  CHECK(move::read_ram(0x0480, 17).error() == errc::ram_address_out_of_range);
  CHECK(move::read_ram(0x0480, 16).has_value());
  CHECK(move::read_rom(0x3FFF0, 17).error() == errc::rom_address_out_of_range);
  CHECK(move::read_ics(0, 250, 7).error() == errc::ics_offset_out_of_range);
  CHECK(move::write_ics(0, 255, std::span(big).first(2)).error() == errc::ics_offset_out_of_range);
  CHECK(move::make(destination::ram(0x048F), source::ram(0x0090, 2).value()).error() == errc::ram_address_out_of_range);
  CHECK(logic::make(logic_op::or_, destination::com(), source::literal_u8(1)).error() == errc::destination_not_allowed);
  CHECK(arith::make(arith_op::mul, destination::ram(0x0090), source::ram(0x0092, 3).value()).error() ==
        errc::operand_size_out_of_range);
  CHECK(bit_not::make(destination::com(), 1).error() == errc::destination_not_allowed);
  CHECK(shift::make(destination::ram(0x048F), 1, 2).error() == errc::ram_address_out_of_range);
  CHECK(const_servo::make({}, 10).error() == errc::empty_servo_set);
  CHECK(series_servo::make(series_opt_in, {}).error() == errc::empty_servo_set);
  CHECK(servo_params::make(param_kind::speed, {}).error() == errc::empty_servo_set);
  CHECK(ics_exchange::make(0, 0, 0x0090, 0x0090).error() == errc::ics_length_out_of_range);
  CHECK(ics_exchange::make(0, 65, 0x0090, 0x0090).error() == errc::ics_length_out_of_range);
  CHECK(ics_exchange::make(0, 64, 0x0460, 0x0090).error() == errc::ram_address_out_of_range);
  CHECK(source::literal(big).error() == errc::literal_size_out_of_range);
}

TEST_CASE("a 36-servo CONST frame is 81 bytes in ascending ICS order", "[command][servo]") {
  servo_set<servo_position> all;
  for (int i = 35; i >= 0; --i) all.insert(ics_number::make(i).value(), servo_position::make(7000 + i).value());
  auto c = const_servo::make(all, 5).value();
  auto f = encode(c);
  REQUIRE(f.size() == 81);
  CHECK(f[2] == 0xFF);
  CHECK(f[3] == 0xFF);
  CHECK(f[4] == 0xFF);
  CHECK(f[5] == 0xFF);
  CHECK(f[6] == 0x0F);
  for (int i = 0; i < 36; ++i) {
    const auto at = static_cast<std::size_t>(8 + 2 * i);
    CHECK((f[at] | (f[at + 1] << 8)) == 7000 + i);
  }
}
