// rcb4 ui: the messages a page sends over its WebSocket, parsed and checked (sans-I/O).
// SPDX-License-Identifier: BSL-1.0
//
// One JSON object per text message, with "op" naming what it asks and an optional integer "id"
// that the server's answer repeats:
//
//   {"op":"control"}                                   ask to control the robot (one page at a time)
//   {"op":"release"}                                   give control up
//   {"op":"move","joints":{"left_knee":40},"ms":300}   joint targets in degrees (ms optional)
//   {"op":"free","joints":["left_arm"]}                joints, groups or "all": no torque
//   {"op":"hold","joints":["all"]}                     torque on where they are
//   {"op":"stop"}                                      hold every joint now, stop a motion
//   {"op":"capture","name":"wave","force":false}       save the current pose as wave.yaml
//   {"op":"play_pose","name":"wave","ms":1200}         play a saved pose
//   {"op":"motion_play","slot":2}, {"op":"motion_stop"} the ROM motions
//   {"op":"refresh"}                                   read the pose and motion lists again
//   {"op":"motion_file","slot":2}                      ROM motion 2 as a motion file (YAML text; any page)
//
// The studio's (the motion editor and HTH4's tables; studio_messages.cpp checks them, the robot
// services carry them out). Any page may read:
//   {"op":"motion_list"}                               all 120 slots: used, name, bytes, seconds, broken
//   {"op":"motion_pull","slot":10}                     a slot as a motion file: {"motion": {...}, "yaml": "..."}
//   {"op":"motion_check","text":"robot: ..."}          a motion file (YAML or JSON text) parsed and compiled
//   {"op":"buttons"}, {"op":"trims"}                   the button table (RAM, ROM), every joint's trim
//   {"op":"pose_read","name":"wave"}                   a saved pose's joints (for a motion's step)
// Only the controlling page may change something:
//   {"op":"motion_push","slot":10,"text":"...","dry_run":false}   write a motion (backup first)
//   {"op":"motion_erase","slot":10}, {"op":"motion_resume"}
//   {"op":"motion_put_back","slot":10,"base64":"...","file":"motion-10-….bin"}   a slot's .bin backup back
//   {"op":"play_motion","text":"..."}                  play a motion file from the host ("stop" ends it)
//   {"op":"button_set","buttons":"s1+up","slot":10}, {"op":"button_clear","buttons":"s1+up"}
//   {"op":"button_press","buttons":"triangle","hold":true}, {"op":"button_release"}
//   {"op":"trim_set","joints":{"left_knee":1.5},"persist":false}
//   {"op":"hand","joint":"left_knee","degrees":30}     turn a freed joint by hand (the virtual board only)
//   {"op":"rom_backup"}                                the whole ROM, base64, with its CRC-32
//   {"op":"rom_restore_begin","bytes":262144,"crc32":"1a2b3c4d"}   an image uploaded in pieces:
//   {"op":"rom_restore_piece","offset":0,"base64":"..."}          (at most 45,000 bytes each)
//   {"op":"rom_restore_commit","force":false}          then written as `rcb4 rom restore` writes it
//
// Anything else (not JSON, an unknown op or key, a wrong type, a value out of range, more than
// max_message_bytes, nesting deeper than an object of arrays) is a parse_error with the reason.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace cli::ui {

/**
 * The longest message a page may send; longer ones are refused unread, with a reply (a motion
 * file's text fits, escaped as JSON). The WebSocket itself takes up to ws_frame_max before the
 * server drops a page (a hostile one): every message the page makes stays well below.
 */
inline constexpr std::size_t max_message_bytes = 4 * 1024 * 1024;
/** The WebSocket's own limit: above it the connection is closed (the page checks its messages first). */
inline constexpr std::size_t ws_frame_max = max_message_bytes + 64 * 1024;
/** The longest motion file text a studio message may carry (docs/browser.md: 512 KiB; a slot holds far less). */
inline constexpr std::size_t max_text_bytes = 512 * 1024;
/** The longest joint, group or pose name a message may carry. */
inline constexpr std::size_t max_name_bytes = 64;
/** The longest move or pose time a message may ask, ms (255 frames of 25 ms, protocol.md §5). */
inline constexpr int max_move_ms = 6375;

/** {"op":"control"}: make this page the controlling one. */
struct take_control {};
/** {"op":"release"}: this page stops controlling. */
struct release_control {};
/** {"op":"move"}: joint targets in degrees, in the order given; ms: how long (else the server picks). */
struct move_request {
  std::vector<std::pair<std::string, double>> joints;  ///< joint name → degrees
  std::optional<int> ms;                               ///< 0..max_move_ms
};
/** {"op":"free"} / {"op":"hold"}: torque off or on for joints, groups or "all". */
struct power_request {
  bool free = false;               ///< true: free, false: hold
  std::vector<std::string> words;  ///< joint or group names, "all"
};
/** {"op":"stop"}: hold every joint where it is and stop a running motion. */
struct stop_request {};
/** {"op":"capture"}: save the measured pose under @p name. */
struct capture_request {
  std::string name;    ///< [A-Za-z0-9_-], 1..64 bytes
  bool force = false;  ///< replace a pose of that name
};
/** {"op":"play_pose"}: play the saved pose @p name. */
struct play_pose_request {
  std::string name;       ///< as capture names it
  std::optional<int> ms;  ///< 0..max_move_ms; else the pose's own time or the server's default
};
/** {"op":"motion_play"}: play ROM motion @p slot. */
struct motion_play_request {
  unsigned slot = 0;  ///< 1..120
};
/** {"op":"motion_stop"}: suspend the ROM program. */
struct motion_stop_request {};
/** {"op":"refresh"}: read the saved poses and the motion slots again. */
struct refresh_request {};
/** {"op":"motion_file"}: ROM motion @p slot read back as a motion file (reading only: any page may ask). */
struct motion_file_request {
  unsigned slot = 0;  ///< 1..120
};

/** A studio request (see the file comment): its op and its fields, each checked already. */
struct studio_request {
  std::string op;       ///< "motion_push" …
  std::string args;     ///< the message's fields but op and id, as a JSON object text
  bool writes = false;  ///< it changes the robot or its files: only the controlling page may ask
};

/** True for a studio op that only reads (any page may ask it); the others need control. */
inline bool studio_reads(std::string_view op) noexcept {
  return op == "motion_list" || op == "motion_pull" || op == "motion_check" || op == "buttons" || op == "trims" ||
         op == "pose_read";
}

/** What a page asks. */
using request = std::variant<take_control, release_control, move_request, power_request, stop_request, capture_request,
                             play_pose_request, motion_play_request, motion_stop_request, refresh_request,
                             motion_file_request, studio_request>;

/** A well-formed message: its request and the id to answer with. */
struct message {
  std::optional<std::int64_t> id;  ///< the page's id for the answer
  request body;                    ///< what it asks
};

/** A message that cannot be used: why, and its id when one could be read. */
struct parse_error {
  std::optional<std::int64_t> id;  ///< the id, when the message had a valid one
  std::string what;                ///< e.g. "move: 'joints' must be an object of numbers"
};

/** Parses one text message from a page. Never throws; any input gives a message or a parse_error. */
std::variant<message, parse_error> parse_message(std::string_view text);

/** True for a pose name a page may use: 1..64 of [A-Za-z0-9_-] (no dots, no slashes). */
bool valid_pose_name(std::string_view name) noexcept;

/** The op name of @p r ("move", "free" …), for answers. */
std::string_view op_name(const request& r) noexcept;

}  // namespace cli::ui
