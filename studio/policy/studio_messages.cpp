// rcb4 ui: the studio's messages (the motion editor and HTH4's tables), each field checked here
// before anything reaches the board loop (see messages.hpp for the list).
// SPDX-License-Identifier: BSL-1.0
#include "message_parts.hpp"

#include <cmath>

namespace cli::ui::detail {
namespace {

unsigned slot_of(const json& o, std::string_view op) {
  const auto& s = required(o, op, "slot");
  if (!s.is_number_integer()) throw refused{std::string(op) + ": 'slot' must be a whole number"};
  const auto v = s.get<std::int64_t>();
  if (v < 1 || v > 120) throw refused{std::string(op) + ": slot " + std::to_string(v) + " is outside 1..120"};
  return static_cast<unsigned>(v);
}

void text_of(const json& o, std::string_view op) {
  const auto& t = required(o, op, "text");
  if (!t.is_string()) throw refused{std::string(op) + ": 'text' must be a motion file's text (YAML or JSON)"};
  if (t.get_ref<const std::string&>().size() > max_text_bytes)
    throw refused{std::string(op) + ": 'text' is longer than " + std::to_string(max_text_bytes) + " bytes"};
}

void buttons_of(const json& o, std::string_view op) { name_of(required(o, op, "buttons"), op, "buttons"); }

}  // namespace

std::optional<request> studio_body_of(const json& o, const std::string& op) {
  studio_request r;
  r.op = op;
  if (op == "motion_list" || op == "buttons" || op == "trims") {
    only_keys(o, op, {"op", "id"});
  } else if (op == "pose_read") {
    only_keys(o, op, {"op", "id", "name"});
    if (!valid_pose_name(name_of(required(o, op, "name"), op, "name")))
      throw refused{"pose_read: a pose name uses A-Z, a-z, 0-9, _ and -"};
  } else if (op == "motion_pull") {
    only_keys(o, op, {"op", "id", "slot"});
    slot_of(o, op);
  } else if (op == "motion_check") {
    only_keys(o, op, {"op", "id", "text"});
    text_of(o, op);
  } else if (op == "motion_push") {
    only_keys(o, op, {"op", "id", "slot", "text", "dry_run"});
    slot_of(o, op);
    text_of(o, op);
    flag_of(o, op, "dry_run");
    r.writes = true;
  } else if (op == "motion_put_back") {  // a slot's .bin backup (from a push or an erase) written back
    only_keys(o, op, {"op", "id", "slot", "base64", "file"});
    slot_of(o, op);
    const auto& b = required(o, op, "base64");
    if (!b.is_string() || b.get_ref<const std::string&>().empty() || b.get_ref<const std::string&>().size() > 60000 ||
        b.get_ref<const std::string&>().find_first_not_of(
            "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/=") != std::string::npos)
      throw refused{"motion_put_back: 'base64' must be 1 to 60,000 characters of base64"};
    if (o.contains("file")) (void)name_of(o.at("file"), op, "file");
    r.writes = true;
  } else if (op == "motion_erase") {
    only_keys(o, op, {"op", "id", "slot"});
    slot_of(o, op);
    r.writes = true;
  } else if (op == "motion_resume" || op == "button_release" || op == "rom_backup") {
    only_keys(o, op, {"op", "id"});
    r.writes = true;
  } else if (op == "play_motion") {
    only_keys(o, op, {"op", "id", "text"});
    text_of(o, op);
    r.writes = true;
  } else if (op == "button_set") {
    only_keys(o, op, {"op", "id", "buttons", "slot"});
    buttons_of(o, op);
    slot_of(o, op);
    r.writes = true;
  } else if (op == "button_clear") {
    only_keys(o, op, {"op", "id", "buttons"});
    buttons_of(o, op);
    r.writes = true;
  } else if (op == "button_press") {
    only_keys(o, op, {"op", "id", "buttons", "hold"});
    buttons_of(o, op);
    flag_of(o, op, "hold");
    r.writes = true;
  } else if (op == "trim_set") {
    only_keys(o, op, {"op", "id", "joints", "persist"});
    const auto& js = required(o, op, "joints");
    if (!js.is_object() || js.empty()) throw refused{"trim_set: 'joints' must be an object of joint names and degrees"};
    for (const auto& [k, v] : js.items()) {
      if (k.empty() || k.size() > max_name_bytes) throw refused{"trim_set: a joint name must be 1..64 bytes"};
      if (!v.is_number() || !std::isfinite(v.get<double>()))
        throw refused{"trim_set: " + shown(k) + " must be a number of degrees"};
    }
    flag_of(o, op, "persist");
    r.writes = true;
  } else if (op == "rom_restore_begin") {
    only_keys(o, op, {"op", "id", "bytes", "crc32"});
    const auto& n = required(o, op, "bytes");
    if (!n.is_number_integer() || n.get<std::int64_t>() != 262144)
      throw refused{"rom_restore_begin: 'bytes' must be 262144: a ROM image is 256 KiB"};
    const auto& c = required(o, op, "crc32");
    if (!c.is_string() || c.get_ref<const std::string&>().size() != 8 ||
        c.get_ref<const std::string&>().find_first_not_of("0123456789abcdefABCDEF") != std::string::npos)
      throw refused{"rom_restore_begin: 'crc32' must be 8 hexadecimal digits"};
  } else if (op == "rom_restore_piece") {
    only_keys(o, op, {"op", "id", "offset", "base64"});
    const auto& at = required(o, op, "offset");
    if (!at.is_number_integer() || at.get<std::int64_t>() < 0 || at.get<std::int64_t>() >= 262144)
      throw refused{"rom_restore_piece: 'offset' must be 0..262143"};
    const auto& b = required(o, op, "base64");
    if (!b.is_string() || b.get_ref<const std::string&>().size() > 60000 ||
        b.get_ref<const std::string&>().find_first_not_of(
            "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/=") != std::string::npos)
      throw refused{"rom_restore_piece: 'base64' must be at most 60,000 characters of base64"};
  } else if (op == "rom_restore_commit") {
    only_keys(o, op, {"op", "id", "force"});
    flag_of(o, op, "force");
  } else if (op == "hand") {
    only_keys(o, op, {"op", "id", "joint", "degrees"});
    name_of(required(o, op, "joint"), op, "joint");
    const auto& d = required(o, op, "degrees");
    if (!d.is_number() || !std::isfinite(d.get<double>())) throw refused{"hand: 'degrees' must be a number"};
    r.writes = true;
  } else {
    return std::nullopt;
  }
  r.writes = !studio_reads(op);
  json args = o;
  args.erase("op");
  args.erase("id");
  r.args = args.dump();
  return r;
}

}  // namespace cli::ui::detail
