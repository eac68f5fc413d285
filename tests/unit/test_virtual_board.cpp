// The virtual board, exercised only through frames on its wire (board_wire.hpp).
// SPDX-License-Identifier: BSL-1.0
#include "board_wire.hpp"

#include <catch2/catch.hpp>

#include <string>
#include <tuple>

using namespace rcb4;
using namespace std::chrono_literals;
using rcb4::testing::board_wire;

namespace {
std::vector<std::uint8_t> bytes(std::initializer_list<int> l) {
  std::vector<std::uint8_t> v;
  for (int x : l) v.push_back(static_cast<std::uint8_t>(x));
  return v;
}
}  // namespace

TEST_CASE("board: ping in both forms and VERSION", "[board]") {
  board_wire w;
  CHECK(w.send(ping{}).is_ack());
  CHECK(w.send(ping{ping_form::short_}).is_ack());
  auto v = w.send(version{});
  REQUIRE(v.bytes().size() == 32);
  CHECK(std::string(v.bytes().begin(), v.bytes().begin() + 9) == "CB-4 V1.0");
}

TEST_CASE("board: power-on RAM is an HTH4 2.2 boot", "[board]") {
  board_wire w;
  CHECK(w.read_word(0x0000) == board::default_config);
  CHECK(w.read_word(0x0038) == 0x03FF);
  for (unsigned k = 0; k < 4; ++k) CHECK(w.read_word(static_cast<std::uint16_t>(0x003C + 2 * k)) == 0x8000);
  for (unsigned k = 0; k < 36; ++k) {
    const auto entry = w.read_word(static_cast<std::uint16_t>(0x0044 + 2 * k));
    if ((k < 22 && k != 10 && k != 11) || k == 35)  // a KHR-3HV's slots, and the receiver's
      CHECK(entry == 0x0090 + 20 * k);
    else
      CHECK(entry == 0xFFFF);
  }
  CHECK(w.read_word(0x0090 + 4) == 7500);  // ICS 0 current position
  CHECK(w.read_word(0x008C) == 0x0357);    // vector table
  // The program starts at StartupCmd (hth4-files.md §3): a CALL of DefaultStartup, a RETURN, then
  // the main loop.
  const auto pc = w.read_ram(0x0002, 3);
  CHECK((pc[0] | (pc[1] << 8) | (pc[2] << 16)) == 0x000444);
  w.wait(std::chrono::milliseconds(50));
  const auto later = w.read_ram(0x0002, 3);
  CHECK((later[0] | (later[1] << 8) | (later[2] << 16)) == 0x00044B);
  CHECK(w.read_ram(0x0005, 1)[0] == 0);  // nothing left on the stack
}

TEST_CASE("board: MOV between RAM, ICS, ROM and COM", "[board][mov]") {
  board_wire w;
  CHECK(w.write_ram(0x0400, {1, 2, 3, 4}).is_ack());
  CHECK(w.read_ram(0x0400, 4) == bytes({1, 2, 3, 4}));
  // RAM → RAM
  CHECK(w.send(move::make(destination::ram(0x0410), source::ram(0x0400, 4).value()).value()).is_ack());
  CHECK(w.read_ram(0x0410, 4) == bytes({1, 2, 3, 4}));
  // ICS fields go through the allocation table: ICS 3's target is RAM 0x0090 + 60 + 6.
  const std::uint8_t pos[] = {0x40, 0x1F};
  CHECK(w.send(move::write_ics(3, 6, pos).value()).is_ack());
  CHECK(w.read_word(0x0090 + 60 + 6) == 8000);
  auto r = w.send(move::read_ics(3, 6, 2).value());
  CHECK(r.u16() == 8000);
  // Move ICS 3's block pointer: the same ICS read now comes from 0x0400.
  CHECK(w.write_ram(0x0044 + 6, {0x00, 0x04}).is_ack());
  CHECK(w.send(move::read_ics(3, 0, 4).value()).bytes()[3] == 4);
  // Unallocated slot (ICS 30) → NACK, both ways.
  CHECK(w.send(move::read_ics(30, 4, 2).value()).is_nack());
  CHECK(w.send(move::write_ics(30, 6, pos).value()).is_nack());
  // ROM: literal → ROM, ROM → COM, RAM → ROM.
  const std::uint8_t aa55[] = {0xAA, 0x55};
  CHECK(w.send(move::write_rom(0x030000, aa55).value()).is_ack());
  CHECK(w.send(move::read_rom(0x030000, 2).value()).u16() == 0x55AA);
  CHECK(w.send(move::make(destination::rom(0x030010), source::ram(0x0400, 2).value()).value()).is_ack());
  CHECK(w.send(move::read_rom(0x030010, 2).value()).u16() == 0x0201);
  // The ROM keeps it: a second board fed this ROM image reads it back.
  board_wire other;
  REQUIRE(other.board().load_rom(w.board().rom()).has_value());
  CHECK(other.send(move::read_rom(0x030000, 2).value()).u16() == 0x55AA);
  CHECK_FALSE(other.board().load_rom(std::span(w.board().rom()).first(100)).has_value());
}

