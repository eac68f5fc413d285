// Operations (sans-I/O) run against the virtual board through frames only.
// SPDX-License-Identifier: BSL-1.0
#include "board_wire.hpp"

#include <rcb4/ops.hpp>

#include <catch2/catch.hpp>

#include <random>

using namespace rcb4;
using namespace std::chrono_literals;
using rcb4::testing::board_wire;

namespace {
using rcb4::testing::run;
std::size_t read_size(const command& c) { return std::get<move>(c).src().size(); }
}  // namespace

TEST_CASE("ops: memory of any length in legal frames, never a 1-byte read", "[ops]") {
  board_wire w;
  std::vector<std::uint8_t> pattern(300);
  for (std::size_t i = 0; i < pattern.size(); ++i) pattern[i] = static_cast<std::uint8_t>(i * 7);
  ops::write_memory wr(ops::memory::ram, 0x0300, pattern);
  const auto writes = run(w, wr);
  CHECK(wr.error() == errc{});
  CHECK(writes.size() == 3);  // 121 + 121 + 58
  ops::read_memory rd(ops::memory::ram, 0x0300, 300);
  const auto reads = run(w, rd);
  REQUIRE(rd.error() == errc{});
  CHECK(rd.value() == pattern);
  CHECK(reads.size() == 3);  // 128 + 128 + 44
  // 129 bytes would end with a 1-byte piece: it is read as 2 overlapping bytes instead.
  ops::read_memory odd(ops::memory::ram, 0x0300, 129);
  const auto odd_reads = run(w, odd);
  REQUIRE(odd.error() == errc{});
  CHECK(odd.value() == std::vector<std::uint8_t>(pattern.begin(), pattern.begin() + 129));
  for (const auto& c : odd_reads) CHECK(read_size(c) >= 2);
  for (std::uint32_t at : {0x0400u, 0x048Fu}) {
    ops::read_memory one(ops::memory::ram, at, 1);
    const auto r = run(w, one);
    REQUIRE(one.error() == errc{});
    CHECK(one.value().size() == 1);
    CHECK(read_size(r.at(0)) == 2);
  }
  // ROM and ICS fields too.
  ops::write_memory rom_w(ops::memory::rom, 0x020000, pattern);
  run(w, rom_w);
  ops::read_memory rom_r(ops::memory::rom, 0x020000, 300);
  run(w, rom_r);
  CHECK(rom_r.value() == pattern);
  ops::read_memory ics(ops::memory::ics, 4, 2, 3);
  run(w, ics);
  CHECK((ics.value()[0] | (ics.value()[1] << 8)) == 7500);
  // Out of range: refused before anything is sent.
  ops::read_memory bad(ops::memory::ram, 0x0480, 32);
  CHECK(run(w, bad).empty());
  CHECK(bad.error() == errc::ram_address_out_of_range);
  ops::read_memory unallocated(ops::memory::ics, 4, 2, 30);
  run(w, unallocated);
  CHECK(unallocated.error() == errc::nack);
}

