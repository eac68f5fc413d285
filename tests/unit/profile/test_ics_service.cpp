// The ICS servo service (rcb4/robot/services/ics.hpp) on in-process virtual lines: what it
// writes, what it refuses, and that a refusal writes nothing.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/services/ics.hpp>

#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <string>

using namespace rcb4;
using namespace rcb4::robot::services;
using ics::field;

namespace {
ics::servo_id id_of(unsigned n) { return ics::servo_id::make(n).value(); }
ics_virtual_link one(unsigned id = 0, std::uint32_t baud = 115200, std::uint32_t seed = 1) {
  return ics_virtual_link(ics::virtual_line({ics::virtual_servo(id_of(id), baud, seed)}));
}
refusal_kind kind_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const refused& r) {
    return r.kind;
  }
  FAIL("not refused");
  return refusal_kind::usage;
}
}  // namespace

TEST_CASE("ics service finds a lone servo's ID and baud", "[ics]") {
  auto l = one(7, 625000);
  ics_servo s(l, {}, {});
  CHECK(s.id() == id_of(7));
  CHECK(s.baud() == 625000);
  CHECK(s.read_id() == id_of(7));
  auto l2 = one(7, 625000);
  CHECK(kind_of([&] { ics_servo(l2, id_of(3), {}); }) == refusal_kind::timeout);
  CHECK(kind_of([&] { ics_servo(l2, {}, 115200); }) == refusal_kind::timeout);
  CHECK(kind_of([&] { ics_servo(l2, {}, 9600); }) == refusal_kind::usage);
}

TEST_CASE("ics service sets fields: backup first, only those bytes, read back", "[ics]") {
  auto l = one(4);
  ics_servo s(l, {}, {});
  const auto before = s.read_eeprom();
  int saves = 0;
  const ics_backup save = [&](const ics::eeprom_image& e) {
    CHECK(e == before);
    ++saves;
    return std::string("saved.bin");
  };
  const auto r = s.set_fields({{field::stretch, 40}, {field::reverse, 1}}, save);
  CHECK(saves == 1);
  CHECK(r.written);
  CHECK(r.backup == "saved.bin");
  CHECK(r.after.get(field::stretch) == 40);
  CHECK(r.after.get(field::reverse) == 1);
  CHECK(r.after.same_unit(before));
  for (std::size_t i = 0; i < 64; ++i)
    if (i != 2 && i != 3 && i != 15) CHECK(r.after.bytes()[i] == before.bytes()[i]);
  CHECK(l.line().servos()[0].stretch() == 40);  // the servo took it
  // the same again: nothing to write, no backup
  CHECK_FALSE(s.set_fields({{field::stretch, 40}}, save).written);
  CHECK(saves == 1);
  // a backup that cannot be saved stops the write
  const ics_backup fails = [](const ics::eeprom_image&) -> std::string { throw std::runtime_error("disk full"); };
  CHECK_THROWS_AS(s.set_fields({{field::stretch, 20}}, fails), std::runtime_error);
  CHECK(s.read_eeprom().get(field::stretch) == 40);
  CHECK(kind_of([&] { s.set_fields({{field::stretch, 0}}, save); }) == refusal_kind::usage);
  CHECK(kind_of([&] { s.set_fields({{field::id, 3}}, save); }) == refusal_kind::usage);
  CHECK(kind_of([&] { s.set_fields({{field::speed, 9}, {field::speed, 10}}, save); }) == refusal_kind::usage);
  CHECK(saves == 1);
}

TEST_CASE("ics service restores only onto the same servo unless forced", "[ics]") {
  auto mine = one(2, 115200, 1);
  auto other = one(2, 115200, 9);
  ics_servo a(mine, {}, {});
  ics_servo b(other, {}, {});
  const auto theirs = b.read_eeprom();
  const auto own = a.read_eeprom();
  const ics_backup save = [](const ics::eeprom_image&) { return std::string("old.bin"); };
  CHECK(kind_of([&] { a.restore(theirs, false, save); }) == refusal_kind::board);
  CHECK(a.read_eeprom() == own);
  auto edited = theirs;
  REQUIRE(edited.set(field::speed, 50));
  const auto r = a.restore(edited, true, save);
  CHECK(r.after.get(field::speed) == 50);
  CHECK(r.after.same_unit(own));  // its own factory bytes kept
  CHECK(!r.notes.empty());
}