TEST_CASE("board: logic, NOT and SHIFT with Z/C flags and the S bit", "[board][alu]") {
  board_wire w;
  auto flags = [&w] { return config_word::decode(w.read_word(0x0000)); };
  REQUIRE(w.write_ram(0x0400, {0xF0, 0x0F}).is_ack());
  auto r = w.send(logic::make(logic_op::and_, destination::ram(0x0400), source::literal_u8(0x0F)).value());
  CHECK(r.bytes()[0] == 0x00);
  CHECK(flags().zero_flag);
  CHECK(w.read_ram(0x0400, 1)[0] == 0x00);
  r = w.send(logic::make(logic_op::or_, destination::ram(0x0401), source::literal_u8(0xF0)).value());
  CHECK(r.bytes()[0] == 0xFF);
  CHECK_FALSE(flags().zero_flag);
  // Flags only: the result comes back, memory is unchanged.
  r = w.send(
      logic::make(logic_op::xor_, destination::ram(0x0401), source::literal_u8(0xFF), store_mode::flags_only).value());
  CHECK(r.bytes()[0] == 0x00);
  CHECK(flags().zero_flag);
  CHECK(w.read_ram(0x0401, 1)[0] == 0xFF);
  r = w.send(bit_not::make(destination::ram(0x0400), 2).value());
  CHECK(r.bytes()[0] == 0xFF);
  CHECK(r.bytes()[1] == 0x00);
  // SHIFT: a 16-bit value shifted left 4 and right 8, the 2015 encoding.
  REQUIRE(w.write_ram(0x0402, {0x34, 0x12}).is_ack());
  CHECK(w.send(shift::make(destination::ram(0x0402), 4, 2).value()).u16() == 0x2340);
  CHECK(w.send(shift::make(destination::ram(0x0402), -8, 2).value()).u16() == 0x0023);
  // A board that reads counts as KONDO's manual prints them shifts the other way.
  board_wire manual(board::options{.shift = shift_encoding::kondo_manual});
  REQUIRE(manual.write_ram(0x0402, {0x10, 0x00}).is_ack());
  const auto c = shift::make(destination::ram(0x0402), 1, 2, shift_encoding::kondo_manual).value();
  CHECK(manual.send(c).u16() == 0x0020);
  CHECK(w.send(logic::make(logic_op::and_, destination::ics(30, 0), source::literal_u16(1)).value()).is_nack());
}

