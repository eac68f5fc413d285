// rcb4 — robot services: the whole ROM (see rcb4/robot/services/rom.hpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/ops/layout.hpp>
#include <rcb4/ops/memory.hpp>
#include <rcb4/ops/motion.hpp>
#include <rcb4/ops/system.hpp>
#include <rcb4/robot/services/buttons.hpp>
#include <rcb4/robot/services/rom.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>

namespace rcb4::robot::services {

using rcb4::ops::memory;

std::vector<std::uint8_t> backup_rom(link& l, std::string_view label) {
  rcb4::ops::read_memory op(memory::rom, 0, rom_size);
  std::size_t done = 0;
  try {
    while (auto c = op.next()) {
      op.on_reply(l.exchange(*c));
      l.progress(label, done = std::min<std::size_t>(rom_size, done + rcb4::ops::max_read), rom_size);
    }
    if (op.error() != errc{}) l.failed(op.error());
  } catch (const std::system_error& e) {
    throw refused(refusal_kind::line,
                  fmt::format("reading ROM stopped at 0x{:06X} of 0x{:06X}: {}", done, rom_size, e.what()),
                  "nothing was written; try again (a slower --baud on a poor cable)", {}, e.code());
  }
  return op.value();
}

std::uint32_t crc32(std::span<const std::uint8_t> bytes) noexcept {
  std::uint32_t c = 0xFFFFFFFFu;
  for (const auto b : bytes) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return ~c;
}

std::string crc32_line(const std::string& name, std::span<const std::uint8_t> image, const std::string& version) {
  return fmt::format("{:08x}  {}  {} bytes  {}  {}\n", crc32(image), name, image.size(), file_stamp(), version);
}

void save_rom_image(const std::string& path, std::span<const std::uint8_t> image, const std::string& version) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(image.data()), static_cast<std::streamsize>(image.size()));
  out.flush();
  std::ofstream sum(path + ".crc32", std::ios::trunc);
  sum << crc32_line(std::filesystem::path(path).filename().string(), image, version);
  sum.flush();
  if (!out || !sum)
    throw refused(refusal_kind::usage, fmt::format("cannot write {} or its .crc32: {}", path, std::strerror(errno)),
                  "name another place");
}

std::string crc_in_name(const std::string& path) {
  const auto name = std::filesystem::path(path).stem().string();
  const auto at = name.rfind("-crc32-");
  if (at == std::string::npos || name.size() != at + 7 + 8) return {};
  const auto hex = name.substr(at + 7);
  for (const char c : hex)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return {};
  return hex;
}

std::vector<std::uint8_t> load_rom_image(const std::string& path, bool no_check) {
  std::error_code ec;
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw refused(refusal_kind::usage, fmt::format("{} is not a regular file", path));
  if (const auto size = std::filesystem::file_size(path, ec); !ec && size != rom_size)
    throw refused(refusal_kind::usage, fmt::format("{} holds {} bytes; a ROM image is {} (rcb4 rom backup "
                                                   "makes one)",
                                                   path, size, rom_size));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw refused(refusal_kind::usage, fmt::format("{} cannot be read ({})", path, std::strerror(errno)));
  std::vector<std::uint8_t> image(rom_size + 1);
  in.read(reinterpret_cast<char*>(image.data()), static_cast<std::streamsize>(image.size()));
  image.resize(static_cast<std::size_t>(in.gcount()));
  if (image.size() != rom_size)
    throw refused(refusal_kind::usage, fmt::format("{} holds {} bytes; a ROM image is {} (rcb4 rom backup "
                                                   "makes one)",
                                                   path, image.size(), rom_size));
  std::ifstream sum(path + ".crc32");
  std::string word;
  // Without a .crc32 beside it, a CRC in the file's own name ("…-crc32-1a2b3c4d.bin", as rcb4 ui
  // downloads a backup: one file, which no browser splits) is the check.
  if (!(sum >> word)) word = crc_in_name(path);
  if (word.empty()) {
    if (no_check) return image;
    throw refused(refusal_kind::usage, fmt::format("{}.crc32 is missing or empty: the image cannot be checked", path),
                  "rcb4 rom backup writes it beside the image; --no-check restores one without it (its plausibility "
                  "is still checked)");
  }
  const auto want = fmt::format("{:08x}", crc32(image));
  if (word != want)
    throw refused(refusal_kind::usage,
                  fmt::format("{} has CRC-32 {}, its .crc32 (or its name) says {}: the file changed or is damaged",
                              path, want, word),
                  crc_in_name(path) == word && !std::filesystem::exists(path + ".crc32")
                      ? fmt::format("--no-check does not write a file that fails its check; if you changed {} on "
                                    "purpose, rename it without its -crc32-{} and restore with --no-check",
                                    path, word)
                      : fmt::format("--no-check does not write a file that fails its check; if you changed {} on "
                                    "purpose, delete {}.crc32 and restore with --no-check",
                                    path, path));
  return image;
}

