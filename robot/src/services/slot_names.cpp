// rcb4 — robot services: the names of a board's motion slots (see rcb4/robot/services/slot_names.hpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/services/link.hpp>
#include <rcb4/robot/services/slot_names.hpp>

#include <fmt/format.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cerrno>
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

std::map<unsigned, std::string> load_slot_names(const std::string& robot, const std::string& file) {
  std::map<unsigned, std::string> out;
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
    if (kv.second.IsScalar()) out[n] = kv.second.Scalar();
  }
  return out;
}

void set_slot_name(const std::string& robot, unsigned n, const std::string& name, const std::string& file) {
  if (name.size() > 64 || name.find_first_of("\r\n") != std::string::npos)
    throw refused(refusal_kind::usage, fmt::format("the name '{}' is not one line of at most 64 characters", name));
  auto root = read_file(file);
  if (name.empty()) {
    if (root[robot] && root[robot].IsMap()) root[robot].remove(n);
  } else {
    root[robot][n] = name;
  }
  std::error_code ec;
  const fs::path path(file);
  if (path.has_parent_path()) fs::create_directories(path.parent_path(), ec);
  const auto tmp = file + ".tmp-" + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::trunc);
    YAML::Emitter e;
    e << root;
    out << "# motion slot names kept by rcb4 (the board has no place for them): robot -> slot -> name\n"
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

std::string slot_name(const model& m, unsigned n, const std::map<unsigned, std::string>& names) {
  if (const auto it = names.find(n); it != names.end() && !it->second.empty()) return it->second;
  return std::string(m.motion(n));
}

std::string slot_name(const model& m, unsigned n) {
  try {
    return slot_name(m, n, load_slot_names(m.name()));
  } catch (const refused&) {
    return std::string(m.motion(n));
  }
}

}  // namespace rcb4::robot::services
