// rcb4 ui: the policy between the pages and the robot (sans-I/O: no socket, thread or clock).
// SPDX-License-Identifier: BSL-1.0
//
// Pages join and leave and send messages (messages.hpp); the controller answers them with
// letters (JSON text for one page) and hands the board loop actions. It decides:
//  - who controls: the first page to join, or the first to ask once nobody does; the others only
//    watch, and what they ask to change is refused;
//  - how fast: slider moves are gathered per joint and sent at most once per move_interval, each
//    joint taking at least the time max_speed allows (a jump across the slider is not a slam);
//  - where: targets beyond a joint's limits are clamped to the limit, with a note to the page;
//  - how much: each page may send messages_per_second (with a burst); more are refused;
//  - what a lost page leaves: when the controlling page goes, its pending moves are dropped and
//    the joints it moved are held where they are, a motion it started is stopped.
#pragma once

#include "messages.hpp"

#include <rcb4/robot/ops.hpp>

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <variant>
#include <vector>

namespace cli::ui {

/** A page, as the server numbers its WebSockets. */
using client_id = std::uint64_t;
/** The controller's clock (time is passed in; nothing here reads it). */
using clock = std::chrono::steady_clock;

/** The controller's limits. */
struct settings {
  double max_speed = 90;                            ///< degrees per second no move from a page exceeds
  std::chrono::milliseconds move_interval{40};      ///< at most one move frame per interval (25 a second)
  double messages_per_second = 60;                  ///< per page, sustained
  double message_burst = 120;                       ///< per page, at once
  std::chrono::milliseconds default_pose_ms{1000};  ///< a pose played without a time of its own
};

/** Joint targets to send, checked against the limits; each joint with its own duration. */
struct move_action {
  std::vector<rcb4::robot::joint_target> targets;  ///< name, degrees, time
};
/** Free or hold joints. */
struct power_action {
  bool free = false;                              ///< true: free, false: hold
  std::vector<const rcb4::robot::joint*> joints;  ///< which
};
/** Hold @p joints where they are (a stop or a lost page), and stop a running motion. */
struct stop_action {
  std::vector<const rcb4::robot::joint*> joints;  ///< to hold now
  bool motion = false;                            ///< suspend the ROM program too
};
/** Save the measured pose as NAME.yaml. */
struct capture_action {
  std::string name;    ///< checked: valid_pose_name
  bool force = false;  ///< replace an existing file
};
/** Play the saved pose NAME. */
struct play_pose_action {
  std::string name;       ///< checked: valid_pose_name
  std::optional<int> ms;  ///< asked time (the speed limit may lengthen it)
};
/** Play ROM motion @p slot. */
struct motion_play_action {
  unsigned slot = 0;  ///< 1..120
};
/** Suspend the ROM program. */
struct motion_stop_action {};
/** Read the pose and motion lists again. */
struct refresh_action {};
/** Read ROM motion @p slot and give it back as a motion file. */
struct motion_file_action {
  unsigned slot = 0;  ///< 1..120
};

/** A studio op (messages.hpp) for the board loop's studio part (studio_ops.cpp). */
struct studio_action {
  std::string op;    ///< "motion_push" …
  std::string args;  ///< its checked fields, a JSON object text
};

/** What the board loop does for a page. */
struct action {
  client_id from = 0;              ///< the page that asked (0: the server itself)
  std::optional<std::int64_t> id;  ///< the page's id for the answer
  std::variant<move_action, power_action, stop_action, capture_action, play_pose_action, motion_play_action,
               motion_stop_action, refresh_action, motion_file_action, studio_action>
      body;  ///< what to do
};

/** A JSON text for one page. */
struct letter {
  client_id to = 0;  ///< the page
  std::string text;  ///< one JSON object
};

/** What an event leads to. */
struct effects {
  std::vector<letter> letters;  ///< to send
  std::vector<action> actions;  ///< for the board loop, in order
};

/** The shortest time a move of @p degrees may take under @p s (at least one move interval). */
std::chrono::milliseconds paced_time(double degrees, const settings& s);

/** The pages' policy; see the file comment. Not thread-safe: one owner calls it. */
class controller {
 public:
  /** For robot @p m (which must outlive it). */
  explicit controller(const rcb4::robot::model& m, settings s = {});

  /** Page @p c connected: it learns its role (control when nobody controls). */
  effects join(client_id c);
  /** Page @p c is gone; when it controlled, its moves stop (see the file comment). */
  effects leave(client_id c);
  /** Page @p c sent @p text at @p now. */
  effects receive(client_id c, std::string_view text, clock::time_point now);
  /** The gathered slider moves, when one is due at @p now (at most one per move_interval). */
  std::optional<action> due_move(clock::time_point now);
  /** When due_move will next give a move: nothing when no slider move waits (the board loop wakes then). */
  std::optional<clock::time_point> move_due_at() const;
  /**
   * The board's latest reading, one entry per model joint: the target angle (nothing when free,
   * held or unknown) and the measured angle (nothing when silent), and the longest move the
   * board makes (255 frames of its period). Moves are timed from the farthest of these and the
   * last target sent; a move that would need longer than @p longest goes part way at the speed
   * limit, and the rest follows at the next interval.
   */
  void observe(std::span<const std::optional<double>> targets, std::span<const std::optional<double>> angles,
               std::chrono::milliseconds longest = std::chrono::milliseconds(max_move_ms));

  /** The controlling page, if any. */
  std::optional<client_id> controlling() const noexcept { return controller_; }
  /** How many pages are connected. */
  std::size_t pages() const noexcept { return pages_.size(); }
  /** The limits in force. */
  const settings& limits() const noexcept { return settings_; }

 private:
  struct page {
    double tokens = 0;
    clock::time_point refilled{};
    bool warned = false;  ///< told about the rate once since the bucket emptied
  };
  struct pending {
    double degrees = 0;
    std::optional<int> ms;
    client_id from = 0;
    std::optional<std::int64_t> id;  ///< the page's id, answered once this move is sent
  };
  letter role_letter(client_id c) const;
  void roles_to_all(effects& e) const;
  bool admit(client_id c, clock::time_point now, effects& e);
  void handle(client_id c, const message& m, effects& e);
  std::size_t index_of(const rcb4::robot::joint* j) const noexcept;

  const rcb4::robot::model* model_;
  settings settings_;
  std::map<client_id, page> pages_;
  std::optional<client_id> controller_;
  std::map<std::size_t, pending> pending_;          ///< joint index → latest slider target
  std::vector<std::optional<double>> observed_;     ///< per joint: the board's target
  std::vector<std::optional<double>> measured_;     ///< per joint: the measured angle
  std::chrono::milliseconds longest_{max_move_ms};  ///< the board's longest move
  std::vector<std::optional<double>> commanded_;    ///< per joint: the last target sent from a page
  std::set<std::size_t> moved_;                     ///< joints the controlling page moved
  bool started_motion_ = false;                     ///< the controlling page played a motion
  std::optional<clock::time_point> last_move_;      ///< when due_move last gave a move
};

/** {"type":"error","id":…,"op":…,"message":…} */
std::string error_text(std::optional<std::int64_t> id, std::string_view op, std::string_view message);
/** {"type":"reply","id":…,"op":…,"ok":true} plus the fields of @p extra (a JSON object text, or empty). */
std::string reply_text(std::optional<std::int64_t> id, std::string_view op, std::string_view extra = {});

}  // namespace cli::ui
