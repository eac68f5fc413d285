// rcb4 — private: the project checks with the place of each error told by the caller (a file's
// line when read, "motion M003 frame 2" for a value).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/robot/hth4/project.hpp>

#include <rcb4/commands/flow.hpp>
#include <rcb4/frame.hpp>

#include <functional>
#include <span>

namespace rcb4::robot::hth4 {

/** True for a 7-byte JUMP or CALL frame as HTH4 keeps them (protocol.md §4.3: [07][0B|0C][a0][a1][a2][COND][SUM]). */
inline bool is_branch(std::span<const std::uint8_t> f) {
  return f.size() == 7 && f[0] == 7 && (f[1] == jump::command_code || f[1] == call::command_code);
}
/** The 24-bit target of a JUMP or CALL frame, low byte first (FF FF FF: HTH4's placeholder, §5.4). */
inline std::uint32_t branch_target(std::span<const std::uint8_t> f) {
  return static_cast<std::uint32_t>(f[2] | (f[3] << 8)) | (static_cast<std::uint32_t>(f[4]) << 16);
}
/** Points the JUMP or CALL frame @p f at @p t and makes its SUM again. */
inline void set_branch_target(std::span<std::uint8_t> f, std::uint32_t t) {
  f[2] = static_cast<std::uint8_t>(t);
  f[3] = static_cast<std::uint8_t>(t >> 8);
  f[4] = static_cast<std::uint8_t>(t >> 16);
  f[6] = checksum(f.first(6));
}

/** Where in a project a check failed. */
struct place {
  enum kind_t { in_root, in_motion, in_frame, in_servo, in_startup, in_priority } kind = in_root;
  unsigned index = 0;  ///< the motion's number, the servo's ICS number, the priority entry
  unsigned frame = 0;  ///< the frame within the motion
};
/** Names a place for an error ("FILE:LINE: <anyType>" or "FILE: motion M003 frame 2"). */
using where_fn = std::function<std::string(const place&)>;

/** The checks of project.hpp, each error at where(place). Throws profile_error. */
void check_project(const project& p, const where_fn& where);
/** "motion M003 frame 2" */
std::string describe(const place& pl);
/** The compare type HTH4 names @p name, or nothing. */
std::optional<compare_type> compare_from(std::string_view name);

}  // namespace rcb4::robot::hth4