TEST_CASE("ics service refuses ID work with two servos and corrupt replies", "[ics]") {
  ics_virtual_link two(ics::virtual_line({ics::virtual_servo(id_of(0)), ics::virtual_servo(id_of(1), 115200, 2)}));
  CHECK(kind_of([&] { ics_servo(two, {}, {}); }) == refusal_kind::board);
  ics_servo s(two, id_of(0), 115200);
  CHECK(kind_of([&] { s.set_id(id_of(5)); }) == refusal_kind::board);
  CHECK(two.line().servos()[0].id() == id_of(0));
  CHECK(two.line().servos()[1].id() == id_of(1));
  const auto found = ics_scan(two, {}, {});
  REQUIRE(found.size() == 2);
  CHECK(found[1].id == id_of(1));
  CHECK(found[1].ics36);

  ics_virtual_link bad(ics::virtual_line({ics::virtual_servo{}}, ics::line_faults{false, true}));
  CHECK(kind_of([&] { ics_servo(bad, id_of(0), 115200); }) == refusal_kind::board);
  ics_virtual_link quiet(ics::virtual_line({ics::virtual_servo{}}, ics::line_faults{true, false}));
  CHECK(kind_of([&] { ics_servo(quiet, {}, {}); }) == refusal_kind::timeout);
  CHECK(ics_scan(quiet, {}, {}).empty());  // the echo came back: an ICS line with no servo
  // Nothing at all comes back (an RCB-4 board's port, an adapter in COM mode): said, not "no servo".
  struct dead final : ics_link {
    std::uint32_t b = 115200;
    std::vector<std::uint8_t> transact(std::span<const std::uint8_t>, std::size_t, std::chrono::milliseconds) override {
      return {};
    }
    std::vector<std::uint8_t> linger(std::chrono::milliseconds) override { return {}; }
    void set_baud(std::uint32_t baud) override { b = baud; }
    std::uint32_t baud() const override { return b; }
  } nothing;
  for (const auto& f : {std::function<void()>([&] { (void)ics_scan(nothing, {}, {}); }),
                        std::function<void()>([&] { ics_servo(nothing, {}, {}); })}) {
    try {
      f();
      FAIL("not refused");
    } catch (const refused& r) {
      CHECK(r.kind == refusal_kind::timeout);
      CHECK(std::string(r.what()).find("not even the echo") != std::string::npos);
    }
  }
}

TEST_CASE("ics service: ID set on a lone servo, moves, settings text", "[ics]") {
  auto l = one(0);
  ics_servo s(l, {}, {});
  CHECK(s.set_id(id_of(12)) == id_of(12));
  CHECK(s.read_eeprom().get(field::id) == 12);
  CHECK(s.move(8833) == 7500);
  CHECK(kind_of([&] { s.move(3000); }) == refusal_kind::usage);
  CHECK(kind_of([&] { s.write(ics::sub::current, 64); }) == refusal_kind::usage);
  CHECK(s.write(ics::sub::speed, 30) == 30);
  CHECK(s.read(ics::sub::speed) == 30);
  CHECK(parse_ics_setting("stretch=40") == std::pair{field::stretch, 40L});
  CHECK(parse_ics_setting("reverse=on") == std::pair{field::reverse, 1L});
  CHECK(parse_ics_setting("user_offset=-5") == std::pair{field::user_offset, -5L});
  CHECK(parse_ics_setting("baud=625000") == std::pair{field::baud, 625000L});
  for (const char* bad :
       {"stretch", "stretch=", "stretch=4x", "baud=9600", "free=1", "id=2", "nope=1", "max_limit=7000"})
    CHECK(kind_of([&] { (void)parse_ics_setting(bad); }) == refusal_kind::usage);
}

TEST_CASE("ics service refuses damaged backups and a slave flag unless forced", "[ics]") {
  auto l = one(3);
  ics_servo s(l, {}, {});
  const auto before = s.read_eeprom();
  const ics_backup save = [](const ics::eeprom_image&) { return std::string("old.bin"); };
  auto damaged = before;
  REQUIRE(damaged.set_raw(3, 0));  // stretch 0: beyond 1..127
  REQUIRE(damaged.set_raw(4, 0));
  CHECK(kind_of([&] { s.restore(damaged, false, save); }) == refusal_kind::usage);  // --force writes it (trust tests)
  auto odd_baud = before;
  REQUIRE(odd_baud.set_raw(28, 5));
  CHECK(kind_of([&] { s.restore(odd_baud, true, save); }) == refusal_kind::usage);
  CHECK(s.read_eeprom() == before);
  CHECK(kind_of([&] { s.set_fields({{field::slave, 1}}, save); }) == refusal_kind::usage);
  CHECK(s.read_eeprom() == before);
  CHECK(s.set_id(id_of(3)) == id_of(3));  // already: nothing written
  const auto r = s.set_fields({{field::slave, 1}}, save, true);
  CHECK(r.written);
  CHECK(!r.notes.empty());
  CHECK(kind_of([&] { (void)s.read_eeprom(); }) == refusal_kind::timeout);  // a slave never answers
}

