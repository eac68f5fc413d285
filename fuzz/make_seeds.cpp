// Writes the golden frames (tests/support/golden.hpp) as fuzz seeds: fuzz/seeds/{command,reply}/
// (with the harnesses' option bytes first) and fuzz/seeds/frames/ (the reply frames alone, for
// the template a user copies to fuzz their own wrapper).
// Run by hand when the golden table grows: make_seeds <fuzz/seeds directory>.
// SPDX-License-Identifier: BSL-1.0
#include "golden.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace {
void write(const std::filesystem::path& p, std::span<const std::uint8_t> header, std::span<const std::uint8_t> frame) {
  std::ofstream f(p, std::ios::binary);
  f.write(reinterpret_cast<const char*>(header.data()), static_cast<std::streamsize>(header.size()));
  f.write(reinterpret_cast<const char*>(frame.data()), static_cast<std::streamsize>(frame.size()));
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_seeds <seeds directory>\n");
    return 2;
  }
  const std::filesystem::path dir(argv[1]);
  std::filesystem::create_directories(dir / "command");
  std::filesystem::create_directories(dir / "reply");
  std::filesystem::create_directories(dir / "frames");
  int i = 0;
  for (const auto& g : rcb4::golden::requests) {
    const std::uint8_t opt[] = {
        static_cast<std::uint8_t>(g.options.shift == rcb4::shift_encoding::kondo_manual ? 1 : 0)};
    write(dir / "command" / ("golden-" + std::to_string(i++)), opt, g.frame);
  }
  i = 0;
  for (const auto& g : rcb4::golden::replies) {
    const std::uint8_t hdr[] = {g.expected.command, static_cast<std::uint8_t>(g.expected.data ? 1 : 0),
                                static_cast<std::uint8_t>(g.expected.data ? g.expected.data_size - 1 : 0)};
    write(dir / "reply" / ("golden-" + std::to_string(i)), hdr, g.frame);
    write(dir / "frames" / ("golden-" + std::to_string(i++)), {}, g.frame);
  }
  std::printf("wrote %zu command and %zu reply seeds to %s\n", std::size(rcb4::golden::requests),
              std::size(rcb4::golden::replies), argv[1]);
  return 0;
}
