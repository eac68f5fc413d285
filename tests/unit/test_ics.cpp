// The ICS codec (rcb4/ics): golden frames written by hand from ics.md §2.4 and §4.4, both
// directions, the echo, the EEPROM image's fields, and the virtual servo and line.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/ics/commands.hpp>
#include <rcb4/ics/eeprom.hpp>
#include <rcb4/ics/virtual_servo.hpp>

#include <catch2/catch.hpp>

#include <vector>

using namespace rcb4;
using namespace rcb4::ics;
using bytes = std::vector<std::uint8_t>;

namespace {
servo_id id_of(unsigned n) { return servo_id::make(n).value(); }
bytes request_of(const frame& f) { return {f.data.begin(), f.data.begin() + static_cast<std::ptrdiff_t>(f.size)}; }
bytes cat(bytes a, const bytes& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}
/** An image written by hand: ICSSW's example values (ics.md §4.2), factory bytes of our own. */
bytes hand_image() {
  return {0x05, 0x0A,                                            // 1-2 check mark 0x5A
          0x03, 0x0C,                                            // 3-4 stretch gain 60 (= 30 × 2)
          0x07, 0x0F,                                            // 5-6 speed 127
          0x00, 0x01,                                            // 7-8 punch 1
          0x00, 0x02,                                            // 9-10 dead band 2
          0x02, 0x08,                                            // 11-12 damping 40
          0x0F, 0x0A,                                            // 13-14 safe timer 250
          0x08, 0x09,                                            // 15 slave; 16 PWMINH + reverse
          0x02, 0x0C, 0x0E, 0x0C,                                // 17-20 maximum 11500
          0x00, 0x0D, 0x0A, 0x0C,                                // 21-24 minimum 3500
          0x03, 0x07,                                            // 25-26 factory
          0x00, 0x0A,                                            // 27-28 baud code 10: 115200
          0x05, 0x00,                                            // 29-30 temperature limit 80
          0x03, 0x0F,                                            // 31-32 current limit 63
          0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09,  // 33-41 factory
          0x0A, 0x0B, 0x0C, 0x0D, 0x0E, 0x0F, 0x00, 0x01, 0x02,  // 42-50 factory
          0x00, 0x03,                                            // 51-52 response 3
          0x0F, 0x0B,                                            // 53-54 user offset -5 (0xFB)
          0x06, 0x09,                                            // 55-56 factory
          0x00, 0x0C,                                            // 57-58 ID 12
          0x07, 0x08, 0x03, 0x0C, 0x0F, 0x0E};                   // 59-64 stretch sets 120, 60, 254 (stored)
}
}  // namespace

TEST_CASE("ICS golden requests from ics.md 2.4", "[ics]") {
  CHECK(request_of(set_position::make(id_of(3), 8833).value().request()) == bytes{0x83, 0x45, 0x01});
  CHECK(request_of(set_position::free(id_of(3)).request()) == bytes{0x83, 0x00, 0x00});
  CHECK(request_of(set_position::make(id_of(0), 7500).value().request()) == bytes{0x80, 0x3A, 0x4C});
  CHECK(request_of(read_parameter::make(id_of(12), sub::temperature).value().request()) == bytes{0xAC, 0x04});
  CHECK(request_of(read_parameter::make(id_of(12), sub::current).value().request()) == bytes{0xAC, 0x03});
  CHECK(request_of(write_parameter::make(id_of(12), sub::stretch, 90).value().request()) == bytes{0xCC, 0x01, 0x5A});
  CHECK(request_of(write_parameter::make(id_of(12), sub::temperature, 60).value().request()) ==
        bytes{0xCC, 0x04, 0x3C});
  CHECK(request_of(read_position(id_of(12)).request()) == bytes{0xAC, 0x05});
  CHECK(request_of(read_eeprom(id_of(12)).request()) == bytes{0xAC, 0x00});
  CHECK(request_of(read_id{}.request()) == bytes{0xFF, 0x00, 0x00, 0x00});
  CHECK(request_of(write_id(id_of(9)).request()) == bytes{0xE9, 0x01, 0x01, 0x01});
  const auto image = eeprom_image::parse(hand_image()).value();
  CHECK(request_of(write_eeprom(id_of(12), image).request()) == cat({0xCC, 0x00}, hand_image()));
  // +45 degrees is 8833 counts (ics.md 2.4: 45 x 4000/135 = 1333)
  CHECK(position::counts(45.0) == std::optional<std::uint16_t>(8833));
  CHECK(position::counts(-135.0) == std::optional<std::uint16_t>(3500));
  CHECK(!position::counts(135.5));
}

