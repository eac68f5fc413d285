// Unit tests of the robot services that step with the clock (rcb4/robot/services/host_play.hpp,
// record.hpp) and of trims.hpp, on a virtual board driven on a virtual clock: no sleeps, no I/O.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/board/virtual_board.hpp>
#include <rcb4/command.hpp>
#include <rcb4/ops/motion.hpp>
#include <rcb4/ops/system.hpp>
#include <rcb4/reply.hpp>
#include <rcb4/robot/profile.hpp>
#include <rcb4/robot/services/host_play.hpp>
#include <rcb4/robot/services/moves.hpp>
#include <rcb4/robot/services/record.hpp>
#include <rcb4/robot/services/trims.hpp>

#include <catch2/catch.hpp>

#include <array>
#include <chrono>
#include <vector>

namespace {

namespace sv = rcb4::robot::services;
using namespace std::chrono_literals;

/** The board in-process on a clock the test moves: each exchange costs 1 ms of it. */
class clocked_link final : public sv::link {
 public:
  explicit clocked_link(rcb4::board::virtual_board& b) : b_(b) {}
  rcb4::reply exchange(const rcb4::command& c) override {
    std::array<std::uint8_t, 256> frame{};
    const auto n = rcb4::serialize(c, frame);
    REQUIRE(n);
    now_ += 1ms;
    out_.clear();
    b_.receive(std::span(frame).first(*n), now_, out_);
    const auto r = rcb4::parse_reply(out_, rcb4::expected_reply(c));
    if (r.status != rcb4::parse_status::complete)
      throw std::system_error(make_error_code(rcb4::errc::bad_reply_length));
    ++exchanges;
    return r.value();  // points into out_, which lives until the next exchange
  }
  /** Moves the clock to @p t (never back) and lets the board run to it. */
  void at(rcb4::board::board_time t) {
    if (t > now_) now_ = t;
    b_.advance_to(now_);
  }
  rcb4::board::board_time now() const { return now_; }
  std::size_t exchanges = 0;

 private:
  rcb4::board::virtual_board& b_;
  rcb4::board::board_time now_{};
  std::vector<std::uint8_t> out_;
};

rcb4::board::virtual_board khr_board(const rcb4::robot::model& m) {
  rcb4::board::options o;
  o.servos = m.mask();
  return rcb4::board::virtual_board(o);
}

double degrees_of(const rcb4::board::virtual_board& b, const rcb4::robot::joint& j) {
  const auto block = b.block_of(j.ics);
  REQUIRE(block);
  return *rcb4::robot::to_degrees(j, b.ram16(*block + 4u));
}

}  // namespace

TEST_CASE("host_play: poses sent when the board has reached the one before, at the file's timing", "[services]") {
  const auto m = rcb4::robot::open_profile("khr-3hv");
  auto b = khr_board(m);
  clocked_link l(b);
  const auto period = sv::run(l, rcb4::ops::read_config{}).period;
  const auto d = rcb4::robot::parse_motion(
      "robot: KHR-3HV\nperiod_ms: 10\nsteps:\n  - pose: {left_knee: 30}\n    time_ms: 300\n"
      "  - pose: {left_knee: -20}\n    time_ms: 200\n  - end\n",
      "m.yaml", m);
  sv::host_play p(l, m, rcb4::hth4_2_2, period, d, "m.yaml", true);
  std::vector<std::chrono::milliseconds> asked;
  const auto start = l.now();
  auto next = p.advance(0ms);
  while (next) {
    asked.push_back(*next);
    l.at(start + *next);
    next = p.advance(std::chrono::duration_cast<std::chrono::milliseconds>(l.now() - start));
  }
  REQUIRE(p.poses() == 2);
  // The second pose is due when the first is reached (300 ms after it was sent), the end 200 ms later.
  REQUIRE(asked.size() == 2);
  CHECK(asked[0] >= 300ms);
  CHECK(asked[1] >= asked[0] + 190ms);  // 200 ms in whole frames of the board's period
  CHECK(asked[1] < asked[0] + 215ms);
  CHECK(degrees_of(b, *m.find("left_knee")) == Approx(-20).margin(0.5));
}

TEST_CASE("host_play: refused before anything is sent", "[services]") {
  const auto m = rcb4::robot::open_profile("khr-3hv");
  auto b = khr_board(m);
  clocked_link l(b);
  SECTION("a pose beyond a limit") {
    const auto d = rcb4::robot::parse_motion(
        "robot: KHR-3HV\nperiod_ms: 10\nsteps:\n  - pose: {left_knee: 300}\n    time_ms: 300\n", "far.yaml", m);
    try {
      sv::host_play p(l, m, rcb4::hth4_2_2, rcb4::output_period::ms10, d, "far.yaml", true);
      FAIL("not refused");
    } catch (const sv::refused& r) {
      CHECK(r.kind == sv::refusal_kind::usage);
      CHECK_THAT(r.what(), Catch::Contains("far.yaml") && Catch::Contains("nothing was sent"));
    }
    CHECK(l.exchanges == 0);
  }
  SECTION("a ROM motion runs: the move rule's words") {
    const auto play =
        rcb4::robot::parse_motion("robot: KHR-3HV\nperiod_ms: 10\nsteps:\n  - call: 2\n  - end\n", "c.yaml", m);
    // Motion 2 of the default ROM plays; a file played now would fight it.
    sv::host_play caller(l, m, rcb4::hth4_2_2, rcb4::output_period::ms10, play, "c.yaml", true);
    REQUIRE(caller.advance(0ms));  // motion 2 started on the board
    const auto d = rcb4::robot::parse_motion(
        "robot: KHR-3HV\nperiod_ms: 10\nsteps:\n  - pose: {left_knee: 10}\n    time_ms: 100\n  - end\n", "k.yaml", m);
    try {
      sv::host_play p(l, m, rcb4::hth4_2_2, rcb4::output_period::ms10, d, "k.yaml", true);
      FAIL("not refused");
    } catch (const sv::refused& r) {
      CHECK(r.kind == sv::refusal_kind::board);
      CHECK_THAT(r.what(), Catch::Contains("is running on the board: it would overwrite the move"));
    }
    caller.stop();
    CHECK_FALSE(sv::move_refusal(sv::run(l, rcb4::ops::read_motion_state{})));
  }
}