TEST_CASE("ops: the read planner is exact", "[ops][planner]") {
  const auto slow = ops::link_cost::at(115200, 0ns), fast = ops::link_cost::at(1250000, 1ms);
  std::vector<ops::byte_range> blocks;
  for (std::uint32_t k = 0; k < 22; ++k) blocks.push_back({0x0092 + 20 * k, 6});
  CHECK(ops::plan_reads(blocks, slow).size() == 22);  // no overhead: gaps cost more than frames
  CHECK(ops::plan_reads(blocks, fast).size() == 4);   // 1 ms per exchange: merge into ≤128-byte reads
  for (const auto& r : ops::plan_reads(blocks, fast)) CHECK(r.size <= 128);
  // Against brute force over every grouping of up to 8 random ranges.
  std::mt19937 rng(5);
  for (int round = 0; round < 300; ++round) {
    std::vector<ops::byte_range> ranges;
    std::uint32_t at = 0;
    const int n = std::uniform_int_distribution<int>(1, 8)(rng);
    for (int i = 0; i < n; ++i) {
      at += static_cast<std::uint32_t>(std::uniform_int_distribution<int>(1, 60)(rng));
      const auto size = static_cast<std::uint32_t>(std::uniform_int_distribution<int>(1, 20)(rng));
      ranges.push_back({at, size});
      at += size;
    }
    const auto cost =
        ops::link_cost::at(1250000, std::chrono::microseconds(std::uniform_int_distribution<int>(0, 800)(rng)));
    std::int64_t best = std::numeric_limits<std::int64_t>::max();
    for (unsigned cuts = 0; cuts < (1u << (n - 1)); ++cuts) {
      std::int64_t total = 0;
      std::size_t first = 0;
      bool ok = true;
      for (int i = 0; i < n; ++i) {
        if (i == n - 1 || (cuts & (1u << i))) {
          const auto span = ranges[static_cast<std::size_t>(i)].address + ranges[static_cast<std::size_t>(i)].size -
                            ranges[first].address;
          if (span > 128) ok = false;
          total += cost.read(span).count();
          first = static_cast<std::size_t>(i) + 1;
        }
      }
      if (ok) best = std::min(best, total);
    }
    std::int64_t planned = 0;
    for (const auto& r : ops::plan_reads(ranges, cost)) planned += cost.read(r.size).count();
    REQUIRE(planned == best);
  }
}

TEST_CASE("ops: the heap-free planner makes the same plan, and says when it cannot hold one", "[ops][planner]") {
  std::mt19937 rng(11);
  for (int round = 0; round < 300; ++round) {
    std::vector<ops::byte_range> ranges;  // overlapping, touching, out of order, long: all allowed
    const int n = std::uniform_int_distribution<int>(0, 35)(rng);
    for (int i = 0; i < n; ++i)
      ranges.push_back({static_cast<std::uint32_t>(std::uniform_int_distribution<int>(0, 1000)(rng)),
                        static_cast<std::uint32_t>(std::uniform_int_distribution<int>(0, 150)(rng))});
    const auto cost =
        ops::link_cost::at(1250000, std::chrono::microseconds(std::uniform_int_distribution<int>(0, 1500)(rng)));
    const auto heap = ops::plan_reads(ranges, cost);
    const auto fixed = ops::plan_reads_fixed<80>(ranges, cost);
    REQUIRE(fixed.has_value());  // 35 ranges of at most 150 bytes: at most 70 parts
    REQUIRE(std::vector<ops::byte_range>(fixed->begin(), fixed->end()) == heap);
  }
  // More ranges than it holds, or more parts after splitting: nothing, never a cut plan.
  const std::vector<ops::byte_range> three{{0, 2}, {10, 2}, {20, 2}};
  CHECK_FALSE(ops::plan_reads_fixed<2>(three, {}).has_value());
  CHECK(ops::plan_reads_fixed<3>(three, {}).has_value());
  const std::vector<ops::byte_range> long_one{{0x0100, 300}};  // 128 + 128 + 44
  CHECK_FALSE(ops::plan_reads_fixed<2>(long_one, {}).has_value());
  REQUIRE(ops::plan_reads_fixed<3>(long_one, {}).has_value());
  CHECK(ops::plan_reads_fixed<3>(long_one, {})->size() == 3);
  CHECK(ops::plan_reads_fixed<1>(std::vector<ops::byte_range>{}, {})->empty());
}

TEST_CASE("ops: read_servo_states_fixed reads what read_servo_states reads, without the heap", "[ops][servo]") {
  board_wire w;
  REQUIRE(w.send(single_servo{3, 8000, 0}).is_ack());
  ops::read_servo_states_fixed fixed(ops::link_cost::at(1250000, 1ms));
  ops::read_servo_states heap(ops::link_cost::at(1250000, 1ms));
  const auto frames_fixed = run(w, fixed);
  const auto frames_heap = run(w, heap);
  REQUIRE(fixed.error() == errc{});
  CHECK(frames_fixed == frames_heap);  // the same reads, byte for byte
  REQUIRE(fixed.value().size() == 20);
  CHECK(std::vector<ops::servo_state>(fixed.value().begin(), fixed.value().end()) == heap.value());
  CHECK(fixed.value()[3].target == 8000);
  // A table no board should have: refused as by the heap version.
  REQUIRE(w.write_ram(0x0044, {0x91, 0x00}).is_ack());  // ICS 0 at an odd address
  ops::read_servo_states_fixed bad;
  run(w, bad);
  CHECK(bad.error() == errc::bad_allocation_table);
  CHECK(bad.value().empty());
}