TEST_CASE("ICS golden replies from ics.md 2.4 with the echo before them", "[ics]") {
  const auto pos = set_position::make(id_of(3), 8833).value();
  auto r = parse_exchange(pos, bytes{0x83, 0x45, 0x01, 0x03, 0x3A, 0x4E});
  REQUIRE(r.ok());
  CHECK(r.value() == 7502);
  CHECK(r.consumed == 6);
  // ID 0 at 115200 keeps bit 7 of its reply header (ICS 2.0 compatibility)
  const auto zero = set_position::make(id_of(0), 7500).value();
  CHECK(parse_exchange(zero, bytes{0x80, 0x3A, 0x4C, 0x80, 0x3A, 0x4C}).value() == 7500);
  CHECK(parse_exchange(zero, bytes{0x80, 0x3A, 0x4C, 0x00, 0x3A, 0x4C}).value() == 7500);
  const auto temp = read_parameter::make(id_of(12), sub::temperature).value();
  CHECK(parse_exchange(temp, bytes{0xAC, 0x04, 0x2C, 0x04, 0x4B}).value() == 75);
  const auto cur = read_parameter::make(id_of(12), sub::current).value();
  CHECK(parse_exchange(cur, bytes{0xAC, 0x03, 0x2C, 0x03, 0x45}).value() == 69);
  const auto st = write_parameter::make(id_of(12), sub::stretch, 90).value();
  CHECK(parse_exchange(st, bytes{0xCC, 0x01, 0x5A, 0x4C, 0x01, 0x5A}).value() == 90);
  CHECK(parse_exchange(read_position(id_of(12)), bytes{0xAC, 0x05, 0x2C, 0x05, 0x3A, 0x4C}).value() == 7500);
  CHECK(parse_exchange(read_id{}, bytes{0xFF, 0x00, 0x00, 0x00, 0xEC}).value() == id_of(12));
  CHECK(parse_exchange(write_id(id_of(9)), bytes{0xE9, 0x01, 0x01, 0x01, 0xE9}).value() == id_of(9));
  const auto e = parse_exchange(read_eeprom(id_of(12)), cat({0xAC, 0x00, 0x2C, 0x00}, hand_image()));
  REQUIRE(e.ok());
  CHECK(e.consumed == 68);
  const auto image = eeprom_image::parse(hand_image()).value();
  auto w = parse_exchange(write_eeprom(id_of(12), image), cat(cat({0xCC, 0x00}, hand_image()), {0x4C, 0x00}));
  CHECK(w.ok());
  CHECK(w.consumed == 68);
}

TEST_CASE("ICS replies: the echo, short reads and wrong replies", "[ics]") {
  const auto temp = read_parameter::make(id_of(12), sub::temperature).value();
  // every split of the exchange is need_more until the last byte
  const bytes whole{0xAC, 0x04, 0x2C, 0x04, 0x4B};
  for (std::size_t n = 0; n < whole.size(); ++n) {
    const auto r = parse_exchange(temp, std::span(whole).first(n));
    CHECK(r.status == parse_status::need_more);
    CHECK(r.needed == whole.size() - n);
  }
  CHECK(parse_exchange(temp, bytes{0xAD, 0x04, 0x2C}).error == errc::ics_line_echo_mismatch);     // a collision
  CHECK(parse_exchange(temp, bytes{0xAC, 0x04, 0x2D, 0x04, 0x4B}).error == errc::ics_bad_reply);  // another ID
  CHECK(parse_exchange(temp, bytes{0xAC, 0x04, 0x2C, 0x03, 0x4B}).error == errc::ics_bad_reply);  // another SC
  CHECK(parse_exchange(temp, bytes{0xAC, 0x04, 0x2C, 0x04, 0xCB}).error == errc::ics_bad_reply);  // bit 7 set
  const auto st = write_parameter::make(id_of(12), sub::stretch, 90).value();
  CHECK(parse_exchange(st, bytes{0xCC, 0x01, 0x5A, 0x4C, 0x01, 0x59}).error == errc::ics_bad_reply);  // not taken
  const auto pos = set_position::make(id_of(3), 8833).value();
  CHECK(parse_exchange(pos, bytes{0x83, 0x45, 0x01, 0x83, 0x3A, 0x4E}).error == errc::ics_bad_reply);  // bit 7: ID 3
  CHECK(parse_exchange(read_id{}, bytes{0xFF, 0x00, 0x00, 0x00, 0xA0}).error == errc::ics_bad_reply);
  CHECK(parse_exchange(write_id(id_of(9)), bytes{0xE9, 0x01, 0x01, 0x01, 0xE8}).error == errc::ics_bad_reply);
  auto bad = hand_image();
  bad[40] = 0x10;  // not a nibble
  CHECK(parse_exchange(read_eeprom(id_of(12)), cat({0xAC, 0x00, 0x2C, 0x00}, bad)).error == errc::ics_bad_eeprom);
}

