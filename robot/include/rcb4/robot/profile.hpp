// rcb4 — robot profiles and pose files: YAML a person edits by hand (yaml-cpp), JSON for poses too.
// SPDX-License-Identifier: BSL-1.0
//
// A profile names a robot's joints (ICS slot or servo ID + bus, direction, offset, limits), its
// groups and its motion names; see profiles/khr-3hv.yaml for the format, with comments. A bad
// profile is a profile_error whose message starts "FILE:LINE:COLUMN:" and says what is wrong.
//
// A pose is a set of joint angles in degrees:
//
//   {"robot": "KHR-3HV", "joints": {"left_knee": 30.0, "head_yaw": -12.5}}
//
// in JSON (.json) or the same in YAML (.yaml, .yml); a "time_ms" key may say how long playing it takes.
#pragma once

#include <rcb4/robot/model.hpp>

#include <chrono>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace rcb4::robot {

/** A profile or pose file that cannot be used; what() is "FILE:LINE:COLUMN: what is wrong". */
struct profile_error : std::runtime_error {
  /** @p where is "FILE:LINE:COLUMN" (or "FILE"), @p what the problem. */
  profile_error(const std::string& where, const std::string& what) : std::runtime_error(where + ": " + what) {}
};

/** Parses a profile's @p text; @p source names it in errors. Throws profile_error. */
model parse_profile(std::string_view text, const std::string& source);
/** Reads and parses the profile file @p path. Throws profile_error (also when unreadable). */
model load_profile(const std::filesystem::path& path);

/** The names of the built-in profiles ("khr-3hv", "kxr-l2"), the shipped profiles/ files. */
std::vector<std::string_view> builtin_profiles();
/** The text of built-in profile @p name, or nothing. */
std::optional<std::string_view> builtin_profile_text(std::string_view name);
/**
 * The profile @p what names: a built-in name ("khr-3hv"), else a file path. Throws
 * profile_error naming both readings when neither works.
 */
model open_profile(std::string_view what);

/** Joint angles in degrees, by name, in the order given. */
struct pose {
  std::string robot;  ///< its robot: the file's, else the profile's name (empty: none, not written)
  std::vector<std::pair<std::string, double>> joints;  ///< name → degrees
  std::optional<std::chrono::milliseconds> time;       ///< how long playing it takes, when the file says
};

/**
 * Parses a pose (JSON or YAML) for @p m: every name must be a joint of @p m, every angle a bare
 * number, and its robot (when given) must be @p m's name. Throws profile_error.
 */
pose parse_pose(std::string_view text, const std::string& source, const model& m);
/** Reads a pose file. Throws profile_error. */
pose load_pose(const std::filesystem::path& path, const model& m);
/** The pose as JSON text (one key per joint, a line each). */
std::string pose_json(const pose& p);
/** The pose as YAML text. */
std::string pose_yaml(const pose& p);
/**
 * Writes @p p to @p path: YAML for .yaml/.yml, JSON for .json; another extension is a
 * profile_error (nothing written), as is a file that cannot be written.
 */
void save_pose(const std::filesystem::path& path, const pose& p);

}  // namespace rcb4::robot