TEST_CASE("ops: servo states through the allocation table", "[ops][servo]") {
  board_wire w;
  REQUIRE(w.send(single_servo{3, 8000, 0}).is_ack());
  // Move ICS 5's block to 0x0400 and give it a trim: the state must come from there.
  REQUIRE(w.write_ram(0x0400, {0, 2, 0xF6, 0xFF, 0x10, 0x1F, 0x10, 0x1F}).is_ack());  // trim −10, 7952
  REQUIRE(w.write_ram(0x0044 + 10, {0x00, 0x04}).is_ack());
  ops::read_servo_states op(ops::link_cost::at(1250000, 1ms));
  run(w, op);
  REQUIRE(op.error() == errc{});
  const auto& s = op.value();
  REQUIRE(s.size() == 20);  // a KHR-3HV: ICS 0-9 and 12-21
  CHECK(s[3].position == 8000);
  CHECK(s[3].target == 8000);
  CHECK(s[5].trim == -10);
  CHECK(s[5].position == 7952);
  CHECK(s[0].position == 7500);
  CHECK(op.plan().size() <= 5);
}

TEST_CASE("ops: play a motion, follow its state, stop one", "[ops][motion]") {
  board_wire w;
  ops::play_motion play(2);
  CHECK(run(w, play).size() == 7);  // config, the slot's first bytes and frame, suspend, PC, CALL, resume
  REQUIRE(play.error() == errc{});
  ops::read_motion_state st;
  run(w, st);
  CHECK(st.value().running);
  CHECK(st.value().motion == 2u);
  w.wait(2s);
  ops::read_motion_state after;
  run(w, after);
  CHECK_FALSE(after.value().running);
  CHECK(after.value().program_counter == hth4_2_2.main_loop.value());
  // Stop during the first pose: that pose still completes (the servo loop runs without the
  // program), but no later pose comes, so the arm stays up instead of returning to 7500.
  ops::play_motion again(2);
  run(w, again);
  w.wait(100ms);
  ops::stop_motion stop;
  run(w, stop);
  REQUIRE(stop.error() == errc{});
  CHECK_FALSE(config_word::decode(stop.value()).rom_program);
  w.wait(2s);
  CHECK(w.read_word(0x0090 + 60 + 4) == 9500);
  CHECK(w.read_word(0x0090 + 100 + 4) == 10300);
  ops::play_motion nope(121);
  CHECK(run(w, nope).empty());
  CHECK(nope.error() == errc::motion_out_of_range);
}

TEST_CASE("ops: an allocation table of zeros (no project) has no servos, not made-up ones", "[ops][servo]") {
  board_wire w;
  REQUIRE(w.write_ram(0x0044, std::vector<std::uint8_t>(70, 0x00)).is_ack());  // every entry 0x0000
  ops::scan_servos scan;
  run(w, scan);
  CHECK(scan.error() == errc{});
  CHECK(scan.value().empty());
  ops::read_servo_states states;
  run(w, states);
  CHECK(states.error() == errc{});
  CHECK(states.value().empty());  // not 22 servos read from the config word and the program counter
}

namespace {
/** An allocation table (70 bytes) from ICS → block address; every other entry 0xFFFF. */
std::vector<std::uint8_t> table_of(std::initializer_list<std::pair<unsigned, std::uint16_t>> entries) {
  std::vector<std::uint8_t> t(70, 0xFF);
  for (const auto& [k, a] : entries) {
    t[2 * k] = static_cast<std::uint8_t>(a & 0xFF);
    t[2 * k + 1] = static_cast<std::uint8_t>(a >> 8);
  }
  return t;
}
}  // namespace

