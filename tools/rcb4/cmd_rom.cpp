// rcb4 command-line tool: rom backup FILE, rom restore FILE: the board's whole 256 KiB ROM (protocol.md
// §8: the program, the motions, the vector table, the config image) to a file and back, with a CRC-32
// beside it (FILE.crc32), written only where it differs, and read back.
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <boost/crc.hpp>

#include <ctime>
#include <filesystem>
#include <fstream>

namespace cli {
namespace {

using rcb4::ops::memory;
constexpr std::size_t piece = 128;  // compared and rewritten in pieces of one read

std::uint32_t crc32(std::span<const std::uint8_t> b) {
  boost::crc_32_type c;
  c.process_bytes(b.data(), b.size());
  return c.checksum();
}

/** The whole ROM, with a progress line on a terminal. */
std::vector<std::uint8_t> read_all(session& s, const std::string& what, const globals& g) {
  rcb4::ops::read_memory op(memory::rom, 0, rcb4::rom_size);
  progress bar(what, rcb4::rom_size, g.json);
  rcb4::transport::error_code ec;
  std::size_t done = 0;
  s.run_steps(op, ec, [&] { bar.update(done = std::min<std::size_t>(rcb4::rom_size, done + rcb4::ops::max_read)); });
  bar.finish();
  if (ec)
    throw failure(explain(ec, "").exit,
                  fmt::format("reading ROM stopped at 0x{:06X} of 0x{:06X}: {}", done, rcb4::rom_size,
                              plain_message(rcb4::transport::system_error(ec).what())),
                  "nothing was written; try again (a slower --baud on a poor cable)");
  return op.value();
}

/** Writes @p image to @p path and its checksum line to @p path.crc32. */
void save(const std::string& path, std::span<const std::uint8_t> image, const std::string& version) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(image.data()), static_cast<std::streamsize>(image.size()));
  out.flush();
  std::ofstream sum(path + ".crc32", std::ios::trunc);
  sum << fmt::format("{:08x}  {}  {} bytes  {}  {}\n", crc32(image), std::filesystem::path(path).filename().string(),
                     image.size(), file_stamp(), version);
  sum.flush();
  if (!out || !sum)
    throw failure(exit_usage, fmt::format("cannot write {} or its .crc32: {}", path, std::strerror(errno)),
                  "name another place");
}

int backup(session& s, const std::string& path, bool force, const globals& g) {
  if (std::filesystem::exists(path) && !force)
    throw usage_error(fmt::format("FILE: {} exists (--force replaces it)", path));
  const auto version = s.run(rcb4::ops::read_version{});
  const auto image = read_all(s, "reading ROM", g);
  save(path, image, version);
  const auto erased = static_cast<std::size_t>(std::count(image.begin(), image.end(), std::uint8_t{0xFF}));
  if (g.json)
    emit(json{{"file", path},
              {"bytes", image.size()},
              {"crc32", fmt::format("{:08x}", crc32(image))},
              {"erased_bytes", erased},
              {"version", version}});
  else
    fmt::print("ROM (0x000000..0x03FFFF, {} bytes, {} of them 0xFF) -> {}\n  CRC-32 {:08x} in {}.crc32\n", image.size(),
               erased, path, crc32(image), path, path);
  return exit_ok;
}

/** The image in @p path, checked against its .crc32. */
std::vector<std::uint8_t> load(const std::string& path, bool no_check) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw usage_error(fmt::format("FILE: {} cannot be read ({})", path, std::strerror(errno)));
  std::vector<std::uint8_t> image{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (image.size() != rcb4::rom_size)
    throw usage_error(fmt::format("FILE: {} holds {}; a ROM image is {} (rcb4 rom backup makes one)", path,
                                  plural(image.size(), "byte"), rcb4::rom_size));
  std::ifstream sum(path + ".crc32");
  std::string word;
  if (!(sum >> word)) {
    if (no_check) return image;
    throw usage_error(fmt::format("FILE: {}.crc32 is missing or empty: the image cannot be checked", path));
  }
  const auto want = fmt::format("{:08x}", crc32(image));
  if (word != want)
    throw failure(
        exit_usage,
        fmt::format("FILE: {} has CRC-32 {}, its .crc32 says {}: the file changed or is damaged", path, want, word),
        fmt::format("--no-check does not write a file that fails its check; if you changed {} on purpose, "
                    "delete {}.crc32 and restore with --no-check",
                    path, path));
  return image;
}

