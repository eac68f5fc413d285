// Value types, servo sets (against a reference model), memory map, errors.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/error_category.hpp>
#include <rcb4/fmt.hpp>

#include <catch2/catch.hpp>

#include <map>
#include <random>
#include <system_error>

using namespace rcb4;

TEST_CASE("servo_set matches a sorted map under random inserts and erases", "[servo_set]") {
  std::mt19937 rng(42);
  for (int round = 0; round < 200; ++round) {
    servo_set<servo_position> set;
    std::map<int, int> model;
    for (int step = 0; step < 100; ++step) {
      const int k = std::uniform_int_distribution<int>(0, 35)(rng);
      const int v = std::uniform_int_distribution<int>(0, 16383)(rng);
      if (std::uniform_int_distribution<int>(0, 3)(rng) == 0) {
        set.erase(ics_number::make(k).value());
        model.erase(k);
      } else {
        set.insert(ics_number::make(k).value(), servo_position::make(v).value());
        model[k] = v;
      }
      REQUIRE(set.size() == model.size());
      auto it = model.begin();
      for (auto e : set) {
        REQUIRE(e.ics.value() == it->first);
        REQUIRE(e.value.value() == it->second);
        ++it;
      }
    }
  }
}

TEST_CASE("errc is a std::error_code with category rcb4", "[errors]") {
  std::error_code ec = errc::bad_checksum;
  CHECK(std::string(ec.category().name()) == "rcb4");
  CHECK(ec.message() == "checksum mismatch");
  CHECK(ec == errc::bad_checksum);
  CHECK(fmt::format("{}", errc::nack) == "board answered NACK");
  for (int e = 1; e <= static_cast<int>(errc_last); ++e)
    CHECK(std::error_code(static_cast<errc>(e)).message() != "unknown rcb4 error");
}

TEST_CASE("battery voltage follows DOC-FW (AD0 × 25 / 1024)", "[memory_map]") {
  CHECK(battery_volts(0) == Approx(0.0));
  CHECK(battery_volts(1024) == Approx(25.0));
  CHECK(battery_volts(442) == Approx(10.79).margin(0.01));  // a 10.8 V pack
}

TEST_CASE("formatters describe commands for a person", "[fmt]") {
  CHECK(fmt::format("{}", command{single_servo{0, 7500, 10}}) == "SINGLE ICS 0 → 7500 in 10 frames");
  CHECK(fmt::format("{}", command{single_servo{5, servo_position::free(), 0, update_flags::leave}}) ==
        "SINGLE ICS 5 → FREE in 0 frames (leave update flags)");
  CHECK(fmt::format("{}", command{move::read_ram(0x0000, 2).value()}) == "MOV RAM[0x0000+2] → COM");
  CHECK(fmt::format("{}", command{call{0x000B80}}) == "CALL 0x000B80");
  CHECK(fmt::format("{}", command{jump{0x001000, condition{true, false}}}) == "JUMP 0x001000 if Z=1 or C=0");
  CHECK(fmt::format("{}", command{const_servo::make({{3, 8000}, {1, servo_position::hold()}}, 20).value()}) ==
        "CONST 2 servos in 20 frames: 1=HOLD 3=8000");
  CHECK(fmt::format("{}", command{shift::make(destination::ram(0x0090), -2, 1).value()}) ==
        "SHIFT RAM[0x0090+1] right 2");
  const std::uint8_t b[] = {0x0A, 0x00, 0xFF};
  CHECK(fmt::format("{}", hex(b)) == "0A 00 FF");
  CHECK(fmt::format("{}", config_word::decode(0x8083)).find("COM 1250000 baud") != std::string::npos);
}