TEST_CASE("ops: the allocation table parser takes blocks anywhere in the user area, none odd or overlapping",
          "[ops][servo]") {
  // HeartToHeart4's layout: 0x0090 + 20k (protocol.md §6), written out by hand.
  const auto hth4 = ops::parse_allocation_table(table_of({{0, 0x0090}, {1, 0x00A4}, {2, 0x00B8}}));
  REQUIRE(hth4.has_value());
  REQUIRE(hth4->size() == 3);
  CHECK((*hth4)[1] == ops::servo_slot{ics_number::make(1).value(), 0x00A4});
  // Another layout (§7: read the table, do not assume 0x0090 + 20k): even, apart, inside the area.
  const auto moved = ops::parse_allocation_table(table_of({{0, 0x0400}, {5, 0x0092}, {7, 0x047C}}));
  REQUIRE(moved.has_value());
  CHECK(moved->size() == 3);
  CHECK(ops::parse_allocation_table(table_of({})).value().empty());
  CHECK(ops::parse_allocation_table(std::vector<std::uint8_t>(70, 0x00)).value().empty());  // no project
  // Refused whole: not one made-up servo.
  CHECK(ops::parse_allocation_table(table_of({{0, 0x0090}, {1, 0x0091}})).error() == errc::bad_allocation_table);
  CHECK(ops::parse_allocation_table(table_of({{0, 0x0090}, {3, 0x0090}})).error() == errc::bad_allocation_table);
  CHECK(ops::parse_allocation_table(table_of({{0, 0x0090}, {1, 0x00A2}})).error() == errc::bad_allocation_table);
  CHECK(ops::parse_allocation_table(table_of({{4, 0x0010}})).error() == errc::bad_allocation_table);  // config area
  CHECK(ops::parse_allocation_table(table_of({{4, 0x047E}})).error() == errc::bad_allocation_table);  // past 0x048F
  CHECK(ops::parse_allocation_table(table_of({{4, 0x8000}})).error() == errc::bad_allocation_table);
  CHECK(ops::parse_allocation_table(std::vector<std::uint8_t>(69, 0xFF)).error() == errc::bad_allocation_table);
}

TEST_CASE("ops: a board whose allocation table is nonsense gets an error from every reader and writer",
          "[ops][servo]") {
  // The trial's tables: every block shifted by one byte, a duplicate, one outside the area.
  const std::vector<std::vector<std::uint8_t>> tables = {
      table_of({{0, 0x0091}, {1, 0x00A5}, {2, 0x00B9}}),
      table_of({{0, 0x0090}, {1, 0x00A4}, {2, 0x00A4}}),
      table_of({{0, 0x0090}, {1, 0x0500}}),
  };
  for (const auto& t : tables) {
    board_wire w;
    REQUIRE(w.write_ram(0x0044, t).is_ack());
    ops::scan_servos scan;
    run(w, scan);
    CHECK(scan.error() == errc::bad_allocation_table);
    CHECK(scan.value().empty());
    ops::read_servo_states states;
    run(w, states);
    CHECK(states.error() == errc::bad_allocation_table);
    CHECK(states.value().empty());
    ops::scan_slots probe;
    run(w, probe);
    CHECK(probe.error() == errc::bad_allocation_table);
    const auto before = w.read_word(0x0090 + 6);
    auto free_all = ops::set_servo_power(ops::power_state::free);
    const auto sent = run(w, free_all);
    CHECK(free_all.error() == errc::bad_allocation_table);
    CHECK(sent.size() == 1);  // the table read only: nothing freed
    CHECK(w.read_word(0x0090 + 6) == before);
  }
}