TEST_CASE("board: arithmetic, carry and borrow", "[board][alu]") {
  board_wire w;
  auto carry = [&w] { return config_word::decode(w.read_word(0x0000)).carry_flag; };
  auto zero = [&w] { return config_word::decode(w.read_word(0x0000)).zero_flag; };
  REQUIRE(w.write_ram(0x0462, {0xFE, 0xFF}).is_ack());
  CHECK(w.send(arith::make(arith_op::add, destination::ram(0x0462), source::literal_u16(3)).value()).u16() == 0x0001);
  CHECK(carry());
  CHECK(w.send(arith::make(arith_op::sub, destination::ram(0x0462), source::literal_u16(1)).value()).u16() == 0);
  CHECK(carry());  // no borrow: C = 1
  CHECK(zero());
  CHECK(w.send(arith::make(arith_op::sub, destination::ram(0x0462), source::literal_u16(1)).value()).u16() == 0xFFFF);
  CHECK_FALSE(carry());  // borrow: C = 0
  REQUIRE(w.write_ram(0x0464, {100}).is_ack());
  CHECK(w.send(arith::make(arith_op::mul, destination::ram(0x0464), source::literal_u8(3)).value()).bytes()[0] == 44);
  CHECK(carry());  // 300 does not fit a byte
  REQUIRE(w.write_ram(0x0464, {100}).is_ack());
  CHECK(w.send(arith::make(arith_op::div, destination::ram(0x0464), source::literal_u8(7)).value()).bytes()[0] == 14);
  REQUIRE(w.write_ram(0x0464, {100}).is_ack());
  CHECK(w.send(arith::make(arith_op::mod, destination::ram(0x0464), source::literal_u8(7)).value()).bytes()[0] == 2);
  // (2-byte operands: a 1-byte data reply and a NACK have the same shape on the wire, §2.2)
  CHECK(w.send(arith::make(arith_op::div, destination::ram(0x0464), source::literal_u16(0)).value()).is_nack());
  // Compare without storing (S bit).
  CHECK(
      w.send(
           arith::make(arith_op::sub, destination::ram(0x0464), source::literal_u8(2), store_mode::flags_only).value())
          .bytes()[0] == 0);
  CHECK(zero());
  CHECK(w.read_ram(0x0464, 1)[0] == 2);
  // Arithmetic to COM: refused by default (2015 report), answered with the opt-in.
  const auto to_com = arith::make(arith_op::add, destination::com(), source::literal_u16(5), store_mode::store,
                                  arith::com_output::allow)
                          .value();
  CHECK(w.send(to_com).is_nack());
  board_wire permissive(board::options{.allow_arith_to_com = true});
  CHECK(permissive.send(to_com).u16() == 5);
}

TEST_CASE("board: JUMP, CALL and RETURN with conditions and a 16-deep stack", "[board][flow]") {
  board_wire w;
  auto pc = [&w] {
    auto b = w.read_ram(0x0002, 3);
    return b[0] | (b[1] << 8) | (b[2] << 16);
  };
  // Suspend the ROM program so the PC stays where we put it.
  REQUIRE(w.write_ram(0x0000, {0x00, 0x00}).is_ack());
  CHECK(w.send(jump{0x001000}).is_ack());
  CHECK(pc() == 0x001000);
  // Z is 0 after this compare: "if Z=1" is not taken, "if Z=0" is.
  REQUIRE(
      w.send(
           arith::make(arith_op::sub, destination::ram(0x0400), source::literal_u8(1), store_mode::flags_only).value())
          .kind() == reply_kind::data);
  CHECK(w.send(jump{0x002000, condition{true, {}}}).is_ack());
  CHECK(pc() == 0x001000);
  CHECK(w.send(jump{0x002000, condition{false, {}}}).is_ack());
  CHECK(pc() == 0x002000);
  CHECK(w.send(call{0x003000}).is_ack());
  CHECK(pc() == 0x003000);
  CHECK(w.read_ram(0x0005, 1)[0] == 1);
  CHECK(w.send(ret{}).is_ack());
  CHECK(pc() == 0x002000);
  CHECK(w.read_ram(0x0005, 1)[0] == 0);
  for (int i = 0; i < 16; ++i) CHECK(w.send(call{0x003000}).is_ack());
  CHECK(w.send(call{0x003000}).is_nack());  // 17th: stack full
  // RETURN with nothing to return to stops the ROM program.
  board_wire v;
  CHECK(config_word::decode(v.read_word(0)).rom_program);
  CHECK(v.send(ret{}).is_ack());
  CHECK_FALSE(config_word::decode(v.read_word(0)).rom_program);
}

