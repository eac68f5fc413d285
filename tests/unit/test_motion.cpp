// Motion programs: the assembler against frames written by hand from motions.md §1 and
// protocol.md §4 (never from our own encoder), the disassembler and lift back, and the virtual
// board running an assembled motion.
// SPDX-License-Identifier: BSL-1.0
#include "board_wire.hpp"

#include <rcb4/motion/disassemble.hpp>
#include <rcb4/ops.hpp>

#include <catch2/catch.hpp>

using namespace rcb4;
using namespace rcb4::motion;
using namespace std::chrono_literals;
using rcb4::testing::board_wire;

namespace {
servo_set<servo_position> ics0(int position) {
  servo_set<servo_position> s;
  s.insert(ics_number{0}, servo_position::make(position).value());
  return s;
}

// Motion 1 of the HTH4 2.0/2.1 layout (slot 0x000BB8): a pose, a loop of two poses three times,
// a call of motion 40, then while any button is held back into the loop, then RETURN.
const program sample{{
    pose{ics0(7500), frames{28}},               // 0x0BB8
    set_counter{hth4_counter, 3},               // 0x0BC3
    label{"loop"},                              //
    pose{ics0(8500), frames{10}},               // 0x0BCB
    pose{ics0(6500), frames{10}},               // 0x0BD6
    count_down{hth4_counter, "loop"},           // 0x0BE1 SUB, 0x0BE9 JUMP Z=0
    call_motion{rom_address{0x0143B8}},         // 0x0BF0
    branch_if::buttons(0x0000, "loop", false),  // 0x0BF7 SUB S, 0x0C00 JUMP Z=0
    end{},                                      // 0x0C07
}};

const std::vector<std::uint8_t> sample_bytes = {
    0x0B, 0x10, 0x01, 0x00, 0x00, 0x00, 0x00, 0x1C, 0x4C, 0x1D, 0xA1,  // CONST ICS 0 = 7500, 28 frames
    0x08, 0x00, 0x02, 0x57, 0x04, 0x00, 0x03, 0x68,                    // MOV 3 -> 0x0457 (SetCounter)
    0x0B, 0x10, 0x01, 0x00, 0x00, 0x00, 0x00, 0x0A, 0x34, 0x21, 0x7B,  // CONST ICS 0 = 8500, 10 frames
    0x0B, 0x10, 0x01, 0x00, 0x00, 0x00, 0x00, 0x0A, 0x64, 0x19, 0xA3,  // CONST ICS 0 = 6500, 10 frames
    0x08, 0x07, 0x02, 0x57, 0x04, 0x00, 0x01, 0x6D,                    // SUB 1 from 0x0457 (motions.md §1)
    0x07, 0x0B, 0xCB, 0x0B, 0x00, 0x04, 0xEC,                          // JUMP 0x000BCB if Z = 0
    0x07, 0x0C, 0xB8, 0x43, 0x01, 0x00, 0x0F,                          // CALL motion 40 (motions.md §1)
    0x09, 0x07, 0x82, 0x50, 0x03, 0x00, 0x00, 0x00, 0xE5,              // SUB S 0x0350 - 0x0000 (CmpButton)
    0x07, 0x0B, 0xCB, 0x0B, 0x00, 0x04, 0xEC,                          // JUMP 0x000BCB if Z = 0
    0x03, 0x0D, 0x10,                                                  // RETURN
};

const slot hth4_2_0_motion_1{rom_address{0x000BB8}, 2048};

std::string failure_of(const outcome<std::vector<std::uint8_t>>& o) {
  return ok(o) ? std::string("(assembled)") : std::get<failure>(o).message;
}
}  // namespace

TEST_CASE("motion: the assembler writes HTH4's frames, labels resolved", "[motion]") {
  const auto bytes = assemble(sample, hth4_2_0_motion_1);
  REQUIRE(ok(bytes));
  CHECK(std::get<std::vector<std::uint8_t>>(bytes) == sample_bytes);
  // The same program at HTH4 2.2's motion 1 (0x000B80): only the jump targets move.
  auto moved = sample_bytes;
  for (std::size_t at : {std::size_t{51}, std::size_t{74}}) {  // the two JUMPs' address low bytes
    moved[at] = 0x93;                                          // 0x000B93 = 0x0B80 + 19
    moved[at + 4] = static_cast<std::uint8_t>(0x07 + 0x0B + 0x93 + 0x0B + 0x00 + 0x04);
  }
  const auto at_2_2 = assemble(sample, slot_of(hth4_2_2, 1).value());
  REQUIRE(ok(at_2_2));
  CHECK(std::get<std::vector<std::uint8_t>>(at_2_2) == moved);
}

