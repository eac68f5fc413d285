// A template: fuzz YOUR code that wraps rcb4's reply parser. Copy this file, replace the part
// marked "your code" with your own wrapper (or include it), and keep the harness below it.
//
//   libFuzzer (clang):  clang++-16 -std=c++20 -g -O1 -fsanitize=fuzzer,address,undefined
//                         -I<rcb4>/include my_fuzzer.cpp -o my_fuzzer
//                       ./my_fuzzer -max_total_time=60 corpus/ <rcb4>/fuzz/seeds/frames
//   replay (any compiler, e.g. in your GCC unit-test build): add <rcb4>/fuzz/replay_main.cpp,
//                       then  ./my_replay <rcb4>/fuzz/seeds/frames corpus/
//
// The input is what the line gave: bytes that should be a reply frame and may be anything.
// fuzz/seeds/frames holds the project's golden reply frames (written by rcb4_make_seeds), a good
// first corpus. A property that fails calls __builtin_trap(): libFuzzer saves the input.
// The project's own build runs this very file (fuzz.run.template, fuzz.replay.template).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/rcb4.hpp>

#include <cstdint>
#include <optional>
#include <span>

namespace {

// --- your code (replace): a wrapper as a program would write it ----------------------------------
/** The battery voltage from the reply to a 2-byte read of AD0 (RAM 0x0022, protocol.md §6). */
std::optional<double> battery_volts_from(std::span<const std::uint8_t> line) {
  const auto read = rcb4::move::read_ram(rcb4::ram::ad(0).value(), 2).value();
  const auto r = rcb4::parse_reply(line, rcb4::expected_reply(rcb4::command{read}));
  if (!r.ok() || r.value().kind() != rcb4::reply_kind::data) return std::nullopt;  // NACK, garbage, short
  return rcb4::battery_volts(r.value().u16());
}
// --- end of your code ----------------------------------------------------------------------------

void check(bool ok) {
  if (!ok) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> line(data, size);
  const auto volts = battery_volts_from(line);
  if (!volts) return 0;
  // What your wrapper promises, written as checks: a value only from a whole, valid reply frame
  // ([05][00][lo][hi][SUM], protocol.md §2.1), and within what 16 bits of AD0 can mean.
  check(size >= 5 && data[0] == 5 && data[1] == 0x00 && rcb4::checksum_ok(line.first(5)));
  check(*volts >= 0.0 && *volts <= 65535 * 25.0 / 1024.0);
  check(*volts == rcb4::battery_volts(static_cast<std::uint16_t>(data[2] | (data[3] << 8))));
  return 0;
}
