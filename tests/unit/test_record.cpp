// Teaching by demonstration: samples of a robot moved by hand into the poses that replay them.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/record.hpp>

#include <catch2/catch.hpp>

#include <numeric>

using namespace rcb4;
using namespace rcb4::robot;
using ms = std::chrono::milliseconds;

namespace {
joint make_joint(const char* name, unsigned ics, double lower = -130, double upper = 130) {
  joint j;
  j.name = name;
  j.ics = ics_number::make(ics).value();
  j.lower = lower;
  j.upper = upper;
  return j;
}
const joint knee = make_joint("left_knee", 16);
const joint elbow = make_joint("left_elbow_pitch", 8, -90, 90);

/** Feeds @p f(t) for t = 0, step, ... up to @p until (inclusive) into @p r. */
template <class F>
void feed(recorder& r, long long until, long long step, F f) {
  for (long long t = 0; t <= until; t += step) {
    const std::vector<double> s = f(t);
    r.sample(ms(t), s);
  }
}
long long total_ms(const recorder& r) {
  long long sum = 0;
  for (std::size_t i = 1; i < r.poses().size(); ++i) sum += r.poses()[i].time.count();
  return sum;
}
}  // namespace

TEST_CASE("record: a still robot is one pose for the whole pause", "[record]") {
  recorder r({&knee}, 2.0, output_period::ms10);
  feed(r, 2000, 100, [](long long) { return std::vector<double>{10}; });
  r.finish();
  REQUIRE(r.poses().size() == 2);
  CHECK(r.poses()[0].time == ms(1000));  // the lead-in
  CHECK(r.poses()[0].degrees == std::vector<double>{10});
  CHECK(r.poses()[1].time == ms(2000));  // the pause, kept as time at the same angle
  CHECK(r.samples() == 21);
}

TEST_CASE("record: a steady sweep is one pose, a turn a pose at the turn", "[record]") {
  recorder r({&knee, &elbow}, 2.0, output_period::ms15);
  // The knee from 0 to 40 over 400 ms and back over 400 ms; the elbow still at -20.
  feed(r, 800, 50, [](long long t) {
    const double k = t <= 400 ? 0.1 * static_cast<double>(t) : 40 - 0.1 * static_cast<double>(t - 400);
    return std::vector<double>{k, -20};
  });
  r.finish();
  REQUIRE(r.poses().size() == 3);
  CHECK(r.poses()[1].degrees == std::vector<double>{40, -20});
  CHECK(r.poses()[1].time == ms(405));  // 400 ms: 27 frames of 15 ms, the 5 ms given back later
  CHECK(r.poses()[2].degrees == std::vector<double>{0, -20});
  CHECK(r.poses()[2].time == ms(390));
  CHECK(total_ms(r) == 795);  // 800 ms within a frame
}

TEST_CASE("record: a pause then a move keeps the end of the pause", "[record]") {
  recorder r({&knee}, 1.0, output_period::ms10);
  // Still at 0 for a second, then to 30 in 300 ms.
  feed(r, 1300, 100,
       [](long long t) { return std::vector<double>{t <= 1000 ? 0.0 : 0.1 * static_cast<double>(t - 1000)}; });
  r.finish();
  REQUIRE(r.poses().size() == 3);
  CHECK(r.poses()[1].degrees == std::vector<double>{0});
  CHECK(r.poses()[1].time == ms(1000));
  CHECK(r.poses()[2].degrees == std::vector<double>{30});
  CHECK(r.poses()[2].time == ms(300));
}

TEST_CASE("record: no pose is longer than a CONST carries, times are whole frames", "[record]") {
  recorder r({&knee}, 2.0, output_period::ms10);
  feed(r, 6000, 100, [](long long) { return std::vector<double>{5}; });
  r.finish();
  for (std::size_t i = 1; i < r.poses().size(); ++i) {
    CHECK(r.poses()[i].time <= ms(2550));
    CHECK(r.poses()[i].time.count() % 10 == 0);
  }
  CHECK(total_ms(r) == 6000);
}

TEST_CASE("record: a joint moved beyond its limit is taken at the limit, and counted", "[record]") {
  recorder r({&elbow}, 2.0, output_period::ms10);
  feed(r, 300, 100, [](long long t) { return std::vector<double>{t < 200 ? 0.0 : 95.0}; });
  r.finish();
  CHECK(r.clamped() == 2);
  CHECK(r.poses().back().degrees == std::vector<double>{90});
}

TEST_CASE("record: small jitter makes no pose", "[record]") {
  recorder r({&knee}, 2.0, output_period::ms10);
  feed(r, 3000, 100, [](long long t) { return std::vector<double>{(t / 100) % 2 ? 11.5 : 10.0}; });
  r.finish();
  CHECK(r.poses().size() == 3);  // the lead-in, the 2550 ms a pose carries at most, the rest
}
