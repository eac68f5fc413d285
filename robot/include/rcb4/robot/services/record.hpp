// rcb4 — robot services: teach by demonstration. The joints are sampled while a person moves the
// robot by hand (freed first when asked); robot::recorder keeps the poses that replay the movement
// and the result is a motion document to save or push (rcb4/robot/record.hpp, motions.md §2).
// SPDX-License-Identifier: BSL-1.0
//
// The driver owns the clock and the stop (Enter, Ctrl-C, a duration): the service only reads.
//
//   recording rec(link, robot, joints, {.free = true});   // checked, then the joints freed
//   while (!stop) { rec.sample(elapsed()); wait_until(next); }
//   auto report = rec.finish();                           // held again; report.document: the motion
#pragma once

#include <rcb4/ops/planner.hpp>
#include <rcb4/robot/motion_file.hpp>
#include <rcb4/robot/ops.hpp>
#include <rcb4/robot/record.hpp>
#include <rcb4/robot/services/link.hpp>

#include <chrono>
#include <cstddef>
#include <system_error>
#include <vector>

namespace rcb4::robot::services {

/** How a recording samples. */
struct record_options {
  double threshold = 2.0;                   ///< degrees a joint may leave the straight line before a pose is kept
  bool free = false;                        ///< free the joints first (no torque), hold them again at the end
  std::chrono::milliseconds lead_in{1000};  ///< the first pose's time (from wherever the robot is when played)
  ops::link_cost cost{};                    ///< the link, for the planner's reads
};

/** What a recording kept. */
struct record_report {
  motion_document document;          ///< the poses, then end
  std::size_t samples = 0;           ///< samples taken
  std::size_t clamped = 0;           ///< angles beyond a limit, kept at the limit
  bool held = false;                 ///< the joints were freed and are held again
  std::chrono::milliseconds span{};  ///< from the first sample to the last
  std::error_code lost;              ///< set by a driver whose board went away part way (what was kept is above)
};

/** A recording under way; see the file comment. Destroyed unfinished, it holds what it freed (best effort). */
class recording {
 public:
  /**
   * Refused (board) while a motion runs, when a joint has no servo block or its servo does not
   * answer: nothing is freed. Then frees @p joints when options.free.
   */
  recording(link& l, const model& robot, std::vector<const joint*> joints, const record_options& options);
  ~recording();
  recording(const recording&) = delete;
  recording& operator=(const recording&) = delete;

  /** Reads every joint once and takes it as the sample at @p t since the recording began. */
  void sample(std::chrono::milliseconds t);
  /**
   * Ends the recording: the joints held again when they were freed (unless @p board_lost: the
   * link failed, what was recorded is still returned) and the poses as a motion document.
   */
  record_report finish(bool board_lost = false);
  /** The recorder (samples and poses so far, for a progress line). */
  const recorder& poses() const noexcept { return rec_; }

 private:
  std::vector<double> read_angles();
  link& l_;
  const model& robot_;
  std::vector<const joint*> joints_;
  record_options o_;
  joint_map map_;
  output_period period_{};
  recorder rec_;
  servo_mask mask_;
  bool freed_ = false;
  std::chrono::milliseconds last_{};
};

}  // namespace rcb4::robot::services
