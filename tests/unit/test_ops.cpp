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
/** Runs @p op on the board; returns the commands it sent. */
template <class Op>
std::vector<command> run(board_wire& w, Op& op) {
  std::vector<command> sent;
  while (auto c = op.next()) {
    sent.push_back(*c);
    op.on_reply(w.send(*c));
  }
  return sent;
}
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
  REQUIRE(s.size() == 22);
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
  CHECK(run(w, play).size() == 5);
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
  CHECK(w.read_word(0x0090 + 100 + 4) == 10500);
  ops::play_motion nope(121);
  CHECK(run(w, nope).empty());
  CHECK(nope.error() == errc::motion_out_of_range);
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
