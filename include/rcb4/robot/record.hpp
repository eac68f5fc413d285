// rcb4 — teaching by demonstration: joint samples taken while a person moves the robot by hand,
// turned into the few poses that replay them (std only, sans-I/O: the caller reads the joints and
// gives each sample its time).
// SPDX-License-Identifier: BSL-1.0
//
// A board plays a pose by moving every listed servo in a straight line (in position) over the
// pose's frames (protocol.md §5). So the recorder keeps a sample as a pose only where the straight
// line from the last kept pose no longer passes within the threshold of every sample taken since:
// a still robot gives one pose for the whole pause (its time is the pause), a steady sweep one
// pose for the sweep, a turn a pose at the turn. No segment is longer than a CONST carries (255
// frames); times are whole frames of the board's period.
//
//   robot::recorder rec(joints, 2.0 /* degrees */, output_period::ms15);
//   while (recording) rec.sample(elapsed_ms, angles);   // angles in the order of joints
//   rec.finish();
//   for (const auto& p : rec.poses()) ...                // degrees and milliseconds
#pragma once

#include <rcb4/robot/model.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <span>
#include <vector>

namespace rcb4::robot {

/** A pose the recorder kept: an angle per recorded joint, and how long getting there takes. */
struct recorded_pose {
  std::vector<double> degrees;     ///< in the order of the recorder's joints
  std::chrono::milliseconds time;  ///< whole frames of the period (the first: the recorder's lead-in)
};

/** Turns samples into poses; see the file comment. */
class recorder {
 public:
  /**
   * Records @p joints; a sample off the straight line by more than @p threshold degrees (on any
   * joint) makes a pose; times are frames of @p period; the first pose takes @p lead_in (moving
   * the robot from wherever it is when played to where the recording starts).
   */
  recorder(std::vector<const joint*> joints, double threshold, output_period period,
           std::chrono::milliseconds lead_in = std::chrono::milliseconds(1000))
      : joints_(std::move(joints)),
        threshold_(threshold),
        frame_ms_(milliseconds(period)),
        lead_in_(lead_in),
        longest_ms_(255 * static_cast<long long>(milliseconds(period))) {}

  /**
   * Takes a sample at @p t (since the recording began, not going back) of every joint, in the
   * joints' order; an angle beyond a joint's limits is taken at the limit (counted in clamped()).
   */
  void sample(std::chrono::milliseconds t, std::span<const double> degrees) {
    std::vector<double> s(degrees.begin(), degrees.end());
    s.resize(joints_.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
      const double c = std::clamp(s[i], joints_[i]->lower, joints_[i]->upper);
      if (c != s[i]) ++clamped_;
      s[i] = std::round(c * 100) / 100;  // hundredths: the servo resolves about a thirtieth
    }
    if (t < last_t_) t = last_t_;
    ++samples_;
    if (poses_.empty()) {
      keep(t, s, lead_in_);
      return;
    }
    pending_.push_back({t, s});
    // The latest sample the line from the kept pose may end at: back off until it fits.
    if (!fits(pending_.size() - 1)) {
      pending_.pop_back();
      if (!pending_.empty()) {
        const auto last = pending_.back();
        keep(last.t, last.degrees);
        pending_.clear();
      }
      pending_.push_back({t, s});
      if (!fits(0)) {  // one sample after the kept pose: always a line of one step
        keep(t, s);
        pending_.clear();
      }
    }
    last_t_ = t;
  }

  /** Ends the recording: the last sample becomes the last pose (a pause at the end included). */
  void finish() {
    if (!pending_.empty()) keep(pending_.back().t, pending_.back().degrees);
    pending_.clear();
  }

  /** The poses kept so far. */
  const std::vector<recorded_pose>& poses() const noexcept { return poses_; }
  /** The joints, in the order of each pose's degrees. */
  const std::vector<const joint*>& joints() const noexcept { return joints_; }
  /** Samples taken. */
  std::size_t samples() const noexcept { return samples_; }
  /** Angles that were beyond a joint's limit and taken at the limit. */
  std::size_t clamped() const noexcept { return clamped_; }

 private:
  struct timed {
    std::chrono::milliseconds t;
    std::vector<double> degrees;
  };

  /** True when the line from the kept pose to pending_[end] passes within the threshold of pending_[0..end). */
  bool fits(std::size_t end) const {
    const auto& b = pending_[end];
    const double span = static_cast<double>((b.t - kept_t_).count());
    if ((b.t - kept_t_).count() > longest_ms_) return false;
    for (std::size_t k = 0; k <= end; ++k) {
      const double f = span > 0 ? static_cast<double>((pending_[k].t - kept_t_).count()) / span : 1.0;
      for (std::size_t i = 0; i < kept_.size(); ++i) {
        const double line = kept_[i] + (b.degrees[i] - kept_[i]) * f;
        if (std::abs(pending_[k].degrees[i] - line) > threshold_) return false;
      }
    }
    return true;
  }

  void keep(std::chrono::milliseconds t, const std::vector<double>& s, std::chrono::milliseconds forced = {}) {
    long long ms = forced.count() > 0 ? forced.count() : (t - kept_t_).count() + carry_;
    long long frames = (ms + frame_ms_ / 2) / frame_ms_;
    if (frames < 1) frames = 1;
    if (frames > 255) frames = 255;
    if (forced.count() == 0) carry_ = ms - frames * frame_ms_;  // what rounding took, given back next time
    poses_.push_back({s, std::chrono::milliseconds(frames * frame_ms_)});
    kept_ = s;
    kept_t_ = t;
  }

  std::vector<const joint*> joints_;
  double threshold_;
  long long frame_ms_;
  std::chrono::milliseconds lead_in_;
  long long longest_ms_;
  std::vector<recorded_pose> poses_;
  std::vector<double> kept_;
  std::chrono::milliseconds kept_t_{0}, last_t_{0};
  std::vector<timed> pending_;
  long long carry_ = 0;
  std::size_t samples_ = 0, clamped_ = 0;
};

}  // namespace rcb4::robot
