// rcb4 — robot services: ICS EEPROM backups on disk and settings typed as text. See
// rcb4/robot/services/ics.hpp.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/services/ics.hpp>
#include <rcb4/robot/services/rom.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace rcb4::robot::services {

using ics::field;

void save_ics_image(const std::string& path, const ics::eeprom_image& image, bool replace) {
  if (!replace && std::filesystem::exists(path))
    throw refused(refusal_kind::usage, fmt::format("{} exists: a backup does not replace a file", path),
                  "another name, or --force to replace it");
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(image.bytes().data()), ics::eeprom_image::size);
  out.close();
  // Its CRC-32 beside it (FILE.crc32, as a ROM backup's): a bit that flips in the file, inside a
  // field's range, is caught when it is restored. The 64 bytes stay as the servo holds them.
  std::ofstream sum(path + ".crc32", std::ios::trunc);
  sum << crc32_line(std::filesystem::path(path).filename().string(), image.bytes(), "ICS EEPROM");
  sum.close();
  if (!out || !sum)
    throw refused(refusal_kind::usage, fmt::format("cannot write {} or its .crc32: {}", path, std::strerror(errno)),
                  "nothing was written to the servo");
}

ics_backup ics_backup_in(const std::string& dir, ics::servo_id id) {
  return [dir, id](const ics::eeprom_image& e) {
    const auto stamp = file_stamp();
    auto path = fmt::format("{}/ics-id{}-{}.bin", dir, id.value(), stamp);
    for (int k = 2; std::filesystem::exists(path); ++k)
      path = fmt::format("{}/ics-id{}-{}-{}.bin", dir, id.value(), stamp, k);
    save_ics_image(path, e);
    return path;
  };
}

ics::eeprom_image load_ics_image(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw refused(refusal_kind::usage,
                  fmt::format("{} is not a file: give a backup from `rcb4 ics eeprom backup`", path));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw refused(refusal_kind::usage, fmt::format("cannot read {}: {}", path, std::strerror(errno)));
  const std::vector<std::uint8_t> raw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (raw.size() != ics::eeprom_image::size)
    throw refused(
        refusal_kind::usage,
        fmt::format("{} holds {} bytes; an ICS EEPROM backup is 64 (`rcb4 ics eeprom backup FILE`)", path, raw.size()));
  // A backup rcb4 wrote has its CRC-32 beside it; one from another tool (64 bytes alone) has none.
  if (std::ifstream sum(path + ".crc32"); sum) {
    std::string word;
    sum >> word;
    const auto want = fmt::format("{:08x}", crc32(raw));
    if (word != want)
      throw refused(refusal_kind::usage,
                    fmt::format("{} has CRC-32 {}, its .crc32 says {}: the file changed or is damaged; nothing written",
                                path, want, word.empty() ? "nothing" : word),
                    fmt::format("if you changed it on purpose, delete {}.crc32 (then it is read as it is)", path));
  }
  auto e = ics::eeprom_image::parse(raw);
  if (!e)
    throw refused(refusal_kind::usage,
                  fmt::format("{} is no ICS EEPROM image: {} (first bytes {})", path, rcb4::message(e.error()),
                              fmt::format("{:02X}", fmt::join(std::span(raw).first(8), " "))));
  return *e;
}

std::pair<ics::field, long> parse_ics_setting(std::string_view text) {
  const auto eq = text.find('=');
  const auto name = text.substr(0, eq);
  const auto* inf = ics::find_field(name);
  if (eq == std::string_view::npos || !inf) {
    std::string names;
    for (const auto& i : ics::fields)
      if (i.writable) names += fmt::format("{}{}", names.empty() ? "" : ", ", i.name);
    throw refused(refusal_kind::usage,
                  eq == std::string_view::npos
                      ? fmt::format("'{}': expected FIELD=VALUE with a field of {}", text, names)
                      : fmt::format("no EEPROM field is called '{}': the fields are {}", name, names));
  }
  if (!inf->writable)
    throw refused(refusal_kind::usage,
                  fmt::format("{} cannot be set{}", inf->name,
                              inf->f == field::id ? ": use `rcb4 ics id set N` (the ID command, one servo alone)"
                                                  : " (the servo reports it)"));
  const auto v = text.substr(eq + 1);
  long value = 0;
  if (inf->nibbles == 0 && (v == "on" || v == "true" || v == "yes"))
    value = 1;
  else if (inf->nibbles == 0 && (v == "off" || v == "false" || v == "no"))
    value = 0;
  else {
    const bool hex = v.size() > 2 && v[0] == '0' && (v[1] == 'x' || v[1] == 'X');  // 0x30, as `position` takes
    const auto digits = hex ? v.substr(2) : v;
    const auto [p, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value, hex ? 16 : 10);
    if (ec != std::errc{} || p != digits.data() + digits.size() || v.empty())
      throw refused(refusal_kind::usage, inf->nibbles == 0 ? fmt::format("{}: '{}': give on or off", inf->name, v)
                                                           : fmt::format("{}: '{}' is not a number", inf->name, v));
  }
  ics::eeprom_image probe;
  if (!probe.set(inf->f, value))
    throw refused(refusal_kind::usage, inf->f == field::baud ? fmt::format("baud={}: 115200, 625000 or 1250000", value)
                                                             : fmt::format("{}={}: out of range {}..{}", inf->name,
                                                                           value, inf->min, inf->max));
  return {inf->f, value};
}

}  // namespace rcb4::robot::services
