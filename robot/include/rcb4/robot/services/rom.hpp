// rcb4 — robot services: the whole ROM (protocol.md §8: boot code, main loop, motions, the vector
// table, the config image) read into an image and written back where it differs, each piece read
// back, with the ROM it replaces saved first.
// SPDX-License-Identifier: BSL-1.0
//
//   const auto image = backup_rom(link);                      // 262,144 bytes
//   restore_rom(link, image, save_here, /*force=*/false);     // refused when it is no RCB-4 program
#pragma once

#include <rcb4/robot/services/link.hpp>

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

namespace rcb4::robot::services {

/** The ROM is rewritten in pieces of one read (128 bytes), only those that differ. */
inline constexpr std::size_t rom_piece = 128;

/** The whole ROM (progress under "reading ROM"); a failure part way is refused naming where it stopped. */
std::vector<std::uint8_t> backup_rom(link& l, std::string_view label = "reading ROM");

/**
 * Why @p image is not a plausible RCB-4 ROM as HTH4 writes one, or empty when it is: a frame at
 * 0x000000 (the boot code), a main loop where HTH4's layouts put it (0x00044B for 2.x, 0x0003FD
 * for 1.3) and a layout told from motion 1 (rcb4/ops/layout.hpp). An erased or foreign image
 * written over the board's program leaves a board that does nothing at power-on.
 */
std::string implausible_rom(std::span<const std::uint8_t> image);

/** The CRC-32 (IEEE 802.3, as zlib and `crc32` compute it) of @p bytes: an image file's check. */
std::uint32_t crc32(std::span<const std::uint8_t> bytes) noexcept;

/** The check line of image file @p name: "crc32  name  N bytes  date  version" (its .crc32 file's text). */
std::string crc32_line(const std::string& name, std::span<const std::uint8_t> image, const std::string& version);
/**
 * Writes @p image to @p path and its check line to PATH.crc32 ("crc32  name  N bytes  date
 * version"); a refusal (usage) when either cannot be written.
 */
void save_rom_image(const std::string& path, std::span<const std::uint8_t> image, const std::string& version);

/**
 * The image in @p path, checked against PATH.crc32 (without one, only with @p no_check); refused
 * (usage) naming what is wrong: unreadable, not rom_size bytes, a CRC that differs.
 */
std::vector<std::uint8_t> load_rom_image(const std::string& path, bool no_check);
/** The CRC-32 a ROM image's file name carries ("rcb4-rom-STAMP-crc32-1a2b3c4d.bin": rcb4 ui's one-file backup), or "".
 */
std::string crc_in_name(const std::string& path);

/** Saves the ROM a restore replaces and returns where it went (the front end's file I/O). */
using rom_sink = std::function<std::string(std::span<const std::uint8_t> now)>;

/** What a restore did. */
struct restore_report {
  std::size_t pieces = 0;        ///< pieces of 128 bytes that differed and were written
  bool unchanged = false;        ///< the ROM already was the image
  bool program_stopped = false;  ///< the ROM program was running and was stopped for the write
  bool buttons_loaded = false;   ///< RAM's button table loaded from the restored ROM (as power-on does)
  std::string before;            ///< where the replaced ROM was saved
};

/**
 * Writes @p image where it differs from the board's ROM: refused (nothing written) when it is not
 * rom_size bytes, is implausible (unless @p force), or a motion runs or is stopped part way; the
 * ROM it replaces goes to @p save first; each piece is read back; the button table the board
 * compares (RAM) is then loaded from the new ROM, so what `buttons` lists is what a press does.
 * @p now: the board's ROM as the caller has just read it (rom_size bytes), not read again; empty:
 * read here.
 */
restore_report restore_rom(link& l, std::span<const std::uint8_t> image, const rom_sink& save, bool force,
                           std::span<const std::uint8_t> now = {});

}  // namespace rcb4::robot::services