TEST_CASE("ics backups never replace a file unless asked", "[ics]") {
  const auto dir = std::filesystem::temp_directory_path() / ("rcb4-ics-unit-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const ics::virtual_servo servo(id_of(1));
  const auto path = (dir / "a.bin").string();
  save_ics_image(path, servo.image());
  CHECK(load_ics_image(path) == servo.image());
  CHECK(kind_of([&] { save_ics_image(path, servo.image()); }) == refusal_kind::usage);
  save_ics_image(path, servo.image(), true);
  const auto in = ics_backup_in(dir.string(), id_of(1));
  const auto first = in(servo.image());
  const auto second = in(servo.image());
  CHECK(first != second);  // the same second: -2
  CHECK(std::filesystem::exists(first));
  CHECK(std::filesystem::exists(second));
  std::filesystem::remove_all(dir);
}

TEST_CASE("ics service: a line that fails during the EEPROM write names the backup", "[ics]") {
  struct unplugged final : ics_link {
    ics_virtual_link inner{ics::virtual_line({ics::virtual_servo{}})};
    bool pulled = false;
    std::vector<std::uint8_t> transact(std::span<const std::uint8_t> request, std::size_t expect,
                                       std::chrono::milliseconds wait) override {
      if (pulled || (request.size() == 66)) {  // the EEPROM write: the cable comes out
        pulled = true;
        throw std::system_error(std::make_error_code(std::errc::io_error), "write");
      }
      return inner.transact(request, expect, wait);
    }
    std::vector<std::uint8_t> linger(std::chrono::milliseconds wait) override { return inner.linger(wait); }
    void set_baud(std::uint32_t baud) override { inner.set_baud(baud); }
    std::uint32_t baud() const override { return inner.baud(); }
  } l;
  ics_servo s(l, {}, {});
  const ics_backup save = [](const ics::eeprom_image&) { return std::string("kept.bin"); };
  try {
    (void)s.set_fields({{field::stretch, 30}}, save);
    FAIL("not refused");
  } catch (const refused& r) {
    CHECK(r.kind == refusal_kind::line);
    CHECK(r.backup == "kept.bin");
    CHECK(r.code == std::errc::io_error);
    CHECK(std::string(r.what()).find("may or may not") != std::string::npos);
  }
}

TEST_CASE("ics service: a restore keeps byte 16's fixed and FREE bits and refuses an odd stretch", "[ics]") {
  auto l = one(2);
  ics_servo s(l, {}, {});
  const auto before = s.read_eeprom();
  const ics_backup save = [](const ics::eeprom_image&) { return std::string("old.bin"); };
  auto bits = before;
  REQUIRE(bits.set_raw(16, static_cast<std::uint8_t>(before.bytes()[15] | 0x6)));
  const auto r = s.restore(bits, false, save);
  CHECK_FALSE(r.written);  // only bits rcb4 never writes differ
  CHECK(s.read_eeprom() == before);
  auto odd = before;
  REQUIRE(odd.set_raw(4, 1));  // stretch stored 0x01: odd
  CHECK(kind_of([&] { s.restore(odd, false, save); }) == refusal_kind::usage);
  auto tuned = before;
  REQUIRE(tuned.set(field::speed, 77));
  const auto dry = s.restore(tuned, false, save, true);
  CHECK_FALSE(dry.written);
  CHECK(dry.backup.empty());
  REQUIRE(dry.changed.size() == 1);
  CHECK(s.read_eeprom() == before);
  auto dry_set = s.set_fields({{field::punch, 3}}, save, false, true);
  CHECK_FALSE(dry_set.written);
  CHECK(s.read_eeprom() == before);
}

TEST_CASE("ics service: a forced restore from another unit keeps this unit's user offset", "[ics]") {
  auto mine = one(2, 115200, 1);
  auto other = one(2, 115200, 5);
  ics_servo a(mine, {}, {});
  ics_servo b(other, {}, {});
  const ics_backup save = [](const ics::eeprom_image&) { return std::string("old.bin"); };
  (void)b.set_fields({{field::user_offset, -9}, {field::stretch, 44}}, save);
  const auto r = a.restore(b.read_eeprom(), true, save);
  CHECK(r.after.get(field::stretch) == 44);
  CHECK(r.after.get(field::user_offset) == 0);
  CHECK(r.notes.size() >= 2);
}

TEST_CASE("ics service: a 3.6 servo that stops answering is not called ICS 3.5", "[ics]") {
  ics_virtual_link l(ics::virtual_line({ics::virtual_servo{}}));
  ics_servo s(l, {}, {});
  (void)s.position();
  (void)s.set_fields(
      {{field::slave, 1}}, [](const ics::eeprom_image&) { return std::string("x"); }, true);
  try {
    (void)s.position();
    FAIL("answered");
  } catch (const refused& r) {
    CHECK(r.kind == refusal_kind::timeout);
  }
}