TEST_CASE("ICS values are range checked", "[ics]") {
  CHECK(servo_id::make(31));
  CHECK(servo_id::make(32).error() == errc::ics_id_out_of_range);
  CHECK(servo_id::make(-1).error() == errc::ics_id_out_of_range);
  CHECK(set_position::make(id_of(1), 3499).error() == errc::ics_value_out_of_range);
  CHECK(set_position::make(id_of(1), 11501).error() == errc::ics_value_out_of_range);
  CHECK(set_position::make(id_of(1), 0).error() == errc::ics_value_out_of_range);  // free is asked by name
  CHECK(write_parameter::make(id_of(1), sub::stretch, 0).error() == errc::ics_value_out_of_range);
  CHECK(write_parameter::make(id_of(1), sub::stretch, 128).error() == errc::ics_value_out_of_range);
  CHECK(write_parameter::make(id_of(1), sub::current, 64).error() == errc::ics_value_out_of_range);
  CHECK(write_parameter::make(id_of(1), sub::current, 63));
  CHECK(write_parameter::make(id_of(1), sub::eeprom, 1).error() == errc::ics_value_out_of_range);
  CHECK(read_parameter::make(id_of(1), sub::position).error() == errc::ics_value_out_of_range);
  CHECK(baud_code(625000) == std::optional<std::uint8_t>(1));
  CHECK(baud_of_code(0) == std::optional<std::uint32_t>(1250000));
  CHECK(!baud_code(9600));
  CHECK(wire_micros(6, 115200) == 573);  // ics.md §1: 0.57 ms
}

TEST_CASE("ICS requests parse back as the servo reads them", "[ics]") {
  CHECK(set_position::parse(bytes{0x83, 0x45, 0x01}).value() == set_position::make(id_of(3), 8833).value());
  CHECK(set_position::parse(bytes{0x83, 0x00, 0x00}).value() == set_position::free(id_of(3)));
  CHECK(!set_position::parse(bytes{0x83, 0x00, 0x01}));  // 1 is neither free nor in range
  CHECK(read_parameter::parse(bytes{0xAC, 0x04}).value() == read_parameter::make(id_of(12), sub::temperature).value());
  CHECK(!read_parameter::parse(bytes{0xAC, 0x05}));
  CHECK(write_parameter::parse(bytes{0xCC, 0x01, 0x5A}).value().value() == 90);
  CHECK(read_id::parse(bytes{0xFF, 0x00, 0x00, 0x00}));
  CHECK(write_id::parse(bytes{0xFF, 0x01, 0x01, 0x01}).value().id() == id_of(31));
  CHECK(write_eeprom::parse(cat({0xCC, 0x00}, hand_image())).value().image().bytes()[57] == 0x0C);
  CHECK(request_size_of(0xCC, 0x00) == 66);
  CHECK(request_size_of(0xCC, 0x01) == 3);
  CHECK(request_size_of(0x4C) == 0);
}

TEST_CASE("ICS EEPROM fields decode from hand-written bytes", "[ics]") {
  static_assert(std::size(fields) == static_cast<std::size_t>(field::stretch_3) + 1);
  for (std::size_t i = 0; i < std::size(fields); ++i) CHECK(static_cast<std::size_t>(fields[i].f) == i);
  const auto e = eeprom_image::parse(hand_image()).value();
  CHECK(e.get(field::stretch) == 30);
  CHECK(e.get(field::speed) == 127);
  CHECK(e.get(field::punch) == 1);
  CHECK(e.get(field::dead_band) == 2);
  CHECK(e.get(field::damping) == 40);
  CHECK(e.get(field::safe_timer) == 250);
  CHECK(e.get(field::slave) == 1);
  CHECK(e.get(field::rotation) == 0);
  CHECK(e.get(field::pwm_inhibit) == 1);
  CHECK(e.get(field::free) == 0);
  CHECK(e.get(field::reverse) == 1);
  CHECK(e.get(field::max_limit) == 11500);
  CHECK(e.get(field::min_limit) == 3500);
  CHECK(e.get(field::baud) == 115200);
  CHECK(e.get(field::temperature_limit) == 80);
  CHECK(e.get(field::current_limit) == 63);
  CHECK(e.get(field::response) == 3);
  CHECK(e.get(field::user_offset) == -5);
  CHECK(e.get(field::id) == 12);
  CHECK(e.get(field::stretch_1) == 60);
  CHECK(e.get(field::stretch_2) == 30);
  CHECK(e.get(field::stretch_3) == 127);
  auto bad = hand_image();
  bad[1] = 0x0B;  // no check mark
  CHECK(eeprom_image::parse(bad).error() == errc::ics_bad_eeprom);
  const auto short_image = hand_image();
  CHECK(eeprom_image::parse(std::span(short_image).first(63)).error() == errc::ics_bad_eeprom);
}