TEST_CASE("motion: the assembler refuses what the board could not run, naming the step", "[motion]") {
  const auto with = [](std::vector<step> steps) {
    return failure_of(assemble(program{std::move(steps)}, hth4_2_0_motion_1));
  };
  CHECK(with({}) == "an empty motion: it needs at least a RETURN (end)");
  CHECK(with({pose{ics0(7500), frames{5}}}).find("the last step is neither an end") == 0);
  CHECK(with({label{"a"}, label{"a"}, end{}}) == "step 1 (label): the label 'a' is defined twice");
  CHECK(with({go_to{"nowhere"}}) == "step 0 (go_to): no label is called 'nowhere'");
  CHECK(with({go_to{"x"}, end{}, label{"x"}}).find("the last step is neither an end") == 0);  // a label marks a step
  CHECK(with({pose{{}, frames{5}}, end{}}) == "step 0 (pose): no servo selected");
  CHECK(with({branch_if{button_word, 3, 0, compare::equal, "a"}, label{"a"}, end{}}) ==
        "step 0 (branch_if): the value is 1 or 2 bytes");
  CHECK(with({branch_if{button_word, 1, 300, compare::equal, "a"}, label{"a"}, end{}}) ==
        "step 0 (branch_if): a 1-byte value compares with 0-255");
  CHECK(with({set_counter{ram_address{0x048F}, 1}, end{}}) == "(assembled)");
  CHECK(with({call_motion{rom_address{0x000BB8}}, end{}}).find("step 0 (call_motion): the motion calls itself") == 0);
  // A slot too small: 11 + 3 bytes in 13.
  CHECK(failure_of(assemble(program{{pose{ics0(7500), frames{5}}, end{}}}, slot{rom_address{0x0BB8}, 13})) ==
        "the motion takes 14 bytes, its slot holds 13");
  // The stack: the main loop's CALL, this motion's, and callees 14 deep in turn fill 16.
  const program caller{{call_motion{rom_address{0x0143B8}}, end{}}};
  CHECK(ok(assemble(caller, hth4_2_0_motion_1, 14)));
  CHECK(failure_of(assemble(caller, hth4_2_0_motion_1, 15)) ==
        "the calls would nest 17 deep with the main loop's: the board's stack holds 16");
}

TEST_CASE("motion: disassembly follows the code, lift gives the program back", "[motion]") {
  auto rom = sample_bytes;
  // Leftovers of an older, longer motion after the RETURN: not code (nothing reaches them).
  const std::vector<std::uint8_t> leftovers = {0x0B, 0x10, 0x01, 0x00, 0x00, 0x00, 0x00, 0x0A, 0x34, 0x21, 0x7B, 0xFF};
  rom.insert(rom.end(), leftovers.begin(), leftovers.end());
  rom.resize(2048, 0xFF);
  const auto l = disassemble(rom, hth4_2_0_motion_1);
  CHECK(l.problems.empty());
  REQUIRE(l.code.size() == 10);
  CHECK(l.code.front().address == 0x0BB8);
  CHECK(l.code.back().address == 0x0C07);
  CHECK(std::holds_alternative<ret>(*l.code.back().cmd));
  CHECK(l.calls == std::vector<std::uint32_t>{0x0143B8});
  const auto p = lift(l);
  REQUIRE(ok(p));
  const auto& lifted = std::get<program>(p);
  CHECK(lifted.steps.size() == sample.steps.size());
  CHECK(std::get<label>(lifted.steps[2]).name == "L0BCB");
  const auto again = assemble(lifted, hth4_2_0_motion_1);
  REQUIRE(ok(again));
  CHECK(std::get<std::vector<std::uint8_t>>(again) == sample_bytes);

  // HTH4's own loop shape (motions.md §1): SUB, JUMP out when 0, JUMP back.
  const program hth4_loop{{set_counter{hth4_counter, 2}, label{"body"}, pose{ics0(8000), frames{5}},
                           count_down{hth4_counter, "out", true}, go_to{"body"}, label{"out"}, end{}}};
  const auto hb = assemble(hth4_loop, hth4_2_0_motion_1);
  REQUIRE(ok(hb));
  const auto& hbytes = std::get<std::vector<std::uint8_t>>(hb);
  const auto hl = lift(disassemble(hbytes, hth4_2_0_motion_1));
  REQUIRE(ok(hl));
  CHECK(std::get<std::vector<std::uint8_t>>(assemble(std::get<program>(hl), hth4_2_0_motion_1)) == hbytes);
}

