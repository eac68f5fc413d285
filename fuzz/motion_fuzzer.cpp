// libFuzzer harness: a motion slot's bytes read back (rcb4/motion/disassemble.hpp), whatever the
// ROM holds. Properties:
//   - every instruction of the listing lies inside the slot and the bytes given, once, ascending,
//     and is the frame parse_command reads there;
//   - where lift() gives a program, assembling it gives exactly the listing's bytes from the
//     slot's start (the code is one block), and reading those back gives the same program.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/motion/disassemble.hpp>

namespace {
void check(bool ok) {
  if (!ok) __builtin_trap();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const rcb4::motion::slot where{rcb4::rom_address{0x000BB8}, 2048};
  const std::span<const std::uint8_t> bytes(data, std::min<std::size_t>(size, where.size));
  const auto l = rcb4::motion::disassemble(bytes, where);
  std::uint32_t previous = 0;
  std::vector<std::uint8_t> code;
  for (const auto& in : l.code) {
    check(in.address >= 0x0BB8 && in.address < 0x0BB8 + bytes.size());
    check(code.empty() || in.address > previous);
    previous = in.address;
    check(in.address - 0x0BB8 + in.bytes.size() <= bytes.size());
    check(std::equal(in.bytes.begin(), in.bytes.end(), bytes.begin() + (in.address - 0x0BB8)));
    check(in.cmd.has_value() == (in.error == rcb4::errc{}));
    code.insert(code.end(), in.bytes.begin(), in.bytes.end());
  }
  const auto p = rcb4::motion::lift(l);
  if (!rcb4::motion::ok(p)) return 0;
  const auto again = rcb4::motion::assemble(std::get<rcb4::motion::program>(p), where);
  check(rcb4::motion::ok(again));
  const auto& out = std::get<std::vector<std::uint8_t>>(again);
  check(out == code);
  const auto back = rcb4::motion::lift(rcb4::motion::disassemble(out, where));
  check(rcb4::motion::ok(back) && std::get<rcb4::motion::program>(back) == std::get<rcb4::motion::program>(p));
  return 0;
}
