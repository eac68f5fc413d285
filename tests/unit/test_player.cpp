// The host-side motion player: the actions a driver carries out, step by step, against what the
// board would do with the same program (motions.md §1-§2), without a clock or a port.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/motion/player.hpp>

#include <catch2/catch.hpp>

using namespace rcb4;
using namespace rcb4::motion;

namespace {
servo_set<servo_position> knee(int position) {
  servo_set<servo_position> s;
  s.insert(ics_number{16}, servo_position::make(position).value());
  return s;
}
template <class T>
T as(const action& a) {
  REQUIRE(std::holds_alternative<T>(a));
  return std::get<T>(a);
}
// Three knee bends, again while UP is held.
const program knee_bends{{set_counter{hth4_counter, 3}, label{"again"}, pose{knee(8389), frames{20}},
                          count_down{hth4_counter, "again"}, branch_if::buttons(0x0001, "again"), end{}}};
}  // namespace

TEST_CASE("player: poses as CONST frames with their frames to wait, a loop counted in the player", "[player]") {
  player p(knee_bends);
  REQUIRE(p.error().empty());
  for (int i = 0; i < 3; ++i) {
    const auto s = as<send>(p.next());
    CHECK(s.frames == 20);
    // protocol.md §5 by hand: ICS 16, flags set, 20 frames, 8389 = 0x20C5.
    const auto f = encode(s.cmd);
    CHECK(std::vector<std::uint8_t>(f.begin(), f.end()) ==
          std::vector<std::uint8_t>{0x0B, 0x10, 0x00, 0x00, 0x01, 0x00, 0x00, 0x14, 0xC5, 0x20, 0x15});
  }
  // The button test reads the button word from the board.
  const auto r = as<read_value>(p.next());
  CHECK(r.address.value() == 0x0350);
  CHECK(r.size == 2);
  p.value(0x0000);  // nothing pressed: on to the end
  as<finished>(p.next());
  CHECK(p.done());
  CHECK(p.error().empty());
  CHECK(p.poses() == 3);
}

TEST_CASE("player: a held button goes round again, and the counter wraps as the board's SUB does", "[player]") {
  player p(knee_bends);
  for (int i = 0; i < 3; ++i) as<send>(p.next());
  as<read_value>(p.next());
  p.value(0x0100);  // UP held (00 01 at 0x0350, read low byte first): back to 'again'
  as<send>(p.next());
  // The counter was 0: SUB 1 makes 255, not 0, so the loop goes on as it would on the board.
  as<send>(p.next());
  CHECK(p.poses() == 5);
}

TEST_CASE("player: a test of the counter compares the player's value, any other RAM is read", "[player]") {
  const program prog{{set_counter{hth4_counter, 2}, label{"top"}, count_down{hth4_counter, "out", true},
                      branch_if{hth4_counter, 1, 1, compare::equal, "one"}, go_to{"top"}, label{"one"},
                      servo_parameter{param_kind::stretch, {{ics_number{16}, servo_param{60}}}},
                      branch_if{ram_address{0x0460}, 1, 5, compare::below, "top"}, label{"out"},
                      call_motion{rom_address{0x001380}}, end{}}};
  player p(prog);
  REQUIRE(p.error().empty());
  // 2 - 1 = 1: not zero, no exit; equal to 1: to 'one'; the stretch frame, with no wait.
  const auto s = as<send>(p.next());
  CHECK(s.frames == 0);
  CHECK(std::holds_alternative<servo_params>(s.cmd));
  // 0x0460 is no counter of the player: read from the board. 7 is not below 5: on to 'out'.
  const auto r = as<read_value>(p.next());
  CHECK(r.address.value() == 0x0460);
  CHECK(r.size == 1);
  p.value(0x1107);  // a 1-byte value: the high byte is not part of it
  CHECK(as<play_code>(p.next()).address.value() == 0x001380);
  as<finished>(p.next());
  CHECK(p.done());
  CHECK(p.calls() == 1);
}

TEST_CASE("player: programs that cannot be played say why and finish", "[player]") {
  player spin(program{{label{"a"}, go_to{"a"}}});
  as<finished>(spin.next());
  CHECK_FALSE(spin.done());
  CHECK(spin.error().find("without a pose, a read or a call") != std::string::npos);

  player missing(program{{go_to{"nowhere"}}});
  CHECK(missing.error() == "step 0: no label is called 'nowhere'");
  as<finished>(missing.next());

  player twice(program{{label{"a"}, label{"a"}, end{}}});
  CHECK(twice.error().find("'a' is defined twice") != std::string::npos);

  player past(program{{pose{knee(7500), frames{1}}}});
  as<send>(past.next());
  as<finished>(past.next());
  CHECK(past.error().find("runs past its last step") != std::string::npos);

  player empty_pose(program{{pose{{}, frames{1}}, end{}}});
  CHECK_FALSE(empty_pose.error().empty());

  player early(knee_bends);
  early.value(3);
  CHECK(early.error() == "value() without a read_value");
}