TEST_CASE("ops: an empty motion slot is refused before anything changes", "[ops][motion]") {
  board_wire w;
  const auto before = w.read_word(0);
  ops::play_motion play(120);  // the virtual board's slot 120 is erased ROM (0xFF)
  const auto sent = run(w, play);
  CHECK(play.error() == errc::motion_slot_empty);
  CHECK(sent.size() == 2);  // the config and the slot read: no write
  CHECK(w.read_word(0) == before);
}

TEST_CASE("ops: a motion slot of another ROM layout is refused before anything changes", "[ops][motion]") {
  board_wire w;  // the virtual board's program is HTH4 2.2's: motion 2 starts at 0x0B80 + 2048
  const auto before = w.read_word(0);
  // HTH4 2.0's motion 2 is at 0x0BB8 + 2048 = 0x13B8, 56 bytes into 2.2's motion 2: its first byte
  // looks like a SIZE, but the frame it would start fails its checksum.
  ops::play_motion play(2, hth4_2_0);
  const auto sent = run(w, play);
  CHECK(play.error() == errc::motion_slot_not_a_frame);
  REQUIRE(sent.size() == 3);  // the config, the slot's first bytes, the frame they announce: no write
  CHECK(std::get<move>(sent[2]) == move::read_rom(rom_address{0x13B8}, transfer_size{0x4C}).value());
  CHECK(w.read_word(0) == before);
}

TEST_CASE("ops: a refused CALL restores the config read at the start", "[ops][motion]") {
  board_wire w;
  const auto before = w.read_word(0);
  REQUIRE(config_word::decode(before).rom_program);
  ops::play_motion play(2);
  std::vector<command> sent;
  while (auto c = play.next()) {
    sent.push_back(*c);
    // The board refuses the CALL (a full stack on a real board; protocol.md §4.3): NACK 04 0C 15 25.
    play.on_reply(std::holds_alternative<call>(*c) ? reply::nack(0x0C) : w.send(*c));
  }
  CHECK(play.error() == errc::nack);
  CHECK(play.refused());
  REQUIRE(sent.size() == 7);        // ... then the restoring write
  CHECK(w.read_word(0) == before);  // the ROM program runs again, as it did
  CHECK(play.value() == before);
}

TEST_CASE("ops: sensors, PIO, receiver and degrees", "[ops][sensors]") {
  board_wire w;
  w.board().set_battery_volts(11.1);
  w.board().set_receiver(static_cast<std::uint16_t>(krr_button::up), {1, 2, 3, 4});
  w.wait(20ms);
  ops::read_analog a;
  run(w, a);
  REQUIRE(a.error() == errc{});
  CHECK(a.value().battery_volts == Approx(11.1).margin(0.05));
  ops::read_pio p;
  run(w, p);
  CHECK(p.value().direction == 0x03FF);
  ops::read_receiver r;
  run(w, r);
  CHECK(r.value().buttons == 0x0001);
  CHECK(r.value().analog[3] == 4);
  CHECK(ops::from_degrees(0).value() == servo_position{7500});
  CHECK(ops::from_degrees(135).value() == servo_position{11500});
  CHECK(ops::to_degrees(servo_position{3500}) == Approx(-135.0));
  CHECK(ops::from_degrees(300).error() == errc::position_out_of_range);
  CHECK(std::isnan(ops::to_degrees(servo_position::free())));
}