// hth4-files.md §8: after a flags-only SUB of C1 − 10 (Z = 1 equal, C = 0 on a borrow), COND 0D
// and 0F with C1 = 5, 10, 20 — the hardware test of §8 run on the virtual board. "Either" (what
// rcb4 follows, two_flag_jump) predicts taken, taken, not for 0D (≤) and not, taken, taken for 0F
// (≥); "both" predicts not, not, not and not, taken, not.
TEST_CASE("board: a JUMP comparing two flags is taken when either matches (hth4-files.md 8)", "[board][flow]") {
  static_assert(condition::decode(0x0D).value() == condition{true, false});
  static_assert(condition::decode(0x0F).value() == condition{true, true});
  const bool either = two_flag_jump == two_flag_rule::either;
  for (const auto& [c1, le, ge] :
       {std::tuple{5, true, false}, std::tuple{10, true, true}, std::tuple{20, false, true}}) {
    for (const std::uint8_t cond : {std::uint8_t{0x0D}, std::uint8_t{0x0F}}) {
      board_wire w;
      REQUIRE(w.write_ram(0x0000, {0x00, 0x00}).is_ack());  // the ROM program suspended: the PC stays
      REQUIRE(w.write_ram(0x0457, {static_cast<std::uint8_t>(c1)}).is_ack());
      CHECK(w.send(jump{0x001000}).is_ack());
      REQUIRE(
          w.send(arith::make(arith_op::sub, destination::ram(0x0457), source::literal_u8(10), store_mode::flags_only)
                     .value())
              .kind() == reply_kind::data);
      CHECK(w.send(jump{0x002000, condition::decode(cond).value()}).is_ack());
      const auto b = w.read_ram(0x0002, 3);
      const bool taken = (b[0] | (b[1] << 8) | (b[2] << 16)) == 0x002000;
      const bool expected = either ? (cond == 0x0D ? le : ge) : (cond == 0x0D ? false : c1 == 10);
      INFO("C1 " << c1 << ", COND " << int(cond));
      CHECK(taken == expected);
    }
  }
  // The relation each condition tests, in one table.
  CHECK(std::string(condition::decode(0x0D).value().relation()) == (either ? "<=" : "never"));
  CHECK(std::string(condition::decode(0x0F).value().relation()) == (either ? ">=" : "=="));
  CHECK(std::string(condition::decode(0x05).value().relation()) == "==");
  CHECK(std::string(condition::decode(0x04).value().relation()) == "!=");
  CHECK(std::string(condition::decode(0x08).value().relation()) == "<");
  CHECK(std::string(condition::decode(0x0A).value().relation()) == ">=");
  CHECK(std::string(condition::always().relation()) == "always");
}

TEST_CASE("board: SINGLE and CONST interpolate over frames, FREE and HOLD", "[board][servo]") {
  board_wire w;
  const std::uint16_t ics2_pos = 0x0090 + 40 + 4, ics2_out = 0x0090 + 40 + 6;
  CHECK(w.send(single_servo{2, 8500, 10}).is_ack());
  CHECK(w.read_ram(0x0007, 1)[0] == 0x04);  // update flag of ICS 2 set
  w.wait(50ms);                             // 5 of 10 frames at 10 ms
  CHECK(w.read_word(ics2_pos) == 8000);
  w.wait(50ms);
  CHECK(w.read_word(ics2_pos) == 8500);
  CHECK(w.read_word(ics2_out) == 8500);
  CHECK(w.read_ram(0x0007, 1)[0] == 0x00);  // cleared when done
  CHECK(w.send(single_servo{2, 7000, 0}).is_ack());
  CHECK(w.read_word(ics2_pos) == 7000);  // 0 frames: at once
  CHECK(w.send(single_servo{2, servo_position::free(), 10}).is_ack());
  CHECK(w.read_word(ics2_out) == 0x8000);
  CHECK(w.read_word(ics2_pos) == 7000);
  // From FREE (or HOLD) a move starts where the servo was measured, here turned by hand to 8000.
  CHECK(w.board().turn_by_hand(ics_number{2}, 8000));
  CHECK(w.send(single_servo{2, 7000, 10}).is_ack());
  w.wait(50ms);
  CHECK(w.read_word(ics2_pos) == 7500);
  CHECK(w.send(single_servo{2, servo_position::hold(), 10}).is_ack());
  CHECK(w.read_word(ics2_out) == 0x7FFF);
  CHECK(w.read_word(ics2_pos) == 7500);
  CHECK(w.send(single_servo{2, 8500, 10}).is_ack());
  w.wait(50ms);
  CHECK(w.read_word(ics2_pos) == 8000);
  CHECK(w.send(single_servo{30, 7500, 10}).is_nack());  // unallocated
  // CONST: several servos, unallocated ones ignored, ascending order respected.
  CHECK(w.send(const_servo::make({{1, 9000}, {0, 6000}, {30, 7000}}, 4).value()).is_ack());
  w.wait(40ms);
  CHECK(w.read_word(0x0090 + 4) == 6000);
  CHECK(w.read_word(0x0090 + 20 + 4) == 9000);
}

