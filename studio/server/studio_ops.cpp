// rcb4 ui: the studio's ops on the board (see studio_ops.hpp).
// SPDX-License-Identifier: BSL-1.0
#include "studio_ops.hpp"

#include <rcb4/motion/buttons.hpp>
#include <rcb4/motion/disassemble.hpp>
#include <rcb4/ops/layout.hpp>
#include <rcb4/robot/motion_balance.hpp>
#include <rcb4/robot/motion_file.hpp>
#include <rcb4/robot/services/buttons.hpp>
#include <rcb4/robot/services/motion_slots.hpp>
#include <rcb4/robot/services/rom.hpp>
#include <rcb4/robot/services/slot_names.hpp>
#include <rcb4/robot/services/trims.hpp>

#include <array>
#include <cmath>
#include <filesystem>

namespace cli::ui {
namespace {

namespace sv = rcb4::robot::services;
namespace robot = rcb4::robot;
namespace mo = rcb4::motion;

/** The page's words for a service's refusal: what, and what to do. */
std::string words(const sv::refused& e) {
  auto hint = e.hint;
  if (const auto at = hint.find("--force"); at != std::string::npos)
    hint.replace(at, 7, "ticking force");  // the page's box
  return hint.empty() ? std::string(e.what()) : std::string(e.what()) + " (" + hint + ")";
}

std::string base64(std::span<const std::uint8_t> b) {
  static constexpr char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((b.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < b.size(); i += 3) {
    const auto byte = [&](std::size_t k) { return k < b.size() ? unsigned{b[k]} : 0u; };
    const unsigned v = (byte(i) << 16u) | (byte(i + 1) << 8u) | byte(i + 2);
    out += digits[(v >> 18) & 63];
    out += digits[(v >> 12) & 63];
    out += i + 1 < b.size() ? digits[(v >> 6) & 63] : '=';
    out += i + 2 < b.size() ? digits[v & 63] : '=';
  }
  return out;
}

std::vector<std::uint8_t> unbase64(const std::string& text) {
  std::vector<std::uint8_t> out;
  unsigned acc = 0;
  int bits = 0;
  for (const char c : text) {
    int v = -1;
    if (c >= 'A' && c <= 'Z')
      v = c - 'A';
    else if (c >= 'a' && c <= 'z')
      v = c - 'a' + 26;
    else if (c >= '0' && c <= '9')
      v = c - '0' + 52;
    else if (c == '+')
      v = 62;
    else if (c == '/')
      v = 63;
    else if (c == '=')
      break;
    else
      throw studio_refusal("rom_restore_piece: not base64");
    acc = (acc << 6) | static_cast<unsigned>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<std::uint8_t>((acc >> bits) & 0xFF));
    }
  }
  return out;
}

std::uint16_t button_word(const std::string& text) {
  const auto b = mo::parse_buttons(text);
  if (!mo::ok(b)) throw studio_refusal("buttons: " + std::get<mo::failure>(b).message);
  return std::get<std::uint16_t>(b);
}

json entries_json(const std::vector<rcb4::vector_entry>& entries, const rcb4::rom_layout& layout, const robot::model& m,
                  const std::map<unsigned, std::vector<std::uint8_t>>& codes) {
  json out = json::array();
  for (const auto& e : entries) {
    const auto b = e.buttons();
    const std::uint32_t a = e.target.value(), base = layout.motion_base.value();
    const bool slot =
        a >= base && (a - base) % layout.slot_size == 0 && (a - base) / layout.slot_size < layout.motion_count;
    const unsigned n = slot ? (a - base) / layout.slot_size + 1 : 0;
    out.push_back({{"buttons", b ? json(mo::buttons_text(*b)) : json(nullptr)},
                   {"word", b ? json(*b) : json(nullptr)},
                   {"slot", slot ? json(n) : json(nullptr)},
                   {"name", slot ? json(sv::slot_name(m, n,
                                                      codes.contains(n) ? std::span<const std::uint8_t>(codes.at(n))
                                                                        : std::span<const std::uint8_t>{}))
                                 : json(nullptr)},
                   {"address", a}});
  }
  return out;
}

}  // namespace

