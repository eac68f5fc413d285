// The ICS service never writes from an EEPROM image it has not verified (ics.md §4.1: an image has
// no checksum; a byte that failed its parity check reaches the program as 0x00, a valid nibble),
// and a backup of values outside rcb4's ranges goes back with --force, byte for byte.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/services/ics.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <string>
#include <vector>

using namespace rcb4;
using namespace rcb4::robot::services;
using ics::field;

namespace {
ics::servo_id id_of(unsigned n) { return ics::servo_id::make(n).value(); }

/**
 * A line that delivers 0x00 in place of image byte @p byte (1-based) in the EEPROM reads listed in
 * @p garbled (0: the first EEPROM read), as Linux delivers a byte that failed its parity check.
 * With @p walk, each garbled read zeroes a different byte (a line that never reads the same twice).
 */
struct zeroing_link final : ics_link {
  ics_virtual_link inner{ics::virtual_line({ics::virtual_servo(id_of(0), 115200, 1)})};
  std::vector<int> garbled;
  std::size_t byte = 6;
  bool walk = false;
  int reads = 0;
  int writes = 0;
  std::vector<std::uint8_t> transact(std::span<const std::uint8_t> request, std::size_t expect,
                                     std::chrono::milliseconds wait) override {
    auto rx = inner.transact(request, expect, wait);
    if (request.size() == 66) ++writes;
    if (request.size() == 2 && (request[0] & 0xE0u) == 0xA0u && request[1] == 0x00) {  // EEPROM read (ics.md §2.3)
      const int n = reads++;
      for (const int g : garbled) {
        const std::size_t at = 2 + 2 + (walk ? byte + static_cast<std::size_t>(n) : byte) - 1;  // echo, header, SC
        if ((g == n || g < 0) && rx.size() > at) rx[at] = 0x00;
      }
    }
    return rx;
  }
  std::vector<std::uint8_t> linger(std::chrono::milliseconds wait) override { return inner.linger(wait); }
  void set_baud(std::uint32_t baud) override { inner.set_baud(baud); }
  std::uint32_t baud() const override { return inner.baud(); }
  ics::eeprom_image held() { return inner.line().servos()[0].image(); }
};
}  // namespace

TEST_CASE("ics EEPROM: one zeroed byte in the first read changes nothing but what was asked", "[ics]") {
  zeroing_link l;
  const auto truth = l.held();
  REQUIRE(truth.bytes()[5] != 0);  // byte 6 (speed's low nibble) is not 0 already: the zero is a change
  ics_servo s(l, {}, {});
  l.garbled = {0};
  std::vector<ics::eeprom_image> saved;
  const ics_backup save = [&](const ics::eeprom_image& e) {
    saved.push_back(e);
    return std::string("b.bin");
  };
  const auto r = s.set_fields({{field::stretch, 50}}, save);
  CHECK(r.written);
  CHECK(r.verified);
  REQUIRE(saved.size() == 1);
  CHECK(saved[0] == truth);  // the backup is the servo's true image
  auto want = truth;
  REQUIRE(want.set(field::stretch, 50));
  CHECK(l.held() == want);  // only the stretch changed on the servo
  CHECK(l.held().get(field::speed) == truth.get(field::speed));
  REQUIRE(r.changed.size() == 1);
  CHECK(r.changed[0].first == field::stretch);
}

TEST_CASE("ics EEPROM: a zeroed byte in a restore's read and in a backup's read is never used", "[ics]") {
  zeroing_link l;
  const auto truth = l.held();
  ics_servo s(l, {}, {});
  l.garbled = {0};
  CHECK(s.read_eeprom() == truth);  // what `eeprom backup` and `eeprom show` use
  auto tuned = truth;
  REQUIRE(tuned.set(field::punch, 3));
  l.garbled = {l.reads};  // the restore's first read
  std::vector<ics::eeprom_image> saved;
  const auto r = s.restore(tuned, false, [&](const ics::eeprom_image& e) {
    saved.push_back(e);
    return std::string("b.bin");
  });
  REQUIRE(saved.size() == 1);
  CHECK(saved[0] == truth);
  CHECK(l.held() == tuned);
  CHECK(r.changed.size() == 1);
}

TEST_CASE("ics EEPROM: a line whose reads never agree is refused with both images, nothing written", "[ics]") {
  zeroing_link l;
  const auto truth = l.held();
  ics_servo s(l, {}, {});
  l.garbled = {-1};  // every read, a different byte each time: bytes 3-6 (stretch 60, speed 127: none 0 already)
  l.walk = true;
  l.byte = 3;
  int saves = 0;
  try {
    (void)s.set_fields({{field::stretch, 50}}, [&](const ics::eeprom_image&) {
      ++saves;
      return std::string("b.bin");
    });
    FAIL("not refused");
  } catch (const refused& e) {
    CHECK(e.kind == refusal_kind::board);
    const std::string what = e.what();
    CHECK(what.find("never agreed") != std::string::npos);
    CHECK(what.find("read 1:") != std::string::npos);
    CHECK(what.find("read 2:") != std::string::npos);
    CHECK(what.find("byte 3") != std::string::npos);
    CHECK(e.backup.empty());
  }
  CHECK(saves == 0);
  CHECK(l.writes == 0);
  CHECK(l.reads == 4);  // bounded
  CHECK(l.held() == truth);
}

