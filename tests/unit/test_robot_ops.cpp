// Robot operations on the virtual board: joints located through the allocation table, read,
// moved in CONST frames timed by the board's output period, trims in RAM and ROM; scans and the
// motion list. Expected bytes and figures are worked out by hand from protocol.md.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/ops/survey.hpp>
#include <rcb4/robot/ops.hpp>

#include <catch2/catch.hpp>

#include "board_wire.hpp"

using namespace rcb4;
using namespace rcb4::robot;
using namespace std::chrono_literals;
using rcb4::testing::board_wire;
using rcb4::testing::run;

namespace {
joint make_joint(std::string name, unsigned ics, int direction = 1, double offset = 0) {
  joint j;
  j.name = std::move(name);
  j.ics = ics_number::make(ics).value();
  j.direction = direction;
  j.offset = offset;
  j.lower = -90;
  j.upper = 90;
  return j;
}
/** Three joints of the virtual KHR-3HV, one reversed with an offset, and one on a slot it lacks. */
model arm(bool with_unallocated = false) {
  std::vector<joint> js{make_joint("head_yaw", 0), make_joint("left_knee", 16, -1, 5), make_joint("right_knee", 17)};
  if (with_unallocated) js.push_back(make_joint("tail", 10));
  return std::get<model>(model::make("test", js, {{"knees", {"left_knee", "right_knee"}}}));
}
std::vector<joint_move> checked(const model& m, std::vector<joint_target> t, std::chrono::milliseconds time) {
  auto r = check_targets(m, t, time);
  if (!ok(r)) FAIL(std::get<problem>(r).message);
  return std::get<std::vector<joint_move>>(r);
}
}  // namespace

TEST_CASE("robot ops: joints are located through the allocation table and read in planned reads", "[robot]") {
  board_wire w;
  const auto m = arm(true);
  // Move right_knee's block (ICS 17) to 0x0400 with position 8000 and trim -3: the read must follow the table.
  REQUIRE(w.write_ram(0x0400, {0, 8, 0xFD, 0xFF, 0x40, 0x1F, 0x40, 0x1F}).is_ack());
  REQUIRE(w.write_ram(0x0044 + 2 * 17, {0x00, 0x04}).is_ack());
  locate_joints where(m);
  run(w, where);
  REQUIRE(where.error() == errc{});
  REQUIRE(where.value().missing().size() == 1);
  CHECK(where.value().missing()[0]->name == "tail");
  CHECK(where.value().block_of(*m.find("right_knee")) == 0x0400);

  read_joints rd(where.value(), fields::state, ops::link_cost::at(1250000, 1ms));
  run(w, rd);
  REQUIRE(rd.error() == errc{});
  const auto& v = rd.value();
  REQUIRE(v.size() == 4);
  CHECK(v[0].position == 7500);
  CHECK(v[0].degrees().value() == Approx(0.0));
  // left_knee: servo at 7500 = servo 0°, joint = (0 - 5) / -1 = +5°
  CHECK(v[1].degrees().value() == Approx(5.0));
  CHECK(v[2].position == 8000);
  CHECK(v[2].trim == -3);
  CHECK(v[2].degrees().value() == Approx(500 * 135.0 / 4000));
  CHECK_FALSE(v[3].allocated);
  CHECK_FALSE(v[3].degrees().has_value());
  // At 1 ms per exchange one read covers ICS 0 and 16 (0x0092..0x01D7 is beyond 128 bytes: two), plus 0x0400.
  CHECK(rd.plan().size() == 3);

  // positions only, on a fast link: one 2-byte read per joint.
  read_joints fast(where.value(), fields::positions, ops::link_cost::at(1250000, 0ms));
  CHECK(fast.plan().size() == 3);
  for (const auto& r : fast.plan()) CHECK(r.size == 2);
  run(w, fast);
  CHECK(fast.value()[2].position == 8000);
  CHECK(fast.value()[2].target == 0);  // not read
  fast.restart();
  REQUIRE(w.write_ram(0x0404, {0x58, 0x1B}).is_ack());  // 7000
  run(w, fast);
  CHECK(fast.value()[2].position == 7000);
}