TEST_CASE("motion: what cannot be read back is named, never made up", "[motion]") {
  const std::vector<std::uint8_t> erased(64, 0xFF);
  const auto e = disassemble(erased, hth4_2_0_motion_1);
  REQUIRE(e.problems.size() == 1);
  CHECK(e.problems[0].find("0x000BB8: not a frame") == 0);
  CHECK(std::get<failure>(lift(e)).message == e.problems[0]);
  // A jump out of the slot.
  const std::vector<std::uint8_t> out = {0x07, 0x0B, 0x00, 0x00, 0x01, 0x00, 0x13};  // JUMP 0x010000
  const auto o = disassemble(out, hth4_2_0_motion_1);
  REQUIRE(o.problems.size() == 1);
  CHECK(o.problems[0] == "0x000BB8: jumps out of the slot, to 0x010000");
  // HTH4's terminal MotionJump: a JUMP to another slot's first byte is a way out, like a call.
  const std::vector<std::uint8_t> tail_jump = {0x07, 0x0B, 0xB8, 0x13, 0x00, 0x00, 0xDD};  // JUMP 0x0013B8 (motion 2)
  const auto t = disassemble(tail_jump, hth4_2_0_motion_1);
  CHECK(t.problems.empty());
  CHECK(t.calls == std::vector<std::uint32_t>{0x0013B8});
  CHECK(t.notes.at(0) ==
        "0x000BB8: jumps to 0x0013B8 (another motion): the board goes on there and does not come back");
  // Code that runs for ever: listed, with a note.
  const std::vector<std::uint8_t> forever = {0x07, 0x0B, 0xB8, 0x0B, 0x00, 0x00, 0xD5};  // JUMP 0x000BB8
  const auto f = disassemble(forever, hth4_2_0_motion_1);
  CHECK(f.problems.empty());
  CHECK(f.notes == std::vector<std::string>{"0x000BB8: jumps to itself: the motion never ends (until it is stopped)"});
  // Code that runs off the bytes read.
  const std::vector<std::uint8_t> cut = {0x08, 0x00, 0x02, 0x57, 0x04, 0x00, 0x03, 0x68};  // MOV, then nothing
  CHECK(disassemble(cut, hth4_2_0_motion_1).problems.at(0) == "the code runs on to 0x000BC0, past the 8 bytes read");
  // A command no step expresses: SINGLE (0x0F) ICS 0 to 7500 in 5 frames.
  const std::vector<std::uint8_t> single = {0x07, 0x0F, 0x00, 0x05, 0x4C, 0x1D, 0x84, 0x03, 0x0D, 0x10};
  const auto s = disassemble(single, hth4_2_0_motion_1);
  CHECK(s.problems.empty());
  CHECK(std::get<failure>(lift(s)).message ==
        "0x000BB8: a command motions do not use (no step says that; the listing shows it)");
  // A jump over bytes that are no code: the listing is right, the steps cannot lay that out.
  const std::vector<std::uint8_t> gap = {0x07, 0x0B, 0xC0, 0x0B, 0x00, 0x00, 0xDD, 0x55, 0x03, 0x0D, 0x10};
  const auto g = disassemble(gap, hth4_2_0_motion_1);
  CHECK(g.problems.empty());
  CHECK(g.code.size() == 2);
  CHECK(std::get<failure>(lift(g)).message.find("not one block") != std::string::npos);
}

