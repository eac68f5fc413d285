// The virtual board's parts on their own (memory, servos, vectors, timers, processor), and the
// vector-jump table and timers on the whole board (motions.md §2, §4).
// SPDX-License-Identifier: BSL-1.0
#include "board_wire.hpp"

#include <rcb4/board/memory.hpp>
#include <rcb4/board/program.hpp>
#include <rcb4/board/servos.hpp>
#include <rcb4/board/vectors.hpp>
#include <rcb4/ops/motion.hpp>

#include <catch2/catch.hpp>

#include <array>

using namespace rcb4;
using namespace std::chrono_literals;
using rcb4::testing::board_wire;

namespace {
// protocol.md §6: [cond][dstWord][srcWord][addr×3]; cond B5 = EOF 0x80 | WORD 0x20 | literal 0x10 |
// compare Z 0x04 | Z = 1 0x01; dst 0x0350 (the KRR button word); the literal as the word lies in
// RAM for UP (0x0001, high byte first: 00 01); CALL (bit 6 clear) 0x001380, HTH4 2.2+ motion 2.
constexpr std::array<std::uint8_t, 8> up_plays_2 = {0xB5, 0x50, 0x03, 0x00, 0x01, 0x80, 0x13, 0x00};

board::memory blank_memory() {
  board::memory m;
  m.rom.assign(rom_size, 0xFF);
  return m;
}
}  // namespace

TEST_CASE("vector entry: HTH4's button pattern, byte by byte", "[board][vector][codec]") {
  const auto e = vector_entry::decode(up_plays_2);
  REQUIRE(e);
  CHECK(e->last);
  CHECK(e->action == vector_action::call);
  CHECK(e->word);
  CHECK(e->src_literal);
  CHECK(e->dst == vector_operand::ram(krr::buttons));
  CHECK(e->target == rom_address{0x1380});
  CHECK(e->buttons() == 0x0001);
  CHECK(vector_entry::button(0x0001, rom_address{0x1380}, true).encode() == up_plays_2);
  // A JUMP on "dst ≥ src" (C compared, C = 1) over one byte of ICS 3's block, offset 4: not a button.
  const std::array<std::uint8_t, 8> jump_if_at_least = {0x4A, 0x04, 0x83, 0x20, 0x00, 0x00, 0x20, 0x00};
  const auto j = vector_entry::decode(jump_if_at_least);
  REQUIRE(j);
  CHECK(j->action == vector_action::jump);
  CHECK_FALSE(j->word);
  CHECK_FALSE(j->src_literal);
  CHECK(j->dst.is_ics());
  CHECK(j->dst.ics_slot() == 3);
  CHECK(j->dst.address() == 4);
  CHECK_FALSE(j->buttons());
  CHECK(j->fires(0x21, 0x20));
  CHECK(j->fires(0x120, 0x20));  // one byte: 0x20 ≥ 0x20
  CHECK_FALSE(j->fires(0x1F, 0x20));
  CHECK(j->encode() == jump_if_at_least);
}