TEST_CASE("robot ops: a servo that never answered has no angle", "[robot]") {
  board::options o;
  o.unanswered.insert(ics_number{16});  // left_knee's servo: its measured position stays 0
  board_wire w(o);
  const auto m = arm();
  locate_joints where(m);
  run(w, where);
  read_joints rd(where.value(), fields::state);
  run(w, rd);
  REQUIRE(rd.error() == errc{});
  const auto& knee = rd.value()[1];
  CHECK(knee.allocated);
  CHECK(knee.position == 0);
  CHECK_FALSE(knee.answered());
  CHECK_FALSE(knee.degrees().has_value());  // not -253 degrees
  CHECK(rd.value()[0].degrees().value() == Approx(0.0));
  // A block the board never drove reads a target of 0: no angle either.
  joint_reading never = knee;
  never.target = 0;
  CHECK_FALSE(never.target_degrees().has_value());
  never.target = 7500;
  CHECK(never.target_degrees().has_value());  // the centre is an angle (the joint's offset decides which)
}

TEST_CASE("robot ops: a move becomes CONST frames timed by the board's output period", "[robot]") {
  board_wire w;
  const auto m = arm();
  // head to 30° over 300 ms, knees to 10° over the default 500 ms: at 10 ms, 30 and 50 frames.
  auto moves = checked(m, {{"head_yaw", 30, 300ms}, {"left_knee", 10, {}}, {"right_knee", 10, {}}}, 500ms);
  move_joints op(moves);
  const auto sent = run(w, op);
  REQUIRE(op.error() == errc{});
  REQUIRE(sent.size() == 4);  // table, config, two CONST frames
  const auto& slow = std::get<const_servo>(sent[2]);
  CHECK(slow.speed().value() == 50);  // slowest first
  CHECK(slow.targets().size() == 2);
  // left_knee 10°: servo −10 + 5 = −5° → 7500 − 148.1 = 7352; right_knee 10° → 7500 + 296.3 = 7796
  CHECK(slow.targets().find(ics_number{16})->value() == 7352);
  CHECK(slow.targets().find(ics_number{17})->value() == 7796);
  const auto& fast = std::get<const_servo>(sent[3]);
  CHECK(fast.speed().value() == 30);
  CHECK(fast.targets().find(ics_number{0})->value() == 8389);  // 7500 + 30 × 29.63
  CHECK(op.value()[0].frames == 30);
  w.wait(600ms);
  CHECK(w.read_word(0x0090 + 4) == 8389);
  CHECK(w.read_word(0x0090 + 20 * 16 + 4) == 7352);

  // At a 25 ms period the same 300 ms is 12 frames.
  REQUIRE(w.write_ram(0x0000, {static_cast<std::uint8_t>((board::default_config & 0xCF) | 0x30),
                               static_cast<std::uint8_t>(board::default_config >> 8)})
              .is_ack());
  move_joints slow25(checked(m, {{"head_yaw", 0, 300ms}}, 0ms));
  const auto sent25 = run(w, slow25);
  REQUIRE(slow25.error() == errc{});
  CHECK(std::get<const_servo>(sent25.back()).speed().value() == 12);
  CHECK(slow25.period() == output_period::ms25);
}

TEST_CASE("robot ops: a control loop's targets, set in degrees, go out as one CONST frame", "[robot]") {
  board_wire w;
  const auto m = arm(true);
  locate_joints where(m);
  run(w, where);
  REQUIRE(where.error() == errc{});
  joint_targets t(where.value());
  REQUIRE(t.joints().size() == 3);  // "tail" has no block: it takes no target
  CHECK(t.joints()[1]->name == "left_knee");
  CHECK_FALSE(t.set("head_yaw", 30).has_value());
  CHECK_FALSE(t.set(1, 10).has_value());  // left_knee
  const auto refused = t.set("right_knee", 100);
  REQUIRE(refused.has_value());
  CHECK(refused->message == "right_knee: 100 degrees is beyond its upper limit 90");
  CHECK(t.set("tail", 0)->message == "no located joint is called 'tail'");
  CHECK(t.set(3, 0).has_value());
  CHECK(t.set(*m.find("tail"), 0).has_value());
  CHECK_FALSE(t.set(*m.find("head_yaw"), 30).has_value());  // by the joint a reading names
  // protocol.md §4.7: SIZE 9+2·3, CMD 10, mask ICS 0, 16, 17 = 01 00 03 00 00, 1 frame, then in
  // ICS order 8389 (head 30°), 7352 (left knee 10°: servo −5°), HOLD 7FFF (right knee, never set).
  const auto frame = t.frame(frames{1}).value();
  const std::vector<std::uint8_t> expected{0x0F, 0x10, 0x01, 0x00, 0x03, 0x00, 0x00, 0x01,
                                           0xC5, 0x20, 0xB8, 0x1C, 0xFF, 0x7F, 0x5B};
  const auto encoded = encode(frame);
  CHECK(std::vector<std::uint8_t>(encoded.bytes().begin(), encoded.bytes().end()) == expected);
  CHECK(w.send(frame).is_ack());
  w.wait(50ms);
  CHECK(w.read_word(0x0090 + 6) == 8389);  // head_yaw's output
  // Nothing located: no frame.
  CHECK(joint_targets(joint_map{}).frame(frames{1}).error() == errc::empty_servo_set);
}