json body_json(const robot::model& m) {
  const auto* k = m.body();
  if (!k) return nullptr;
  const auto v3 = [](const robot::vec3& v) { return json::array({v[0], v[1], v[2]}); };
  json links = json::array();
  for (const auto& l : k->links) {
    json shapes = json::array();
    for (const auto& s : l.shapes)
      shapes.push_back({{"type", s.type == robot::shape::kind::box        ? "box"
                                 : s.type == robot::shape::kind::cylinder ? "cylinder"
                                                                          : "sphere"},
                        {"size", v3(s.size)},
                        {"xyz", v3(s.xyz)},
                        {"rpy", v3(s.rpy)}});
    links.push_back({{"name", l.name}, {"shapes", std::move(shapes)}});
  }
  json joints = json::array();
  for (const auto& j : k->joints)
    joints.push_back({{"name", j.name},
                      {"fixed", j.fixed},
                      {"parent", j.parent},
                      {"child", j.child},
                      {"xyz", v3(j.xyz)},
                      {"rpy", v3(j.rpy)},
                      {"axis", v3(j.axis)}});
  return json{
      {"root", k->root()->name}, {"links", std::move(links)}, {"joints", std::move(joints)}, {"source", k->source}};
}

studio_ops::studio_ops(session& s, const robot::model& m, const loop_options& o)
    : s_(s), m_(m), o_(o), link_(s, true) {}

studio_ops::~studio_ops() {
  try {
    stop();
  } catch (...) {  // the loop is ending: the board may be gone
  }
}

std::string studio_ops::backup_path(const std::string& what) const {
  const auto dir = o_.poses / "backups";
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);  // a folder that cannot be made: the save says why
  // Two backups in one second (an erase, then its backup put back) get -2, -3: a backup never
  // replaces a file, and must never stop the work for a name.
  const auto stamp = sv::file_stamp();
  auto path = dir / fmt::format("{}-{}.bin", what, stamp);
  for (int k = 2; std::filesystem::exists(path, ec); ++k) path = dir / fmt::format("{}-{}-{}.bin", what, stamp, k);
  return path.string();
}

