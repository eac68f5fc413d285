// rcb4 command-line tool: read and write RAM, ROM and an ICS slot's fields, any length.
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

namespace cli {
namespace {

/** What `read`/`write` address: a memory, and for ICS the slot. */
struct memory_options {
  std::string kind;  ///< ram, rom, ics
  std::string address;
  long long ics = -1;
};

struct memory_target {
  rcb4::ops::memory kind;
  std::string_view name;  ///< RAM, ROM, ICS
  std::uint32_t size;     ///< bytes in that memory
  rcb4::ics_number ics{};
};

memory_target target(const memory_options& o) {
  memory_target t{rcb4::ops::memory::ram, "RAM", rcb4::ram_size};
  if (o.kind == "rom") t = {rcb4::ops::memory::rom, "ROM", rcb4::rom_size};
  if (o.kind == "ics") {
    if (o.ics < 0) throw usage_error("ics memory needs --ics N (the slot, 0..35)");
    t = {rcb4::ops::memory::ics, "ICS slot memory", 256, checked<rcb4::ics_number>(o.ics, "--ics")};
  } else if (o.ics >= 0) {
    throw usage_error(fmt::format("--ics is for ics memory, not {}", o.kind));
  }
  return t;
}

/** The address, checked against the memory it is in (protocol.md §6, §8). */
std::uint32_t address(const memory_target& t, std::string_view text) {
  const auto a = parse_int(text, "ADDR", -0x7FFFFFFFLL, 0x7FFFFFFFLL);
  if (a < 0 || a >= t.size)
    throw usage_error(fmt::format("ADDR: {} is outside {} (0x0000..0x{:04X})", text, t.name, t.size - 1));
  return static_cast<std::uint32_t>(a);
}

/** A usage error when @p n bytes at @p addr leave the memory: the operation's own range check. */
void check_range(const memory_target& t, std::uint32_t addr, std::size_t n) {
  if (const auto e = rcb4::ops::read_memory(t.kind, addr, n, t.ics).error(); e != rcb4::errc{})
    throw usage_error(fmt::format("{} at 0x{:X} run outside {} (it ends at 0x{:X}): {}", plural(n, "byte"), addr,
                                  t.name, t.size, rcb4::message(e)));
}

void hexdump(std::uint32_t base, std::span<const std::uint8_t> b) {
  for (std::size_t i = 0; i < b.size(); i += 16) {
    std::string ascii;
    for (std::size_t k = i; k < std::min(b.size(), i + 16); ++k)
      ascii += (b[k] >= 0x20 && b[k] < 0x7F) ? static_cast<char>(b[k]) : '.';
    fmt::print("0x{:06X}  {:<47}  {}\n", base + i, rcb4::hex(b.subspan(i, std::min<std::size_t>(16, b.size() - i))),
               ascii);
  }
}

/** A transfer that failed part-way: how far it got, so the user knows what the memory now holds. */
[[noreturn]] void partial(const rcb4::transport::error_code& ec, bool writing, std::size_t done, std::size_t total,
                          std::uint32_t addr, std::string_view name) {
  auto f = explain(std::error_code(ec), ec.message());
  std::string hint = f.hint;
  if (writing && done > 0)
    hint = fmt::format(
        "{} 0x{:06X}..0x{:06X} holds the new bytes; from 0x{:06X} on, the old ones (the piece in "
        "flight may have landed).\n  {}",
        name, addr, addr + done - 1, addr + done, f.hint);
  json facts;
  facts["address"] = addr;
  facts[writing ? "written" : "read"] = done;
  facts["total"] = total;
  throw failure(
      f.exit, fmt::format("{} stopped after {} of {} bytes: {}", writing ? "write" : "read", done, total, ec.message()),
      hint, facts);
}

int read(session& s, const memory_options& o, std::size_t len, const std::string& output, const globals& g) {
  const auto t = target(o);
  const auto addr = address(t, o.address);
  check_range(t, addr, len);
  std::ofstream out;  // opened before the transfer: a bad path fails now, not after the whole read
  if (!output.empty() && output != "-") {
    out.open(output, std::ios::binary | std::ios::trunc);
    if (!out) throw failure(exit_io, fmt::format("--output {}: cannot create it: {}", output, std::strerror(errno)));
  }
  rcb4::ops::read_memory op(t.kind, addr, len, t.ics);
  progress bar(fmt::format("reading {}", t.name), len, g.json);
  rcb4::transport::error_code ec;
  s.run_steps(op, ec, [&] { bar.update(op.value().size()); });
  if (ec) partial(ec, false, op.value().size(), len, addr, t.name);
  bar.finish();
  const auto& bytes = op.value();
  if (output == "-") {  // binary to stdout, for a pipe
    std::fwrite(bytes.data(), 1, bytes.size(), stdout);
    return exit_ok;
  }
  if (!output.empty()) {
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) throw failure(exit_io, fmt::format("--output {}: writing it failed: {}", output, std::strerror(errno)));
    if (g.json) {
      json j;
      j["memory"] = o.kind;
      j["address"] = addr;
      j["read"] = bytes.size();
      j["output"] = output;
      emit(j);
    } else {
      fmt::print("read {} at 0x{:06X} into {}\n", plural(bytes.size(), "byte"), addr, output);
    }
  } else if (g.json) {
    json j;
    j["memory"] = o.kind;
    j["address"] = addr;
    j["bytes"] = std::vector<int>(bytes.begin(), bytes.end());
    emit(j);
  } else {
    hexdump(addr, bytes);
  }
  return exit_ok;
}

int write(session& s, const memory_options& o, const std::vector<std::uint8_t>& bytes, const globals& g) {
  const auto t = target(o);
  const auto addr = address(t, o.address);
  check_range(t, addr, bytes.size());
  rcb4::ops::write_memory op(t.kind, addr, bytes, t.ics);
  progress bar(fmt::format("writing {}", t.name), bytes.size(), g.json);
  rcb4::transport::error_code ec;
  std::size_t frames = 0;
  s.run_steps(op, ec, [&] {
    ++frames;
    bar.update(op.value());
  });
  if (ec) partial(ec, true, op.value(), bytes.size(), addr, t.name);
  bar.finish();
  if (g.json) {
    json j;
    j["memory"] = o.kind;
    j["address"] = addr;
    j["written"] = op.value();
    j["frames"] = frames;
    emit(j);
  } else {
    fmt::print("wrote {} at 0x{:06X} in {}\n", plural(op.value(), "byte"), addr, plural(frames, "frame"));
  }
  return exit_ok;
}

void memory_options_of(CLI::App* cmd, memory_options& o) {
  cmd->add_option("MEMORY", o.kind, "ram, rom, or ics (an ICS slot's fields, with --ics)")
      ->required()
      ->check(CLI::IsMember({"ram", "rom", "ics"}));
  cmd->add_option("ADDR", o.address, "address: decimal or 0x hex")->required();
  cmd->add_option("--ics", o.ics, "the ICS slot (0..35) for ics memory")->check(int_range(0, 35));
}

}  // namespace

