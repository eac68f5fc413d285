// rcb4 ui: the pages' actions carried out on the board (see board_loop_class.hpp): joint moves,
// free and hold, stop, saved poses captured and played, the ROM's motions played, stopped, read.
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

/** Moves @p targets (checked here again: nothing from a page is trusted). */
json board_loop::move(std::vector<robot::joint_target> targets) {
  refuse_during_motion();
  if (studio_.playing()) throw refusal{"a motion plays from the host: it would overwrite the move (Stop it first)"};
  // A CONST frame carries 255 frames at most (protocol.md §5): 2.55 s on a 10 ms board. A longer
  // time (a page's, or the speed limit's) becomes the slowest move the board can make.
  for (auto& t : targets)
    if (t.time && *t.time > slowest()) t.time = slowest();
  auto checked = robot::check_targets(m_, targets, 0ms);
  if (!robot::ok(checked)) throw refusal{std::get<robot::problem>(checked).message};
  auto moves = std::get<std::vector<robot::joint_move>>(std::move(checked));
  located();
  for (const auto& mv : moves)
    if (!map_.block_of(*mv.j)) throw refusal{mv.j->name + ": the board has no servo block for it (see rcb4 scan)"};
  robot::move_joints op(std::move(moves));
  t::error_code ec;
  s_.run_steps(op, ec, [] {});
  if (ec) throw refusal{words_of(ec, "move")};
  move_at_ms_ = std::chrono::duration<double, std::milli>(std::chrono::system_clock::now().time_since_epoch()).count();
  std::chrono::milliseconds longest{0};
  for (const auto& mv : op.value())
    longest = std::max(longest, std::chrono::milliseconds(mv.frames * rcb4::milliseconds(op.period())));
  return json{{"ms", longest.count()}, {"joints", op.value().size()}};
}

rcb4::servo_mask board_loop::mask_of(const std::vector<const robot::joint*>& joints,
                                     std::vector<std::string>* missing) {
  located();
  rcb4::servo_mask mask;
  for (const auto* j : joints) {
    if (map_.block_of(*j))
      mask.insert(j->ics);
    else if (missing)
      missing->push_back(j->name);
  }
  return mask;
}

json board_loop::stop_motions_first(bool rom_motion) {
  json out = json::object();
  // A motion played from the host stops first: its next pose must not follow what comes next.
  if (studio_.playing()) {
    try {
      studio_.stop();
    } catch (const std::exception&) {  // the board may not answer: what comes next is tried anyway
    }
    out["play_stopped"] = true;
  }
  if (!rom_motion) return out;
  // The state is read now, not taken from the last poll: a motion started since must stop too.
  // Only a motion is stopped: with none (the program in its main loop) the program stays on, so
  // the remote's buttons still play their motions.
  bool running = true;
  try {
    const auto st = must(ops::read_motion_state(*o_.layout), "read the motion state");
    running = st.running && st.motion;
  } catch (const refusal&) {
    // Unknown: stop it anyway.
  }
  if (running) {
    insist([] { return ops::stop_motion{}; }, "stop the motion");
    out["motion_stopped"] = true;
  }
  return out;
}

json board_loop::act(const power_action& a) {
  std::vector<std::string> missing;
  const auto mask = mask_of(a.joints, &missing);
  if (mask.empty()) throw refusal{"none of these joints has a servo block on the board (see rcb4 scan)"};
  // A motion's next pose would power the joints again (a free robot jerked back mid-fall), or move
  // held ones on: whatever plays stops first, and the answer says so.
  json out = stop_motions_first(true);
  // The board's stop lets the pose under way run on: with a ROM motion stopped, every joint holds
  // where it is first, so the joints not named stop too (a host play's stop holds them itself).
  if (out.contains("motion_stopped")) hold_all();
  must(ops::set_servo_power(a.free ? ops::power_state::free : ops::power_state::hold, mask), a.free ? "free" : "hold");
  out["joints"] = a.joints.size() - missing.size();
  out["missing"] = missing;
  return out;
}

json board_loop::act(const stop_action& a) {
  // Stopping a motion comes first (it would drive the joints again), then the hold.
  json out = stop_motions_first(a.motion);
  const auto mask = mask_of(a.joints, nullptr);
  if (!mask.empty()) insist([&] { return ops::set_servo_power(ops::power_state::hold, mask); }, "hold");
  out["held"] = a.joints.size();
  return out;
}

std::filesystem::path board_loop::pose_path(const std::string& name, bool for_reading) const {
  try {
    return ui::pose_path(o_.poses, name, for_reading);
  } catch (const studio_refusal& e) {
    throw refusal{e.what()};
  }
}

json board_loop::act(const capture_action& a) {
  const auto path = pose_path(a.name, false);
  std::error_code fec;
  if (!a.force && std::filesystem::exists(path, fec))
    throw refusal{fmt::format("a pose called '{}' exists already: replace it, or choose another name", a.name)};
  located();
  auto rs =
      must(robot::read_joints(map_, robot::fields::positions, ops::link_cost::at(s_.baud(), 1ms)), "read the joints");
  robot::pose p{m_.name(), {}, std::nullopt};
  std::vector<std::string> left_out, clamped;
  for (const auto& r : rs) {
    if (const auto d = r.degrees()) {
      // Hundredths, within the limits, so that the pose can be played; a joint beyond them (a
      // motion can put it there) is named in the answer.
      const double h = std::round(*d * 100) / 100;
      const double within = std::clamp(h, r.j->lower, r.j->upper);
      if (std::abs(within - h) >= 0.05)
        clamped.push_back(fmt::format("{} {} (at {:.1f}, beyond its limit)", r.j->name, robot::number_text(within), h));
      p.joints.emplace_back(r.j->name, within);
    } else {
      left_out.push_back(r.j->name);
    }
  }
  if (p.joints.empty()) throw refusal{"no joint answered: nothing to capture"};
  try {
    std::filesystem::create_directories(o_.poses);
    robot::save_pose(path, p);
  } catch (const std::exception& e) {
    throw refusal{fmt::format("cannot save {}: {}", path.string(), plain_message(e.what()))};
  }
  refresh_lists();
  return json{{"name", a.name},
              {"file", path.string()},
              {"joints", p.joints.size()},
              {"left_out", left_out},
              {"clamped", clamped}};
}