json studio_ops::act(const studio_action& a, client_id from) {
  const auto args = json::parse(a.args, nullptr, false);
  const auto slot = [&] { return args.at("slot").get<unsigned>(); };
  const sv::backup_sink backup = [this](unsigned n, std::span<const std::uint8_t> old) {
    return sv::save_backup_file(n, old, backup_path(fmt::format("motion-{}", n)));
  };
  try {
    const auto& op = a.op;
    if (op == "motion_push" || op == "motion_put_back" || op == "motion_erase")
      codes_.erase(slot());  // read again by the next list
    if (op == "motion_list") return list();
    if (op == "motion_pull") return pull(slot());
    if (op == "motion_check") return check(args.at("text").get<std::string>());
    if (op == "motion_push")
      return push(slot(), args.at("text").get<std::string>(), args.value("dry_run", false), backup);
    if (op == "motion_put_back") {  // a .bin backup, as `rcb4 motion push FILE.bin N` puts it back
      sv::push_source src;
      src.bin = unbase64(args.at("base64").get<std::string>());
      src.name = args.value("file", std::string("the backup"));
      const auto r = sv::push_motion(link_, m_, *o_.layout, slot(), src, backup);
      return json{{"slot", r.motion},   {"bytes", r.bytes.size()}, {"unchanged", r.unchanged},
                  {"backup", r.backup}, {"summary", r.summary},    {"notes", r.notes}};
    }
    if (op == "motion_erase") {
      const auto r = sv::erase_motion(link_, *o_.layout, slot(), backup, m_.name());
      return json{{"slot", r.motion}, {"unchanged", r.unchanged}, {"backup", r.backup}, {"callers", r.callers}};
    }
    if (op == "motion_resume") {
      sv::run(link_, rcb4::ops::resume_motion());
      return json::object();
    }
    if (op == "play_motion") return play(args.at("text").get<std::string>(), from);
    if (op == "buttons") return buttons();
    if (op == "button_set" || op == "button_clear") {
      const auto word = button_word(args.at("buttons").get<std::string>());
      const auto r =
          op == "button_set" ? sv::set_button(link_, *o_.layout, word, slot()) : sv::clear_button(link_, word);
      return json{{"done", r.done}, {"entries", entries_json(r.entries, *o_.layout, m_, codes_)}};
    }
    if (op == "button_press") {
      const auto r =
          sv::press(link_, *o_.layout, button_word(args.at("buttons").get<std::string>()), args.value("hold", false));
      return json{{"entry", r.entry},
                  {"held", r.held},
                  {"slot", r.state.motion ? json(*r.state.motion) : json(nullptr)},
                  {"running", r.state.running}};
    }
    if (op == "button_release") {
      sv::release(link_);
      return json::object();
    }
    if (op == "trims") return trims();
    if (op == "pose_read") return pose_read(args.at("name").get<std::string>());
    if (op == "trim_set") {
      std::vector<std::pair<std::string, double>> items;
      for (const auto& [k, v] : args.at("joints").items()) items.emplace_back(k, v.get<double>());
      const auto r = sv::set_trims(link_, m_, items, args.value("persist", false));
      json written = json::object();
      for (const auto& t : r.written) written[t.j->name] = t.counts;
      return json{{"written", written}, {"persist", r.persistent}};
    }
    if (op == "hand") return hand(args.at("joint").get<std::string>(), args.at("degrees").get<double>());
    if (op == "rom_backup") return rom_backup();
    if (op == "rom_restore_begin") {
      upload_.assign(rcb4::rom_size, 0xFF);
      uploaded_.assign(rcb4::rom_size, false);
      upload_crc_ = static_cast<std::uint32_t>(std::stoul(args.at("crc32").get<std::string>(), nullptr, 16));
      return json{{"bytes", upload_.size()}};
    }
    if (op == "rom_restore_piece")
      return rom_restore_piece(args.at("offset").get<std::size_t>(), args.at("base64").get<std::string>());
    if (op == "rom_restore_commit") return rom_restore_commit(args.value("force", false));
    throw studio_refusal("unknown studio op " + op);
  } catch (const sv::refused& e) {
    throw studio_refusal(words(e));
  } catch (const robot::profile_error& e) {
    throw studio_refusal(std::string(plain_message(e.what())));
  } catch (const std::system_error& e) {
    const auto f = explain(e.code(), a.op);
    throw studio_refusal(
        fmt::format("{}: {}{}", a.op, plain_message(e.what()), f.hint.empty() ? "" : " (" + f.hint + ")"));
  } catch (const boost::system::system_error& e) {
    const auto f = explain(std::error_code(e.code()), a.op);
    throw studio_refusal(
        fmt::format("{}: {}{}", a.op, plain_message(e.what()), f.hint.empty() ? "" : " (" + f.hint + ")"));
  } catch (const json::exception& e) {  // the fields were checked by the parser: a slip of ours
    throw studio_refusal(a.op + ": " + e.what());
  }
}

json studio_ops::list() {
  const auto& layout = *o_.layout;
  const auto used = sv::run(link_, rcb4::ops::list_motions(layout));
  const auto period = sv::run(link_, rcb4::ops::read_config{}).period;
  const auto names = sv::load_slot_labels(m_.name());
  const auto states = sv::slot_states(used, layout);
  codes_.clear();
  for (const auto& v : used) codes_[v.number] = v.code;
  json slots = json::array();
  for (unsigned n = 1; n <= layout.motion_count; ++n) {
    const auto it = std::find_if(used.begin(), used.end(), [&](const auto& v) { return v.number == n; });
    json e{{"slot", n},
           {"name", sv::slot_name(
                        m_, n, names,
                        it != used.end() ? std::span<const std::uint8_t>(it->code) : std::span<const std::uint8_t>{})}};
    e["used"] = it != used.end();
    if (it != used.end()) {
      e["bytes"] = it->size;
      e["commands"] = it->frames;
      const auto& state = states[static_cast<std::size_t>(it - used.begin())];
      e["broken"] = !state.problem.empty();
      if (!state.problem.empty()) e["problem"] = state.problem;
      e["seconds"] = nullptr;
      if (const auto& t = state.plays) {
        e["endless"] = t->endless;
        e["calls"] = t->calls;  // their time is not counted: no seconds then
        if (const auto s = sv::play_seconds(*t, period)) e["seconds"] = *s;
      }
    }
    slots.push_back(std::move(e));
  }
  return json{{"slots", slots}, {"layout", layout.name}};
}