void add_memory_commands(CLI::App& app, context& ctx) {
  auto* read_cmd = app.add_subcommand("read", "read memory (any length, in 128-byte pieces), hex dump");
  auto ro = std::make_shared<memory_options>();
  auto len = std::make_shared<std::string>();
  auto output = std::make_shared<std::string>();
  memory_options_of(read_cmd, *ro);
  read_cmd->add_option("LEN", *len, "bytes to read: decimal or 0x hex")->required();
  read_cmd->add_option("--output", *output, "write the bytes to FILE (binary; - for stdout) instead of a hex dump")
      ->type_name("FILE")
      ->check(CLI::Validator(
          [](std::string& v) { return v.empty() ? std::string("an empty file name") : std::string(); }, ""));
  read_cmd->footer(
      "examples:\n  rcb4 read ram 0x0000 2                      the config word\n"
      "  rcb4 read rom 0 0x40000 --output rom.bin    the whole ROM (progress on a terminal)");
  read_cmd->callback([&ctx, ro, len, output] {
    const auto n = static_cast<std::size_t>(parse_int(*len, "LEN", 1, rcb4::rom_size));
    const auto t = target(*ro);  // usage errors before the device opens
    check_range(t, address(t, ro->address), n);
    ctx.action = [&ctx, ro, n, output] {
      session s(ctx.g);
      return read(s, *ro, n, *output, ctx.g);
    };
  });

  auto* write_cmd = app.add_subcommand("write", "write hex bytes (any length, in pieces the board takes)");
  auto wo = std::make_shared<memory_options>();
  auto words = std::make_shared<std::vector<std::string>>();
  auto file = std::make_shared<std::string>();
  memory_options_of(write_cmd, *wo);
  auto* hex = write_cmd->add_option("BYTES", *words, "hex bytes: \"12 34\", 1234, 0x12,0x34");
  write_cmd->add_option("--file", *file, "the bytes from FILE (binary), e.g. a ROM image")
      ->type_name("FILE")
      ->check(CLI::ExistingFile)
      ->excludes(hex);
  write_cmd->footer("examples:\n  rcb4 write ram 0x0400 12 34 56\n  rcb4 write rom 0 --file rom.bin");
  write_cmd->callback([&ctx, wo, words, file] {
    auto bytes = std::make_shared<std::vector<std::uint8_t>>();
    if (!file->empty()) {
      std::ifstream f(*file, std::ios::binary);
      bytes->assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
      if (!f.eof() && f.fail()) throw failure(exit_io, fmt::format("--file {}: cannot read it", *file));
      if (bytes->empty()) throw usage_error(fmt::format("--file {}: the file is empty", *file));
    } else {
      *bytes = parse_hex(join(*words), "BYTES");
    }
    if (bytes->empty()) throw usage_error("write: give the bytes to write, e.g. \"12 34\", or --file FILE");
    const auto t = target(*wo);
    check_range(t, address(t, wo->address), bytes->size());
    ctx.action = [&ctx, wo, bytes] {
      session s(ctx.g);
      return write(s, *wo, *bytes, ctx.g);
    };
  });
}

}  // namespace cli