TEST_CASE("board: SERIES reboots by default (as measured in 2015) and executes when asked", "[board][servo]") {
  board_wire w;
  REQUIRE(w.write_ram(0x0400, {0x12}).is_ack());
  const auto series = series_servo::make(series_opt_in, {{0, {8000, 0}}, {1, {6000, 0}}}).value();
  const auto frame = encode(series);
  CHECK(w.send_bytes(frame.bytes()).empty());  // silence
  CHECK(w.read_ram(0x0400, 1)[0] == 0x00);     // RAM back to power-on
  CHECK(w.board().stats().reboots == 1);
  board_wire e(board::options{.series = board::series_behaviour::execute});
  CHECK(e.send(series).is_ack());
  CHECK(e.read_word(0x0090 + 4) == 8000);
  CHECK(e.read_word(0x0090 + 20 + 4) == 6000);
}

TEST_CASE("board: SPEED/STRETCH are stored per servo", "[board][servo]") {
  board_wire w;
  CHECK(w.send(servo_params::make(param_kind::stretch, {{0, 60}, {30, 10}}).value()).is_ack());
  CHECK(w.send(servo_params::make(param_kind::speed, {{0, 100}}).value()).is_ack());
  CHECK(w.board().servo_params_of(0) == std::pair<std::uint8_t, std::uint8_t>{100, 60});
  CHECK(w.board().servo_params_of(30) == std::pair<std::uint8_t, std::uint8_t>{127, 127});
}

TEST_CASE("board: NACK and silence where the board gives them", "[board][errors]") {
  board_wire w;
  const auto bad_sum = bytes({0x04, 0xFE, 0x06, 0x09});
  CHECK(w.send_bytes(bad_sum) == bytes({0x04, 0xFE, 0x15, 0x17}));
  // Incomplete: silence until the rest arrives.
  const auto p = bytes({0x04, 0xFE, 0x06, 0x08});
  CHECK(w.send_bytes(std::span(p).first(2)).empty());
  CHECK(w.send_bytes(std::span(p).subspan(2)) == bytes({0x04, 0xFE, 0x06, 0x08}));
  // An impossible SIZE byte is dropped, then the next frame is answered.
  CHECK(w.send_bytes(bytes({0x00, 0x02, 0x04, 0xFE, 0x06, 0x08})) == bytes({0x04, 0xFE, 0x06, 0x08}));
  // Two frames in one read: two replies, in order.
  CHECK(w.send_bytes(bytes({0x03, 0xFE, 0x01, 0x04, 0xFE, 0x06, 0x08})).size() == 8);
  // Unknown command: NACK.
  CHECK(w.send_bytes(bytes({0x03, 0x13, 0x16})) == bytes({0x04, 0x13, 0x15, 0x2C}));
  // ICS 0x0E: the virtual servos do not answer raw ICS, so the board NACKs.
  CHECK(w.send(ics_exchange::make(0, 2, 0x0400, 0x0410).value()).is_nack());
  // Strict timing: a gap over 150 µs in the middle of a frame drops it.
  board_wire strict(board::options{.strict_timing = true});
  CHECK(strict.send_bytes(std::span(p).first(2)).empty());
  CHECK(strict.send_bytes(std::span(p).subspan(2), 200us).empty());
  CHECK(strict.board().pending_bytes() == 2);                              // the tail waits as the start of a new frame
  CHECK(strict.send_bytes(p, 1000us) == bytes({0x04, 0xFE, 0x06, 0x08}));  // next frame is fine
}

