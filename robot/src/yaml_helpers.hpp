// rcb4 — the YAML helpers the profile, pose and motion file parsers share (private to rcb4::profile).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/robot/profile.hpp>

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string>
#include <string_view>

namespace rcb4::robot::detail {

/** "FILE:LINE:COLUMN" of a node's mark, or FILE when there is none. */
inline std::string where(const std::string& source, const YAML::Mark& m) {
  if (m.is_null()) return source;
  return source + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1);
}

/** Throws profile_error at @p n. */
[[noreturn]] inline void fail(const std::string& source, const YAML::Node& n, const std::string& what) {
  throw profile_error(where(source, n.Mark()), what);
}

/** The scalar @p n, else a profile_error naming @p what. */
inline std::string scalar(const std::string& source, const YAML::Node& n, const std::string& what) {
  if (!n.IsScalar()) fail(source, n, what + ": expected a single value");
  return n.Scalar();
}

/** The bare number @p n (a quoted one is a string), else a profile_error. */
inline double number(const std::string& source, const YAML::Node& n, const std::string& what) {
  const std::string s = scalar(source, n, what);
  // A quoted scalar ("10") is a string, in YAML and in JSON: a number is written bare.
  if (n.Tag() == "!") fail(source, n, what + ": expected a number, not the string \"" + s + "\"");
  try {
    std::size_t used = 0;
    const double v = std::stod(s, &used);
    if (used == s.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  fail(source, n, what + ": expected a number, not '" + s + "'");
}

/** The whole number @p n in [@p lo, @p hi], else a profile_error. */
inline long integer(const std::string& source, const YAML::Node& n, const std::string& what, long lo, long hi) {
  const double v = number(source, n, what);
  if (v != std::floor(v) || v < static_cast<double>(lo) || v > static_cast<double>(hi))
    fail(source, n,
         what + ": expected a whole number in " + std::to_string(lo) + ".." + std::to_string(hi) + ", not " +
             n.Scalar());
  return static_cast<long>(v);
}

/** @p text parsed; a syntax error is a profile_error at its line. */
inline YAML::Node parse_yaml(std::string_view text, const std::string& source) {
  try {
    return YAML::Load(std::string(text));
  } catch (const YAML::Exception& e) {  // syntax errors, and yaml-cpp's own limits (nesting depth)
    throw profile_error(where(source, e.mark), e.msg);
  }
}

/**
 * The largest profile, pose or motion file read (4 MiB). A motion fills at most a 2 KiB slot, so
 * its file, comments and all, is far smaller; a bigger file is refused by its size before it is
 * parsed (a 50 MB file once took a minute and gigabytes of memory to be refused by its content).
 */
inline constexpr std::uintmax_t max_file_bytes = 4u << 20;

/** The bytes of @p path; a profile_error when it cannot be read or is larger than max_file_bytes. */
inline std::string read_file(const std::filesystem::path& path) {
  // A FIFO or a device would block or never end: only regular files (or links to them) are read.
  std::error_code ec;
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw profile_error(path.string(), "is not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw profile_error(path.string(), "cannot be read (" + std::string(std::strerror(errno)) + ")");
  if (const auto size = std::filesystem::file_size(path, ec); !ec && size > max_file_bytes)
    throw profile_error(path.string(), "holds " + std::to_string(size) + " bytes, more than " +
                                           std::to_string(max_file_bytes >> 20) +
                                           " MiB: not a profile, pose or motion file (refused unread)");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/** Keys of a mapping, each checked against @p allowed and for repetition. */
inline void check_keys(const std::string& source, const YAML::Node& map,
                       std::initializer_list<std::string_view> allowed, const std::string& what) {
  std::vector<std::string> seen;
  for (const auto& kv : map) {
    const std::string k = scalar(source, kv.first, what);
    if (std::find(allowed.begin(), allowed.end(), k) == allowed.end()) {
      std::string list;
      for (auto a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      fail(source, kv.first, what + ": unknown key '" + k + "' (known: " + list + ")");
    }
    if (std::find(seen.begin(), seen.end(), k) != seen.end())
      fail(source, kv.first, what + ": '" + k + "' is given twice");
    seen.push_back(k);
  }
}

/** A motion file's words for an if_ram comparison, in motion::compare's order. */
inline constexpr std::string_view compares[] = {"equal", "not_equal", "below", "at_least", "at_most"};

/** @p v as "0x" and @p digits hexadecimal digits ("0x000B80"). */
inline std::string hex(std::uint32_t v, int digits) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%0*X", digits, static_cast<unsigned>(v));
  return b;
}

/** A profile's `kinematics:` node, checked against the profile's joints; a profile_error at the entry at fault. */
kinematics parse_body(const std::string& source, const YAML::Node& n, const std::vector<std::string>& profile_joints);
/** A profile's `dynamics:` read and checked against @p body (a profile_error with its place). */
dynamics parse_dynamics(const std::string& source, const YAML::Node& n, const kinematics& body);

}  // namespace rcb4::robot::detail
