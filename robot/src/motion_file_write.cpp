// rcb4 — motion files written: YAML a person reads and edits (one step per item, the shortest
// numbers that read back the same), JSON for programs, and files (see rcb4/robot/motion_file.hpp).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/motion/buttons.hpp>
#include <rcb4/robot/motion_file.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>

#include "yaml_helpers.hpp"

namespace rcb4::robot {
namespace {
using namespace detail;

// --- writing ---------------------------------------------------------------------------------

std::string yaml_quoted(std::string_view s) {
  // A JSON string is a YAML double-quoted scalar; invalid UTF-8 becomes U+FFFD.
  return nlohmann::json(std::string(s)).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

/** A key as YAML writes it: bare when it is a plain word, quoted otherwise ("ics 7"). */
std::string key_text(std::string_view k) {
  const bool plain = !k.empty() && std::all_of(k.begin(), k.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  }) && std::isalpha(static_cast<unsigned char>(k[0]));
  return plain && k != "free" && k != "hold" && k != "end" ? std::string(k) : yaml_quoted(k);
}

/** The shortest text that reads back as exactly @p d: 30, 101.25, 12.345678 (a file read and written keeps its values).
 */
std::string degrees_text(double d) {
  char b[32];
  const auto r = std::to_chars(b, b + sizeof b, d);
  std::string out(b, r.ptr);
  return out == "-0" ? "0" : out;
}

std::string word_text(std::uint16_t w) {
  if (servo_position::make(w) && servo_position::make(w)->is_free()) return "free";
  if (servo_position::make(w) && servo_position::make(w)->is_hold()) return "hold";
  return std::to_string(w);
}

std::string step_yaml(const motion_step& s) {
  return std::visit(
      [](const auto& x) -> std::string {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, motion::label>) {
          return "- label: " + key_text(x.name) + "\n";
        } else if constexpr (std::is_same_v<T, motion_pose>) {
          std::string out = "- pose: ";
          if (!x.file.empty()) {
            out += yaml_quoted(x.file);
          } else {
            out += "{";
            for (std::size_t i = 0; i < x.targets.size(); ++i) {
              const auto& t = x.targets[i];
              out += (i ? ", " : "") + key_text(t.key) + ": " +
                     (t.degrees ? degrees_text(*t.degrees) : word_text(*t.word));
            }
            out += "}";
          }
          return out + "\n  time_ms: " + std::to_string(x.time.count()) + "\n";
        } else if constexpr (std::is_same_v<T, motion::set_counter>) {
          std::string out = "- set_counter: " + std::to_string(x.value) + "\n";
          if (x.counter != motion::hth4_counter) out += "  counter: " + hex(x.counter.value(), 4) + "\n";
          return out;
        } else if constexpr (std::is_same_v<T, motion::count_down>) {
          std::string out =
              x.when_zero ? "- count_down: " + key_text(x.to) + "\n  when: zero\n" : "- loop: " + key_text(x.to) + "\n";
          if (x.counter != motion::hth4_counter) out += "  counter: " + hex(x.counter.value(), 4) + "\n";
          return out;
        } else if constexpr (std::is_same_v<T, motion::branch_if>) {
          if (x.address == motion::button_word && x.size == 2 &&
              (x.how == motion::compare::equal || x.how == motion::compare::not_equal))
            return std::string(x.how == motion::compare::equal ? "- if_buttons: " : "- unless_buttons: ") +
                   yaml_quoted(motion::buttons_text(x.buttons_of())) + "\n  goto: " + key_text(x.to) + "\n";
          return "- if_ram: " + hex(x.address.value(), 4) + "\n  size: " + std::to_string(x.size) + "\n  " +
                 std::string(compares[static_cast<std::size_t>(x.how)]) + ": " +
                 (x.size == 1 ? std::to_string(x.value) : hex(x.value, 4)) + "\n  goto: " + key_text(x.to) + "\n";
        } else if constexpr (std::is_same_v<T, motion::go_to>) {
          return "- goto: " + key_text(x.to) + "\n";
        } else if constexpr (std::is_same_v<T, motion_call>) {
          return x.address ? "- call_address: " + hex(*x.address, 6) + "\n"
                           : "- call: " + std::to_string(x.number) + "\n";
        } else if constexpr (std::is_same_v<T, motion_params>) {
          std::string out = std::string("- ") + (x.kind == param_kind::speed ? "speed" : "stretch") + ": {";
          for (std::size_t i = 0; i < x.values.size(); ++i)
            out += (i ? ", " : "") + key_text(x.values[i].first) + ": " + std::to_string(x.values[i].second);
          return out + "}\n";
        } else {
          return "- end\n";
        }
      },
      s);
}

}  // namespace

