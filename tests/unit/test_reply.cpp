// Replies: golden replies split at every byte; every host-side rejection; board-side encoding.
// SPDX-License-Identifier: BSL-1.0
#include "golden.hpp"

#include <rcb4/fmt.hpp>

#include <catch2/catch.hpp>

#include <array>
#include <numeric>
#include <vector>

using namespace rcb4;

TEST_CASE("golden replies parse the same fed in any split", "[reply][golden]") {
  for (const auto& g : golden::replies) {
    INFO(g.name);
    // Feed exactly what the parser asks for, from every starting split.
    for (std::size_t cut = 0; cut <= g.frame.size(); ++cut) {
      std::size_t have = cut;
      auto r = parse_reply(g.frame.first(have), g.expected);
      while (r.status == parse_status::need_more) {
        REQUIRE(r.needed >= 1);
        have += r.needed;
        REQUIRE(have <= g.frame.size());  // never asks past the frame
        r = parse_reply(g.frame.first(have), g.expected);
      }
      REQUIRE(r.ok());
      REQUIRE(r.consumed == g.frame.size());
      REQUIRE(r.value() == g.value);
    }
    auto any = parse_reply_frame(g.frame);
    REQUIRE(any.ok());
    REQUIRE(any.consumed == g.frame.size());
  }
}

TEST_CASE("a 126-byte read answers with a 129-byte frame", "[reply]") {
  std::vector<std::uint8_t> frame{0x81, 0x00};
  for (int i = 0; i < 126; ++i) frame.push_back(static_cast<std::uint8_t>(i));
  // 0x81 + (0 + 1 + ... + 125) = 0x81 + 7875 = 0x1F44 → 0x44, worked out by hand.
  frame.push_back(0x44);
  const auto shape = expected_reply(move::read_ram(0x0090, 126).value());
  REQUIRE(shape.frame_size() == 129);
  for (std::size_t cut = 0; cut < frame.size(); ++cut) {
    auto r = parse_reply(std::span(frame).first(cut), shape);
    REQUIRE(r.status == parse_status::need_more);
    if (cut >= 1) REQUIRE(cut + r.needed == 129);
  }
  auto r = parse_reply(frame, shape);
  REQUIRE(r.ok());
  REQUIRE(r.value().bytes().size() == 126);
  CHECK(r.value().bytes()[125] == 125);
  const auto again = encode(r.value());
  CHECK(std::equal(frame.begin(), frame.end(), again.begin(), again.end()));
}

TEST_CASE("host-side reply errors name what was wrong", "[reply][errors]") {
  const reply_shape ack_ping{0xFE, false, 0};
  const reply_shape two_bytes{0x00, true, 2};
  const std::uint8_t bad_sum[] = {0x04, 0xFE, 0x06, 0x09};
  CHECK(parse_reply(bad_sum, ack_ping).error == errc::bad_checksum);
  const std::uint8_t echo[] = {0x04, 0x0F, 0x06, 0x19};
  auto e = parse_reply(echo, ack_ping);
  CHECK(e.error == errc::echo_mismatch);
  CHECK(e.command == 0x0F);
  const std::uint8_t echo_early[] = {0x04, 0x0F};
  CHECK(parse_reply(echo_early, ack_ping).error == errc::echo_mismatch);  // fails before waiting
  const std::uint8_t len[] = {0x06, 0xFE};
  CHECK(parse_reply(len, ack_ping).error == errc::bad_reply_length);
  CHECK(parse_reply(len, two_bytes).error == errc::bad_reply_length);
  const std::uint8_t code[] = {0x04, 0xFE, 0x07, 0x09};
  CHECK(parse_reply(code, ack_ping).error == errc::bad_ack_code);
  const std::uint8_t ack_mov[] = {0x04, 0x00, 0x06, 0x0A};
  CHECK(parse_reply(ack_mov, two_bytes).error == errc::unexpected_ack);
  CHECK(parse_reply(std::span<const std::uint8_t>{}, ack_ping).needed == 4);
  const std::uint8_t short_frame[] = {0x03, 0xFE, 0x01};
  CHECK(parse_reply_frame(short_frame).error == errc::frame_too_short);
}

TEST_CASE("a reply shape no board can answer is refused, never trapped on", "[reply][errors]") {
  // reply_shape is a public aggregate: {cmd, data, 0} and sizes above 252 can be built by anyone.
  // The frame 03 00 03 (well-formed: its sum is right) trapped in parse_reply (review R3).
  const std::uint8_t three[] = {0x03, 0x00, 0x03};
  for (const std::uint8_t n : {std::uint8_t{0}, std::uint8_t{253}, std::uint8_t{255}}) {
    INFO(int(n));
    const reply_shape shape{0x00, true, n};
    const auto r = parse_reply(three, shape);
    CHECK(r.status == parse_status::error);
    CHECK(r.error == errc::bad_reply_length);
    CHECK(r.consumed == 3);
    CHECK(parse_reply(std::span<const std::uint8_t>{}, shape).status == parse_status::error);
  }
  // and compile time says the same
  static_assert(parse_reply(std::array<std::uint8_t, 3>{0x03, 0x00, 0x03}, reply_shape{0x00, true, 0}).error ==
                errc::bad_reply_length);
}

TEST_CASE("board-side replies", "[reply]") {
  CHECK(encode(reply::ack(0x0F)) == reply_frame(std::span<const std::uint8_t>({0x04, 0x0F, 0x06, 0x19})));
  CHECK(encode(reply::nack(0xFE)) == reply_frame(std::span<const std::uint8_t>(golden::nack_ping)));
  std::vector<std::uint8_t> too_big(253, 0);
  CHECK(reply::data(0x00, too_big).error() == errc::frame_too_long);
  CHECK(reply::data(0x00, std::span(too_big).first(252)).value().wire_size() == 255);
  CHECK(reply::data(0x00, std::span(too_big).first(0)).error() == errc::frame_too_long);
  std::uint8_t small[3];
  CHECK(serialize(reply::ack(0), small).error() == errc::buffer_too_small);
  CHECK(fmt::format("{}", reply::nack(0x0C)) == "NACK to CALL");
  CHECK(fmt::format("{}", golden::replies[4].value) == "DATA from MOV, 2 bytes: 83 4C");
}