json studio_ops::pull(unsigned slot) {
  const auto r = sv::pull_motion(link_, m_, *o_.layout, slot);
  return json{{"slot", slot},
              {"name", r.document.name},
              {"motion", json::parse(robot::motion_json(r.document))},
              {"yaml", robot::motion_yaml(r.document, fmt::format("motion {} of the board, pulled by rcb4 ui", slot))},
              {"plays", r.plays},
              {"problem", r.beyond.empty() ? json(nullptr) : json(r.beyond)}};
}

json studio_ops::check(const std::string& text) {
  const auto d = robot::parse_motion(text, "the motion", m_);
  const auto period = sv::run(link_, rcb4::ops::read_config{}).period;
  const auto c = robot::to_program(d, m_, *o_.layout, period, true);
  json out{{"motion", json::parse(robot::motion_json(d))}, {"yaml", robot::motion_yaml(d)}};
  // Does it stand? Each pose held still (robot/motion_balance.hpp), for the editor to mark.
  out["balance"] = nullptr;
  if (m_.body() && m_.dynamics()) {
    json poses = json::array();
    for (const auto& p : robot::check_balance(d, m_).poses)
      poses.push_back({{"step", p.step},
                       {"margin_mm", std::round(p.at.margin * 10) / 10},
                       {"stable", p.at.stable()},
                       {"tilt_deg", std::round(p.at.tilt * 10) / 10},
                       {"touching", p.at.touching}});
    out["balance"] = poses;
  }
  if (!robot::ok(c)) {
    out["problem"] = std::get<robot::problem>(c).message;
    return out;
  }
  const auto& cm = std::get<robot::compiled_motion>(c);
  out["problem"] = nullptr;
  out["notes"] = cm.notes;
  out["plays"] = sv::play_time_text(mo::play_time(cm.program), cm.period);
  const auto code = mo::assemble(cm.program, mo::slot_of(*o_.layout, 1).value());
  out["bytes"] = mo::ok(code) ? json(std::get<std::vector<std::uint8_t>>(code).size()) : json(nullptr);
  return out;
}

json studio_ops::push(unsigned slot, const std::string& text, bool dry_run, const sv::backup_sink& backup) {
  sv::push_source src;
  src.document = robot::parse_motion(text, "the motion", m_);
  src.name = "the motion";
  src.rescale = true;  // the editor's times are milliseconds, whatever the board's period
  const auto r = sv::push_motion(link_, m_, *o_.layout, slot, src, backup, dry_run);
  return json{{"slot", r.motion},         {"address", r.address}, {"bytes", r.bytes.size()},
              {"unchanged", r.unchanged}, {"dry_run", r.dry_run}, {"backup", r.backup},
              {"summary", r.summary},     {"notes", r.notes},     {"name", r.name}};
}

json studio_ops::play(const std::string& text, client_id from) {
  if (play_) throw studio_refusal("a motion already plays from the host: Stop it first");
  const auto d = robot::parse_motion(text, "the motion", m_);
  const auto period = sv::run(link_, rcb4::ops::read_config{}).period;
  play_ = std::make_unique<sv::host_play>(link_, m_, *o_.layout, period, d, "the motion", true);
  play_start_ = clock::now();
  play_from_ = from;
  play_name_ = d.name.empty() ? "the motion" : d.name;
  try {
    const auto next = play_->advance(std::chrono::milliseconds(0));
    play_next_ = next ? std::optional(play_start_ + *next) : std::nullopt;
  } catch (...) {
    play_.reset();
    throw;
  }
  return json{{"playing", true}, {"notes", play_->notes()}};
}

