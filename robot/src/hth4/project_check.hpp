// rcb4 — private: the project checks with the place of each error told by the caller (a file's
// line when read, "motion M003 frame 2" for a value).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/robot/hth4/project.hpp>

#include <functional>

namespace rcb4::robot::hth4 {

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
