// rcb4 command-line tool: rom backup FILE, rom restore FILE: the board's whole 256 KiB ROM (protocol.md
// §8: the program, the motions, the vector table, the config image) to a file and back, with a CRC-32
// beside it (FILE.crc32), written only where it differs, and read back.
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/robot/services/rom.hpp>

#include <ctime>
#include <filesystem>
#include <fstream>

namespace cli {
namespace {

namespace sv = rcb4::robot::services;

using sv::crc32;

/** Writes @p image to @p path and its check line to @p path.crc32. */
void save(const std::string& path, std::span<const std::uint8_t> image, const std::string& version) {
  sv::save_rom_image(path, image, version);
}

int backup(session& s, const std::string& path, bool force, const globals& g) {
  if (std::filesystem::exists(path) && !force)
    throw usage_error(fmt::format("FILE: {} exists (--force replaces it)", path));
  const auto version = s.run(rcb4::ops::read_version{});
  session_link link(s, g.json);
  const auto image = sv::backup_rom(link);
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
std::vector<std::uint8_t> load(const std::string& path, bool no_check) { return sv::load_rom_image(path, no_check); }

int restore(session& s, const std::string& path, bool no_check, bool force, const globals& g) {
  const auto image = load(path, no_check);
  const auto version = s.run(rcb4::ops::read_version{});
  session_link link(s, g.json);
  // Beside the image being restored: where the user keeps ROM images.
  const auto save_before = [&](std::span<const std::uint8_t> now) {
    const std::string before =
        (std::filesystem::path(path).parent_path() / fmt::format("rom-before-restore-{}.bin", file_stamp())).string();
    save(before, now, version);
    return before;
  };
  const auto r = sv::restore_rom(link, image, save_before, force);
  if (r.unchanged) {
    if (g.json)
      emit(json{{"restored", path}, {"pieces_written", 0}, {"unchanged", true}, {"buttons_loaded", r.buttons_loaded}});
    else
      fmt::print("the board's ROM already is {}: nothing written\n", path);
    return exit_ok;
  }
  if (g.json)
    emit(json{{"restored", path},
              {"pieces_written", r.pieces},
              {"bytes_written", r.pieces * sv::rom_piece},
              {"unchanged", false},
              {"before", r.before},
              {"buttons_loaded", r.buttons_loaded}});
  else
    fmt::print(
        "wrote {} of {} bytes that differed ({} of {}), each read back; the ROM it replaced is in {}\n"
        "{}{}the board runs the restored program after it is powered off and on\n",
        plural(r.pieces, "piece"), sv::rom_piece, r.pieces * sv::rom_piece, rcb4::rom_size, r.before,
        r.program_stopped ? "the ROM program was stopped for the write; " : "",
        r.buttons_loaded ? "the button table the board compares (RAM) now is the restored one; "
                         : "the restored button table does not read: RAM's is left as it was; ");
  return exit_ok;
}

}  // namespace

void add_rom_commands(CLI::App& app, context& ctx) {
  auto* rom = app.add_subcommand("rom", "the whole 256 KiB ROM (program, motions, button table) to a file and back");
  rom->require_subcommand(1);
  struct rom_options {
    std::string file;
    bool force = false, no_check = false, force_image = false;
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
  r->add_option(
       "FILE", ro->file,
       "an image from rcb4 rom backup, checked against FILE.crc32 (or the CRC-32 in its name: rcb4 ui's backup)")
      ->required();
  r->add_flag("--no-check", ro->no_check,
              "write an image that has no CRC-32 beside it or in its name (its size is still checked)");
  r->add_flag("--force", ro->force_image,
              "write an image that does not look like an RCB-4 program (no boot code, no main loop, no HTH4 layout)");
  on_device(r, ctx, [&ctx, ro](session& s) { return restore(s, ro->file, ro->no_check, ro->force_image, ctx.g); });
}

}  // namespace cli
