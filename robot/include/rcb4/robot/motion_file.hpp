// rcb4 — motion files: a ROM motion as a person edits it, in the profile's joint names, degrees
// and milliseconds (YAML through yaml-cpp), turned into a motion program (rcb4/motion/program.hpp)
// of the board's frames and back.
// SPDX-License-Identifier: BSL-1.0
//
//   # what the motion does
//   robot: KHR-3HV
//   name: wave                      # optional
//   period_ms: 15                   # the output period the times were made for (10, 15, 20, 25)
//   steps:
//     - pose: {left_shoulder_roll: 80, left_elbow: -45}   # joints in degrees, the rest stay
//       time_ms: 300                                      # turned into frames of period_ms
//     - pose: poses/crouch.yaml     # a pose file (beside this one); its time_ms if the step has none
//     - label: again                # a name loops and jumps go to
//     - set_counter: 3              # HTH4's counter C1 (RAM 0x0457); counter: 0x0460 for another
//     - pose: {left_elbow: -90, "ics 10": free}            # a servo outside the profile by ICS
//       time_ms: 150
//     - loop: again                 # counter - 1, back to 'again' while it is not 0
//     - count_down: done            # counter - 1, to 'done' when it is 0 (HTH4's Loop block)
//       when: zero
//     - if_buttons: up              # KRR buttons equal (unless_buttons: differ); goto: a label
//       goto: again
//     - if_ram: 0x0460              # any 1- or 2-byte RAM value: equal, not_equal, below,
//       size: 1                     # at_least, at_most a literal
//       equal: 3
//       goto: done
//     - stretch: {legs: 60, head_yaw: 127}  # or speed:; joints, groups, "all", "ics N": 1..127
//     - call: 5                     # another motion by number (call_address: 0x0143B8 by address)
//     - goto: again
//     - label: done
//     - end                         # RETURN
//
// Any step but end may also carry how the studio shows it, which the board never sees:
//       name: crouch                # a name for the step (a pose's, in the list and timeline)
//       at: [240, 96]               # its flowchart block's top-left, in pixels
//
// Every step is one step of the program (the same numbers in messages). A pose's angles are
// checked against the joint's limits, its time against the 255 frames a CONST carries, and the
// file's period against the board's, before anything is assembled.
#pragma once

#include <rcb4/motion/program.hpp>
#include <rcb4/robot/model.hpp>
#include <rcb4/robot/profile.hpp>

#include <array>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace rcb4::robot {

/** One servo of a pose: a joint in degrees, or a position word (FREE, HOLD, or a servo by ICS). */
struct motion_target {
  std::string key;                    ///< a joint name, or "ics N" for a servo outside the profile
  std::optional<double> degrees;      ///< a joint's angle
  std::optional<std::uint16_t> word;  ///< otherwise: FREE, HOLD, or the raw position of "ics N"
  friend bool operator==(const motion_target&, const motion_target&) = default;
};
/** A pose step: its servos, and how long getting there takes. */
struct motion_pose {
  std::vector<motion_target> targets;  ///< at least one
  std::chrono::milliseconds time{};    ///< 0 .. 255 frames of the period
  std::string file;                    ///< the pose file it came from, or empty (inline)
  friend bool operator==(const motion_pose&, const motion_pose&) = default;
};
/** A stretch or speed step: joints, groups, "all" or "ics N" to 1..127. */
struct motion_params {
  param_kind kind = param_kind::stretch;                 ///< which parameter
  std::vector<std::pair<std::string, unsigned>> values;  ///< name → value
  friend bool operator==(const motion_params&, const motion_params&) = default;
};
/** A call of another motion: by its number in the layout, or by address. */
struct motion_call {
  unsigned number = 0;                   ///< 1-based; 0 when @p address is given
  std::optional<std::uint32_t> address;  ///< a ROM address
  friend bool operator==(const motion_call&, const motion_call&) = default;
};
/** One step of a motion file. */
using motion_step = std::variant<motion::label, motion_pose, motion::set_counter, motion::count_down, motion::branch_if,
                                 motion::go_to, motion_call, motion_params, motion::end>;

/** How the studio shows a step (the board never sees it): its name and its flowchart block's place. */
struct step_view {
  std::string name;                       ///< a name for the step; empty: none
  std::optional<std::array<long, 2>> at;  ///< the flowchart block's top-left (x, y) in pixels; none: laid out in order
  friend bool operator==(const step_view&, const step_view&) = default;
};

/** A motion file. */
struct motion_document {
  std::string robot;                           ///< the profile's robot name
  std::string name;                            ///< optional
  output_period period = output_period::ms15;  ///< the period the times were made for
  std::vector<motion_step> steps;              ///< in the order they are laid out
  std::vector<std::string> where;              ///< per step, "FILE:LINE" for messages (empty for steps made in code)
  std::vector<step_view> views;                ///< per step, how the studio shows it (may be empty: none for any)
};

/**
 * Parses a motion file for @p m: every key known, every joint @p m's, every number in range;
 * pose files are read relative to @p dir. Limits are checked by to_program. Throws
 * profile_error "FILE:LINE:COLUMN: what is wrong".
 */
motion_document parse_motion(std::string_view text, const std::string& source, const model& m,
                             const std::filesystem::path& dir = {});
/** Reads and parses a motion file. Throws profile_error. */
motion_document load_motion(const std::filesystem::path& path, const model& m);
/** The motion as YAML text, a step per item, in the form parse_motion reads. */
std::string motion_yaml(const motion_document& d, std::string_view comment = {});
/**
 * The motion as one JSON object with the keys of its YAML ("robot", "name", "period_ms", "steps":
 * a step per item), for programs that hold steps as data (pyrcb4): JSON is YAML too, so the text
 * parse_motion reads back is json.dumps of it.
 */
std::string motion_json(const motion_document& d);
/** Writes motion_yaml(@p d) to @p path (.yaml or .yml). Throws profile_error. */
void save_motion(const std::filesystem::path& path, const motion_document& d, std::string_view comment = {});

/** A motion file as the board's program. */
struct compiled_motion {
  motion::program program;         ///< a step per file step
  output_period period{};          ///< the period its frames are of
  std::vector<std::string> notes;  ///< times rounded to whole frames, a rescale
};
/**
 * @p d as a program for a board with @p board_period and @p layout: the file's period must be the
 * board's unless @p rescale (then every time is kept in milliseconds and turned into the board's
 * frames); every angle within its joint's limits; labels unique and defined; a call's motion
 * inside the layout. A problem names the step (1-based), its line, and what is wrong.
 */
outcome<compiled_motion> to_program(const motion_document& d, const model& m, const rom_layout& layout,
                                    output_period board_period, bool rescale = false);
/**
 * @p p as a motion file of @p m: servos on a joint in degrees, others as "ics N"; frames of
 * @p period in milliseconds; a call of a slot's first byte by the motion's number in @p layout.
 */
motion_document from_program(const motion::program& p, const model& m, const rom_layout& layout, output_period period);

}  // namespace rcb4::robot
