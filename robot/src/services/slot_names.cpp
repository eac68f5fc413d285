// rcb4 — robot services: the names of a board's motion slots (see rcb4/robot/services/slot_names.hpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/frame.hpp>
#include <rcb4/robot/services/link.hpp>
#include <rcb4/robot/services/rom.hpp>
#include <rcb4/robot/services/slot_names.hpp>

#include <fmt/format.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace rcb4::robot::services {
namespace {

namespace fs = std::filesystem;

/** The whole file as YAML (a map of robots), or an empty map when there is none. */
YAML::Node read_file(const std::string& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) return YAML::Node(YAML::NodeType::Map);
  if (fs::file_size(file, ec) > 1024 * 1024)
    throw refused(refusal_kind::usage, fmt::format("{}: over 1 MiB: not a slot names file", file));
  try {
    auto root = YAML::LoadFile(file);
    if (root.IsNull()) return YAML::Node(YAML::NodeType::Map);
    if (!root.IsMap()) throw refused(refusal_kind::usage, fmt::format("{}: not a map of robots to slot names", file));
    return root;
  } catch (const YAML::Exception& e) {
    throw refused(refusal_kind::usage, fmt::format("{}:{}: {}", file, e.mark.line + 1, e.msg));
  }
}

}  // namespace

std::string slot_names_file() {
  if (const char* f = std::getenv("RCB4_SLOT_NAMES"); f && *f) return f;
  if (const char* x = std::getenv("XDG_CONFIG_HOME"); x && *x)
    return (fs::path(x) / "rcb4" / "slot-names.yaml").string();
  const char* home = std::getenv("HOME");
  return (fs::path(home && *home ? home : ".") / ".config" / "rcb4" / "slot-names.yaml").string();
}

std::uint32_t code_fingerprint(std::span<const std::uint8_t> slot) {
  // The frames as rcb4::ops::list_motions walks them: a size of 3-128 that fits, a sum that is
  // right; the walk ends after a RETURN (03 0D 10, protocol.md §4.4) or before a frame that is none.
  std::size_t at = 0;
  while (at < slot.size()) {
    const std::size_t size = slot[at];
    if (size < 3 || size > rcb4::max_request_size || at + size > slot.size()) break;
    unsigned sum = 0;
    for (std::size_t i = at; i + 1 < at + size; ++i) sum += slot[i];
    if ((sum & 0xFFu) != slot[at + size - 1]) break;
    at += size;
    if (size == 3 && slot[at - size + 1] == 0x0D) break;
  }
  return crc32(slot.first(at));
}

std::map<unsigned, slot_label> load_slot_labels(const std::string& robot, const std::string& file) {
  std::map<unsigned, slot_label> out;
  const auto root = read_file(file);
  const auto names = root[robot];
  if (!names) return out;
  if (!names.IsMap())
    throw refused(refusal_kind::usage, fmt::format("{}: {}: not a map of slots to names", file, robot));
  for (const auto& kv : names) {
    unsigned n = 0;
    try {
      n = kv.first.as<unsigned>();
    } catch (const YAML::Exception&) {
      throw refused(refusal_kind::usage,
                    fmt::format("{}:{}: '{}' is not a slot number", file, kv.first.Mark().line + 1, kv.first.Scalar()));
    }
    if (kv.second.IsScalar()) {  // written before names were tied to code: kept, never shown
      out[n] = slot_label{kv.second.Scalar(), std::nullopt};
    } else if (kv.second.IsMap() && kv.second["name"] && kv.second["name"].IsScalar()) {
      slot_label l{kv.second["name"].Scalar(), std::nullopt};
      if (const auto c = kv.second["code"]; c && c.IsScalar()) {
        const auto& text = c.Scalar();
        std::uint32_t v = 0;
        const auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), v, 16);
        if (ec == std::errc{} && p == text.data() + text.size() && text.size() == 8) l.code = v;
      }
      out[n] = l;
    }
  }
  return out;
}

void set_slot_name(const std::string& robot, unsigned n, const std::string& name, std::optional<std::uint32_t> code,
                   const std::string& file) {
  if (name.size() > 64 || name.find_first_of("\r\n") != std::string::npos)
    throw refused(refusal_kind::usage, fmt::format("the name '{}' is not one line of at most 64 characters", name));
  auto root = read_file(file);
  if (name.empty()) {
    if (root[robot] && root[robot].IsMap()) root[robot].remove(n);
  } else {
    YAML::Node entry(YAML::NodeType::Map);
    entry.SetStyle(YAML::EmitterStyle::Flow);
    entry["name"] = name;
    if (code) entry["code"] = fmt::format("{:08x}", *code);
    root[robot][n] = entry;
  }
  std::error_code ec;
  const fs::path path(file);
  if (path.has_parent_path()) fs::create_directories(path.parent_path(), ec);
  const auto tmp = file + ".tmp-" + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::trunc);
    YAML::Emitter e;
    e << root;
    out << "# motion slot names kept by rcb4 (the board has no place for them): robot -> slot -> name and the\n"
        << "# CRC-32 of the code it names (a slot holding other code shows no name)\n"
        << e.c_str() << "\n";
    if (!out)
      throw refused(refusal_kind::usage,
                    fmt::format("{}: cannot be written ({}): the name was not kept", file, std::strerror(errno)));
  }
  fs::rename(tmp, file, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw refused(refusal_kind::usage, fmt::format("{}: cannot be written: the name was not kept", file));
  }
}

std::string slot_name(const model& m, unsigned n, const std::map<unsigned, slot_label>& labels,
                      std::span<const std::uint8_t> code) {
  if (const auto it = labels.find(n); it != labels.end() && !it->second.name.empty() && it->second.code &&
                                      !code.empty() && *it->second.code == code_fingerprint(code))
    return it->second.name;
  return std::string(m.motion(n));
}

std::string slot_name(const model& m, unsigned n, std::span<const std::uint8_t> code) {
  try {
    return slot_name(m, n, load_slot_labels(m.name()), code);
  } catch (const refused&) {
    return std::string(m.motion(n));
  }
}

}  // namespace rcb4::robot::services
