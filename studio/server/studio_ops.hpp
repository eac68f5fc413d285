// rcb4 ui: the studio's ops on the board (the motion editor and HTH4's tables), each a robot
// service (rcb4/robot/services/) run by the board loop: motion slots listed, pulled, pushed (the
// backup named), erased; a motion file played from the host at its authored timing (stepped by the
// loop); the button table; trims; the whole ROM read. Its answers are JSON objects for the page.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include "app.hpp"
#include "board_loop.hpp"
#include "controller.hpp"

#include <rcb4/robot/services/host_play.hpp>
#include <rcb4/robot/services/motion_slots.hpp>

#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace cli::ui {

/** The robot's body (the profile's kinematics) for the page's 3D view, or null when the profile has none. */
json body_json(const rcb4::robot::model& m);

/** Where saved pose @p name is in @p folder: NAME.yaml, or an existing NAME.json when @p for_reading. */
std::filesystem::path pose_path(const std::filesystem::path& folder, const std::string& name, bool for_reading);

/** @p j as the text a page gets (bytes that are no UTF-8 replaced, never an exception). */
inline std::string text_of(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

/** A studio op that did not do what it was asked: the words for the page (nothing was changed unless they say so). */
struct studio_refusal : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/** The studio's ops, for one board loop (one thread). */
class studio_ops {
 public:
  /** For @p s (the loop's session), robot @p m, backups under @p o.poses / "backups". */
  studio_ops(session& s, const rcb4::robot::model& m, const loop_options& o);
  ~studio_ops();
  studio_ops(const studio_ops&) = delete;
  studio_ops& operator=(const studio_ops&) = delete;

  /** Carries out @p a for page @p from; the answer's fields. Throws studio_refusal. */
  json act(const studio_action& a, client_id from);
  /** When a motion played from the host next needs the loop; nothing when none plays. */
  std::optional<clock::time_point> due() const;
  /** True while a motion plays from the host (moves from the page would fight it). */
  bool playing() const noexcept { return play_ != nullptr; }
  /** Steps the motion played from the host; when it ends or fails, the letter for the page that started it. */
  std::optional<letter> tick();
  /** Stops a motion played from the host (Stop, a lost page); a ROM motion it called stops too. */
  void stop();

 private:
  json list();
  json pull(unsigned slot);
  json check(const std::string& text);
  json push(unsigned slot, const std::string& text, bool dry_run, const rcb4::robot::services::backup_sink& backup);
  json play(const std::string& text, client_id from);
  json buttons();
  json trims();
  json pose_read(const std::string& name);
  json hand(const std::string& joint, double degrees);
  json rom_backup();
  /** Where a backup of @p what ("motion-10") goes: POSES/backups/WHAT-DATE.bin (the folder made). */
  std::string backup_path(const std::string& what) const;
  json rom_restore_piece(std::size_t offset, const std::string& base64);
  json rom_restore_commit(bool force);

  session& s_;
  const rcb4::robot::model& m_;
  const loop_options& o_;
  session_link link_;
  std::unique_ptr<rcb4::robot::services::host_play> play_;
  /** Each used slot's code as the last list() read it: the buttons' names are checked against it (slot_names.hpp). */
  std::map<unsigned, std::vector<std::uint8_t>> codes_;
  clock::time_point play_start_{};
  std::optional<clock::time_point> play_next_;
  client_id play_from_ = 0;
  std::string play_name_;
  std::vector<std::uint8_t> upload_;  ///< a ROM image being uploaded (rom_restore_begin … commit)
  std::vector<bool> uploaded_;        ///< which of its bytes came
  std::uint32_t upload_crc_ = 0;      ///< the CRC-32 the page says it has
};

}  // namespace cli::ui
