// rcb4 — motion files (yaml-cpp): parse, and turn into a motion program and back (the writers:
// motion_file_write.cpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/motion/buttons.hpp>
#include <rcb4/robot/motion_file.hpp>

#include <nlohmann/json.hpp>

#include <cctype>
#include <charconv>
#include <cstdio>
#include <map>
#include <set>

#include "yaml_helpers.hpp"

namespace rcb4::robot {
namespace {
using namespace detail;

constexpr std::string_view step_kinds[] = {"pose",         "label",          "set_counter", "loop", "count_down",
                                           "if_buttons",   "unless_buttons", "if_ram",      "goto", "call",
                                           "call_address", "stretch",        "speed"};
constexpr long longest_time_ms = 255 * 25;  // 255 frames of the longest period

bool same_name(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

/** "ics 7" → 7; nothing when @p key is not of that form. */
std::optional<unsigned> ics_key(std::string_view key) {
  if (key.size() < 5 || key.substr(0, 4) != "ics ") return std::nullopt;
  unsigned v = 0;
  for (char c : key.substr(4)) {
    if (!std::isdigit(static_cast<unsigned char>(c)) || v > 100) return std::nullopt;
    v = v * 10 + static_cast<unsigned>(c - '0');
  }
  return v;
}

std::string label_name(const std::string& source, const YAML::Node& n, const std::string& what) {
  const std::string s = scalar(source, n, what);
  if (s.empty()) fail(source, n, what + ": a label needs a name");
  return s;
}

ram_address ram_of(const std::string& source, const YAML::Node& n, const std::string& what) {
  return ram_address::make(static_cast<std::uint16_t>(integer(source, n, what, 0, 0x048F))).value();
}

motion_target parse_target(const std::string& source, const YAML::Node& k, const YAML::Node& v, const model& m) {
  motion_target t;
  t.key = scalar(source, k, "joint name");
  const std::string value = v.IsScalar() ? v.Scalar() : std::string();
  const bool word = value == "free" || value == "hold";
  if (const auto ics = ics_key(t.key)) {
    if (*ics >= ics_slots) fail(source, k, t.key + ": an ICS number is 0..35");
    t.word = word ? (value == "free" ? servo_position::free() : servo_position::hold()).value()
                  : static_cast<std::uint16_t>(
                        integer(source, v, t.key + " (a position word: 0..16383, free, hold)", 0, 0x3FFF));
    return t;
  }
  if (!m.find(t.key))
    fail(source, k, "no joint of " + m.name() + " is called '" + t.key + "' (a servo outside the profile: \"ics N\")");
  if (word)
    t.word = (value == "free" ? servo_position::free() : servo_position::hold()).value();
  else
    t.degrees = number(source, v, t.key + " (degrees, free or hold)");
  return t;
}

motion_pose parse_pose_step(const std::string& source, const YAML::Node& n, const model& m,
                            const std::filesystem::path& dir) {
  check_keys(source, n, {"pose", "time_ms"}, "pose");
  motion_pose p;
  const YAML::Node v = n["pose"];
  std::optional<std::chrono::milliseconds> file_time;
  if (v.IsMap()) {
    if (v.size() == 0) fail(source, v, "pose: names no joint");
    for (const auto& kv : v) {
      auto t = parse_target(source, kv.first, kv.second, m);
      for (const auto& e : p.targets)
        if (e.key == t.key) fail(source, kv.first, t.key + " is given twice");
      p.targets.push_back(std::move(t));
    }
  } else if (v.IsScalar()) {
    p.file = v.Scalar();
    const auto path = dir / std::filesystem::path(p.file);
    const pose loaded = load_pose(path, m);  // its own errors name its file and line
    for (const auto& [name, deg] : loaded.joints) p.targets.push_back({name, deg, std::nullopt});
    file_time = loaded.time;
  } else {
    fail(source, v, "pose: a mapping of joints to degrees, or a pose file");
  }
  if (n["time_ms"])
    p.time = std::chrono::milliseconds(integer(source, n["time_ms"], "time_ms", 0, longest_time_ms));
  else if (file_time)
    p.time = *file_time;
  else
    fail(source, n, "pose: time_ms says how long getting there takes (0 for at once)");
  return p;
}

motion_params parse_params(const std::string& source, const YAML::Node& n, const std::string& kind, const model& m) {
  check_keys(source, n, {kind}, kind);
  motion_params p;
  p.kind = kind == "speed" ? param_kind::speed : param_kind::stretch;
  const YAML::Node v = n[kind];
  if (!v.IsMap() || v.size() == 0)
    fail(source, v, kind + ": a mapping of joints, groups, all or \"ics N\" to 1..127, such as {legs: 60}");
  for (const auto& kv : v) {
    const std::string key = scalar(source, kv.first, kind);
    if (const auto ics = ics_key(key)) {
      if (*ics >= ics_slots) fail(source, kv.first, key + ": an ICS number is 0..35");
    } else if (const auto s = m.select(key); !ok(s)) {
      fail(source, kv.first, std::get<problem>(s).message);
    }
    for (const auto& e : p.values)
      if (e.first == key) fail(source, kv.first, key + " is given twice");
    p.values.emplace_back(key, static_cast<unsigned>(integer(source, kv.second, key, 1, 127)));
  }
  return p;
}

motion_step parse_step(const std::string& source, const YAML::Node& n, const model& m,
                       const std::filesystem::path& dir) {
  if (n.IsScalar()) {
    if (n.Scalar() == "end") return motion::end{};
    fail(source, n, "a step is end, or a mapping such as {pose: {left_knee: 30}, time_ms: 300}");
  }
  if (!n.IsMap()) fail(source, n, "a step is end, or a mapping such as {pose: {left_knee: 30}, time_ms: 300}");
  std::vector<std::string> kinds;
  const bool test = n["if_buttons"] || n["unless_buttons"] || n["if_ram"];
  for (auto k : step_kinds)
    if (n[std::string(k)] && !(test && k == "goto")) kinds.emplace_back(k);
  if (kinds.empty()) {
    std::string list;
    for (auto k : step_kinds) list += (list.empty() ? "" : ", ") + std::string(k);
    fail(source, n, "the step says what it does with one of: " + list + " (or is end)");
  }
  if (kinds.size() > 1)
    fail(source, n, "one step does one thing: " + kinds[0] + " and " + kinds[1] + " are both given");
  const std::string& kind = kinds[0];
  const YAML::Node v = n[kind];
  if (kind == "pose") return parse_pose_step(source, n, m, dir);
  if (kind == "stretch" || kind == "speed") return parse_params(source, n, kind, m);
  if (kind == "label") {
    check_keys(source, n, {"label"}, kind);
    return motion::label{label_name(source, v, kind)};
  }
  if (kind == "set_counter") {
    check_keys(source, n, {"set_counter", "counter"}, kind);
    motion::set_counter s;
    s.value = static_cast<std::uint8_t>(integer(source, v, kind, 0, 255));
    if (n["counter"]) s.counter = ram_of(source, n["counter"], "counter");
    return s;
  }
  if (kind == "loop" || kind == "count_down") {
    if (kind == "loop")
      check_keys(source, n, {"loop", "counter"}, kind);
    else
      check_keys(source, n, {"count_down", "when", "counter"}, kind);
    motion::count_down c;
    c.to = label_name(source, v, kind);
    if (n["counter"]) c.counter = ram_of(source, n["counter"], "counter");
    if (n["when"]) {
      const std::string w = scalar(source, n["when"], "when");
      if (w != "zero" && w != "not_zero") fail(source, n["when"], "when: zero or not_zero, not '" + w + "'");
      c.when_zero = w == "zero";
    }
    return c;
  }
  if (kind == "if_buttons" || kind == "unless_buttons") {
    check_keys(source, n, {kind, "goto"}, kind);
    if (!n["goto"]) fail(source, n, kind + ": goto names the label to jump to");
    const auto b = motion::parse_buttons(scalar(source, v, kind));
    if (!motion::ok(b)) fail(source, v, kind + ": " + std::get<motion::failure>(b).message);
    return motion::branch_if::buttons(std::get<std::uint16_t>(b), label_name(source, n["goto"], "goto"),
                                      kind == "if_buttons");
  }
  if (kind == "if_ram") {
    check_keys(source, n, {"if_ram", "size", "equal", "not_equal", "below", "at_least", "at_most", "goto"}, kind);
    if (!n["goto"]) fail(source, n, "if_ram: goto names the label to jump to");
    if (!n["size"]) fail(source, n, "if_ram: size says whether the value is 1 or 2 bytes");
    motion::branch_if b;
    b.address = ram_of(source, v, kind);
    b.size = static_cast<std::uint8_t>(integer(source, n["size"], "size", 1, 2));
    int given = 0;
    for (std::size_t i = 0; i < std::size(compares); ++i)
      if (const YAML::Node c = n[std::string(compares[i])]) {
        ++given;
        b.how = static_cast<motion::compare>(i);
        b.value =
            static_cast<std::uint16_t>(integer(source, c, std::string(compares[i]), 0, b.size == 1 ? 0xFF : 0xFFFF));
      }
    if (given != 1)
      fail(source, n, "if_ram: one of equal, not_equal, below, at_least, at_most gives the value to compare with");
    b.to = label_name(source, n["goto"], "goto");
    return b;
  }
  if (kind == "goto") {
    check_keys(source, n, {"goto"}, kind);
    return motion::go_to{label_name(source, v, kind)};
  }
  if (kind == "call") {
    check_keys(source, n, {"call"}, kind);
    return motion_call{static_cast<unsigned>(integer(source, v, "call (a motion's number)", 1, 120)), std::nullopt};
  }
  check_keys(source, n, {"call_address"}, kind);
  return motion_call{0, static_cast<std::uint32_t>(integer(source, v, "call_address", 0, 0x3FFFF))};
}

motion_document parse_motion_nodes(std::string_view text, const std::string& source, const model& m,
                                   const std::filesystem::path& dir) {
  const YAML::Node root = parse_yaml(text, source);
  if (!root.IsMap())
    throw profile_error(source, "a motion file is a mapping with period_ms and steps (robot and name are optional)");
  check_keys(source, root, {"robot", "name", "period_ms", "steps"}, "motion");
  motion_document d;
  d.robot = m.name();
  if (root["robot"]) {
    d.robot = scalar(source, root["robot"], "robot");
    if (!same_name(d.robot, m.name()))
      fail(source, root["robot"],
           "this motion is " + d.robot + "'s, not " + m.name() + "'s (--robot names the profile it was made with)");
  }
  if (root["name"]) d.name = scalar(source, root["name"], "name");
  if (!root["period_ms"])
    throw profile_error(source,
                        "period_ms: say which output period the times were made for (10, 15, 20 or 25; "
                        "rcb4 config shows the board's)");
  const long period = integer(source, root["period_ms"], "period_ms", 10, 25);
  if (period % 5 != 0) fail(source, root["period_ms"], "period_ms: the board's periods are 10, 15, 20 and 25");
  d.period = static_cast<output_period>((period - 10) / 5);
  const YAML::Node steps = root["steps"];
  if (!steps || !steps.IsSequence() || steps.size() == 0)
    throw profile_error(where(source, steps ? steps.Mark() : root.Mark()),
                        "steps: expected a list of steps, the last an end or a goto");
  bool any_view = false;
  std::vector<step_view> views;
  for (auto s : steps) {
    step_view v;
    if (s.IsMap()) {  // how the studio shows the step: read, then out of the way of the step's own keys
      if (s["name"]) {
        v.name = scalar(source, s["name"], "name");
        if (v.name.size() > 80) fail(source, s["name"], "name: at most 80 characters");
        s.remove("name");
      }
      if (const YAML::Node at = s["at"]) {
        if (!at.IsSequence() || at.size() != 2)
          fail(source, at, "at: the flowchart block's place, [x, y] in pixels (0..100000)");
        v.at =
            std::array<long, 2>{integer(source, at[0], "at: x", 0, 100000), integer(source, at[1], "at: y", 0, 100000)};
        s.remove("at");
      }
    }
    any_view = any_view || v != step_view{};
    views.push_back(std::move(v));
    d.steps.push_back(parse_step(source, s, m, dir));
    d.where.push_back(s.Mark().is_null() ? source : source + ":" + std::to_string(s.Mark().line + 1));
  }
  if (any_view) d.views = std::move(views);
  return d;
}

/**
 * The angle of @p p on @p j with the fewest decimals (up to 4) that gives @p p back: 8389 on a
 * KRS joint is 30, not 30.0038. The value is what its text reads as, so a file written and read
 * again holds the same numbers.
 */
std::optional<double> shortest_degrees(const joint& j, servo_position p) {
  const auto exact = to_degrees(j, p.value());
  if (!exact) return std::nullopt;
  for (int decimals = 0; decimals <= 4; ++decimals) {
    const double scale = std::pow(10.0, decimals);
    const double d = std::stod(number_text(std::round(*exact * scale) / scale));
    // to_position's mapping without its limits: a pulled pose may lie beyond them (push says so).
    const double cpd = (j.kind.high - j.kind.low) / (2 * j.kind.half_turn);
    const double raw = std::round((j.kind.high + j.kind.low) / 2.0 + (d * j.direction + j.offset) * cpd);
    if (raw == p.value()) return d;
  }
  return std::stod(number_text(*exact));
}

}  // namespace

motion_document parse_motion(std::string_view text, const std::string& source, const model& m,
                             const std::filesystem::path& dir) {
  try {
    return parse_motion_nodes(text, source, m, dir);
  } catch (const YAML::Exception& e) {
    throw profile_error(where(source, e.mark), e.msg);
  }
}

motion_document load_motion(const std::filesystem::path& path, const model& m) {
  return parse_motion(read_file(path), path.string(), m, path.parent_path());
}

// --- to and from programs ----------------------------------------------------------------------

outcome<compiled_motion> to_program(const motion_document& d, const model& m, const rom_layout& layout,
                                    output_period board_period, bool rescale) {
  compiled_motion out;
  const unsigned file_ms = milliseconds(d.period), board_ms = milliseconds(board_period);
  if (d.period != board_period) {
    if (!rescale)
      return problem{"the motion was made for " + std::to_string(file_ms) +
                     " ms frames and the board's output period "
                     "is " +
                     std::to_string(board_ms) + " ms: each of its frames would last " + std::to_string(board_ms) +
                     " ms (--rescale keeps its times in milliseconds; or set the board's period: rcb4 "
                     "config set period=" +
                     std::to_string(file_ms) + ")"};
    out.notes.push_back("times kept in milliseconds: frames of " + std::to_string(file_ms) + " ms made frames of " +
                        std::to_string(board_ms) + " ms");
  }
  out.period = board_period;
  const auto at = [&](std::size_t i) {
    return "step " + std::to_string(i + 1) +
           (i < d.where.size() && !d.where[i].empty() ? " (" + d.where[i] + ")" : "") + ": ";
  };
  if (d.steps.empty()) return problem{"the motion has no steps"};
  if (!std::holds_alternative<motion::end>(d.steps.back()) && !std::holds_alternative<motion::go_to>(d.steps.back()))
    return problem{at(d.steps.size() - 1) +
                   "the last step is neither end nor goto: the board would run on into the bytes after the motion"};
  std::set<std::string> labels;
  for (std::size_t i = 0; i < d.steps.size(); ++i)
    if (const auto* l = std::get_if<motion::label>(&d.steps[i]))
      if (!labels.insert(l->name).second) return problem{at(i) + "the label '" + l->name + "' is defined twice"};
  // A step after an end or an unconditional goto, with no label between, never runs: it is
  // assembled as written, but the board never gets there and a pull (which follows the code) will
  // not show it.
  for (std::size_t i = 1; i < d.steps.size(); ++i) {
    const bool returns = std::holds_alternative<motion::end>(d.steps[i - 1]);
    if ((returns || std::holds_alternative<motion::go_to>(d.steps[i - 1])) &&
        !std::holds_alternative<motion::label>(d.steps[i]))
      out.notes.push_back(at(i) + "never runs: the step before it always " + (returns ? "returns" : "jumps away") +
                          " (it is written, but a pull will not show it)");
  }
  for (std::size_t i = 0; i < d.steps.size(); ++i) {
    const auto& s = d.steps[i];
    const auto target = [&](const std::string& to) -> std::optional<problem> {
      if (labels.count(to)) return std::nullopt;
      return problem{at(i) + "no label is called '" + to + "'"};
    };
    if (const auto* p = std::get_if<motion_pose>(&s)) {
      if (p->targets.empty()) return problem{at(i) + "the pose names no servo"};
      motion::pose pose;
      std::map<unsigned, std::string> seen;
      for (const auto& t : p->targets) {
        const joint* j = m.find(t.key);
        const auto ics_n = j ? std::optional<unsigned>(j->ics.value()) : ics_key(t.key);
        if (!ics_n || *ics_n >= ics_slots)
          return problem{at(i) + "no joint of " + m.name() + " is called '" + t.key + "'"};
        const auto ics = ics_number::make(*ics_n).value();
        if (const auto e = seen.find(*ics_n); e != seen.end())
          return problem{at(i) + e->second + " and " + t.key + " are the same servo (ICS " + std::to_string(*ics_n) +
                         ")"};
        seen.emplace(*ics_n, t.key);
        if (t.degrees) {
          if (!j) return problem{at(i) + t.key + ": degrees need a joint of the profile"};
          auto pos = to_position(*j, *t.degrees);
          if (!ok(pos)) return problem{at(i) + std::get<problem>(pos).message};
          pose.targets.insert(ics, std::get<servo_position>(pos));
        } else {
          const auto w = servo_position::make(t.word.value_or(0xFFFF));
          if (!t.word || !w) return problem{at(i) + t.key + ": not a position word"};
          pose.targets.insert(ics, *w);
        }
      }
      const long long ms = p->time.count();
      if (ms < 0) return problem{at(i) + "a negative time"};
      auto f = static_cast<unsigned long long>((ms + board_ms / 2) / board_ms);
      if (f == 0 && ms > 0) f = 1;
      if (f > 255)
        return problem{at(i) + std::to_string(ms) + " ms is " + std::to_string(f) + " frames of " +
                       std::to_string(board_ms) + " ms; a pose takes at most 255 (" + std::to_string(255 * board_ms) +
                       " ms): split it in two"};
      if (f * board_ms != static_cast<unsigned long long>(ms))
        out.notes.push_back(at(i) + std::to_string(ms) + " ms is " + std::to_string(f) + " frames of " +
                            std::to_string(board_ms) + " ms (" + std::to_string(f * board_ms) + " ms)");
      pose.time = frames::make(static_cast<unsigned>(f)).value();
      out.program.steps.emplace_back(std::move(pose));
    } else if (const auto* pr = std::get_if<motion_params>(&s)) {
      motion::servo_parameter sp{pr->kind, {}};
      std::map<unsigned, std::string> seen;
      for (const auto& [key, value] : pr->values) {
        std::vector<unsigned> slots;
        if (const auto n = ics_key(key); n && !m.find(key)) {
          slots.push_back(*n);
        } else {
          const auto sel = m.select(key);
          if (!ok(sel)) return problem{at(i) + std::get<problem>(sel).message};
          for (const auto* j : std::get<std::vector<const joint*>>(sel)) slots.push_back(j->ics.value());
        }
        const auto v = servo_param::make(value);
        if (!v) return problem{at(i) + key + ": " + std::to_string(value) + " is outside 1..127"};
        for (unsigned n : slots) {
          if (n >= ics_slots) return problem{at(i) + key + ": an ICS number is 0..35"};
          if (const auto e = seen.find(n); e != seen.end())
            return problem{at(i) + e->second + " and " + key + " both set ICS " + std::to_string(n)};
          seen.emplace(n, key);
          sp.values.insert(ics_number::make(n).value(), *v);
        }
      }
      out.program.steps.emplace_back(std::move(sp));
    } else if (const auto* c = std::get_if<motion_call>(&s)) {
      std::optional<rom_address> a;
      if (c->address) {
        const auto r = rom_address::make(*c->address);
        if (!r) return problem{at(i) + "call_address: " + hex(*c->address, 6) + " is outside the ROM"};
        a = *r;
      } else {
        const auto r = motion_address(layout, c->number);
        if (!r || c->number > layout.motion_count)
          return problem{at(i) + "call: motion " + std::to_string(c->number) + " is outside 1.." +
                         std::to_string(layout.motion_count) + " (" + std::string(layout.name) + " layout)"};
        a = *r;
      }
      out.program.steps.emplace_back(motion::call_motion{*a});
    } else {
      std::optional<problem> bad;
      if (const auto* cd = std::get_if<motion::count_down>(&s)) bad = target(cd->to);
      if (const auto* b = std::get_if<motion::branch_if>(&s)) bad = target(b->to);
      if (const auto* g = std::get_if<motion::go_to>(&s)) bad = target(g->to);
      if (bad) return *bad;
      std::visit(
          [&](const auto& x) {
            using T = std::decay_t<decltype(x)>;
            if constexpr (!std::is_same_v<T, motion_pose> && !std::is_same_v<T, motion_params> &&
                          !std::is_same_v<T, motion_call>)
              out.program.steps.emplace_back(x);
          },
          s);
    }
  }
  return out;
}

motion_document from_program(const motion::program& p, const model& m, const rom_layout& layout, output_period period) {
  motion_document d;
  d.robot = m.name();
  d.period = period;
  for (const auto& s : p.steps) {
    if (const auto* pose = std::get_if<motion::pose>(&s)) {
      motion_pose mp;
      for (const auto& e : pose->targets) {
        const joint* j = m.on(e.ics);
        const auto deg = j ? shortest_degrees(*j, e.value) : std::nullopt;
        if (deg)
          mp.targets.push_back({j->name, *deg, std::nullopt});
        else
          mp.targets.push_back({j ? j->name : "ics " + std::to_string(e.ics.value()), std::nullopt, e.value.value()});
      }
      mp.time = std::chrono::milliseconds(pose->time.value() * milliseconds(period));
      d.steps.emplace_back(std::move(mp));
    } else if (const auto* sp = std::get_if<motion::servo_parameter>(&s)) {
      motion_params mp{sp->kind, {}};
      for (const auto& e : sp->values) {
        const joint* j = m.on(e.ics);
        mp.values.emplace_back(j ? j->name : "ics " + std::to_string(e.ics.value()), e.value.value());
      }
      d.steps.emplace_back(std::move(mp));
    } else if (const auto* c = std::get_if<motion::call_motion>(&s)) {
      const std::uint32_t a = c->address.value(), base = layout.motion_base.value();
      const bool slot_start =
          a >= base && (a - base) % layout.slot_size == 0 && (a - base) / layout.slot_size < layout.motion_count;
      d.steps.emplace_back(slot_start ? motion_call{(a - base) / layout.slot_size + 1, std::nullopt}
                                      : motion_call{0, a});
    } else {
      std::visit(
          [&](const auto& x) {
            using T = std::decay_t<decltype(x)>;
            if constexpr (!std::is_same_v<T, motion::pose> && !std::is_same_v<T, motion::servo_parameter> &&
                          !std::is_same_v<T, motion::call_motion>)
              d.steps.emplace_back(x);
          },
          s);
    }
  }
  return d;
}

}  // namespace rcb4::robot