TEST_CASE("ops: version, typed config read and write, baud switch", "[ops][system]") {
  board_wire w;
  ops::read_version v;
  run(w, v);
  REQUIRE(v.error() == errc{});
  CHECK(v.value() == "CB-4 V1.0      090715");
  CHECK(v.raw()[31] == 0xC7);
  ops::read_config rc;
  run(w, rc);
  REQUIRE(rc.error() == errc{});
  CHECK(rc.value().encode() == 0x008B);  // the board's boot word
  CHECK(rc.value().com_baud == baud_code::b1250000);

  // Change the output period and the LED; the other bits stay as the board had them.
  auto wc = ops::update_config([](config_word& c) {
    c.period = output_period::ms20;
    c.led = true;
  });
  CHECK(run(w, wc).size() == 2);
  REQUIRE(wc.error() == errc{});
  CHECK(w.read_word(0x0000) == (0x008B | 0x0020 | 0x8000));

  // A write that would lose the host is refused before anything is written.
  config_word slow = config_word::decode(0x000B);  // 115200
  auto refused = ops::write_config(slow);
  CHECK(run(w, refused).size() == 1);  // only the read
  CHECK(refused.error() == errc::baud_change_not_allowed);
  CHECK(w.read_word(0x0000) == (0x008B | 0x0020 | 0x8000));

  auto bad = ops::switch_baud(9600);
  CHECK(run(w, bad).empty());
  CHECK(bad.error() == errc::unsupported_baud);

  auto sw = ops::switch_baud(625000);
  run(w, sw);
  REQUIRE(sw.error() == errc{});
  CHECK(w.board().line_baud() == 625000);
  CHECK(sw.value().com_baud == baud_code::b625000);
  CHECK(sw.before().com_baud == baud_code::b1250000);
}

TEST_CASE("ops: scan, free and hold, parameters, per-servo speeds", "[ops][servo]") {
  board_wire w;
  ops::scan_servos scan;
  run(w, scan);
  REQUIRE(scan.error() == errc{});
  REQUIRE(scan.value().size() == 20);  // a KHR-3HV: ICS 0-9 and 12-21
  CHECK(scan.value().front() == ops::servo_slot{ics_number{0}, 0x0090});
  CHECK(scan.value().back() == ops::servo_slot{ics_number{21}, 0x0090 + 21 * 20});

  auto all_free = ops::set_servo_power(ops::power_state::free);
  CHECK(run(w, all_free).size() == 2);  // the table, then one CONST frame
  REQUIRE(all_free.error() == errc{});
  CHECK(all_free.value().size() == 20);
  w.wait(30ms);
  for (unsigned k = 0; k < 22; ++k)
    if (k != 10 && k != 11) CHECK(w.read_word(static_cast<std::uint16_t>(0x0090 + 20 * k + 6)) == 0x8000);

  servo_mask three;
  three.insert(ics_number{3});
  auto hold = ops::set_servo_power(ops::power_state::hold, three);
  CHECK(run(w, hold).size() == 1);  // no table read for an explicit set
  w.wait(30ms);
  CHECK(w.read_word(0x0090 + 60 + 6) == 0x7FFF);
  CHECK(w.read_word(0x0090 + 80 + 6) == 0x8000);

  servo_mask two;
  two.insert(ics_number{1});
  two.insert(ics_number{2});
  auto stretch = ops::set_servo_param(param_kind::stretch, servo_param{30}, two);
  run(w, stretch);
  REQUIRE(stretch.error() == errc{});
  CHECK(w.board().servo_params_of(ics_number{1}).second == 30);
  CHECK(w.board().servo_params_of(ics_number{2}).second == 30);
  CHECK(w.board().servo_params_of(ics_number{3}).second == 127);
  auto speed_all = ops::set_servo_param(param_kind::speed, servo_param{64});
  run(w, speed_all);
  CHECK(w.board().servo_params_of(ics_number{21}).first == 64);

  servo_set<timed_position> moves;
  moves.insert(ics_number{0}, {servo_position{8000}, frames{10}});
  moves.insert(ics_number{1}, {servo_position{7000}, frames{30}});
  moves.insert(ics_number{2}, {servo_position{9000}, frames{10}});
  auto mv = ops::move_servos(moves);
  const auto sent = run(w, mv);
  REQUIRE(mv.error() == errc{});
  REQUIRE(sent.size() == 2);
  CHECK(std::get<const_servo>(sent[0]).speed() == frames{30});  // slowest first
  CHECK(std::get<const_servo>(sent[0]).targets().size() == 1);
  CHECK(std::get<const_servo>(sent[1]).targets().size() == 2);
  w.wait(1s);
  CHECK(w.read_word(0x0090 + 0 + 4) == 8000);
  CHECK(w.read_word(0x0090 + 20 + 4) == 7000);
  CHECK(w.read_word(0x0090 + 40 + 4) == 9000);

  auto none = ops::set_servo_power(ops::power_state::free, servo_mask{});
  CHECK(run(w, none).empty());
  CHECK(none.error() == errc::empty_servo_set);
}