json board_loop::act(const play_pose_action& a) {
  const auto path = pose_path(a.name, true);
  robot::pose p;
  try {
    p = robot::load_pose(path, m_);
  } catch (const std::exception& e) {
    throw refusal{std::string(plain_message(e.what()))};
  }
  // The farthest joint sets the pace: no joint moves faster than the speed limit.
  double span = 0;
  std::string farthest;
  for (const auto& [name, d] : p.joints) {
    const auto* j = m_.find(name);
    const auto i = static_cast<std::size_t>(j - m_.joints().data());
    const double away = angles_[i] ? std::abs(d - *angles_[i]) : j->upper - j->lower;
    if (away > span) {
      span = away;
      farthest = name;
    }
  }
  const double speed = h_.limits().max_speed;
  if (span / speed * 1000 > static_cast<double>(slowest().count()))
    throw refusal{fmt::format(
        "{} is {:.0f} degrees from {}: at the speed limit ({} degrees a second) that takes {:.1f} s, longer than "
        "the slowest move this board makes ({:.2f} s): bring the joint closer first, or raise --speed",
        farthest, span, a.name, robot::number_text(speed), span / speed,
        std::chrono::duration<double>(slowest()).count())};
  auto time = a.ms ? std::chrono::milliseconds(*a.ms) : p.time.value_or(h_.limits().default_pose_ms);
  if (time > slowest())
    throw refusal{fmt::format("a move takes at most 255 output periods: {} ms at this board's {} ms period, not {} ms",
                              slowest().count(), rcb4::milliseconds(period_), time.count())};
  if (a.ms && *a.ms % static_cast<int>(rcb4::milliseconds(period_)) != 0)  // asked for: refused, never rounded
    throw refusal{fmt::format("{} ms is not a whole number of this board's {} ms output periods", *a.ms,
                              rcb4::milliseconds(period_))};
  time = std::max(time, paced_time(span, h_.limits()));
  std::vector<robot::joint_target> targets;
  for (const auto& [name, d] : p.joints) targets.push_back({name, d, time});
  auto out = move(std::move(targets));
  out["name"] = a.name;
  return out;
}

json board_loop::act(const motion_play_action& a) {
  must(ops::play_motion(a.slot, *o_.layout, ops::servo_power::keep), "play the motion");
  return json{{"slot", a.slot}};
}

json board_loop::act(const motion_stop_action&) {
  json out = stop_motions_first(false);  // a motion played from the host is a motion too
  insist([] { return ops::stop_motion{}; }, "stop the motion");
  // The board's own stop lets the pose under way run on (up to 2.55 s): every joint holds where it
  // is now, as the header's Stop does, so the robot stops when the button says so.
  out["held"] = hold_all();
  return out;
}

std::size_t board_loop::hold_all() {
  std::vector<const robot::joint*> all;
  for (const auto& j : m_.joints()) all.push_back(&j);
  const auto mask = mask_of(all, nullptr);
  if (!mask.empty()) insist([&] { return ops::set_servo_power(ops::power_state::hold, mask); }, "hold");
  return all.size();
}

json board_loop::act(const refresh_action&) {
  refresh_lists();
  return nullptr;
}

/** The slot read back as `rcb4 motion pull` writes it. */
json board_loop::act(const motion_file_action& a) {
  const auto where = rcb4::motion::slot_of(*o_.layout, a.slot);
  if (!where || a.slot > o_.layout->motion_count)
    throw refusal{fmt::format("motion {} is outside this board's layout ({} slots)", a.slot, o_.layout->motion_count)};
  const auto bytes = must(ops::read_memory(ops::memory::rom, where->address.value(), where->size), "read the motion");
  if (bytes.empty() || bytes[0] == 0xFF) throw refusal{fmt::format("motion {} is empty", a.slot)};
  const auto l = rcb4::motion::disassemble(bytes, *where);
  if (!l.problems.empty()) throw refusal{fmt::format("motion {}: {}", a.slot, l.problems.front())};
  const auto p = rcb4::motion::lift(l);
  if (!rcb4::motion::ok(p))
    throw refusal{fmt::format("motion {} is code a motion file cannot say: {} (rcb4 motion show {} lists it)", a.slot,
                              std::get<rcb4::motion::failure>(p).message, a.slot)};
  auto d = robot::from_program(std::get<rcb4::motion::program>(p), m_, *o_.layout, period_);
  d.name = robot::services::slot_name(m_, a.slot, bytes);
  const auto again = robot::to_program(d, m_, *o_.layout, period_);
  return json{{"slot", a.slot},
              {"name", d.name},
              {"yaml", robot::motion_yaml(d, fmt::format("motion {} of the board, read by rcb4 ui", a.slot))},
              {"problem", robot::ok(again) ? json(nullptr) : json(std::get<robot::problem>(again).message)}};
}

}  // namespace cli::ui