TEST_CASE("motion: the virtual board runs an assembled motion as a board does", "[motion][board]") {
  const program twice{{set_counter{hth4_counter, 2}, label{"loop"}, pose{ics0(8500), frames{5}},
                       pose{ics0(6500), frames{5}}, count_down{hth4_counter, "loop"}, end{}}};
  const auto where = slot_of(hth4_2_2, 7).value();
  const auto bytes = assemble(twice, where);
  REQUIRE(ok(bytes));
  board_wire w;
  ops::write_memory wr(ops::memory::rom, where.address.value(), std::get<std::vector<std::uint8_t>>(bytes));
  rcb4::testing::run(w, wr);
  REQUIRE(wr.error() == errc{});
  ops::play_motion play(7);
  rcb4::testing::run(w, play);
  REQUIRE(play.error() == errc{});
  int ticks = 0;
  bool saw_8500 = false;
  while (w.read_ram(0x0005, 5) != std::vector<std::uint8_t>(5, 0) && ticks++ < 300) {
    w.wait(10ms);
    saw_8500 = saw_8500 || w.read_word(0x0090 + 4) == 8500;
  }
  CHECK(ticks < 300);                      // it ended (RETURN to the main loop)
  CHECK(saw_8500);                         // through the loop's first pose
  CHECK(w.read_word(0x0090 + 4) == 6500);  // and its last
  CHECK(w.read_ram(0x0457, 1)[0] == 0);    // the counter ran down
}

// HTH4's CmpAD block (hth4-files.md §5.5): SUB flags-only AD2 (RAM 0x0026) − 300, then a JUMP with
// COND 0D for "≤": the frames written from the spec, assembled from an at_most step, read back,
// and run on the virtual board (taken when AD2 ≤ 300 under the "either" rule, §8).
TEST_CASE("motion: at_most is HTH4's AD <= limit compare (COND 0D)", "[motion][board]") {
  const program p{{branch_if{ram_address{0x0026}, 2, 300, compare::at_most, "low"}, set_counter{hth4_counter, 1}, end{},
                   label{"low"}, set_counter{hth4_counter, 2}, end{}}};
  const auto b = assemble(p, slot_of(hth4_2_2, 5).value());
  REQUIRE(ok(b));
  const auto& bytes = std::get<std::vector<std::uint8_t>>(b);
  // 0x2B80 SUB (9), 0x2B89 JUMP (7), 0x2B90 MOV (8), 0x2B98 RETURN (3), 0x2B9B "low".
  const std::vector<std::uint8_t> head = {
      0x09, 0x07, 0x82, 0x26, 0x00, 0x00, 0x2C,
      0x01, 0xE5,  // §5.5, as printed
      0x07, 0x0B, 0x9B, 0x2B, 0x00, 0x0D, static_cast<std::uint8_t>(0x07 + 0x0B + 0x9B + 0x2B + 0x0D)};
  REQUIRE(bytes.size() > head.size());
  CHECK(std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + 16) == head);
  const auto back = lift(disassemble(bytes, slot_of(hth4_2_2, 5).value()));
  REQUIRE(ok(back));
  CHECK(std::get<branch_if>(std::get<program>(back).steps[0]).how == compare::at_most);
  // Run on the virtual board with a noiseless 1-byte value (C2, 0x0458) against 10: §8's test.
  const program q{{branch_if{ram_address{0x0458}, 1, 10, compare::at_most, "low"}, set_counter{hth4_counter, 1}, end{},
                   label{"low"}, set_counter{hth4_counter, 2}, end{}}};
  const auto qb = assemble(q, slot_of(hth4_2_2, 5).value());
  REQUIRE(ok(qb));
  for (const auto& [c2, counter] : {std::pair{5, 2}, std::pair{10, 2}, std::pair{20, 1}}) {
    board_wire w;
    ops::write_memory wr(ops::memory::rom, 0x002B80, std::get<std::vector<std::uint8_t>>(qb));
    rcb4::testing::run(w, wr);
    REQUIRE(wr.error() == errc{});
    REQUIRE(w.write_ram(0x0458, {static_cast<std::uint8_t>(c2)}).is_ack());
    ops::play_motion play(5);
    rcb4::testing::run(w, play);
    REQUIRE(play.error() == errc{});
    w.wait(100ms);
    INFO("C2 " << c2);
    CHECK(w.read_ram(0x0457, 1)[0] == (two_flag_jump == two_flag_rule::either ? counter : 1));
  }
}
