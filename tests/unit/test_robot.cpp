// The robot model: joints in degrees with limits, groups, checks on a model.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/model.hpp>

#include <catch2/catch.hpp>

using namespace rcb4;
using namespace rcb4::robot;

namespace {
joint knee(double lower = -10, double upper = 125) {
  joint j;
  j.name = "left_knee";
  j.ics = ics_number{16};
  j.direction = -1;
  j.offset = 5;
  j.lower = lower;
  j.upper = upper;
  return j;
}
template <class T>
const T& get(const outcome<T>& o) {
  REQUIRE(ok(o));
  return std::get<T>(o);
}
std::string why(const auto& o) {
  REQUIRE_FALSE(ok(o));
  return std::get<problem>(o).message;
}
}  // namespace

TEST_CASE("robot: joint degrees to positions and back, with direction and offset", "[robot]") {
  const auto j = knee();
  CHECK(j.servo_id() == 8);
  CHECK(j.bus() == 1);
  // 7500 + (-1 × 30 + 5) × 4000/135 = 7500 - 25 × 29.6296 = 6759.26 → 6759 (protocol.md §7)
  CHECK(get(to_position(j, 30.0)).value() == 6759);
  // joint 0 is servo +5°: 7500 + 148.15 → 7648
  CHECK(get(to_position(j, 0.0)).value() == 7648);
  CHECK(to_degrees(j, 6759).value() == Approx(30.0).margin(0.02));
  CHECK(to_degrees(j, 7648).value() == Approx(0.0).margin(0.02));
  CHECK_FALSE(to_degrees(j, servo_position::free_value).has_value());
  CHECK_FALSE(to_degrees(j, servo_position::hold_value).has_value());
}

TEST_CASE("robot: an angle beyond a limit is refused, naming the joint and the limit", "[robot]") {
  const auto j = knee();
  CHECK(why(to_position(j, 126.0)).find("left_knee") != std::string::npos);
  CHECK(why(to_position(j, 126.0)).find("upper limit 125") != std::string::npos);
  CHECK(why(to_position(j, -10.5)).find("lower limit -10") != std::string::npos);
  CHECK(why(to_position(j, std::nan(""))).find("not a number") != std::string::npos);
  CHECK(ok(to_position(j, 125.0)));
  CHECK(ok(to_position(j, -10.0)));
}

TEST_CASE("robot: a model refuses duplicates, ICS 35, reversed or unreachable limits, unknown group members",
          "[robot]") {
  auto other = knee();
  other.name = "right_knee";
  other.ics = ics_number{17};
  CHECK(ok(model::make("r", {knee(), other})));
  auto dup_ics = other;
  dup_ics.ics = ics_number{16};
  CHECK(why(model::make("r", {knee(), dup_ics})) == "right_knee: ICS 16 is already left_knee's");
  CHECK(why(model::make("r", {knee(), knee()})) == "joint 'left_knee' is given twice");
  auto rx = other;
  rx.ics = ics_number{35};
  CHECK(why(model::make("r", {rx})).find("ICS 35 is the receiver's slot") != std::string::npos);
  CHECK(why(model::make("r", {knee(40, 20)})) == "left_knee: limits reversed or empty (lower 40, upper 20)");
  CHECK(why(model::make("r", {knee(-10, 141)})).find("beyond its ±135") != std::string::npos);  // -141+5 = -136
  auto bad_dir = other;
  bad_dir.direction = 2;
  CHECK(why(model::make("r", {bad_dir})) == "right_knee: direction is 1 or -1");
  auto caps = other;
  caps.name = "Right Knee";
  CHECK(why(model::make("r", {caps})).find("A-Z, a-z, 0-9 and _") != std::string::npos);
  caps.name = "RLEG_JOINT3";  // URDF's names (KXR's): upper case is a name too
  CHECK(ok(model::make("r", {caps})));
  CHECK(why(model::make("r", {knee()}, {{"legs", {"left_knee", "right_knee"}}})) ==
        "group 'legs': no joint is called 'right_knee'");
  CHECK(why(model::make("r", {knee()}, {}, {{121, "dance"}})).find("outside 1..120") != std::string::npos);
}

TEST_CASE("robot: select a joint, a group or all", "[robot]") {
  auto other = knee();
  other.name = "right_knee";
  other.ics = ics_number{17};
  const auto m = get(model::make("r", {knee(), other}, {{"legs", {"left_knee", "right_knee"}}}, {{2, "bow"}}));
  CHECK(get(m.select("all")).size() == 2);
  CHECK(get(m.select("legs")).size() == 2);
  CHECK(get(m.select("right_knee")).front()->ics.value() == 17);
  CHECK(why(m.select("tail")) == "no joint or group is called 'tail'");
  CHECK(m.motion(2) == "bow");
  CHECK(m.motion(3).empty());
  CHECK(m.on(ics_number{16})->name == "left_knee");
  CHECK(m.on(ics_number{0}) == nullptr);
  CHECK(m.mask().contains(ics_number{17}));
}
