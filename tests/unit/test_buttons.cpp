// Button names, the vector table as entries (motion/buttons.hpp) and the layout told from a ROM
// (ops/layout.hpp), on their own and on the virtual board.
// SPDX-License-Identifier: BSL-1.0
#include "board_wire.hpp"

#include <rcb4/motion/buttons.hpp>
#include <rcb4/ops/layout.hpp>

#include <catch2/catch.hpp>

using namespace rcb4;
namespace mo = rcb4::motion;
using rcb4::testing::board_wire;

TEST_CASE("buttons: names both ways", "[motion][buttons]") {
  CHECK(std::get<std::uint16_t>(mo::parse_buttons("up")) == 0x0001);
  CHECK(std::get<std::uint16_t>(mo::parse_buttons("S1+Up")) == 0x0201);
  CHECK(std::get<std::uint16_t>(mo::parse_buttons("tri+square")) == 0x0110);
  CHECK(std::get<std::uint16_t>(mo::parse_buttons("0x1000")) == 0x1000);
  CHECK(std::get<std::uint16_t>(mo::parse_buttons("3")) == 0x0003);
  CHECK(mo::buttons_text(0x0201) == "up+s1");
  CHECK(mo::buttons_text(0) == "none");
  CHECK(mo::buttons_text(0x0080) == "0x0080");
  const auto bad = mo::parse_buttons("up+jump");
  REQUIRE_FALSE(mo::ok(bad));
  CHECK(std::get<mo::failure>(bad).message.find("'jump' is no button") != std::string::npos);
  CHECK_FALSE(mo::ok(mo::parse_buttons("0x0080")));  // bit 7: no button
  CHECK_FALSE(mo::ok(mo::parse_buttons("0")));
  CHECK_FALSE(mo::ok(mo::parse_buttons("up+")));
  CHECK_FALSE(mo::ok(mo::parse_buttons("")));
  CHECK_FALSE(mo::ok(mo::parse_buttons("0x1G")));
}

TEST_CASE("buttons: a table is edited, encoded and read back", "[motion][buttons]") {
  const rom_address m2{0x1380}, m3{0x1B80}, m4{0x2380};
  auto t = mo::assign_button({}, 0x0001, m2);
  t = mo::assign_button(std::get<std::vector<vector_entry>>(t), 0x0002, m3);
  t = mo::assign_button(std::get<std::vector<vector_entry>>(t), 0x0001, m4);  // replaced in place
  const auto entries = std::get<std::vector<vector_entry>>(t);
  REQUIRE(entries.size() == 2);
  CHECK(entries[0].target == m4);
  const auto bytes = std::get<std::vector<std::uint8_t>>(mo::encode_vector_table(entries));
  // By hand (protocol.md §6): entry 0 UP → CALL 0x002380, entry 1 DOWN → CALL 0x001B80 with EOF.
  const std::vector<std::uint8_t> golden = {0x35, 0x50, 0x03, 0x00, 0x01, 0x80, 0x23, 0x00,
                                            0xB5, 0x50, 0x03, 0x00, 0x02, 0x80, 0x1B, 0x00};
  CHECK(bytes == golden);
  const auto back = mo::decode_vector_table(bytes);
  CHECK(back.ended);
  CHECK(back.problem.empty());
  CHECK(back.entries.size() == 2);
  CHECK(back.entries[1].last);
  const auto cleared = mo::clear_button(entries, 0x0001);
  REQUIRE(cleared);
  CHECK(cleared->size() == 1);
  CHECK_FALSE(mo::clear_button(entries, 0x0004));
  // No entry: one that never fires (the button word minus 0 never borrows: C = 0 alone), with EOF:
  // F8 = EOF 80 | JUMP 40 | WORD 20 | literal 10 | compare C 08 (C = 0); source literal 0.
  const auto empty = std::get<std::vector<std::uint8_t>>(mo::encode_vector_table({}));
  CHECK(empty == std::vector<std::uint8_t>{0xF8, 0x50, 0x03, 0x00, 0x00, 0x00, 0x00, 0x00});
  const auto none = mo::decode_vector_table(empty);
  CHECK(none.entries.empty());
  CHECK(none.ended);
  CHECK_FALSE(none.entries.size());
  std::vector<vector_entry> full(32, vector_entry::button(0x0010, m2));
  CHECK_FALSE(mo::ok(mo::assign_button(full, 0x0020, m2)));
  full.push_back(full[0]);
  CHECK_FALSE(mo::ok(mo::encode_vector_table(full)));
  const std::vector<std::uint8_t> erased(256, 0xFF);
  const auto e = mo::decode_vector_table(erased);
  CHECK(e.entries.empty());
  CHECK(e.problem.find("erased") != std::string::npos);
}

