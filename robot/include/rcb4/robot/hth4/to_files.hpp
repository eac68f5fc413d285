// rcb4 — an HTH4 project as rcb4's own files (hth4-files.md §2; `rcb4 project import P.h4p --to
// DIR`), without I/O: a robot profile from the servo table, a motion file per motion (or its code
// as a .bin where the steps cannot express it), the trims as an HTH4 trim file, and push.sh, the
// tool's commands that put it all on a board (callees before their callers, then the buttons and
// the trims).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/robot/hth4/project.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace rcb4::robot::hth4 {

/** The files a project becomes. */
struct project_files {
  /** One file: its name in the directory and its content (text, or the bytes of a .bin). */
  struct file {
    std::string name;
    std::string text;
    std::vector<std::uint8_t> bytes;
  };
  std::vector<file> files;         ///< profile.yaml, NNN-name.yaml / .bin, buttons.yaml, trims.h4t, push.sh
  std::vector<std::string> notes;  ///< what is kept as code, what is left out, and why
};

/**
 * @p p as files: joints named from the allocated servos' names (made identifiers: lower case,
 * `_` for anything else, each once), limits ±135° (a servo's travel), directions +1; motions
 * lifted to steps at the project's output period, in the 2.2 layout (relocated if the project's
 * is 2.0). @p robot names the robot (empty: the project's Name).
 */
project_files project_as_files(const project& p, const std::string& robot);

/**
 * A directory of rcb4's files (what --to writes, or the same by hand) as a project: profile.yaml's
 * joints as allocated servos; each `NNN-name.yaml` motion file assembled into slot NNN of the 2.2
 * layout (`NNN-name.bin`: its bytes as they are); buttons.yaml (`BUTTONS: N` lines) and trims.h4t
 * where present; the config word's period from the motion files. Throws profile_error naming the
 * file and what is wrong.
 */
project load_project_dir(const std::filesystem::path& dir);

/** @p name as a joint name: lower case letters, digits and `_`, not starting with a digit; empty stays empty. */
std::string identifier(std::string_view name);

}  // namespace rcb4::robot::hth4