std::string motion_yaml(const motion_document& d, std::string_view comment) {
  std::string out;
  std::size_t from = 0;
  while (from < comment.size()) {  // each line of the comment as a YAML comment
    const auto nl = comment.find('\n', from);
    const auto line = comment.substr(from, nl == std::string_view::npos ? std::string_view::npos : nl - from);
    out += "# " + std::string(line) + "\n";
    from = nl == std::string_view::npos ? comment.size() : nl + 1;
  }
  out += "robot: " + yaml_quoted(d.robot) + "\n";
  if (!d.name.empty()) out += "name: " + yaml_quoted(d.name) + "\n";
  out += "period_ms: " + std::to_string(milliseconds(d.period)) + "\n";
  out += "steps:\n";
  for (std::size_t k = 0; k < d.steps.size(); ++k) {
    const auto& s = d.steps[k];
    std::string text = step_yaml(s);
    // How the studio shows it (not for end, which is a bare word).
    if (k < d.views.size() && !std::holds_alternative<motion::end>(s)) {
      const auto& v = d.views[k];
      if (!v.name.empty()) text += "  name: " + yaml_quoted(v.name) + "\n";
      if (v.at) text += "  at: [" + std::to_string((*v.at)[0]) + ", " + std::to_string((*v.at)[1]) + "]\n";
    }
    // Every line of the step indented under "steps:".
    std::size_t at = 0;
    while (at < text.size()) {
      const auto nl = text.find('\n', at);
      out += "  " + text.substr(at, nl - at + 1);
      at = nl + 1;
    }
  }
  return out;
}

namespace {
/** A YAML node as JSON: plain scalars that read as integers, numbers or booleans become them. */
nlohmann::ordered_json to_json(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Sequence: {
      auto out = nlohmann::ordered_json::array();
      for (const auto& item : n) out.push_back(to_json(item));
      return out;
    }
    case YAML::NodeType::Map: {
      auto out = nlohmann::ordered_json::object();
      for (const auto& kv : n) out[kv.first.as<std::string>()] = to_json(kv.second);
      return out;
    }
    case YAML::NodeType::Scalar: {
      const auto& text = n.Scalar();
      if (n.Tag() != "!") {  // a plain scalar (a quoted one is a string whatever it holds)
        long long i = 0;
        if (const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), i);
            ec == std::errc{} && end == text.data() + text.size())
          return i;
        double d = 0;
        if (YAML::convert<double>::decode(n, d) && !text.empty() &&
            (std::isdigit(static_cast<unsigned char>(text[0])) || text[0] == '-' || text[0] == '+' || text[0] == '.'))
          return d;
        if (text == "true" || text == "false") return text == "true";
      }
      return text;
    }
    default: return nullptr;
  }
}
}  // namespace

std::string motion_json(const motion_document& d) { return to_json(YAML::Load(motion_yaml(d))).dump(); }

void save_motion(const std::filesystem::path& path, const motion_document& d, std::string_view comment) {
  const auto ext = path.extension().string();
  if (ext != ".yaml" && ext != ".yml") throw profile_error(path.string(), "a motion file ends in .yaml or .yml");
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw profile_error(path.string(), "cannot be written (" + std::string(std::strerror(errno)) + ")");
  out << motion_yaml(d, comment);
  out.flush();
  if (!out) throw profile_error(path.string(), "writing failed (" + std::string(std::strerror(errno)) + ")");
}

}  // namespace rcb4::robot
