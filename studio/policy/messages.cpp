// rcb4 ui: parsing a page's messages (see messages.hpp for the format).
// SPDX-License-Identifier: BSL-1.0
#include "messages.hpp"

#include "message_parts.hpp"

#include <cmath>
#include <cstdint>
#include <set>

namespace cli::ui {
namespace {

using namespace detail;

/** Deepest nesting a message may have: {"joints":{"a":1}} is 2, an array in there would be 3. */
constexpr int max_depth = 3;

/** True when @p text nests objects/arrays deeper than max_depth (strings skipped). */
bool too_deep(std::string_view text) {
  int depth = 0;
  bool in_string = false, escaped = false;
  for (char c : text) {
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"')
      in_string = true;
    else if (c == '{' || c == '[') {
      if (++depth > max_depth) return true;
    } else if (c == '}' || c == ']') {
      --depth;
    }
  }
  return false;
}

request body_of(const json& o, const std::string& op) {
  // The ops without fields of their own.
  const std::pair<std::string_view, request> bare[] = {{"control", take_control{}},
                                                       {"release", release_control{}},
                                                       {"stop", stop_request{}},
                                                       {"motion_stop", motion_stop_request{}},
                                                       {"refresh", refresh_request{}}};
  for (const auto& [name, r] : bare)
    if (op == name) {
      only_keys(o, op, {"op", "id"});
      return r;
    }
  if (op == "move") {
    only_keys(o, op, {"op", "id", "joints", "ms"});
    const auto& js = required(o, op, "joints");
    if (!js.is_object() || js.empty()) throw refused{"move: 'joints' must be an object of joint names and degrees"};
    move_request m;
    for (const auto& [k, v] : js.items()) {
      if (k.empty() || k.size() > max_name_bytes) throw refused{"move: a joint name must be 1..64 bytes"};
      if (!v.is_number()) throw refused{"move: " + shown(k) + " must be a number of degrees"};
      const double d = v.get<double>();
      if (!std::isfinite(d)) throw refused{"move: " + shown(k) + " must be a finite number of degrees"};
      m.joints.emplace_back(k, d);
    }
    m.ms = ms_of(o, op);
    return m;
  }
  if (op == "free" || op == "hold") {
    only_keys(o, op, {"op", "id", "joints"});
    power_request p;
    p.free = op == "free";
    const auto& js = required(o, op, "joints");
    if (!js.is_array() || js.empty())
      throw refused{op + ": 'joints' must be a list of joint or group names, or [\"all\"]"};
    for (const auto& v : js) p.words.push_back(name_of(v, op, "joints"));
    return p;
  }
  if (op == "capture") {
    only_keys(o, op, {"op", "id", "name", "force"});
    capture_request c;
    c.name = name_of(required(o, op, "name"), op, "name");
    if (!valid_pose_name(c.name)) throw refused{"capture: a pose name uses A-Z, a-z, 0-9, _ and -"};
    c.force = flag_of(o, op, "force");
    return c;
  }
  if (op == "play_pose") {
    only_keys(o, op, {"op", "id", "name", "ms"});
    play_pose_request p;
    p.name = name_of(required(o, op, "name"), op, "name");
    if (!valid_pose_name(p.name)) throw refused{"play_pose: a pose name uses A-Z, a-z, 0-9, _ and -"};
    p.ms = ms_of(o, op);
    return p;
  }
  if (op == "motion_play") {
    only_keys(o, op, {"op", "id", "slot"});
    const auto& s = required(o, op, "slot");
    if (!s.is_number_integer()) throw refused{"motion_play: 'slot' must be a whole number"};
    const auto v = s.get<std::int64_t>();
    if (v < 1 || v > 120) throw refused{"motion_play: slot " + std::to_string(v) + " is outside 1..120"};
    return motion_play_request{static_cast<unsigned>(v)};
  }
  if (op == "motion_file") {
    only_keys(o, op, {"op", "id", "slot"});
    const auto& s = required(o, op, "slot");
    if (!s.is_number_integer()) throw refused{"motion_file: 'slot' must be a whole number"};
    const auto v = s.get<std::int64_t>();
    if (v < 1 || v > 120) throw refused{"motion_file: slot " + std::to_string(v) + " is outside 1..120"};
    return motion_file_request{static_cast<unsigned>(v)};
  }
  if (auto r = studio_body_of(o, op)) return std::move(*r);
  throw refused{"unknown op " + shown(op) +
                " (known: control, release, move, free, hold, stop, capture, play_pose, motion_play, "
                "motion_stop, refresh, motion_file, " +
                std::string(studio_ops_list) + ")"};
}

}  // namespace

bool valid_pose_name(std::string_view name) noexcept {
  if (name.empty() || name.size() > max_name_bytes) return false;
  for (char c : name)
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-'))
      return false;
  return true;
}

std::string_view op_name(const request& r) noexcept {
  struct namer {
    std::string_view operator()(const take_control&) const { return "control"; }
    std::string_view operator()(const release_control&) const { return "release"; }
    std::string_view operator()(const move_request&) const { return "move"; }
    std::string_view operator()(const power_request& p) const { return p.free ? "free" : "hold"; }
    std::string_view operator()(const stop_request&) const { return "stop"; }
    std::string_view operator()(const capture_request&) const { return "capture"; }
    std::string_view operator()(const play_pose_request&) const { return "play_pose"; }
    std::string_view operator()(const motion_play_request&) const { return "motion_play"; }
    std::string_view operator()(const motion_stop_request&) const { return "motion_stop"; }
    std::string_view operator()(const refresh_request&) const { return "refresh"; }
    std::string_view operator()(const motion_file_request&) const { return "motion_file"; }
    std::string_view operator()(const studio_request& s) const { return s.op; }
  };
  return std::visit(namer{}, r);
}

std::variant<message, parse_error> parse_message(std::string_view text) {
  if (text.size() > max_message_bytes)
    return parse_error{std::nullopt, "message of " + std::to_string(text.size()) + " bytes: at most " +
                                         std::to_string(max_message_bytes)};
  if (too_deep(text)) return parse_error{std::nullopt, "message nested too deeply"};
  // Duplicate keys would silently keep one value: refuse them while parsing.
  std::vector<std::set<std::string>> keys;
  bool duplicate = false;
  const json::parser_callback_t cb = [&](int, json::parse_event_t ev, json& parsed) {
    if (ev == json::parse_event_t::object_start)
      keys.emplace_back();
    else if (ev == json::parse_event_t::object_end && !keys.empty())
      keys.pop_back();
    else if (ev == json::parse_event_t::key && !keys.empty())
      duplicate = !keys.back().insert(parsed.get<std::string>()).second || duplicate;
    return true;
  };
  json o;
  try {
    o = json::parse(text.begin(), text.end(), cb, false);
  } catch (const std::exception& e) {  // the callback's get<> cannot fail on a key; kept total anyway
    return parse_error{std::nullopt, std::string("malformed message: ") + e.what()};
  }
  if (o.is_discarded()) return parse_error{std::nullopt, "not a JSON text"};
  if (!o.is_object()) return parse_error{std::nullopt, "a message is a JSON object with an \"op\""};
  std::optional<std::int64_t> id;
  if (const auto it = o.find("id"); it != o.end()) {
    if (!it->is_number_integer()) return parse_error{std::nullopt, "'id' must be a whole number"};
    if (it->is_number_unsigned() && it->get<std::uint64_t>() > static_cast<std::uint64_t>(INT64_MAX))
      return parse_error{std::nullopt, "'id' is too large"};
    id = it->get<std::int64_t>();
  }
  if (duplicate) return parse_error{id, "a key is given twice"};
  const auto op = o.find("op");
  if (op == o.end() || !op->is_string()) return parse_error{id, "a message needs \"op\": a string"};
  try {
    return message{id, body_of(o, op->get<std::string>())};
  } catch (const refused& r) {
    return parse_error{id, r.what};
  } catch (const std::exception& e) {
    return parse_error{id, std::string("malformed message: ") + e.what()};
  }
}

}  // namespace cli::ui