TEST_CASE("ICS EEPROM edit of ics.md 4.4 changes only its bytes", "[ics]") {
  const auto before = eeprom_image::parse(hand_image()).value();
  auto e = before;
  REQUIRE(e.set(field::max_limit, 11000));
  REQUIRE(e.set(field::min_limit, 4000));
  REQUIRE(e.set(field::user_offset, -5));
  REQUIRE(e.set(field::stretch, 45));
  REQUIRE(e.set(field::baud, 625000));
  auto want = hand_image();
  const bytes max{0x02, 0x0A, 0x0F, 0x08}, min{0x00, 0x0F, 0x0A, 0x00};
  std::copy(max.begin(), max.end(), want.begin() + 16);  // bytes 17-20
  std::copy(min.begin(), min.end(), want.begin() + 20);  // bytes 21-24
  want[52] = 0x0F, want[53] = 0x0B;                      // 53-54: -5
  want[2] = 0x05, want[3] = 0x0A;                        // 3-4: 90
  want[27] = 0x01;                                       // 28: 625000; 27 as read
  CHECK(bytes(e.bytes().begin(), e.bytes().end()) == want);
  CHECK(e.same_unit(before));
  CHECK(e.set(field::stretch, 0).error() == errc::ics_value_out_of_range);
  CHECK(e.set(field::max_limit, 7999).error() == errc::ics_value_out_of_range);
  CHECK(e.set(field::baud, 9600).error() == errc::ics_value_out_of_range);
  CHECK(e.set(field::id, 3).error() == errc::ics_value_out_of_range);    // the ID command's work
  CHECK(e.set(field::free, 1).error() == errc::ics_value_out_of_range);  // read only
  REQUIRE(e.set(field::slave, 0));
  CHECK(e.bytes()[14] == 0x00);
  REQUIRE(e.set(field::rotation, 1));
  CHECK(e.bytes()[14] == 0x01);
  // another unit's factory bytes: not the same servo; with_factory_of puts ours back
  auto other = before;
  REQUIRE(other.set_raw(40, 0x00));
  CHECK(!other.same_unit(before));
  CHECK(other.with_factory_of(before) == before);
}

TEST_CASE("ICS virtual line: echo, replies, two servos, faults, rates", "[ics]") {
  virtual_line line({virtual_servo(id_of(0), 115200, 1)});
  bytes out;
  const bytes id_read{0xFF, 0x00, 0x00, 0x00};
  line.feed(id_read, 115200, line_time{0}, out);
  CHECK(out == bytes{0xFF, 0x00, 0x00, 0x00, 0xE0});
  out.clear();
  line.feed(id_read, 625000, line_time{0}, out);  // the servo hears noise at another rate
  CHECK(out == id_read);
  out.clear();  // a frame split in two
  line.feed(bytes{0x80, 0x3A}, 115200, line_time{0}, out);
  line.feed(bytes{0x4C}, 115200, line_time{0}, out);
  CHECK(out == bytes{0x80, 0x3A, 0x4C, 0x80, 0x3A, 0x4C});  // ID 0 at 115200: header 0x80
  // it runs to 8833 (+45 degrees) at 600 degrees a second: there after 75 ms
  out.clear();
  line.feed(bytes{0x80, 0x45, 0x01}, 115200, line_time{1000}, out);
  CHECK(line.servos()[0].position_at(line_time{1000 + 10000}) < 8833);
  CHECK(line.servos()[0].position_at(line_time{1000 + 80000}) == 8833);

  virtual_line two({virtual_servo(id_of(0)), virtual_servo(id_of(1), 115200, 2)});
  out.clear();
  two.feed(id_read, 115200, line_time{0}, out);
  CHECK(out == bytes{0xFF, 0x00, 0x00, 0x00, 0xE0, 0xE1});  // both answer
  out.clear();
  two.feed(bytes{0xE5, 0x01, 0x01, 0x01}, 115200, line_time{0}, out);
  CHECK(two.servos()[0].id() == id_of(5));  // an ID write renames every servo on the wire
  CHECK(two.servos()[1].id() == id_of(5));
  CHECK(!two.servos()[0].image().same_unit(two.servos()[1].image()));  // factory bytes of their own

  virtual_line silent({virtual_servo{}}, line_faults{true, false});
  out.clear();
  silent.feed(id_read, 115200, line_time{0}, out);
  CHECK(out == id_read);
  virtual_line corrupt({virtual_servo{}}, line_faults{false, true});
  out.clear();
  corrupt.feed(id_read, 115200, line_time{0}, out);
  CHECK(out == bytes{0xFF, 0x00, 0x00, 0x00, 0xA0});

  virtual_line old({virtual_servo(id_of(2), 115200, 1, false)});
  out.clear();
  old.feed(bytes{0xA2, 0x05}, 115200, line_time{0}, out);
  CHECK(out == bytes{0xA2, 0x05});  // ICS 3.5: no answer to SC 5
}
