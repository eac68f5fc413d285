// rcb4 ui: the board loop reading the robot (see board_loop_class.hpp): the joints, battery, AD
// channels, motion and link counters as the state every page gets; the pose and motion lists.
// SPDX-License-Identifier: BSL-1.0
#include "board_loop_class.hpp"

#include <rcb4/motion/disassemble.hpp>
#include <rcb4/robot/motion_file.hpp>
#include <rcb4/robot/services/slot_names.hpp>

#include <algorithm>
#include <cmath>
#include <system_error>

namespace cli::ui {

namespace robot = rcb4::robot;
namespace ops = rcb4::ops;
using namespace std::chrono_literals;

// --- reading -------------------------------------------------------------------------------
/** Reads the robot and sends the state; @p joints_only (the read after a slider move) keeps the rest as last read. */
void board_loop::poll(bool joints_only) {
  t::error_code ec;
  if (!reader_) locate(ec);
  if (!ec) {
    reader_->restart();
    s_.run_steps(*reader_, ec, [] {});
  }
  std::optional<ops::analog_inputs> analog;
  std::optional<ops::motion_state> motion;
  joints_only = joints_only && answering_;
  if (!ec && !joints_only) analog = run_ec(ops::read_analog{}, ec);
  if (!ec && !joints_only) motion = run_ec(ops::read_motion_state(*o_.layout), ec);
  if (!ec && !joints_only) {
    const auto cfg = run_ec(ops::read_config{}, ec);
    rom_program_ = cfg.rom_program;
    period_ = cfg.period;
  }
  answering_ = !ec;
  if (ec) {
    error_ = words_of(ec, "reading the robot");
    reader_.reset();  // locate again: the board may have been reset or replaced
    std::fill(angles_.begin(), angles_.end(), std::nullopt);
    std::fill(targets_.begin(), targets_.end(), std::nullopt);
    motion_ = {};
  } else {
    const auto& rs = reader_->value();
    for (std::size_t i = 0; i < rs.size(); ++i) {
      angles_[i] = rs[i].degrees();
      targets_[i] = rs[i].target_degrees();
      modes_[i] = !rs[i].allocated    ? "missing"
                  : rs[i].is_free()   ? "free"
                  : rs[i].is_hold()   ? "hold"
                  : !rs[i].answered() ? "silent"
                                      : "on";
    }
    if (motion) motion_ = *motion;
    if (analog) analog_ = *analog;
  }
  h_.observe(targets_, angles_, slowest());
  h_.set_state(state_text());
}

void board_loop::locate(t::error_code& ec) {
  auto op = robot::locate_joints(m_);
  s_.run_steps(op, ec, [] {});
  if (ec) return;
  map_ = op.value();
  reader_.emplace(map_, robot::fields::state, ops::link_cost::at(s_.baud(), 1ms));
}

std::string board_loop::state_text() {
  const auto now = clock::now();
  const auto& k = s_.c().counters();
  const auto exchanges = k.exchanges.load();
  if (now - last_rate_at_ >= 1s) {
    rate_ =
        static_cast<double>(exchanges - last_exchanges_) / std::chrono::duration<double>(now - last_rate_at_).count();
    last_exchanges_ = exchanges;
    last_rate_at_ = now;
  }
  json j;
  j["type"] = "state";
  j["seq"] = ++seq_;
  j["answering"] = answering_;
  j["error"] = answering_ ? json(nullptr) : json(error_);
  json a = json::array(), g = json::array(), md = json::array();
  for (std::size_t i = 0; i < angles_.size(); ++i) {
    a.push_back(angle_json(angles_[i]));
    g.push_back(angle_json(targets_[i]));
    md.push_back(answering_ ? modes_[i] : "unknown");
  }
  j["angles"] = std::move(a);
  j["targets"] = std::move(g);
  j["modes"] = std::move(md);
  j["output_period_ms"] = rcb4::milliseconds(period_);  // the board's: a move's time is whole periods of it
  if (answering_) {
    j["battery"] = std::round(analog_.battery_volts * 100) / 100;
    json ad = json::array();
    for (std::size_t c = 1; c < analog_.values.size(); ++c) ad.push_back(analog_.values[c]);
    j["ad"] = std::move(ad);
  } else {
    j["battery"] = nullptr;
    j["ad"] = nullptr;
  }
  json mo;
  mo["running"] = motion_.running;
  mo["slot"] = motion_.motion ? json(*motion_.motion) : json(nullptr);
  mo["rom_program"] = rom_program_;
  // A CALL still pending with the program switched off: stopped part way (motion_stop).
  mo["suspended"] = motion_.suspended;
  mo["progress"] = nullptr;
  if (motion_.motion)
    for (const auto& v : motions_)
      if (v.number == *motion_.motion && v.size > 0 && motion_.program_counter >= v.address)
        mo["progress"] =
            std::round(std::min(1.0, (motion_.program_counter - v.address) / static_cast<double>(v.size)) * 1000) /
            1000;
  j["motion"] = std::move(mo);
  json link;
  link["exchanges"] = exchanges;
  link["per_second"] = std::round(rate_ * 10) / 10;
  link["errors"] = k.errors.load();
  link["timeouts"] = k.timeouts.load();
  link["nacks"] = k.nacks.load();
  // When the board acknowledged the last joint move (wall clock, ms since 1970): a page compares it
  // with performance.timeOrigin + performance.now() to time a slider change to the board.
  link["move_at_ms"] = move_at_ms_ ? json(std::round(*move_at_ms_ * 10) / 10) : json(nullptr);
  j["link"] = std::move(link);
  return text_of(j);
}

// --- lists ---------------------------------------------------------------------------------
std::vector<std::string> board_loop::pose_names() const {
  std::vector<std::string> out;
  t::error_code ec;
  for (auto it = std::filesystem::directory_iterator(o_.poses, ec); !ec && it != std::filesystem::directory_iterator();
       it.increment(ec)) {
    const auto& p = it->path();
    if (!(p.extension() == ".yaml" || p.extension() == ".json") || !it->is_regular_file(ec)) continue;
    const auto stem = p.stem().string();
    if (valid_pose_name(stem) && std::find(out.begin(), out.end(), stem) == out.end()) out.push_back(stem);
  }
  std::sort(out.begin(), out.end());
  return out;
}

void board_loop::refresh_lists() {
  if (answering_) {
    ops::list_motions op(*o_.layout);
    t::error_code ec;
    s_.run_steps(op, ec, [] {});
    if (!ec) motions_ = op.value();
  }
  json j;
  j["type"] = "lists";
  j["poses"] = pose_names();
  json ms = json::array();
  for (const auto& v : motions_) {
    const auto name = robot::services::slot_name(m_, v.number, v.code);
    ms.push_back({{"slot", v.number},
                  {"name", name.empty() ? json(nullptr) : json(std::string(name))},
                  {"frames", v.frames},
                  {"readable", v.readable}});
  }
  j["motions"] = std::move(ms);
  j["poses_dir"] = o_.poses.string();
  h_.set_lists(text_of(j));
}

}  // namespace cli::ui