TEST_CASE("robot ops: bad targets are refused before anything is sent", "[robot]") {
  const auto m = arm(true);
  auto why = [&](std::vector<joint_target> t) {
    auto r = check_targets(m, t, 500ms);
    REQUIRE_FALSE(ok(r));
    return std::get<problem>(r).message;
  };
  CHECK(why({{"head_yaw", 91, {}}}).find("head_yaw: 91") == 0);
  CHECK(why({{"head_yaw", 91, {}}}).find("upper limit 90") != std::string::npos);
  CHECK(why({{"neck", 1, {}}}) == "no joint is called 'neck' (see joint list)");
  CHECK(why({{"head_yaw", 1, {}}, {"head_yaw", 2, {}}}) == "head_yaw is given twice");
  CHECK(why({{"head_yaw", 1, 7000ms}}) == "head_yaw: a move takes 0..6375 ms, not 7000");
  CHECK(why({}) == "no joint to move");

  // 3 s is 300 frames at 10 ms: more than a CONST frame carries; refused after the config read.
  board_wire w;
  move_joints too_long(checked(m, {{"head_yaw", 0, 3000ms}}, 0ms));
  const auto sent = run(w, too_long);
  CHECK(too_long.error() == errc::frames_out_of_range);
  CHECK(sent.size() == 2);  // the table and the config word: nothing moved

  move_joints tail(checked(m, {{"tail", 0, {}}}, 100ms));
  CHECK(run(w, tail).size() == 1);
  CHECK(tail.error() == errc::servo_not_allocated);
  CHECK(tail.unallocated()->name == "tail");
}

TEST_CASE("robot ops: frames from milliseconds", "[robot]") {
  CHECK(frames_for(0ms, output_period::ms10) == 0u);
  CHECK(frames_for(1ms, output_period::ms10) == 1u);  // a non-zero time is at least one frame
  CHECK(frames_for(14ms, output_period::ms10) == 1u);
  CHECK(frames_for(15ms, output_period::ms10) == 2u);
  CHECK(frames_for(2550ms, output_period::ms10) == 255u);
  CHECK_FALSE(frames_for(2556ms, output_period::ms10).has_value());
  CHECK(frames_for(6375ms, output_period::ms25) == 255u);
}

TEST_CASE("robot ops: trims go to RAM +2 and, persistently, to HTH4's servo image in ROM", "[robot]") {
  board_wire w;
  const auto m = arm();
  const auto* knee = m.find("left_knee");  // direction -1
  auto t = trim_of(*knee, 1.5);
  REQUIRE(ok(t));
  CHECK(std::get<joint_trim>(t).counts == -44);  // -1 × 1.5 × 29.63 = -44.4
  CHECK(trim_degrees(*knee, -44) == Approx(1.485).margin(0.001));
  CHECK_FALSE(ok(trim_of(*knee, 31)));

  write_trims ram_only({std::get<joint_trim>(t)}, false);
  CHECK(run(w, ram_only).size() == 2);
  REQUIRE(ram_only.error() == errc{});
  CHECK(static_cast<std::int16_t>(w.read_word(0x0090 + 20 * 16 + 2)) == -44);
  w.board().power_on();  // RAM only: gone after a power cycle
  CHECK(w.read_word(0x0090 + 20 * 16 + 2) == 0);

  CHECK(ram_only.in_ram() == 1);
  CHECK(ram_only.in_rom() == 0);

  write_trims kept({std::get<joint_trim>(t)}, true);
  CHECK(run(w, kept).size() == 3);
  REQUIRE(kept.error() == errc{});
  CHECK(kept.in_ram() == 1);
  CHECK(kept.in_rom() == 1);
  // Cut off after the RAM write (the board went away): what changed is known.
  write_trims cut({std::get<joint_trim>(t)}, true);
  CHECK(cut.in_ram() == 0);
  cut.on_reply(w.send(*cut.next()));  // the table
  cut.on_reply(w.send(*cut.next()));  // RAM +2
  CHECK(cut.in_ram() == 1);
  CHECK(cut.in_rom() == 0);
  // ROM 0x00626 + (0x01D0 − 0x0090) + 2 = 0x00768 holds it (protocol.md §8)
  CHECK(w.board().rom()[0x00768] == 0xD4);
  CHECK(w.board().rom()[0x00769] == 0xFF);
  w.board().power_on();
  CHECK(static_cast<std::int16_t>(w.read_word(0x0090 + 20 * 16 + 2)) == -44);

  auto un = arm(true);
  write_trims none({{un.find("tail"), 5}}, true);
  CHECK(run(w, none).size() == 1);
  CHECK(none.error() == errc::servo_not_allocated);
}

