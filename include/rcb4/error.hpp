// rcb4 — error codes of the codec and their messages. No <string>, no <system_error>: firmware and
// single-header users pay for neither; std::error_code interop is in <rcb4/error_category.hpp>.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <cstdint>

namespace rcb4 {

/**
 * Everything the codec can reject. Zero is "no error"; every other value has a message
 * (see message()). constexpr code uses the enum directly; std::error_code interop is in
 * <rcb4/error_category.hpp>.
 */
// A new code gets its line in result.hpp's detail::result_holds_error and bad_result_access()
// too (-Wswitch names a code missing there), so that a constant expression names it.
enum class errc : std::uint8_t {
  // framing (protocol.md §2)
  buffer_too_small = 1,  ///< the caller's output buffer cannot hold the frame
  frame_too_short,       ///< SIZE byte below the 3-byte minimum of a frame
  frame_too_long,        ///< request over 128 bytes (DOC-FW "COM"), reply data over 252 bytes
  bad_frame_size,        ///< SIZE byte does not match the layout of the command
  bad_checksum,          ///< SUM byte is not the low byte of the sum of the preceding bytes
  unknown_command,       ///< CMD byte is not an RCB-4 command
  bad_type_byte,         ///< MOV/ALU TYPE byte with reserved bits set or a kind this command forbids
  reserved_bits_set,     ///< a must-be-zero byte or bit of the layout is not zero
  // value ranges (protocol.md §4–§6)
  ics_out_of_range,            ///< ICS number not in 0–35
  ram_address_out_of_range,    ///< RAM range leaves 0x0000–0x048F
  rom_address_out_of_range,    ///< ROM range leaves 0x000000–0x03FFFF
  ics_offset_out_of_range,     ///< ICS offset + size runs past 255
  transfer_size_out_of_range,  ///< MOV/logic size not in 1–128
  literal_size_out_of_range,   ///< literal source not in 1–121 bytes (frame ≤ 128)
  operand_size_out_of_range,   ///< arithmetic operand not 1 or 2 bytes (DOC-CMD 四則演算)
  ics_length_out_of_range,     ///< ICS 0x0E transmit length not in 1–64
  position_out_of_range,       ///< servo position not in 0–16383 nor FREE/HOLD
  param_out_of_range,          ///< speed/stretch parameter not in 1–127
  frames_out_of_range,         ///< interpolation frames not in 0–255
  shift_count_out_of_range,    ///< shift count not in −127…127
  servo_id_out_of_range,       ///< servo ID/SIO pair outside ICS 0–35
  motion_out_of_range,         ///< motion number outside the layout profile's slots
  empty_servo_set,             ///< a multi-servo command with no servo selected
  bad_condition,               ///< JUMP/CALL condition byte with reserved or orphan bits
  unknown_parameter_kind,      ///< 0x12 SUB byte other than 1 (stretch) or 2 (speed)
  // command rules (protocol.md §4.2, §11)
  destination_not_allowed,  ///< logic/NOT/SHIFT to COM, or arithmetic to COM without opt-in
  flags_only_not_allowed,   ///< S (flags-only) bit on MOV
  // replies (protocol.md §2.2)
  bad_reply_length,  ///< reply length byte is neither the expected length nor 4 (NACK)
  echo_mismatch,     ///< reply CMD byte is not the command that was sent
  bad_ack_code,      ///< 4-byte reply whose status byte is neither 06 (ACK) nor 15 (NACK)
  unexpected_ack,    ///< ACK where a data reply was expected
  nack,              ///< the board refused (NACK): an error where the caller expected success (execute)
  // operations (rcb4/ops.hpp)
  baud_change_not_allowed,  ///< a config write that changes the COM baud (use ops::switch_baud)
  unsupported_baud,         ///< a COM rate other than 115200, 625000 or 1250000 (protocol.md §9)
  index_out_of_range,       ///< counter, user parameter, timer or AD index past the board's count
  motion_slot_empty,        ///< the motion's ROM slot holds no program (erased: 0xFF)
  motion_slot_not_a_frame,  ///< the slot's first bytes fail a frame's checksum: another ROM layout?
  servo_not_allocated,      ///< a servo the operation names has no block in the ICS allocation table
  bad_allocation_table,     ///< an ICS allocation entry is no servo block: odd, overlapping, outside the user area
  // ICS servos on their own line (ics.md; rcb4/ics/)
  ics_id_out_of_range,     ///< ICS servo ID not in 0–31 (ics.md §2.1)
  ics_value_out_of_range,  ///< an ICS parameter or EEPROM field outside its range (ics.md §3)
  ics_line_echo_mismatch,  ///< the one-wire line's echo differs from what was sent: a collision (ics.md §1)
  ics_bad_reply,           ///< an ICS reply's header, sub-command, ID or value is not the one asked (ics.md §2.3)
  ics_bad_eeprom,          ///< an EEPROM image with a byte above 0x0F or without the 0x5A check mark (ics.md §4.1)
  // the link (rcb4/link/exchange_machine.hpp: what any transport's exchange can end with)
  link_timeout,           ///< no (complete) reply within the exchange's deadline
  link_truncated,         ///< a reply began but stopped short of its length before the deadline
  link_echo,              ///< the line echoes what is sent (a loopback plug, not a board)
  link_line_error,        ///< a byte of the reply failed its parity or framing check (a marked line)
  link_closed,            ///< the line closed (end of file: cable unplugged, server gone)
  link_lost,              ///< the link is gone (the driver's I/O said so: EIO, ENODEV ...)
  link_io_error,          ///< the driver's I/O failed in another way (the driver knows the details)
  link_reconnect_failed,  ///< the link was lost and reopening it failed until the policy gave up
  link_cancelled,         ///< the exchange was cancelled (an input of the machine)
};

/** The last errc value (for tables and tests that walk every code). */
inline constexpr errc errc_last = errc::link_cancelled;

/** A short English description of @p e, for logs and exceptions. */
constexpr const char* message(errc e) noexcept {
  if (e == errc{}) return "success";
  switch (e) {
    case errc::buffer_too_small: return "output buffer too small for the frame";
    case errc::frame_too_short: return "frame size byte below 3";
    case errc::frame_too_long: return "frame longer than the board accepts (requests <= 128 bytes)";
    case errc::bad_frame_size: return "frame size byte does not match the command layout";
    case errc::bad_checksum: return "checksum mismatch";
    case errc::unknown_command: return "unknown command byte";
    case errc::bad_type_byte: return "invalid TYPE byte (reserved bits or forbidden kind)";
    case errc::reserved_bits_set: return "reserved byte or bit is not zero";
    case errc::ics_out_of_range: return "ICS number out of range 0-35";
    case errc::ram_address_out_of_range: return "RAM range outside 0x0000-0x048F";
    case errc::rom_address_out_of_range: return "ROM range outside 0x000000-0x03FFFF";
    case errc::ics_offset_out_of_range: return "ICS offset + size past 255";
    case errc::transfer_size_out_of_range: return "transfer size out of range 1-128";
    case errc::literal_size_out_of_range: return "literal size out of range 1-121";
    case errc::operand_size_out_of_range: return "arithmetic operand size must be 1 or 2 bytes";
    case errc::ics_length_out_of_range: return "ICS transmit length out of range 1-64";
    case errc::position_out_of_range: return "servo position out of range 0-16383 (or FREE/HOLD)";
    case errc::param_out_of_range: return "servo speed/stretch parameter out of range 1-127";
    case errc::frames_out_of_range: return "interpolation frames out of range 0-255";
    case errc::shift_count_out_of_range: return "shift count out of range -127..127";
    case errc::servo_id_out_of_range: return "servo ID / SIO side outside ICS 0-35";
    case errc::motion_out_of_range: return "motion number outside the layout's slots";
    case errc::empty_servo_set: return "no servo selected";
    case errc::bad_condition: return "invalid JUMP/CALL condition byte";
    case errc::unknown_parameter_kind: return "servo parameter kind must be 1 (stretch) or 2 (speed)";
    case errc::destination_not_allowed: return "destination not allowed for this command";
    case errc::flags_only_not_allowed: return "flags-only (S) bit not allowed on MOV";
    case errc::bad_reply_length: return "reply length byte unexpected";
    case errc::echo_mismatch: return "reply echoes a different command";
    case errc::bad_ack_code: return "reply status byte neither ACK (06) nor NACK (15)";
    case errc::unexpected_ack: return "ACK received where data was expected";
    case errc::nack: return "board answered NACK";
    case errc::baud_change_not_allowed:
      return "config write would change the COM baud; use switch_baud so the host follows";
    case errc::unsupported_baud: return "COM baud must be 115200, 625000 or 1250000";
    case errc::index_out_of_range: return "counter, parameter or timer index out of range";
    case errc::motion_slot_empty: return "the motion slot holds no program (erased ROM): nothing to play";
    case errc::motion_slot_not_a_frame:
      return "the motion slot does not start with a valid frame: the program was written for another "
             "HeartToHeart4 ROM layout (1.3, 2.0-2.1 or 2.2+)?";
    case errc::servo_not_allocated:
      return "a servo named has no block in the board's ICS allocation table (RAM 0x0044): the board would "
             "ignore it";
    case errc::bad_allocation_table:
      return "the board's ICS allocation table (RAM 0x0044) is not a servo map: an entry points at an odd "
             "address, outside the user area 0x0090-0x048F, or into another servo's block";
    case errc::ics_id_out_of_range: return "ICS servo ID out of range 0-31";
    case errc::ics_value_out_of_range: return "ICS servo parameter out of its range";
    case errc::ics_line_echo_mismatch:
      return "the ICS line's echo differs from what was sent: another device talked at the same time (collision)";
    case errc::ics_bad_reply: return "the ICS reply is not the one asked (header, sub-command, ID or value differs)";
    case errc::ics_bad_eeprom: return "ICS EEPROM image invalid: a byte above 0x0F or no 0x5A check mark";
    case errc::link_timeout: return "no reply from the board before the deadline";
    case errc::link_truncated: return "the board's reply stopped short of its length before the deadline";
    case errc::link_echo: return "the line echoes what is sent: a loopback, not an RCB-4";
    case errc::link_line_error:
      return "a byte of the reply failed its parity or framing check (a noisy line, a wrong rate, or a break)";
    case errc::link_closed: return "the line was closed (unplugged cable or stopped server)";
    case errc::link_lost: return "the link is gone (unplugged adapter?)";
    case errc::link_io_error: return "the line's input or output failed";
    case errc::link_reconnect_failed: return "the link was lost and could not be reopened (device still unplugged?)";
    case errc::link_cancelled: return "the exchange was cancelled";
  }
  return "unknown rcb4 error";
}

}  // namespace rcb4