TEST_CASE("board: a write of the COM baud bits switches the line after the reply", "[board]") {
  board_wire w;
  CHECK(w.board().line_baud() == 1250000);
  auto cfg = config_word::decode(w.read_word(0));
  cfg.com_baud = baud_code::b625000;
  const std::uint16_t v = cfg.encode();
  CHECK(w.write_ram(0x0000, {static_cast<std::uint8_t>(v & 0xFF), static_cast<std::uint8_t>(v >> 8)}).is_ack());
  CHECK(w.board().line_baud() == 625000);
}

TEST_CASE("board: writing 0 to the stack pointer counter resets the stack (play step 2)", "[board][flow]") {
  board_wire w;
  REQUIRE(w.write_ram(0x0000, {0x00, 0x00}).is_ack());  // suspended: nothing returns by itself
  for (int play = 0; play < 40; ++play) {               // motions played in quick succession
    INFO("play " << play);
    REQUIRE(w.write_ram(0x0002, {0x4B, 0x04, 0x00, 0, 0, 0, 0, 0, 0, 0}).is_ack());  // PC, SP = 0, flags
    REQUIRE(w.send(call{motion_address(hth4_2_2, 2).value()}).is_ack());
    CHECK(w.read_ram(0x0005, 1)[0] == 1);  // one CALL deep, whatever came before
  }
}

TEST_CASE("board: KONDO's four-step motion play moves the servos, status per §8.2", "[board][motion]") {
  board_wire w;
  auto status = [&w] {
    auto b = w.read_ram(0x0002, 10);
    const int pc = b[0] | (b[1] << 8) | (b[2] << 16);
    const bool idle = b[3] + b[4] + b[5] + b[6] + b[7] == 0;
    return idle ? 0 : (pc - 0x0B80) / 2048 + 1;
  };
  const std::uint16_t cfg = w.read_word(0);
  auto suspended = config_word::decode(cfg);
  suspended.rom_program = suspended.vector_jump = suspended.ics_enabled = suspended.interpolation_message = false;
  const std::uint16_t s = suspended.encode();
  REQUIRE(w.write_ram(0x0000, {static_cast<std::uint8_t>(s & 0xFF), static_cast<std::uint8_t>(s >> 8)}).is_ack());
  REQUIRE(w.write_ram(0x0002, {0x4B, 0x04, 0x00, 0, 0, 0, 0, 0, 0, 0}).is_ack());
  REQUIRE(w.send(call{motion_address(hth4_2_2, 2).value()}).is_ack());
  auto resumed = config_word::decode(cfg);
  resumed.rom_program = resumed.vector_jump = resumed.ics_enabled = true;
  const std::uint16_t r = resumed.encode();
  REQUIRE(w.write_ram(0x0000, {static_cast<std::uint8_t>(r & 0xFF), static_cast<std::uint8_t>(r >> 8)}).is_ack());
  CHECK(status() == 2);
  w.wait(220ms);  // the program starts on the next tick, then 20 frames: arm up
  CHECK(w.read_word(0x0090 + 60 + 4) == 9500);
  CHECK(status() == 2);
  int guard = 0;
  while (status() != 0 && guard++ < 100) w.wait(10ms);
  CHECK(status() == 0);                         // back in the main loop
  CHECK(w.read_word(0x0090 + 60 + 4) == 7500);  // arm down again
  CHECK(w.read_word(0x0090 + 100 + 4) == 7500);
  CHECK(config_word::decode(w.read_word(0)).rom_program);
  CHECK(w.board().stats().rom_steps > 6);
}

