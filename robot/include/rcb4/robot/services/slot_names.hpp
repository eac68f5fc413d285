// rcb4 — robot services: the names of a board's motion slots. The RCB-4 keeps no names (HTH4 keeps
// them in its project file, hth4-files.md), so rcb4 keeps them in a small YAML file of its own, one
// map per robot model, written when a motion file with a `name:` is pushed and read wherever slots
// are listed (the tool, rcb4 ui, pyrcb4). A name belongs to the code it was given with: each entry
// keeps the fingerprint of the slot's code (CRC-32 of its bytes up to the first RETURN, as a listing
// reads them), and a slot whose code is another's shows no name of the file, so a board never shows
// the name another board's push gave its slot. The profile's `motions:` names are the fallback.
// SPDX-License-Identifier: BSL-1.0
//
//   # ~/.config/rcb4/slot-names.yaml
//   KHR-3HV:
//     10: {name: wave, code: 1a2b3c4d}
//     11: {name: bow deeply, code: 0badf00d}
#pragma once

#include <rcb4/robot/model.hpp>

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>

namespace rcb4::robot::services {

/** The names file: $RCB4_SLOT_NAMES, else $XDG_CONFIG_HOME/rcb4/slot-names.yaml, else ~/.config/rcb4/slot-names.yaml.
 */
std::string slot_names_file();

/** A slot's name and the fingerprint of the code it was given with (none: an entry written before names were tied to
 * code). */
struct slot_label {
  std::string name;                   ///< one line, at most 64 characters
  std::optional<std::uint32_t> code;  ///< code_fingerprint() of the slot when it was named
};

/**
 * The fingerprint of a slot's code: the CRC-32 of its bytes up to and including the first RETURN
 * (or up to the last valid frame), walked as rcb4::ops::list_motions walks a slot. @p slot: the
 * slot's bytes from its start (the whole slot, or as much as holds the code).
 */
std::uint32_t code_fingerprint(std::span<const std::uint8_t> slot);

/** Slot number → label for @p robot; nothing when the file does not exist. A file that does not read: a usage refusal.
 */
std::map<unsigned, slot_label> load_slot_labels(const std::string& robot, const std::string& file = slot_names_file());

/**
 * Names motion @p n of @p robot @p name, for the code whose fingerprint is @p code (an empty name
 * forgets it), the file rewritten whole (through a temporary file renamed over it, so a reader
 * never sees half of it); a usage refusal when it cannot be written. Names are one line of at most
 * 64 characters.
 */
void set_slot_name(const std::string& robot, unsigned n, const std::string& name, std::optional<std::uint32_t> code,
                   const std::string& file = slot_names_file());

/**
 * The name of slot @p n, which holds @p code (its bytes from the slot's start; empty: not known):
 * the file's label when it was given to this very code, else @p m's profile name, else empty.
 */
std::string slot_name(const model& m, unsigned n, const std::map<unsigned, slot_label>& labels,
                      std::span<const std::uint8_t> code);

/** The same, the names file read now (one that does not read: the profile's name). */
std::string slot_name(const model& m, unsigned n, std::span<const std::uint8_t> code);

}  // namespace rcb4::robot::services