TEST_CASE("buttons: a never-firing entry never fires on the board", "[motion][buttons][board]") {
  const auto n = mo::never_entry();
  for (unsigned l : {0u, 1u, 0x100u, 0xFFFFu}) CHECK_FALSE(n.fires(static_cast<std::uint16_t>(l), 0));
  // rcb4 0.1's marker (Z = 1 and C = 0, FD …) fires with no button held when either flag is
  // enough (hth4-files.md §8): it is then a live entry, listed, not hidden.
  const std::uint8_t old_bytes[] = {0xFD, 0x50, 0x03, 0x00, 0x00, 0x00, 0x00, 0x00};
  const auto old = mo::decode_vector_table(old_bytes);
  if constexpr (two_flag_jump == two_flag_rule::either) {
    REQUIRE(old.entries.size() == 1);
    CHECK(old.entries[0].fires(0, 0));
    CHECK_FALSE(old.entries[0].fires(0x0100, 0));
  } else {
    CHECK(old.entries.empty());
  }
}

TEST_CASE("layout: told from the ROM, never guessed", "[ops][layout]") {
  std::vector<std::uint8_t> erased(128, 0xFF);
  const auto pose = encode(const_servo::make({{0, 7500}, {1, 7600}}, 10).value());
  std::vector<std::uint8_t> frame(pose.begin(), pose.end());
  frame.resize(128, 0xFF);
  const auto loop = encode(jump{rom_address{0x044B}});
  std::vector<std::uint8_t> main_loop(loop.begin(), loop.end());
  main_loop.resize(128, 0xFF);
  CHECK(ops::judge_layout(frame, erased, main_loop, erased).layout == &hth4_2_2);
  CHECK(ops::judge_layout(erased, frame, main_loop, erased).layout == &hth4_2_0);
  CHECK(ops::judge_layout(erased, frame, erased, main_loop).layout == &hth4_1_3);
  CHECK(ops::judge_layout(erased, frame, main_loop, main_loop).layout == nullptr);
  const auto none = ops::judge_layout(erased, erased, main_loop, erased);
  CHECK(none.layout == nullptr);
  CHECK(none.reason.find("no motion 1") != std::string::npos);
  // Motion 1 at 0x0B80 whose frames run across 0x0BB8: CONST of 5 servos (9 + 2·5 = 19 bytes) and
  // of 14 (37 bytes) end exactly at 0x0BB8, where the next frame starts: HTH4 2.2.
  servo_set<servo_position> five, fourteen;
  for (std::uint8_t k = 0; k < 14; ++k) {
    if (k < 5) five.insert(ics_number::make(k).value(), servo_position{7500});
    fourteen.insert(ics_number::make(k).value(), servo_position{7500});
  }
  const auto a = encode(const_servo::make(five, frames{1}).value());
  const auto b = encode(const_servo::make(fourteen, frames{1}).value());
  REQUIRE(a.size() + b.size() == 56);
  std::vector<std::uint8_t> across(a.begin(), a.end());
  across.insert(across.end(), b.begin(), b.end());
  across.insert(across.end(), pose.begin(), pose.end());
  across.resize(128, 0xFF);
  const std::vector<std::uint8_t> at_0bb8(across.begin() + 56, across.end());
  CHECK(ops::judge_layout(across, at_0bb8, main_loop, erased).layout == &hth4_2_2);
  CHECK(ops::judge_layout(frame, frame, main_loop, erased).layout == nullptr);  // 13 bytes then erased: not across
}

TEST_CASE("layout: the virtual board's default ROM is HTH4 2.2", "[ops][layout][board]") {
  board_wire w;
  ops::detect_layout d;
  testing::run(w, d);
  REQUIRE(d.error() == errc{});
  CHECK(d.value().layout == &hth4_2_2);
}