TEST_CASE("host_play: a called ROM motion that outlives its limit is stopped and refused as a timeout", "[services]") {
  const auto m = rcb4::robot::open_profile("khr-3hv");
  auto b = khr_board(m);
  clocked_link l(b);
  const auto d =
      rcb4::robot::parse_motion("robot: KHR-3HV\nperiod_ms: 10\nsteps:\n  - call: 2\n  - end\n", "c.yaml", m);
  sv::host_play p(l, m, rcb4::hth4_2_2, rcb4::output_period::ms10, d, "c.yaml", true, 100ms);
  const auto start = l.now();
  try {
    for (auto next = p.advance(0ms); next;
         next = p.advance(std::chrono::duration_cast<std::chrono::milliseconds>(l.now() - start)))
      l.at(start + *next);
    FAIL("motion 2 ended within 100 ms");
  } catch (const sv::refused& r) {
    CHECK(r.kind == sv::refusal_kind::timeout);
    CHECK_THAT(r.what(), Catch::Contains("motion 2, called at step 1, still ran after 0.1 s: stopped"));
  }
  CHECK_FALSE(sv::run(l, rcb4::ops::read_motion_state{}).running);
}

TEST_CASE("recording: samples become poses: freed joints are held again (also when it is dropped)", "[services]") {
  const auto m = rcb4::robot::open_profile("khr-3hv");
  auto b = khr_board(m);
  clocked_link l(b);
  const auto* knee = m.find("left_knee");
  const auto hold_of = [&] { return b.ram16(*b.block_of(knee->ics) + 6u); };
  {
    sv::recording rec(l, m, {knee}, {.threshold = 2.0, .free = true});
    CHECK(hold_of() == 0x8000);  // free
    // A hand turns the knee from 0 to +20 degrees over 1 s, then keeps it there.
    for (int k = 0; k <= 20; ++k) {
      const double deg = k <= 10 ? 2.0 * k : 20.0;
      b.turn_by_hand(knee->ics, std::get<rcb4::servo_position>(rcb4::robot::to_position(*knee, deg)).value());
      rec.sample(std::chrono::milliseconds(100 * k));
    }
    const auto r = rec.finish();
    CHECK(r.held);
    CHECK(hold_of() != 0x8000);
    CHECK(r.samples == 21);
    REQUIRE(r.document.steps.size() >= 3);  // a start, the end of the sweep, the pause, then end
    const auto& last = std::get<rcb4::robot::motion_pose>(r.document.steps[r.document.steps.size() - 2]);
    CHECK(last.targets[0].degrees == Approx(20).margin(0.1));
  }
  {
    sv::recording rec(l, m, {knee}, {.free = true});
    CHECK(hold_of() == 0x8000);
  }  // dropped unfinished: held again
  CHECK(hold_of() != 0x8000);
}

TEST_CASE("trims: set in RAM and ROM, read back, refused with nothing written", "[services]") {
  const auto m = rcb4::robot::open_profile("khr-3hv");
  auto b = khr_board(m);
  clocked_link l(b);
  const auto r = sv::set_trims(l, m, {{"left_knee", 1.5}, {"head_yaw", -2}}, true);
  REQUIRE(r.written.size() == 2);
  for (const auto& t : sv::read_trims(l, m, {m.find("left_knee"), m.find("head_yaw")})) {
    CHECK(t.allocated);
    CHECK(t.rom == t.ram);
    CHECK(t.degrees() == Approx(t.j->name == "left_knee" ? 1.5 : -2.0).margin(0.05));
  }
  const auto ram_only = sv::set_trims(l, m, {{"left_knee", 3}}, false);
  const auto knee = sv::read_trims(l, m, {m.find("left_knee")}).at(0);
  CHECK(knee.degrees() == Approx(3).margin(0.05));
  CHECK(*knee.rom_degrees() == Approx(1.5).margin(0.05));  // power-on still loads the old one
  const auto before = l.exchanges;
  CHECK_THROWS_MATCHES(
      sv::set_trims(l, m, {{"left_knee", 31}}, false), sv::refused,
      Catch::Matchers::Predicate<sv::refused>([](const sv::refused& e) { return e.kind == sv::refusal_kind::limit; }));
  CHECK_THROWS_AS(sv::set_trims(l, m, {{"no_such_joint", 1}}, false), sv::refused);
  CHECK_THROWS_AS(sv::set_trims(l, m, {{"left_knee", 1}, {"left_knee", 2}}, false), sv::refused);
  CHECK(l.exchanges == before);
}
