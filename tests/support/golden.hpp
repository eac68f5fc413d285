// Golden frames, written by hand from protocol.md (sections cited) and the 2015 report.
// Never produced by our serializer: each byte and checksum was worked out from the layouts.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/rcb4.hpp>

#include <array>
#include <cstdint>
#include <span>

namespace rcb4::golden {

using bytes = std::span<const std::uint8_t>;

/** A request frame and the command value it must be. */
struct request {
  const char* name;         ///< what it is
  const char* source;       ///< where the layout comes from
  bytes frame;              ///< the wire bytes
  command value;            ///< the same command built through the API
  codec_options options{};  ///< how to parse it (disputed encodings)
};

// clang-format off
inline constexpr std::uint8_t ping_ack[] = {0x04, 0xFE, 0x06, 0x08};
inline constexpr std::uint8_t ping_short[] = {0x03, 0xFE, 0x01};
inline constexpr std::uint8_t version_req[] = {0x03, 0xFD, 0x00};
inline constexpr std::uint8_t return_req[] = {0x03, 0x0D, 0x10};
inline constexpr std::uint8_t read_config[] = {0x0A, 0x00, 0x20, 0x00, 0x00, 0x00, 0x00, 0x00, 0x02, 0x2C};
inline constexpr std::uint8_t write_config_0080[] = {0x09, 0x00, 0x02, 0x00, 0x00, 0x00, 0x80, 0x00, 0x8B};
inline constexpr std::uint8_t write_config_000b[] = {0x09, 0x00, 0x02, 0x00, 0x00, 0x00, 0x0B, 0x00, 0x16};
inline constexpr std::uint8_t reset_pc_2_2[] = {0x11, 0x00, 0x02, 0x02, 0x00, 0x00, 0x4B, 0x04, 0x00,
                                                0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x64};
inline constexpr std::uint8_t call_motion1[] = {0x07, 0x0C, 0x80, 0x0B, 0x00, 0x00, 0x9E};
inline constexpr std::uint8_t call_motion3[] = {0x07, 0x0C, 0x80, 0x1B, 0x00, 0x00, 0xAE};
inline constexpr std::uint8_t jump_0b80[] = {0x07, 0x0B, 0x80, 0x0B, 0x00, 0x00, 0x9D};
inline constexpr std::uint8_t call_if_z[] = {0x07, 0x0C, 0x00, 0x10, 0x00, 0x05, 0x28};
inline constexpr std::uint8_t jump_if_not_c[] = {0x07, 0x0B, 0x00, 0x10, 0x00, 0x08, 0x2A};
inline constexpr std::uint8_t single_ics0[] = {0x07, 0x0F, 0x00, 0x0A, 0x4C, 0x1D, 0x89};
inline constexpr std::uint8_t single_free5[] = {0x07, 0x0F, 0x05, 0x00, 0x00, 0x80, 0x9B};
inline constexpr std::uint8_t single_free5_leave[] = {0x07, 0x0F, 0x85, 0x00, 0x00, 0x80, 0x1B};
inline constexpr std::uint8_t const_1_3[] = {0x0D, 0x10, 0x0A, 0x00, 0x00, 0x00, 0x00, 0x14,
                                             0x4C, 0x1D, 0x40, 0x1F, 0x03};
inline constexpr std::uint8_t const_0_35_leave[] = {0x0D, 0x10, 0x01, 0x00, 0x00, 0x00, 0x88, 0x01,
                                                    0xFF, 0x7F, 0xAC, 0x0D, 0xDE};
inline constexpr std::uint8_t series_2[] = {0x0B, 0x11, 0x04, 0x00, 0x00, 0x00, 0x00, 0x1E, 0x4C, 0x1D, 0xA7};
inline constexpr std::uint8_t stretch_0_1[] = {0x0B, 0x12, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01, 0x3C, 0x7F, 0xDC};
inline constexpr std::uint8_t speed_4[] = {0x0A, 0x12, 0x10, 0x00, 0x00, 0x00, 0x00, 0x02, 0x64, 0x92};
inline constexpr std::uint8_t read_ics3_pos[] = {0x0A, 0x00, 0x21, 0x00, 0x00, 0x00, 0x04, 0x03, 0x02, 0x34};
inline constexpr std::uint8_t write_ics3_target[] = {0x09, 0x00, 0x12, 0x06, 0x03, 0x00, 0x4C, 0x1D, 0x8D};
inline constexpr std::uint8_t read_rom_motion1[] = {0x0B, 0x00, 0x23, 0x00, 0x00, 0x00, 0x80, 0x0B, 0x00, 0x10, 0xC9};
inline constexpr std::uint8_t ram_to_rom_config[] = {0x0A, 0x00, 0x30, 0xDC, 0x05, 0x00, 0x00, 0x00, 0x02, 0x1D};
inline constexpr std::uint8_t literal_to_rom[] = {0x09, 0x00, 0x32, 0x00, 0x10, 0x00, 0xAA, 0x55, 0x4A};
inline constexpr std::uint8_t and_literal[] = {0x08, 0x01, 0x02, 0x90, 0x00, 0x00, 0x0F, 0xAA};
inline constexpr std::uint8_t xor_flags_only[] = {0x08, 0x03, 0x82, 0x91, 0x00, 0x00, 0xFF, 0x1D};
inline constexpr std::uint8_t not_2[] = {0x0A, 0x04, 0x00, 0x90, 0x00, 0x00, 0x00, 0x00, 0x02, 0xA0};
inline constexpr std::uint8_t shift_left3[] = {0x0A, 0x05, 0x00, 0x90, 0x00, 0x00, 0x00, 0x03, 0x01, 0xA3};
inline constexpr std::uint8_t shift_right1[] = {0x0A, 0x05, 0x00, 0x90, 0x00, 0x00, 0x00, 0xFF, 0x01, 0x9F};
inline constexpr std::uint8_t add_param[] = {0x09, 0x06, 0x02, 0x62, 0x04, 0x00, 0x01, 0x00, 0x78};
inline constexpr std::uint8_t sub_compare[] = {0x0A, 0x07, 0x80, 0x62, 0x04, 0x00, 0x64, 0x04, 0x02, 0x61};
inline constexpr std::uint8_t ics_raw[] = {0x09, 0x0E, 0x02, 0x03, 0x00, 0x04, 0x10, 0x04, 0x34};
// clang-format on

namespace detail {
constexpr std::uint8_t aa55[] = {0xAA, 0x55};
constexpr std::uint8_t zeros10[] = {0x4B, 0x04, 0x00, 0, 0, 0, 0, 0, 0, 0};
constexpr std::uint8_t x0f[] = {0x0F};
constexpr std::uint8_t xff[] = {0xFF};
constexpr std::uint8_t word1[] = {0x01, 0x00};
constexpr std::uint8_t w0080[] = {0x80, 0x00};
constexpr std::uint8_t w000b[] = {0x0B, 0x00};
constexpr std::uint8_t w7500[] = {0x4C, 0x1D};
}  // namespace detail

/** Every golden request, each with the API value it must equal. */
inline constexpr request requests[] = {
    {"ping, ACK form", "§4.11", ping_ack, ping{}},
    {"ping, short form", "§4.11", ping_short, ping{ping_form::short_}},
    {"version", "§4.10", version_req, version{}},
    {"return", "§4.4", return_req, ret{}},
    {"read config word (RAM 0x0000, 2 bytes → COM)", "§4.1, §8.1", read_config, move::read_ram(0x0000, 2).value()},
    {"write config 0x0080 (suspend-style write)", "§8.1 step 1", write_config_0080,
     move::write_ram(0x0000, detail::w0080).value()},
    {"write config 0x000B (resume-style write)", "§8.1 step 4", write_config_000b,
     move::write_ram(0x0000, detail::w000b).value()},
    {"reset PC to 0x00044B (HTH4 2.2)", "§8.1 step 2", reset_pc_2_2, move::write_ram(0x0002, detail::zeros10).value()},
    {"CALL motion 1 (HTH4 2.2, 0x000B80)", "§4.3, §8", call_motion1, call{0x000B80}},
    {"CALL motion 3 (HTH4 2.2, 0x001B80)", "§4.3, §8", call_motion3, call{0x001B80}},
    {"JUMP 0x000B80", "§4.3", jump_0b80, jump{0x000B80}},
    {"CALL 0x001000 if Z=1", "§4.3 COND", call_if_z, call{0x001000, condition{true, {}}}},
    {"JUMP 0x001000 if C=0", "§4.3 COND", jump_if_not_c, jump{0x001000, condition{{}, false}}},
    {"SINGLE ICS 0 → 7500 in 10 frames", "§4.6", single_ics0, single_servo{0, 7500, 10}},
    {"SINGLE ICS 5 FREE", "§4.6, §5", single_free5, single_servo{5, servo_position::free(), 0}},
    {"SINGLE ICS 5 FREE, leave update flags", "§4.6", single_free5_leave,
     single_servo{5, servo_position::free(), 0, update_flags::leave}},
    {"CONST ICS 1 → 7500, ICS 3 → 8000, 20 frames", "§4.7", const_1_3,
     const_servo::make({{1, 7500}, {3, 8000}}, 20).value()},
    {"CONST ICS 35 → 3500, ICS 0 → HOLD (added out of order), leave flags", "§4.7", const_0_35_leave,
     const_servo::make({{35, 3500}, {0, servo_position::hold()}}, 1, update_flags::leave).value()},
    {"SERIES ICS 2 → 7500 in 30 frames", "§4.8", series_2,
     series_servo::make(series_opt_in, {{2, {7500, 30}}}).value()},
    {"STRETCH ICS 0 = 60, ICS 1 = 127", "§4.9", stretch_0_1,
     servo_params::make(param_kind::stretch, {{1, 127}, {0, 60}}).value()},
    {"SPEED ICS 4 = 100", "§4.9", speed_4, servo_params::make(param_kind::speed, {{4, 100}}).value()},
    {"read ICS 3 current position (ICS → COM, +4, 2 bytes)", "§4.1, §7", read_ics3_pos,
     move::read_ics(3, 4, 2).value()},
    {"write ICS 3 target 7500 (literal → ICS, +6)", "§4.1, §7", write_ics3_target,
     move::write_ics(3, 6, detail::w7500).value()},
    {"read 16 bytes of ROM 0x000B80", "§4.1 (TYPE 0x23)", read_rom_motion1, move::read_rom(0x000B80, 16).value()},
    {"copy RAM config to ROM 0x0005DC", "§4.1 (TYPE 0x30), §9", ram_to_rom_config,
     move::make(destination::rom(0x0005DC), source::ram(0x0000, 2).value()).value()},
    {"write AA 55 to ROM 0x001000", "§4.1 (TYPE 0x32)", literal_to_rom,
     move::write_rom(0x001000, detail::aa55).value()},
    {"AND RAM 0x0090 with 0x0F", "§4.2", and_literal,
     logic::make(logic_op::and_, destination::ram(0x0090), source::literal(detail::x0f).value()).value()},
    {"XOR RAM 0x0091 with 0xFF, flags only", "§4.2", xor_flags_only,
     logic::make(logic_op::xor_, destination::ram(0x0091), source::literal(detail::xff).value(), store_mode::flags_only)
         .value()},
    {"NOT 2 bytes at RAM 0x0090", "§4.2", not_2, bit_not::make(destination::ram(0x0090), 2).value()},
    {"SHIFT RAM 0x0090 left 3 (2015 encoding)", "§4.2, §11.5, report App. C", shift_left3,
     shift::make(destination::ram(0x0090), 3, 1).value()},
    {"SHIFT RAM 0x0090 right 1 (2015 encoding: 255)", "§4.2, §11.5, report App. C", shift_right1,
     shift::make(destination::ram(0x0090), -1, 1).value()},
    {"SHIFT RAM 0x0090 left 1 as KONDO's manual encodes it (255)", "§11.5, DOC-CMD", shift_right1,
     shift::make(destination::ram(0x0090), 1, 1, shift_encoding::kondo_manual).value(),
     codec_options{shift_encoding::kondo_manual, false}},
    {"ADD 1 to user parameter 0 (RAM 0x0462)", "§4.2, §6", add_param,
     arith::make(arith_op::add, destination::ram(0x0462), source::literal(detail::word1).value()).value()},
    {"SUB RAM 0x0464 from 0x0462, flags only (compare)", "§4.2", sub_compare,
     arith::make(arith_op::sub, destination::ram(0x0462), source::ram(0x0464, 2).value(), store_mode::flags_only)
         .value()},
    {"ICS 0x0E: ICS 2, 3 bytes from 0x0400, answer to 0x0410", "§4.5", ics_raw,
     ics_exchange::make(2, 3, 0x0400, 0x0410).value()},
};

/** A reply frame, the shape of the command it answers, and what it must parse to. */
struct reply_case {
  const char* name;
  const char* source;
  bytes frame;
  reply_shape expected;
  reply value;
};

// clang-format off
inline constexpr std::uint8_t ack_ping[] = {0x04, 0xFE, 0x06, 0x08};
inline constexpr std::uint8_t nack_ping[] = {0x04, 0xFE, 0x15, 0x17};
inline constexpr std::uint8_t ack_mov[] = {0x04, 0x00, 0x06, 0x0A};
inline constexpr std::uint8_t nack_call[] = {0x04, 0x0C, 0x15, 0x25};
inline constexpr std::uint8_t config_data[] = {0x05, 0x00, 0x83, 0x4C, 0xD4};
inline constexpr std::uint8_t one_byte_0x15[] = {0x04, 0x00, 0x15, 0x19};
inline constexpr std::uint8_t version_mini[] = {
    0x23, 0xFD, 'C', 'B', '-', '4', ' ', 'V', '1', '.', '0', ' ', ' ', ' ', ' ', ' ', ' ',
    '0', '9', '0', '7', '1', '5', ' ', ' ', ' ', ' ', ' ', ' ', ' ', ' ', ' ', ' ', 0xC7, 0x08};
// clang-format on

namespace detail {
constexpr std::uint8_t config_bytes[] = {0x83, 0x4C};
constexpr std::uint8_t byte_15[] = {0x15};
}  // namespace detail

/** Every golden reply. */
inline constexpr reply_case replies[] = {
    {"ACK to ping", "§2.2, §4.11", ack_ping, {0xFE, false, 0}, reply::ack(0xFE)},
    {"NACK to ping", "§2.2 (ROKI)", nack_ping, {0xFE, false, 0}, reply::nack(0xFE)},
    {"ACK to a MOV write", "§2.2", ack_mov, {0x00, false, 0}, reply::ack(0x00)},
    {"NACK to CALL", "§2.2", nack_call, {0x0C, false, 0}, reply::nack(0x0C)},
    {"config word 0x4C83 (data reply to a 2-byte read)",
     "§2.2",
     config_data,
     {0x00, true, 2},
     reply::data(0x00, detail::config_bytes).value()},
    {"NACK where 2 data bytes were expected",
     "§2.2 (failure is a 4-byte NACK)",
     nack_call,
     {0x0C, true, 2},
     reply::nack(0x0C)},
    {"1-byte data reply 0x15 (shape of a NACK)",
     "§2.2",
     one_byte_0x15,
     {0x00, true, 1},
     reply::data(0x00, detail::byte_15).value()},
    {"VERSION of an RCB-4mini",
     "§4.10, §11.18 (IORY)",
     version_mini,
     {0xFD, true, 32},
     reply::data(0xFD, std::span(version_mini).subspan(2, 32)).value()},
};

}  // namespace rcb4::golden