std::string implausible_rom(std::span<const std::uint8_t> image) {
  if (image.size() != rom_size) return fmt::format("it holds {} bytes, not {}", image.size(), rom_size);
  const auto at = [&](std::uint32_t a) { return image.subspan(a, std::min<std::size_t>(128, image.size() - a)); };
  if (!ops::detail::holds_frame(at(0))) return "no boot code at 0x000000 (an RCB-4 program starts there with a frame)";
  if (!ops::detail::holds_frame(at(0x044B)) && !ops::detail::holds_frame(at(0x03FD)))
    return "no main loop at 0x00044B (HTH4 2.x) or 0x0003FD (HTH4 1.3)";
  const auto guess = ops::judge_layout(at(0x0B80), at(0x0BB8), at(0x044B), at(0x03FD));
  if (!guess.layout) return "its HTH4 layout cannot be told: " + guess.reason;
  return {};
}

restore_report restore_rom(link& l, std::span<const std::uint8_t> image, const rom_sink& save, bool force,
                           std::span<const std::uint8_t> known) {
  if (image.size() != rom_size)
    throw refused(refusal_kind::usage,
                  fmt::format("the image holds {} bytes; a ROM image is {}", image.size(), rom_size));
  if (const auto why = implausible_rom(image); !why.empty() && !force)
    throw refused(refusal_kind::usage,
                  fmt::format("the image is not a plausible RCB-4 ROM: {}; written, it would leave a board that "
                              "does nothing at power-on (nothing was written)",
                              why),
                  "--force writes it all the same (only for an image you know)");
  // A motion part way would be cut off, and its code may change under it.
  const auto st = run(l, rcb4::ops::read_motion_state{});
  if (st.running)
    throw refused(refusal_kind::board,
                  st.motion ? fmt::format("motion {} is running: the restore would rewrite what it runs", *st.motion)
                            : fmt::format("the board's program is running a call (program counter 0x{:06X}): the "
                                          "restore would rewrite what it runs",
                                          st.program_counter),
                  "rcb4 motion wait, or rcb4 motion stop, then restore");
  if (st.suspended)
    throw refused(refusal_kind::board,
                  fmt::format("{} is stopped part way: motion resume would continue in rewritten code",
                              st.motion ? fmt::format("motion {}", *st.motion) : std::string("the board's program")),
                  "rcb4 motion play N (any motion) starts the program afresh; then restore");
  restore_report r;
  const auto now = known.size() == rom_size ? std::vector<std::uint8_t>(known.begin(), known.end())
                                            : backup_rom(l, "reading ROM (the backup of what is replaced)");
  std::vector<std::size_t> differ;
  for (std::size_t at = 0; at < image.size(); at += rom_piece)
    if (!std::equal(image.begin() + static_cast<std::ptrdiff_t>(at),
                    image.begin() + static_cast<std::ptrdiff_t>(at + rom_piece),
                    now.begin() + static_cast<std::ptrdiff_t>(at)))
      differ.push_back(at);
  if (differ.empty()) {
    r.unchanged = true;
    r.buttons_loaded = load_buttons_from_rom(l);
    return r;
  }
  // The ROM program fetches from ROM: stop it before its bytes change under it.
  if (run(l, rcb4::ops::read_config{}).rom_program) {
    run(l, rcb4::ops::stop_motion{});
    r.program_stopped = true;
  }
  r.before = save(now);
  const std::string undo =
      fmt::format("the ROM is part old, part new: rcb4 rom restore {} puts the old one back", r.before);
  for (std::size_t i = 0; i < differ.size(); ++i) {
    const auto at = differ[i];
    const auto b = image.subspan(at, rom_piece);
    std::vector<std::uint8_t> back;
    try {
      run(l, rcb4::ops::write_memory(memory::rom, static_cast<std::uint32_t>(at), b));
      back = run(l, rcb4::ops::read_memory(memory::rom, static_cast<std::uint32_t>(at), rom_piece));
    } catch (const std::system_error& e) {
      throw refused(
          refusal_kind::line,
          fmt::format("writing ROM 0x{:06X} failed ({} of {} pieces written): {}", at, i, differ.size(), e.what()),
          undo, r.before, e.code());
    }
    for (std::size_t k = 0; k < rom_piece; ++k)
      if (back[k] != b[k])
        throw refused(refusal_kind::board,
                      fmt::format("ROM 0x{:06X} reads back 0x{:02X}, 0x{:02X} was written", at + k, back[k], b[k]),
                      undo, r.before);
    r.pieces = i + 1;
    l.progress("writing ROM", i + 1, differ.size());
  }
  r.buttons_loaded = load_buttons_from_rom(l);
  return r;
}

}  // namespace rcb4::robot::services
