// Codec micro-benchmarks (Google Benchmark). Prints ns per operation and heap allocations per
// operation next to the targets of the codec issue; nothing here is asserted.
//   targets: CONST36 build + serialize ≤ 50 ns (the 2015 C library: ~2,000 ns),
//            reply parse ≤ 20 ns, 0 heap allocations.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/rcb4.hpp>

#include "alloc_count.hpp"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <vector>

namespace {
using namespace rcb4;

/** Reports allocations per iteration as a counter. */
class alloc_counter {
 public:
  explicit alloc_counter(benchmark::State& s) : state_(s), start_(bench::allocations()) {}
  ~alloc_counter() {
    const auto n = static_cast<double>(bench::allocations() - start_);
    state_.counters["allocs/op"] = n / static_cast<double>(state_.iterations());
  }
  alloc_counter(const alloc_counter&) = delete;
  alloc_counter& operator=(const alloc_counter&) = delete;

 private:
  benchmark::State& state_;
  std::size_t start_;
};

void BM_const36_build_and_serialize(benchmark::State& state) {
  std::uint16_t base = 7000;
  std::array<std::uint8_t, max_request_size> out{};
  alloc_counter allocs(state);
  for (auto _ : state) {
    servo_set<servo_position> targets;
    for (std::uint8_t i = 0; i < 36; ++i)
      targets.insert(ics_number::make(i).value(), servo_position::make(base + i).value());
    auto cmd = const_servo::make(targets, 10);
    auto n = serialize(*cmd, out);
    benchmark::DoNotOptimize(n);
    benchmark::DoNotOptimize(out.data());
    base = static_cast<std::uint16_t>(base ^ 1);
  }
}
BENCHMARK(BM_const36_build_and_serialize);

void BM_mov_read_2_bytes(benchmark::State& state) {
  std::array<std::uint8_t, max_request_size> out{};
  std::uint16_t addr = 0x0090;
  alloc_counter allocs(state);
  for (auto _ : state) {
    auto cmd = move::read_ram(ram_address::make(addr).value(), 2);
    auto n = serialize(*cmd, out);
    benchmark::DoNotOptimize(n);
    benchmark::DoNotOptimize(out.data());
    addr = static_cast<std::uint16_t>(addr ^ 0x20);
  }
}
BENCHMARK(BM_mov_read_2_bytes);

void BM_parse_129_byte_reply(benchmark::State& state) {
  std::vector<std::uint8_t> frame{0x81, 0x00};
  for (int i = 0; i < 126; ++i) frame.push_back(static_cast<std::uint8_t>(i));
  frame.push_back(checksum(frame));
  const auto shape = expected_reply(move::read_ram(0x0090, 126).value());
  alloc_counter allocs(state);
  for (auto _ : state) {
    benchmark::DoNotOptimize(frame.data());
    auto r = parse_reply(frame, shape);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_parse_129_byte_reply);

void BM_parse_ack(benchmark::State& state) {
  const std::uint8_t frame[] = {0x04, 0xFE, 0x06, 0x08};
  alloc_counter allocs(state);
  for (auto _ : state) {
    benchmark::DoNotOptimize(frame);
    auto r = parse_reply(frame, reply_shape{0xFE, false, 0});
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_parse_ack);

void BM_board_parse_const36(benchmark::State& state) {
  servo_set<servo_position> targets;
  for (std::uint8_t i = 0; i < 36; ++i) targets.insert(ics_number::make(i).value(), 7500);
  const auto frame = encode(const_servo::make(targets, 10).value());
  alloc_counter allocs(state);
  for (auto _ : state) {
    benchmark::DoNotOptimize(frame);
    auto r = parse_command(frame.bytes());
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_board_parse_const36);
}  // namespace

int main(int argc, char** argv) {
  std::printf(
      "rcb4 codec benchmarks. Targets: CONST36 <= 50 ns (2015 C library ~2000 ns), "
      "reply parse <= 20 ns, 0 allocs/op.\n");
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