TEST_CASE("ics EEPROM: a backup outside rcb4's ranges goes back with --force, as it is", "[ics]") {
  ics_virtual_link l(ics::virtual_line({ics::virtual_servo(id_of(0), 115200, 1)}));
  ics_servo s(l, {}, {});
  const auto before = s.read_eeprom();
  const ics_backup save = [](const ics::eeprom_image&) { return std::string("old.bin"); };
  auto theirs = before;
  REQUIRE(theirs.set_raw(9, 0));  // dead band 15 (bytes 9-10), as another tool may write it
  REQUIRE(theirs.set_raw(10, 0xF));
  REQUIRE(theirs.set_raw(59, 0x6));  // stretch_1 stored 0x65: odd
  REQUIRE(theirs.set_raw(60, 0x5));
  try {
    (void)s.restore(theirs, false, save);
    FAIL("not refused");
  } catch (const refused& e) {
    CHECK(e.kind == refusal_kind::usage);
    const std::string what = e.what();
    CHECK(what.find("dead_band 15") != std::string::npos);
    CHECK(what.find("stretch_1 stored odd") != std::string::npos);
    CHECK(what.find("damaged or hand-edited") == std::string::npos);
    CHECK(e.hint.find("--force") != std::string::npos);
  }
  CHECK(s.read_eeprom() == before);
  const auto r = s.restore(theirs, true, save);
  CHECK(r.written);
  CHECK(r.verified);
  CHECK(s.read_eeprom() == theirs);  // byte for byte
  CHECK(r.notes.size() == 2);
  // and the user's own backup of that servo goes back too
  auto mine = theirs;
  REQUIRE(mine.set(field::dead_band, 4));
  (void)s.set_fields({{field::dead_band, 4}}, save);
  CHECK(s.read_eeprom().get(field::dead_band) == 4);
  (void)s.restore(theirs, true, save);
  CHECK(s.read_eeprom() == theirs);
  // an odd stored stretch is no "nothing to change": setting the value rewrites it even
  CHECK(s.read_eeprom().stored_odd(field::stretch_1));
  const auto again = s.set_fields({{field::stretch_1, 50}}, save);
  CHECK(again.written);
  CHECK_FALSE(s.read_eeprom().stored_odd(field::stretch_1));
  CHECK(s.read_eeprom().get(field::stretch_1) == 50);
}

namespace {
/**
 * A line whose transacts listed in @p damaged (0: the first) stop at a byte that failed its parity
 * check, as rcb4::transport::ics_port reports it on a marked line: the bytes before it, and
 * last_damaged() true. With @p always, every transact does.
 */
struct damaging_link final : ics_link {
  ics_virtual_link inner{ics::virtual_line({ics::virtual_servo(id_of(0), 115200, 1)})};
  std::vector<int> damaged;
  bool always = false;
  int n = 0;
  bool last = false;
  std::vector<std::uint8_t> transact(std::span<const std::uint8_t> request, std::size_t expect,
                                     std::chrono::milliseconds wait) override {
    auto rx = inner.transact(request, expect, wait);
    const int k = n++;
    last = always || std::find(damaged.begin(), damaged.end(), k) != damaged.end();
    if (last && rx.size() > request.size()) rx.resize(request.size() + 1);  // echo and one good byte, then the damage
    return rx;
  }
  std::vector<std::uint8_t> linger(std::chrono::milliseconds wait) override {
    last = false;
    return inner.linger(wait);
  }
  bool last_damaged() const override { return last; }
  void set_baud(std::uint32_t baud) override { inner.set_baud(baud); }
  std::uint32_t baud() const override { return inner.baud(); }
};
}  // namespace

TEST_CASE("ics: a reply with a damaged byte is tried again and never used, and every try damaged is refused", "[ics]") {
  damaging_link l;
  ics_servo s(l, id_of(0), {});
  const auto truth = s.read(ics::sub::stretch);
  l.n = 0;
  l.damaged = {0};
  CHECK(s.read(ics::sub::stretch) == truth);  // the second try's answer
  CHECK(l.n == 2);

  l.always = true;
  try {
    (void)s.read(ics::sub::stretch);
    FAIL("a reply damaged at every try was used");
  } catch (const refused& r) {
    CHECK(r.kind == refusal_kind::board);
    CHECK(std::string(r.what()).find("failed its parity check") != std::string::npos);
  }
  try {
    (void)s.read_id(false);
    FAIL("a damaged ID reply was used");
  } catch (const refused& r) {
    CHECK(r.kind == refusal_kind::board);
    CHECK(std::string(r.what()).find("failed its parity check") != std::string::npos);
  }
}