std::optional<clock::time_point> studio_ops::due() const {
  if (!play_) return std::nullopt;
  return play_next_.value_or(clock::now());
}

std::optional<letter> studio_ops::tick() {
  if (!play_ || (play_next_ && clock::now() < *play_next_)) return std::nullopt;
  json j{{"type", "played"}, {"name", play_name_}};
  try {
    if (play_next_) {
      const auto now = std::chrono::duration_cast<std::chrono::milliseconds>(clock::now() - play_start_);
      const auto next = play_->advance(now);
      if (next) {
        play_next_ = play_start_ + *next;
        return std::nullopt;
      }
    }
    j["poses"] = play_->poses();
    j["seconds"] = std::round(std::chrono::duration<double>(clock::now() - play_start_).count() * 100) / 100;
    j["error"] = nullptr;
  } catch (const sv::refused& e) {
    j["error"] = words(e);
  } catch (const std::exception& e) {  // the line (std or boost system_error): the play ends, said
    j["error"] = std::string("the board stopped answering: ") + std::string(plain_message(e.what()));
  }
  play_.reset();
  return letter{play_from_, j.dump()};
}

void studio_ops::stop() {
  if (!play_) return;
  auto p = std::move(play_);
  play_next_.reset();
  p->stop();
}

json studio_ops::buttons() {
  const auto t = sv::read_buttons(link_);
  const auto cfg = sv::run(link_, rcb4::ops::read_config{});
  return json{{"ram", entries_json(t.ram.entries, *o_.layout, m_, codes_)},
              {"rom", entries_json(t.rom.entries, *o_.layout, m_, codes_)},
              {"same", t.same()},
              {"problem", t.ram.problem.empty() ? json(nullptr) : json(t.ram.problem)},
              {"rom_program", cfg.rom_program}};
}

json studio_ops::trims() {
  json out = json::array();
  for (const auto& t : sv::read_trims(link_, m_, {})) {
    const auto rom = t.rom_degrees();
    out.push_back({{"name", t.j->name},
                   {"allocated", t.allocated},
                   {"degrees", t.allocated ? json(std::round(t.degrees() * 100) / 100) : json(nullptr)},
                   {"counts", t.allocated ? json(t.ram) : json(nullptr)},  // what the board holds: whole counts
                   {"exact_degrees", t.allocated ? json(t.degrees()) : json(nullptr)},
                   {"rom_degrees", rom ? json(std::round(*rom * 100) / 100) : json(nullptr)}});
  }
  return json{{"trims", out}};
}

std::filesystem::path pose_path(const std::filesystem::path& folder, const std::string& name, bool for_reading) {
  const auto yaml = folder / (name + ".yaml");
  if (!for_reading) return yaml;
  std::error_code ec;
  if (std::filesystem::is_regular_file(yaml, ec)) return yaml;
  const auto json_file = folder / (name + ".json");
  if (std::filesystem::is_regular_file(json_file, ec)) return json_file;
  throw studio_refusal(fmt::format("no pose called '{}' in {} (NAME.yaml or NAME.json)", name, folder.string()));
}

json studio_ops::pose_read(const std::string& name) {
  // Checked against this robot as `pose play` checks it: names, limits (nothing reaches the board).
  robot::pose p;
  try {
    p = robot::load_pose(pose_path(o_.poses, name, true), m_);
  } catch (const studio_refusal&) {
    throw;
  } catch (const std::exception& e) {
    throw studio_refusal(std::string(plain_message(e.what())));
  }
  json joints = json::object();
  for (const auto& [joint, degrees] : p.joints) {
    const auto* j = m_.find(joint);
    if (j && (degrees < j->lower || degrees > j->upper))
      throw studio_refusal(fmt::format("{}: {} is {}°, beyond its limits {}..{}: not inserted", name, joint,
                                       robot::number_text(degrees), robot::number_text(j->lower),
                                       robot::number_text(j->upper)));
    joints[joint] = degrees;
  }
  return {{"name", name}, {"joints", std::move(joints)}, {"time_ms", p.time ? json(p.time->count()) : json(nullptr)}};
}