int restore(session& s, const std::string& path, bool no_check, const globals& g) {
  const auto image = load(path, no_check);
  // A motion part way would be cut off, and its code may change under it.
  if (const auto st = s.run(rcb4::ops::read_motion_state{}); st.running && st.motion)
    throw failure(exit_board, fmt::format("motion {} is running: the restore would rewrite what it runs", *st.motion),
                  "rcb4 motion wait, or rcb4 motion stop, then restore");
  else if (st.suspended && st.motion)
    throw failure(
        exit_board,
        fmt::format("motion {} is stopped part way: motion resume would continue in rewritten code", *st.motion),
        "rcb4 motion play N (any motion) starts the program afresh; then restore");
  const auto version = s.run(rcb4::ops::read_version{});
  const auto now = read_all(s, "reading ROM (the backup of what is replaced)", g);
  std::vector<std::size_t> differ;
  for (std::size_t at = 0; at < image.size(); at += piece)
    if (!std::equal(image.begin() + static_cast<std::ptrdiff_t>(at),
                    image.begin() + static_cast<std::ptrdiff_t>(at + piece),
                    now.begin() + static_cast<std::ptrdiff_t>(at)))
      differ.push_back(at);
  if (differ.empty()) {
    if (g.json)
      emit(json{{"restored", path}, {"pieces_written", 0}, {"unchanged", true}});
    else
      fmt::print("the board's ROM already is {}: nothing written\n", path);
    return exit_ok;
  }
  // The ROM program fetches from ROM: stop it before its bytes change under it.
  const auto cfg = s.run(rcb4::ops::read_config{});
  if (cfg.rom_program) s.run(rcb4::ops::stop_motion{});
  // Beside the image being restored: where the user keeps ROM images.
  const std::string before =
      (std::filesystem::path(path).parent_path() / fmt::format("rom-before-restore-{}.bin", file_stamp())).string();
  save(before, now, version);
  progress bar("writing ROM", differ.size(), g.json);
  for (std::size_t i = 0; i < differ.size(); ++i) {
    const auto at = differ[i];
    const std::span<const std::uint8_t> b(image.data() + at, piece);
    try {
      s.run(rcb4::ops::write_memory(memory::rom, static_cast<std::uint32_t>(at), b));
      const auto back = s.run(rcb4::ops::read_memory(memory::rom, static_cast<std::uint32_t>(at), piece));
      for (std::size_t k = 0; k < piece; ++k)
        if (back[k] != b[k])
          throw failure(
              exit_board, fmt::format("ROM 0x{:06X} reads back 0x{:02X}, 0x{:02X} was written", at + k, back[k], b[k]),
              fmt::format("the ROM is part old, part new: rcb4 rom restore {} puts the old one back", before));
    } catch (const rcb4::transport::system_error& e) {
      throw failure(explain(e.code(), "").exit,
                    fmt::format("writing ROM 0x{:06X} failed ({} of {} pieces written): {}", at, i, differ.size(),
                                plain_message(e.what())),
                    fmt::format("the ROM is part old, part new: rcb4 rom restore {} (or {} again)", before, path));
    }
    bar.update(i + 1);
  }
  bar.finish();
  if (g.json)
    emit(json{{"restored", path},
              {"pieces_written", differ.size()},
              {"bytes_written", differ.size() * piece},
              {"unchanged", false},
              {"before", before}});
  else
    fmt::print(
        "wrote {} of {} bytes that differed ({} of {}), each read back; the ROM it replaced is in {}\n"
        "{}the board runs the restored program after it is powered off and on\n",
        plural(differ.size(), "piece"), piece, differ.size() * piece, rcb4::rom_size, before,
        cfg.rom_program ? "the ROM program was stopped for the write; " : "");
  return exit_ok;
}

}  // namespace

void add_rom_commands(CLI::App& app, context& ctx) {
  auto* rom = app.add_subcommand("rom", "the whole 256 KiB ROM (program, motions, button table) to a file and back");
  rom->require_subcommand(1);
  struct rom_options {
    std::string file;
    bool force = false, no_check = false;
  };
  auto bo = std::make_shared<rom_options>();
  auto* b = rom->add_subcommand("backup", "read the ROM into FILE (262,144 bytes) and its CRC-32 into FILE.crc32");
  b->add_option("FILE", bo->file, "the image to write")->required();
  b->add_flag("--force", bo->force, "replace FILE when it exists");
  on_device(b, ctx, [&ctx, bo](session& s) { return backup(s, bo->file, bo->force, ctx.g); });

  auto ro = std::make_shared<rom_options>();
  auto* r = rom->add_subcommand(
      "restore",
      "write FILE (from rom backup) into ROM where it differs, each piece read back; the ROM it replaces "
      "is saved first, beside FILE (rom-before-restore-DATE.bin)");
  r->add_option("FILE", ro->file, "an image from rcb4 rom backup, checked against FILE.crc32")->required();
  r->add_flag("--no-check", ro->no_check, "write an image that has no .crc32 beside it (its size is still checked)");
  on_device(r, ctx, [&ctx, ro](session& s) { return restore(s, ro->file, ro->no_check, ctx.g); });
}

}  // namespace cli
