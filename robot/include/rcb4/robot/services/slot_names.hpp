// rcb4 — robot services: the names of a board's motion slots. The RCB-4 keeps no names (HTH4 keeps
// them in its project file, hth4-files.md), so rcb4 keeps them in a small YAML file of its own, one
// map per robot, written when a motion file with a `name:` is pushed and read wherever slots are
// listed (the tool, rcb4 ui, pyrcb4). The profile's `motions:` names are the fallback.
// SPDX-License-Identifier: BSL-1.0
//
//   # ~/.config/rcb4/slot-names.yaml
//   KHR-3HV:
//     10: wave
//     11: bow deeply
#pragma once

#include <rcb4/robot/model.hpp>

#include <map>
#include <string>

namespace rcb4::robot::services {

/** The names file: $RCB4_SLOT_NAMES, else $XDG_CONFIG_HOME/rcb4/slot-names.yaml, else ~/.config/rcb4/slot-names.yaml.
 */
std::string slot_names_file();

/** Slot number → name for @p robot; nothing when the file does not exist. A file that does not read: a usage refusal.
 */
std::map<unsigned, std::string> load_slot_names(const std::string& robot, const std::string& file = slot_names_file());

/**
 * Names motion @p n of @p robot @p name (empty: forgets it), the file rewritten whole (through a
 * temporary file renamed over it, so a reader never sees half of it); a usage refusal when it
 * cannot be written. Names are one line of at most 64 characters.
 */
void set_slot_name(const std::string& robot, unsigned n, const std::string& name,
                   const std::string& file = slot_names_file());

/** The name of slot @p n: from @p names, else from @p m's profile, else empty. */
std::string slot_name(const model& m, unsigned n, const std::map<unsigned, std::string>& names);

/** The name of slot @p n of @p m's robot, the names file read now (one that does not read: the profile's name). */
std::string slot_name(const model& m, unsigned n);

}  // namespace rcb4::robot::services