TEST_CASE("vector entry: erased ROM and impossible entries are refused", "[board][vector][codec]") {
  const std::array<std::uint8_t, 8> erased = {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
  CHECK(vector_entry::decode(erased).error() == errc::ics_out_of_range);
  auto bad = up_plays_2;
  bad[0] = 0xB1;  // Z required but not compared
  CHECK(vector_entry::decode(bad).error() == errc::bad_condition);
  bad = up_plays_2;
  bad[1] = 0x90;  // RAM 0x0490: past the end
  bad[2] = 0x04;
  CHECK(vector_entry::decode(bad).error() == errc::ram_address_out_of_range);
  bad = up_plays_2;
  bad[7] = 0x04;  // ROM 0x041380
  CHECK(vector_entry::decode(bad).error() == errc::rom_address_out_of_range);
}

TEST_CASE("board parts: the vector table walk stops at EOF and skips what cannot be read", "[board][vector]") {
  auto m = blank_memory();
  m.put16(ram::vector_table.value(), 0x0357);
  m.put16(ram::ics_allocation.value(), 0x0090);  // ICS 0 has a block; ICS 1 none (0)
  // Entry 0: ICS 1 offset 4 equal to 0: ICS 1 is unallocated, so it never fires.
  auto e0 = vector_entry{};
  e0.dst = vector_operand::ics(ics_number{1}, 4);
  e0.cond = condition{true, std::nullopt};
  e0.target = rom_address{0x2000};
  // Entry 1: DOWN, last. Entry 2 (after EOF): UP.
  const auto e1 = vector_entry::button(0x0002, rom_address{0x3000}, true);
  const auto e2 = vector_entry::button(0x0001, rom_address{0x4000}, true);
  std::uint32_t at = 0x0357;
  for (const auto& e : {e0, e1, e2})
    for (auto b : e.encode()) m.ram[at++] = b;
  CHECK_FALSE(board::firing_vector(m));
  m.ram[0x0350] = 0x00;
  m.ram[0x0351] = 0x01;  // UP: only the entry past EOF would match
  CHECK_FALSE(board::firing_vector(m));
  m.ram[0x0351] = 0x02;  // DOWN
  REQUIRE(board::firing_vector(m));
  CHECK(board::firing_vector(m)->target == rom_address{0x3000});
  m.put16(ram::vector_table.value(), 0xFFFF);  // no table
  CHECK_FALSE(board::firing_vector(m));
}

TEST_CASE("board parts: boot copies the vector entries up to EOF", "[board][vector]") {
  auto m = blank_memory();
  m.rom[0x0919] = 0x57;
  m.rom[0x091A] = 0x03;
  std::uint32_t at = 0x091B;
  for (const auto& e :
       {vector_entry::button(0x0010, rom_address{0x0B80}), vector_entry::button(0x0020, rom_address{0x1380}, true)})
    for (auto b : e.encode()) m.rom[at++] = b;
  m.rom[at] = 0x00;  // a byte after the EOF entry: not copied
  CHECK(board::load_vector_table(m) == 2);
  CHECK(m.ram16(ram::vector_table.value()) == 0x0357);
  CHECK(m.ram[0x0357] == 0x35);
  CHECK(m.ram[0x0357 + 8] == 0xB5);
  CHECK(m.ram[0x0357 + 16] == 0x00);
  auto erased = blank_memory();
  CHECK(board::load_vector_table(erased) == 0);
  CHECK(erased.ram16(ram::vector_table.value()) == 0xFFFF);
}

TEST_CASE("board parts: a timer counts down in steps and stops itself at 0", "[board][timer]") {
  auto m = blank_memory();
  m.put16(0x003C, 2);       // timer 0 running
  m.put16(0x003E, 0x8005);  // timer 1 stopped
  m.put16(0x0040, 0);       // timer 2 running at 0
  board::count_down_timers(m);
  CHECK(m.ram16(0x003C) == 1);
  CHECK(m.ram16(0x003E) == 0x8005);
  CHECK(m.ram16(0x0040) == 0x8000);
  board::count_down_timers(m);
  CHECK(m.ram16(0x003C) == 0x8000);  // DOC-FW p11: the stop bit set at 0
}

TEST_CASE("board parts: servo flags clear when the interpolation ends", "[board][servo]") {
  auto m = blank_memory();
  m.put16(ram::allocation_entry(ics_number{2}).value(), 0x0090);
  m.put16(0x0090 + 4, 7500);  // measured
  m.put16(0x0090 + 6, 7500);  // output
  board::servo_bank s;
  CHECK(s.command(m, ics_number{2}, servo_position{8500}, frames{2}));
  CHECK_FALSE(s.command(m, ics_number{3}, servo_position{8500}, frames{2}));  // no block
  servo_mask both;
  both.insert(ics_number{2});
  both.insert(ics_number{3});
  board::servo_bank::set_update_flags(m, both, update_flags::replace);
  CHECK(m.ram[0x0007] == 0x04);  // ICS 3 has no slot: its flag stays 0 (DOC-CMD p18)
  s.step(m);
  CHECK(m.ram16(0x0090 + 6) == 8000);  // half way
  CHECK(m.ram16(0x0090 + 4) == 8000);  // the measured position follows
  CHECK(board::servo_bank::flags_pending(m));
  s.step(m);
  CHECK(m.ram16(0x0090 + 6) == 8500);
  CHECK_FALSE(board::servo_bank::flags_pending(m));
}

TEST_CASE("board parts: the program stops for the period when it comes round again", "[board][program]") {
  auto m = blank_memory();
  // 0x0100: OR config |= 0x08; JUMP 0x0100 (a main loop that sets the vector switch)
  static constexpr std::uint8_t bit3[] = {0x08};
  const auto orr =
      encode(logic::make(logic_op::or_, destination::ram(ram::config), source::literal(bit3).value()).value());
  const auto back = encode(jump{rom_address{0x0100}});
  std::copy(orr.begin(), orr.end(), m.rom.begin() + 0x0100);
  std::copy(back.begin(), back.end(), m.rom.begin() + 0x0100 + static_cast<std::ptrdiff_t>(orr.size()));
  config_word c;
  c.rom_program = true;
  m.set_config(c);
  m.set_pc(0x0100);
  board::processor p;
  board::servo_bank s;
  board::statistics st;
  p.run_program(m, s, st);
  CHECK(st.rom_steps == 2);
  CHECK(m.pc() == 0x0100);
  CHECK(m.config().vector_jump);
  // A frame that does not parse stops the program and sets the error bit.
  m.set_pc(0x0200);
  p.run_program(m, s, st);
  CHECK_FALSE(m.config().rom_program);
  CHECK(m.config().program_error);
}

TEST_CASE("board: a KRR button plays the motion its vector entry names, as HTH4's main loop does",
          "[board][vector][motion]") {
  board_wire w;
  w.wait(50ms);
  CHECK(w.board().stats().vectors == 0);
  CHECK((w.read_word(0x0000) & 0x08) != 0);  // the main loop keeps the vector switch on
  w.board().set_receiver(0x0001);            // UP: motion 2 (the default image's table)
  w.wait(20ms);
  CHECK(w.board().stats().vectors == 1);
  ops::read_motion_state st;
  testing::run(w, st);
  CHECK(st.value().running);
  CHECK(st.value().motion == 2u);
  CHECK((w.read_word(0x0000) & 0x08) == 0);  // cleared when it fired
  w.board().set_receiver(0);                 // neutral: this play ends, no other starts
  w.wait(2s);
  ops::read_motion_state after;
  testing::run(w, after);
  CHECK_FALSE(after.value().running);
  CHECK((w.read_word(0x0000) & 0x08) != 0);  // set again by the main loop: "the motion has ended" (DOC-PRG p28)
  CHECK(w.board().stats().vectors == 1);
  w.board().set_receiver(0x0001 | 0x0200);  // UP + S1: no entry is equal to it
  w.wait(200ms);
  CHECK(w.board().stats().vectors == 1);
  w.board().set_receiver(0x0002);  // DOWN: motion 3, and again while it is held (the button latches)
  w.wait(20ms);
  ops::read_motion_state down;
  testing::run(w, down);
  CHECK(down.value().motion == 3u);
  w.wait(3s);
  CHECK(w.board().stats().vectors >= 3);
  w.board().set_receiver(0);
  w.wait(2s);
  // With the vector switch off (the host's motion stop clears it), a button does nothing.
  ops::stop_motion stop;
  testing::run(w, stop);
  REQUIRE(stop.error() == errc{});
  const auto fired = w.board().stats().vectors;
  w.board().set_receiver(0x0001);
  w.wait(500ms);
  CHECK(w.board().stats().vectors == fired);
}

TEST_CASE("board: a motion waits on a timer as HTH4's TimerWaitCmd does", "[board][timer][motion]") {
  board_wire w;
  // Motion 5 (0x002B80): MOV 16 → timer 0; loop: SUB timer 0 − 0x8000 flags only; JUMP loop while
  // Z = 0; ICS 0 to 9000 at once; RETURN (motions.md §1, "Waits / timers").
  const std::uint32_t base = 0x2B80;
  static constexpr std::uint8_t sixteen[] = {0x10, 0x00};
  static constexpr std::uint8_t stopped[] = {0x00, 0x80};
  std::vector<std::uint8_t> code;
  const auto put = [&](const auto& c) {
    const auto f = encode(c);
    code.insert(code.end(), f.begin(), f.end());
  };
  put(move::write_ram(ram::timer, sixteen).value());
  const auto loop = static_cast<std::uint32_t>(base + code.size());
  put(arith::make(arith_op::sub, destination::ram(ram::timer), source::literal(stopped).value(), store_mode::flags_only)
          .value());
  put(jump{rom_address::make(loop).value(), condition{false, std::nullopt}});
  put(single_servo{ics_number{0}, servo_position{9000}, frames{0}});
  put(ret{});
  REQUIRE(w.send(move::write_rom(rom_address::make(base).value(), code).value()).is_ack());
  ops::play_motion play(5);
  testing::run(w, play);
  REQUIRE(play.error() == errc{});
  w.wait(1400ms);
  CHECK(w.read_word(0x0090 + 4) == 7500);  // 16 × 100 ms not over yet
  w.wait(400ms);
  CHECK(w.read_word(0x0090 + 4) == 9000);
  CHECK(w.read_word(0x003C) == 0x8000);
}
