// rcb4 ui: the policy between the pages and the robot (see controller.hpp).
// SPDX-License-Identifier: BSL-1.0
#include "controller.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <utility>

namespace cli::ui {
namespace {

using json = nlohmann::ordered_json;
namespace robot = rcb4::robot;

/** JSON with bad UTF-8 replaced, never a throw (names come from pages). */
std::string dump(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

}  // namespace

std::string error_text(std::optional<std::int64_t> id, std::string_view op, std::string_view message) {
  json j;
  j["type"] = "error";
  j["id"] = id ? json(*id) : json(nullptr);
  j["op"] = op.empty() ? json(nullptr) : json(std::string(op));
  j["message"] = std::string(message);
  return dump(j);
}

std::string reply_text(std::optional<std::int64_t> id, std::string_view op, std::string_view extra) {
  json j;
  j["type"] = "reply";
  j["id"] = id ? json(*id) : json(nullptr);
  j["op"] = std::string(op);
  j["ok"] = true;
  if (!extra.empty()) {
    const auto more = json::parse(extra, nullptr, false);
    if (more.is_object())
      for (const auto& [k, v] : more.items()) j[k] = v;
  }
  return dump(j);
}

std::chrono::milliseconds paced_time(double degrees, const settings& s) {
  const double ms = std::abs(degrees) / s.max_speed * 1000.0;
  const auto t = std::chrono::milliseconds(static_cast<long long>(std::ceil(ms)));
  return std::clamp(t, s.move_interval, std::chrono::milliseconds(max_move_ms));
}

controller::controller(const robot::model& m, settings s)
    : model_(&m),
      settings_(s),
      observed_(m.joints().size()),
      measured_(m.joints().size()),
      commanded_(m.joints().size()) {}

std::size_t controller::index_of(const robot::joint* j) const noexcept {
  return static_cast<std::size_t>(j - model_->joints().data());
}

letter controller::role_letter(client_id c) const {
  json j;
  j["type"] = "role";
  j["role"] = controller_ == c ? "control" : "view";
  j["controlled"] = controller_.has_value();
  return {c, dump(j)};
}

void controller::roles_to_all(effects& e) const {
  for (const auto& [c, p] : pages_) e.letters.push_back(role_letter(c));
}

effects controller::join(client_id c) {
  effects e;
  page p;
  p.tokens = settings_.message_burst;
  pages_[c] = p;
  if (!controller_) {
    controller_ = c;
    moved_.clear();
    started_motion_ = false;
    roles_to_all(e);
  } else {
    e.letters.push_back(role_letter(c));
  }
  return e;
}

effects controller::leave(client_id c) {
  effects e;
  if (pages_.erase(c) == 0) return e;
  if (controller_ != c) return e;
  controller_.reset();
  pending_.clear();
  stop_action stop;
  // A motion it started (ROM or from the host) moves every servo the motion names, up to a 2.55 s
  // pose after its stop: every joint holds where it is then (docs/browser.md); else the ones it moved.
  if (started_motion_)
    for (const auto& j : model_->joints()) stop.joints.push_back(&j);
  else
    for (auto i : moved_) stop.joints.push_back(&model_->joints()[i]);
  stop.motion = started_motion_;
  if (!stop.joints.empty() || stop.motion) e.actions.push_back({c, std::nullopt, std::move(stop)});
  moved_.clear();
  started_motion_ = false;
  roles_to_all(e);
  return e;
}

bool controller::admit(client_id c, clock::time_point now, effects& e) {
  auto& p = pages_[c];
  if (p.refilled != clock::time_point{}) {
    const double s = std::chrono::duration<double>(now - p.refilled).count();
    if (s > 0) p.tokens = std::min(settings_.message_burst, p.tokens + s * settings_.messages_per_second);
  }
  p.refilled = now;
  if (p.tokens >= 1) {
    p.tokens -= 1;
    p.warned = false;
    return true;
  }
  if (!p.warned) {
    p.warned = true;
    e.letters.push_back(
        {c, error_text(std::nullopt, {},
                       "too many messages: at most " + robot::number_text(settings_.messages_per_second) +
                           " a second; the others are dropped")});
  }
  return false;
}

effects controller::receive(client_id c, std::string_view text, clock::time_point now) {
  effects e;
  if (!pages_.count(c)) return e;
  auto parsed = parse_message(text);
  // Stop is never dropped by the rate limit: it is what a flooded robot needs most.
  const auto* msg = std::get_if<message>(&parsed);
  const bool stop = msg && std::holds_alternative<stop_request>(msg->body);
  if (!stop && !admit(c, now, e)) return e;
  if (auto* bad = std::get_if<parse_error>(&parsed)) {
    e.letters.push_back({c, error_text(bad->id, {}, bad->what)});
    return e;
  }
  handle(c, std::get<message>(parsed), e);
  return e;
}

void controller::handle(client_id c, const message& m, effects& e) {
  const auto op = op_name(m.body);
  const auto refuse = [&](std::string_view why) { e.letters.push_back({c, error_text(m.id, op, why)}); };

  if (std::holds_alternative<take_control>(m.body)) {
    if (controller_ == c) {
      e.letters.push_back({c, reply_text(m.id, op)});
    } else if (controller_) {
      refuse("another page controls the robot; it must release control or close first");
    } else {
      controller_ = c;
      moved_.clear();
      started_motion_ = false;
      e.letters.push_back({c, reply_text(m.id, op)});
      roles_to_all(e);
    }
    return;
  }
  if (std::holds_alternative<refresh_request>(m.body)) {  // reading changes nothing: any page
    e.actions.push_back({c, m.id, refresh_action{}});
    return;
  }
  if (const auto* mf = std::get_if<motion_file_request>(&m.body)) {  // reading too
    e.actions.push_back({c, m.id, motion_file_action{mf->slot}});
    return;
  }
  if (const auto* st = std::get_if<studio_request>(&m.body); st && !st->writes) {  // reading: any page
    e.actions.push_back({c, m.id, studio_action{st->op, st->args}});
    return;
  }
  // Stop is the one control every page keeps, a watching one too (its controlling page may hang or
  // be on another screen): every joint holds where it is, a motion stops. It only ever stops.
  if (std::holds_alternative<stop_request>(m.body)) {
    pending_.clear();
    for (auto& target : commanded_) target.reset();
    stop_action s;
    for (const auto& j : model_->joints()) s.joints.push_back(&j);
    s.motion = true;
    e.actions.push_back({c, m.id, std::move(s)});
    return;
  }
  if (std::holds_alternative<motion_stop_request>(m.body)) {
    e.actions.push_back({c, m.id, motion_stop_action{}});
    return;
  }
  if (controller_ != c) {
    refuse("this page only watches: take control first");
    return;
  }
  if (const auto* st = std::get_if<studio_request>(&m.body)) {
    // A motion played from the host or a button pressed is stopped when the page goes, as a ROM motion it started.
    if (st->op == "play_motion" || st->op == "button_press") started_motion_ = true;
    pending_.clear();  // a slider value still waiting would fight what the studio does
    e.actions.push_back({c, m.id, studio_action{st->op, st->args}});
    return;
  }
  if (std::holds_alternative<release_control>(m.body)) {
    // Releasing is not losing the page: the moves it made stay.
    controller_.reset();
    pending_.clear();
    moved_.clear();
    started_motion_ = false;
    e.letters.push_back({c, reply_text(m.id, op)});
    roles_to_all(e);
    return;
  }
  if (const auto* mv = std::get_if<move_request>(&m.body)) {
    // Check every name first: a move with an unknown joint moves nothing.
    std::vector<std::pair<std::size_t, double>> accepted;
    json clamped = json::array();
    for (const auto& [name, degrees] : mv->joints) {
      const auto* j = model_->find(name);
      if (!j) {
        refuse("no joint is called '" + name + "'");
        return;
      }
      const auto i = index_of(j);
      if (std::any_of(accepted.begin(), accepted.end(), [&](const auto& a) { return a.first == i; })) {
        refuse(name + " is given twice");
        return;
      }
      const double d = std::clamp(degrees, j->lower, j->upper);
      if (d != degrees)
        clamped.push_back(name + ": " + robot::number_text(degrees) + " is beyond its " +
                          (degrees < j->lower ? "lower" : "upper") + " limit " + robot::number_text(d) + ": moved to " +
                          robot::number_text(d));
      accepted.emplace_back(i, d);
    }
    for (const auto& [i, d] : accepted) pending_[i] = {d, mv->ms, c, m.id};
    if (!clamped.empty()) {
      json n;
      n["type"] = "note";
      n["id"] = m.id ? json(*m.id) : json(nullptr);
      n["op"] = "move";
      n["clamped"] = clamped;
      e.letters.push_back({c, dump(n)});
    }
    // A move with an id is answered by the board loop once sent (or refused there).
    return;
  }
  if (const auto* p = std::get_if<power_request>(&m.body)) {
    std::vector<const robot::joint*> joints;
    for (const auto& w : p->words) {
      auto sel = model_->select(w);
      if (!robot::ok(sel)) {
        refuse(std::get<robot::problem>(sel).message);
        return;
      }
      for (const auto* j : std::get<std::vector<const robot::joint*>>(sel))
        if (std::find(joints.begin(), joints.end(), j) == joints.end()) joints.push_back(j);
    }
    // A freed joint must not be driven again by a slider value still waiting; a freed or held
    // joint is where it is now, not where it was last sent.
    for (const auto* j : joints) {
      pending_.erase(index_of(j));
      commanded_[index_of(j)].reset();
    }
    e.actions.push_back({c, m.id, power_action{p->free, std::move(joints)}});
    return;
  }
  if (const auto* cap = std::get_if<capture_request>(&m.body)) {
    e.actions.push_back({c, m.id, capture_action{cap->name, cap->force}});
    return;
  }
  if (const auto* pp = std::get_if<play_pose_request>(&m.body)) {
    pending_.clear();
    for (std::size_t i = 0; i < model_->joints().size(); ++i) moved_.insert(i);
    e.actions.push_back({c, m.id, play_pose_action{pp->name, pp->ms}});
    return;
  }
  if (const auto* mp = std::get_if<motion_play_request>(&m.body)) {
    pending_.clear();
    started_motion_ = true;
    e.actions.push_back({c, m.id, motion_play_action{mp->slot}});
    return;
  }
}

std::optional<action> controller::due_move(clock::time_point now) {
  if (pending_.empty()) return std::nullopt;
  if (last_move_ && now - *last_move_ < settings_.move_interval) return std::nullopt;
  move_action mv;
  client_id from = 0;
  std::optional<std::int64_t> id;
  for (auto it = pending_.begin(); it != pending_.end();) {
    const auto i = it->first;
    const auto& p = it->second;
    const auto& j = model_->joints()[i];
    // Timed from the farthest of what the board shows and what was last sent: never too fast.
    double span = 0;
    bool known = false;
    for (const auto& from_deg : {observed_[i], measured_[i], commanded_[i]})
      if (from_deg) {
        span = std::max(span, std::abs(p.degrees - *from_deg));
        known = true;
      }
    if (!known) span = j.upper - j.lower;  // nowhere known (never read): as if across the whole range
    const auto paced = paced_time(span, settings_);
    auto t = p.ms ? std::max(paced, std::chrono::milliseconds(*p.ms)) : paced;
    double degrees = p.degrees;
    bool arrived = true;
    const auto start = observed_[i] ? observed_[i] : measured_[i];
    if (paced > longest_ && start) {
      // Farther than the board's longest move covers at the speed limit: go part way from where
      // the board is; the rest follows once this interval is over.
      const double step = settings_.max_speed * std::chrono::duration<double>(longest_).count();
      degrees = *start + std::clamp(p.degrees - *start, -step, step);
      arrived = std::abs(degrees - p.degrees) < 1e-9;
      t = longest_;
    } else if (t > longest_) {
      t = longest_;
    }
    mv.targets.push_back({j.name, degrees, t});
    commanded_[i] = degrees;
    moved_.insert(i);
    from = p.from;
    if (p.id) id = std::exchange(it->second.id, std::nullopt);
    it = arrived ? pending_.erase(it) : std::next(it);
  }
  last_move_ = now;
  return action{from, id, std::move(mv)};
}

std::optional<clock::time_point> controller::move_due_at() const {
  if (pending_.empty()) return std::nullopt;
  if (!last_move_) return clock::time_point::min();
  return *last_move_ + settings_.move_interval;
}

void controller::observe(std::span<const std::optional<double>> targets, std::span<const std::optional<double>> angles,
                         std::chrono::milliseconds longest) {
  for (std::size_t i = 0; i < observed_.size() && i < targets.size(); ++i) observed_[i] = targets[i];
  for (std::size_t i = 0; i < measured_.size() && i < angles.size(); ++i) measured_[i] = angles[i];
  longest_ = longest;
}

}  // namespace cli::ui