json studio_ops::hand(const std::string& joint, double degrees) {
  const auto* j = m_.find(joint);
  if (!j) throw studio_refusal("hand: no joint is called '" + joint + "'");
  if (!s_.is_virtual()) throw studio_refusal("hand: only the virtual board has a hand; move the real robot yourself");
  const auto p = robot::to_position(*j, std::clamp(degrees, j->lower, j->upper));
  if (!robot::ok(p)) throw studio_refusal("hand: " + std::get<robot::problem>(p).message);
  const auto target = s_.by_hand(j->ics, std::get<rcb4::servo_position>(p).value());
  if (!target) throw studio_refusal("hand: " + joint + " has no servo on the virtual board");
  if (*target != 0x8000) throw studio_refusal("hand: " + joint + " holds its position: free it first");
  return json{{"joint", joint}, {"degrees", std::clamp(degrees, j->lower, j->upper)}};
}

json studio_ops::rom_backup() {
  const auto image = sv::backup_rom(link_);
  const auto version = sv::run(link_, rcb4::ops::read_version{});
  // One file, its CRC-32 in its name (a browser blocks a second automatic download): `rcb4 rom
  // restore FILE` checks it without a .crc32 beside it; the .crc32 line comes along for those who want it.
  const auto file = fmt::format("rcb4-rom-{}-crc32-{:08x}.bin", sv::file_stamp(), sv::crc32(image));
  return json{{"bytes", image.size()},
              {"crc32", fmt::format("{:08x}", sv::crc32(image))},
              {"crc32_line", sv::crc32_line(file, image, version)},
              {"base64", base64(image)},
              {"file", file}};
}

json studio_ops::rom_restore_piece(std::size_t offset, const std::string& base64) {
  if (upload_.empty()) throw studio_refusal("rom_restore_piece: no upload begun (rom_restore_begin first)");
  const auto bytes = unbase64(base64);
  if (offset + bytes.size() > upload_.size())
    throw studio_refusal(fmt::format("rom_restore_piece: {} bytes at {} go past the ROM's end", bytes.size(), offset));
  std::copy(bytes.begin(), bytes.end(), upload_.begin() + static_cast<std::ptrdiff_t>(offset));
  std::fill(uploaded_.begin() + static_cast<std::ptrdiff_t>(offset),
            uploaded_.begin() + static_cast<std::ptrdiff_t>(offset + bytes.size()), true);
  return json{{"received", std::count(uploaded_.begin(), uploaded_.end(), true)}};
}

json studio_ops::rom_restore_commit(bool force) {
  // The checks `rcb4 rom restore` makes: the whole image, its CRC-32, then the service's own.
  if (upload_.empty()) throw studio_refusal("rom_restore_commit: no upload begun");
  const auto missing = std::count(uploaded_.begin(), uploaded_.end(), false);
  auto image = std::move(upload_);
  upload_.clear();
  uploaded_.clear();
  if (missing)
    throw studio_refusal(fmt::format("the image arrived without {} of its bytes: nothing was written", missing));
  if (const auto crc = sv::crc32(image); crc != upload_crc_)
    throw studio_refusal(
        fmt::format("the image's CRC-32 is {:08x}, not the {:08x} the page computed: it was damaged on "
                    "the way; nothing was written",
                    crc, upload_crc_));
  const auto version = sv::run(link_, rcb4::ops::read_version{});
  const auto r = sv::restore_rom(
      link_, image,
      [&](std::span<const std::uint8_t> now) {
        const auto path = backup_path("rom-before-restore");
        sv::save_rom_image(path, now, version);
        return path;
      },
      force);
  return json{{"pieces_written", r.pieces},
              {"unchanged", r.unchanged},
              {"before", r.before},
              {"buttons_loaded", r.buttons_loaded},
              {"program_stopped", r.program_stopped}};
}

}  // namespace cli::ui
