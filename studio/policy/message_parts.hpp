// rcb4 ui: the checks the message parsers share (messages.cpp, studio_messages.cpp); private.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include "messages.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>

namespace cli::ui::detail {

using json = nlohmann::ordered_json;

struct refused {
  std::string what;
};

inline std::string shown(std::string_view s) {
  std::string out = "'";
  for (char c : s.substr(0, max_name_bytes)) out += (static_cast<unsigned char>(c) < 0x20) ? '?' : c;
  if (s.size() > max_name_bytes) out += "...";
  return out + "'";
}

/** The keys of @p o must all be in @p known. */
inline void only_keys(const json& o, std::string_view op, std::initializer_list<std::string_view> known) {
  for (const auto& [k, v] : o.items()) {
    bool found = false;
    for (auto n : known) found = found || k == n;
    if (!found) {
      std::string list;
      for (auto n : known) list += (list.empty() ? "" : ", ") + std::string(n);
      throw refused{std::string(op) + ": unknown key " + shown(k) + " (known: " + list + ")"};
    }
  }
}

inline std::string name_of(const json& v, std::string_view op, std::string_view key) {
  if (!v.is_string()) throw refused{std::string(op) + ": '" + std::string(key) + "' must be a string"};
  const auto& s = v.get_ref<const std::string&>();
  if (s.empty() || s.size() > max_name_bytes)
    throw refused{std::string(op) + ": '" + std::string(key) + "' must be 1.." + std::to_string(max_name_bytes) +
                  " bytes"};
  return s;
}

inline std::optional<int> ms_of(const json& o, std::string_view op) {
  const auto it = o.find("ms");
  if (it == o.end() || it->is_null()) return std::nullopt;
  if (!it->is_number_integer()) throw refused{std::string(op) + ": 'ms' must be a whole number of milliseconds"};
  const auto v = it->get<std::int64_t>();
  if (v < 0 || v > max_move_ms)
    throw refused{std::string(op) + ": 'ms' is " + std::to_string(v) + ", outside 0.." + std::to_string(max_move_ms)};
  return static_cast<int>(v);
}

inline bool flag_of(const json& o, std::string_view op, std::string_view key) {
  const auto it = o.find(key);
  if (it == o.end()) return false;
  if (!it->is_boolean()) throw refused{std::string(op) + ": '" + std::string(key) + "' must be true or false"};
  return it->get<bool>();
}

inline const json& required(const json& o, std::string_view op, std::string_view key) {
  const auto it = o.find(key);
  if (it == o.end()) throw refused{std::string(op) + ": '" + std::string(key) + "' is missing"};
  return *it;
}

/** The ops studio_messages.cpp knows, for the message naming the known ones. */
inline constexpr std::string_view studio_ops_list =
    "motion_list, motion_pull, motion_check, buttons, trims, motion_push, motion_put_back, motion_erase, "
    "motion_resume, "
    "play_motion, "
    "button_set, button_clear, button_press, button_release, trim_set, hand, rom_backup, rom_restore_begin, "
    "rom_restore_piece, rom_restore_commit";

/** A studio op's request (studio_messages.cpp), or nothing when @p op is none of them; throws refused. */
std::optional<request> studio_body_of(const json& o, const std::string& op);

}  // namespace cli::ui::detail