TEST_CASE("board: sensors, PIO, receiver, timers", "[board][io]") {
  board_wire w;
  const auto ad0 = w.read_word(0x0022);
  CHECK(ad0 >= 441);
  CHECK(ad0 <= 443);
  w.board().set_battery_volts(12.0);
  w.wait(10ms);
  CHECK(std::abs(battery_volts(w.read_word(0x0022)) - 12.0) < 0.1);
  w.board().set_ad_raw(3, 300);
  w.wait(10ms);
  CHECK(std::abs(int{w.read_word(0x0028)} - 300) <= 1);
  // PIO: pins 1-2 as inputs see the outside; outputs keep what was written.
  REQUIRE(w.write_ram(0x0038, {0xFC, 0x03}).is_ack());
  REQUIRE(w.write_ram(0x003A, {0xF0, 0x00}).is_ack());
  w.board().set_pio_inputs(0x0003);
  w.wait(10ms);
  CHECK(w.read_word(0x003A) == 0x00F3);
  // KRR receiver: button word stored high byte first at 0x0350.
  w.board().set_receiver(static_cast<std::uint16_t>(krr_button::circle) | static_cast<std::uint16_t>(krr_button::s1),
                         {10, 20, 30, 127});
  const auto b = w.read_ram(0x0350, 6);
  CHECK(krr::decode_buttons(b[0], b[1]) == 0x0240);
  CHECK(b[5] == 127);
  // Timer 0: 5 ticks of 100 ms, running once its stop bit is cleared.
  REQUIRE(w.write_ram(0x003C, {0x05, 0x00}).is_ack());
  w.wait(300ms);
  CHECK(w.read_word(0x003C) == 2);
  w.wait(500ms);
  CHECK(w.read_word(0x003C) == 0x8000);  // at 0 the firmware sets the stop bit (DOC-FW p11)
}

TEST_CASE("board: a servo command sets no update flag for a slot without a servo", "[board][servo][motion]") {
  board::options two;
  two.servos = board::first_slots(2);  // ICS 0 and 1 only
  board_wire w(two);
  servo_set<servo_position> targets;
  for (int k : {0, 3, 9}) targets.insert(ics_number::make(k).value(), servo_position{8000});
  REQUIRE(w.send(const_servo::make(targets, frames{5}).value()).is_ack());
  CHECK(w.read_ram(0x0007, 5) == bytes({0x01, 0, 0, 0, 0}));  // ICS 0 only (DOC-CMD p18: the others 0)
  w.wait(80ms);
  CHECK(w.read_ram(0x0007, 5) == bytes({0, 0, 0, 0, 0}));
  CHECK(w.read_word(0x0090 + 4) == 8000);

  // A motion written for a whole robot runs to its end on a board with none of its servos (it
  // stopped for ever at its first pose, and `motion play 2 --wait` ran to its timeout).
  board::options none;
  none.servos = board::first_slots(0);
  board_wire empty(none);
  REQUIRE(empty.send(call{motion_address(hth4_2_2, 2).value()}).is_ack());
  auto cfg = config_word::decode(empty.read_word(0));
  cfg.rom_program = true;
  const std::uint16_t c = cfg.encode();
  REQUIRE(empty.write_ram(0x0000, {static_cast<std::uint8_t>(c & 0xFF), static_cast<std::uint8_t>(c >> 8)}).is_ack());
  int ticks = 0;
  while (empty.read_ram(0x0005, 5) != bytes({0, 0, 0, 0, 0}) && ticks++ < 200) empty.wait(10ms);
  CHECK(ticks < 200);
  CHECK(empty.read_ram(0x0007, 5) == bytes({0, 0, 0, 0, 0}));
}

TEST_CASE("board: boots with the output period asked (HTH4's samples: 15 ms)", "[board]") {
  board::options fifteen;
  fifteen.period = output_period::ms15;
  board_wire w(fifteen);
  CHECK(config_word::decode(w.read_word(0)).period == output_period::ms15);
  CHECK(config_word::decode(board_wire{}.read_word(0)).period == output_period::ms10);  // the ROM's
  REQUIRE(w.send(single_servo{0, 8500, 10}).is_ack());
  w.wait(140ms);  // 10 frames of 15 ms: not there yet at 140 ms
  CHECK(w.read_word(0x0090 + 4) != 8500);
  w.wait(30ms);
  CHECK(w.read_word(0x0090 + 4) == 8500);
}