TEST_CASE("robot ops: a nonsense allocation table moves nothing and writes no trim", "[robot]") {
  board_wire w;
  // Every KHR-3HV block shifted by one byte (0x0091 + 20k): odd addresses, refused whole.
  std::vector<std::uint8_t> table(70, 0xFF);
  for (unsigned k : {0u, 1u, 2u, 16u, 17u}) {
    const unsigned a = 0x0091 + 20 * k;
    table[2 * k] = static_cast<std::uint8_t>(a & 0xFF);
    table[2 * k + 1] = static_cast<std::uint8_t>(a >> 8);
  }
  REQUIRE(w.write_ram(0x0044, table).is_ack());
  const auto m = arm();
  locate_joints where(m);
  run(w, where);
  CHECK(where.error() == errc::bad_allocation_table);

  const auto trim_before = w.read_word(0x0090 + 20 * 16 + 2);
  const auto target_before = w.read_word(0x0090 + 20 * 16 + 6);
  write_trims trims({std::get<joint_trim>(trim_of(*m.find("left_knee"), 2.0))}, true);
  CHECK(run(w, trims).size() == 1);  // the table read only
  CHECK(trims.error() == errc::bad_allocation_table);
  move_joints mv(checked(m, {{"left_knee", 10, {}}}, 100ms));
  CHECK(run(w, mv).size() == 1);
  CHECK(mv.error() == errc::bad_allocation_table);
  w.wait(200ms);
  CHECK(w.read_word(0x0090 + 20 * 16 + 2) == trim_before);
  CHECK(w.read_word(0x0090 + 20 * 16 + 6) == target_before);
}

TEST_CASE("robot ops: a scan tells allocated slots that answer from those that never did", "[robot]") {
  board::options o;
  o.unanswered.insert(ics_number{7});
  board_wire w(o);
  ops::scan_slots scan(ops::link_cost::at(1250000, 1ms));
  run(w, scan);
  REQUIRE(scan.error() == errc{});
  REQUIRE(scan.value().size() == 20);
  for (const auto& p : scan.value()) CHECK(p.answers() == (p.ics.value() != 7));
  // The silent servo stays silent when driven; a free servo turned by hand is measured there.
  REQUIRE(w.send(single_servo{7, 8000, 0}).is_ack());
  w.wait(20ms);
  CHECK(w.read_word(0x0090 + 20 * 7 + 4) == 0);
  CHECK_FALSE(w.board().turn_by_hand(ics_number{7}, 8000));
  REQUIRE(w.send(single_servo{3, servo_position::free(), 0}).is_ack());
  CHECK(w.board().turn_by_hand(ics_number{3}, 6000));
  w.wait(20ms);
  CHECK(w.read_word(0x0090 + 20 * 3 + 4) == 6000);
}

TEST_CASE("robot ops: the motion list walks used slots to their RETURN", "[robot]") {
  board_wire w;
  ops::list_motions list;
  run(w, list);
  REQUIRE(list.error() == errc{});
  const auto& v = list.value();
  REQUIRE(v.size() == 3);
  // home: one CONST of 20 servos (9 + 2×20 = 49 bytes) and RETURN (3)
  CHECK(v[0].number == 1);
  CHECK(v[0].address == 0x00B80);
  CHECK(v[0].size == 52);
  CHECK(v[0].frames == 2);
  CHECK(v[0].ends);
  // wave: CONSTs of 2, 1, 1, 1, 2 servos (13 + 11 + 11 + 11 + 13) and RETURN
  CHECK(v[1].number == 2);
  CHECK(v[1].size == 62);
  // bow: CONSTs of 4, 2, 4 servos (17 + 13 + 17) and RETURN
  CHECK(v[2].number == 3);
  CHECK(v[2].size == 50);
  CHECK(v[2].frames == 4);
  CHECK(list.slots_done() == 120);

  // A slot whose first frame fails its sum (another layout) is listed as unreadable.
  ops::list_motions other(hth4_2_0);
  run(w, other);
  REQUIRE(other.error() == errc{});
  for (const auto& s : other.value()) CHECK_FALSE(s.ends);
}