TEST_CASE("ops: counters, user parameters, timers, PIO writes, receiver emulation", "[ops][io]") {
  board_wire w;
  auto c = ops::write_counter(10, 200);
  run(w, c);
  REQUIRE(c.error() == errc{});
  auto p = ops::write_user_param(19, -1234);
  run(w, p);
  REQUIRE(p.error() == errc{});
  ops::read_counters rc;
  run(w, rc);
  CHECK(rc.value()[10] == 200);
  CHECK(w.read_ram(0x0457 + 10, 2)[0] == 200);
  ops::read_user_params rp;
  run(w, rp);
  CHECK(rp.value()[19] == -1234);
  CHECK(w.read_word(0x0462 + 38) == static_cast<std::uint16_t>(-1234));

  auto t = ops::write_timer(2, 20);  // 2 s
  run(w, t);
  w.wait(1050ms);
  ops::read_timers rt;
  run(w, rt);
  REQUIRE(rt.error() == errc{});
  CHECK(rt.value()[2] == 10);
  CHECK(rt.value()[0] == ram::timer_stopped);

  auto c2 = ops::write_counter(11, 0);
  CHECK(run(w, c2).empty());
  CHECK(c2.error() == errc::index_out_of_range);
  auto p2 = ops::write_user_param(20, 0);
  CHECK(run(w, p2).empty());
  CHECK(p2.error() == errc::index_out_of_range);
  auto t2 = ops::write_timer(4, 0);
  CHECK(run(w, t2).empty());
  CHECK(t2.error() == errc::index_out_of_range);

  auto pio = ops::write_pio(0x0003, 0x0001);
  run(w, pio);
  REQUIRE(pio.error() == errc{});
  ops::read_pio rpio;
  run(w, rpio);
  CHECK(rpio.value().direction == 0x0003);
  CHECK((rpio.value().value & 0x0003) == 0x0001);
  auto bad_pio = ops::write_pio(0x0400, 0);
  CHECK(run(w, bad_pio).empty());
  CHECK(bad_pio.error() == errc::reserved_bits_set);

  const auto buttons = static_cast<std::uint16_t>(static_cast<std::uint16_t>(krr_button::up) |
                                                  static_cast<std::uint16_t>(krr_button::s1));
  auto emu = ops::emulate_receiver(buttons, {10, 20, 30, 127});
  run(w, emu);
  REQUIRE(emu.error() == errc{});
  ops::read_receiver rr;
  run(w, rr);
  CHECK(rr.value().buttons == buttons);
  CHECK(rr.value().analog == std::array<std::uint8_t, 4>{10, 20, 30, 127});
  CHECK(ops::emulate_receiver(0x0080).error() == errc::reserved_bits_set);
  CHECK(ops::emulate_receiver(0, {128, 0, 0, 0}).error() == errc::param_out_of_range);
}

TEST_CASE("ops: suspend and resume a motion", "[ops][motion]") {
  board_wire w;
  ops::play_motion play(2);
  run(w, play);
  w.wait(100ms);
  ops::suspend_motion suspend;
  run(w, suspend);
  REQUIRE(suspend.error() == errc{});
  w.wait(2s);
  ops::read_motion_state held;
  run(w, held);
  CHECK(held.value().motion == 2u);  // still inside motion 2, not going anywhere
  CHECK(w.read_word(0x0090 + 60 + 4) == 9500);
  auto resume = ops::resume_motion();
  run(w, resume);
  REQUIRE(resume.error() == errc{});
  CHECK(resume.value().rom_program);
  w.wait(3s);
  ops::read_motion_state done;
  run(w, done);
  CHECK_FALSE(done.value().running);
  CHECK(w.read_word(0x0090 + 60 + 4) == 7500);  // the motion finished: the arm is back down
}
