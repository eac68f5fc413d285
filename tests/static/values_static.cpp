// Compile-time checks of value types, servo sets, the memory map and the command concept.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/rcb4.hpp>

namespace {
using namespace rcb4;

// Every alternative of the variant is a Command.
template <class V>
struct all_commands;
template <class... T>
struct all_commands<std::variant<T...>> : std::bool_constant<(Command<T> && ...)> {};
static_assert(all_commands<command>::value);

// Ranges: run-time factories refuse what literals cannot express.
static_assert(ics_number::make(35).has_value() && ics_number::make(36).error() == errc::ics_out_of_range);
static_assert(ics_number::make(-1).error() == errc::ics_out_of_range);
static_assert(ram_address::make(0x048F).has_value() && !ram_address::make(0x0490));
static_assert(rom_address::make(0x3FFFF).has_value() && !rom_address::make(0x40000));
static_assert(transfer_size::make(0).error() == errc::transfer_size_out_of_range);
static_assert(transfer_size::make(129).error() == errc::transfer_size_out_of_range);
static_assert(servo_param::make(0).error() == errc::param_out_of_range && !servo_param::make(128));
static_assert(frames::make(256).error() == errc::frames_out_of_range);
static_assert(servo_position::make(16384).error() == errc::position_out_of_range);
static_assert(servo_position::make(0x8000).value().is_free() && servo_position::make(0x7FFF).value().is_hold());
static_assert(!servo_position::make(0x8001) && !servo_position::make(-1));
static_assert(shift_count::make(-128).error() == errc::shift_count_out_of_range);
static_assert(ics_number::make(300u).error() == errc::ics_out_of_range);  // no wrap to 44

// ICS number ↔ servo ID and SIO side (DOC-GEN p3).
static_assert(to_ics({16, sio_side::sio1_4}).value() == ics_number{32});
static_assert(to_ics({17, sio_side::sio5_8}).value() == ics_number{35});
static_assert(to_ics({18, sio_side::sio1_4}).error() == errc::ics_out_of_range);
static_assert(to_servo_address(ics_number{33}) == servo_address{16, sio_side::sio5_8});

// Servo sets: ascending order whatever the insertion order; popcount size; overwrite.
constexpr servo_set<servo_position> ordered() {
  servo_set<servo_position> s;
  s.insert(20, 7000);
  s.insert(3, 8000);
  s.insert(35, 9000);
  s.insert(3, 8100);  // overwrite
  s.insert(0, 7500);
  return s;
}
static_assert(ordered().size() == 4);
static_assert(ordered().values()[0] == servo_position{7500} && ordered().values()[1] == servo_position{8100} &&
              ordered().values()[2] == servo_position{7000} && ordered().values()[3] == servo_position{9000});
static_assert(ordered().mask().encode(update_flags::replace) ==
              std::array<std::uint8_t, 5>{0x09, 0x00, 0x10, 0x00, 0x08});
static_assert(ordered().mask().encode(update_flags::leave)[4] == 0x88);
constexpr bool erase_keeps_order() {
  auto s = ordered();
  s.erase(3);
  return s.size() == 3 && s.values()[1] == servo_position{7000} && !s.contains(3) &&
         *s.find(35) == servo_position{9000};
}
static_assert(erase_keeps_order());
static_assert(servo_mask::from_bits(std::uint64_t{1} << 36).error() == errc::ics_out_of_range);

// Config register: every word round-trips; fields sit where DOC-FW puts them (§6, §11.8).
constexpr bool config_round_trip() {
  for (unsigned w = 0; w <= 0xFFFF; w += 7)
    if (config_word::decode(static_cast<std::uint16_t>(w)).encode() != w) return false;
  return config_word::decode(0xFFFF).encode() == 0xFFFF;
}
static_assert(config_round_trip());
static_assert(config_word{.led = true}.encode() == 0x8000);
static_assert(config_word{.ics_baud = baud_code::b1250000}.encode() == 0x4000);  // bits 13-14 = 10
static_assert(config_word{.com_baud = baud_code::b1250000}.encode() == 0x0080);  // bits 6-7 = 10
static_assert(config_word{.period = output_period::ms20}.encode() == 0x0020);    // bits 4-5 = 10
static_assert(config_word::decode(0x000B).rom_program && config_word::decode(0x000B).vector_jump);
static_assert(bits_per_second(baud_code::b115200_alt) == 115200 && milliseconds(output_period::ms25) == 25);

// Memory map (§6, §8).
static_assert(ram::allocation_entry(35) == ram_address{0x0044 + 70});
static_assert(ram::ad(0).value() == ram_address{0x0022} && ram::ad(10).value() == ram_address{0x0036} && !ram::ad(11));
static_assert(servo_block::hth4_address(35) == ram_address{0x0090 + 700});
static_assert(motion_address(hth4_2_2, 1).value() == rom_address{0x000B80});
static_assert(motion_address(hth4_2_2, 120).value() == rom_address{0x000B80 + 119 * 2048});
static_assert(motion_address(hth4_2_2, 121).error() == errc::motion_out_of_range);
static_assert(motion_address(hth4_1_3, 2).value() == rom_address{0x000BB8 + 4864});
static_assert(krr::encode_buttons(0x0140) == std::array<std::uint8_t, 2>{0x01, 0x40});
static_assert(krr::decode_buttons(0x01, 0x40) ==
              (static_cast<unsigned>(krr_button::square) | static_cast<unsigned>(krr_button::circle)));
static_assert(hth4_ram::user_param(19).value() == ram_address{0x0488} && !hth4_ram::counter(11));

// Checksum (§2.1): the 2015 report's example 0x04 + 0xFE + 0x06 = 0x108 → 0x08.
constexpr std::uint8_t old_ping[] = {0x04, 0xFE, 0x06};
static_assert(checksum(old_ping) == 0x08);

// Error messages exist for every value.
constexpr bool every_error_has_message() {
  for (int e = 1; e <= static_cast<int>(errc_last); ++e)
    if (std::string_view(message(static_cast<errc>(e))) == "unknown rcb4 error") return false;
  return true;
}
static_assert(every_error_has_message());
}  // namespace

int main() { return 0; }
