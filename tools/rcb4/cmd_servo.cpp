// rcb4 command-line tool: servo list|get|move|free|hold|speed|stretch, by ICS number.
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <algorithm>
#include <cmath>

namespace cli {
namespace {

using namespace std::chrono_literals;
using rcb4::ics_number;

/** KRS servos turn ±135° over 3500..11500 (4000 counts per 135°, protocol.md §7). */
constexpr double servo_degrees = 135.0;
constexpr int servo_low = 3500, servo_high = 11500;

void print_states(const std::vector<rcb4::ops::servo_state>& states, const globals& g) {
  if (g.json) {
    json list = json::array();
    for (const auto& st : states) {
      json j;
      j["ics"] = st.ics.value();
      j["trim"] = st.trim;
      j["position"] = st.position;
      j["degrees"] = degrees_json(st.position);  // null: the servo never answered (0)
      j["answered"] = st.answered();
      j["target"] = st.target;
      j["target_state"] = st.target == rcb4::servo_position::free_value   ? "free"
                          : st.target == rcb4::servo_position::hold_value ? "hold"
                                                                          : "position";
      list.push_back(j);
    }
    emit(list);
    return;
  }
  fmt::print("{:>4}  {:>6}  {:<20}  {}\n", "ICS", "trim", "position", "target");
  for (const auto& st : states)
    fmt::print("{:>4}  {:>6}  {:<20}  {}\n", st.ics.value(), st.trim, position_text(st.position, "no answer"),
               position_text(st.target, "never driven"));
}

/** ICS numbers, each once; none or "all" means every allocated servo (nullopt). */
std::optional<rcb4::servo_mask> servos_of(const std::vector<std::string>& words) {
  if (words.empty() || (words.size() == 1 && words[0] == "all")) return std::nullopt;
  rcb4::servo_mask m;
  for (const auto& w : words) {
    const auto n = checked<ics_number>(parse_int(w, "ICS", 0, 35), "ICS");
    if (m.contains(n)) throw usage_error(fmt::format("ICS {} is given twice", n.value()));
    m.insert(n);
  }
  return m;
}

/** A board whose allocation table lists no servo: an error that says so, never an empty success. */
[[noreturn]] void no_servos() {
  throw failure(exit_board,
                "the board has no servo allocated: its ICS allocation table (RAM 0x0044) lists no block in the "
                "servo area",
                "a board nobody set up (HeartToHeart4 writes the table with the robot's project); "
                "`rcb4 read ram 0x44 72` shows the table");
}

/** Every allocated servo's state; an empty allocation table is an error. */
std::vector<rcb4::ops::servo_state> states_of(session& s) {
  auto states = s.run(rcb4::ops::read_servo_states(rcb4::ops::link_cost::at(s.baud(), 1ms)));
  if (states.empty()) no_servos();
  return states;
}

/** Refuses (exit 1, nothing sent) servos the board has no block for: the board would ignore them. */
void require_allocated(session& s, const std::optional<rcb4::servo_mask>& m) {
  const auto slots = s.run(rcb4::ops::scan_servos{});
  if (slots.empty()) no_servos();
  if (!m) return;
  for (auto n : *m)
    if (std::none_of(slots.begin(), slots.end(), [&](const auto& slot) { return slot.ics == n; }))
      throw failure(exit_board, fmt::format("ICS {} has no servo allocated", n.value()),
                    "rcb4 servo list shows the allocated slots");
}

json ics_list(const rcb4::servo_mask& done) {
  json a = json::array();
  for (auto n : done) a.push_back(n.value());
  return a;
}

/** ICS=POS[@FRAMES] targets, checked: positions, degrees within the servo's turn, frames. */
rcb4::servo_set<rcb4::timed_position> targets_of(const std::vector<std::string>& items, long long frames_default,
                                                 bool degrees) {
  rcb4::servo_set<rcb4::timed_position> targets;
  for (const std::string_view item : items) {
    const auto eq = item.find('=');
    if (eq == std::string_view::npos) throw usage_error(fmt::format("expected ICS=POS, not '{}'", item));
    const auto ics = checked<ics_number>(parse_int(item.substr(0, eq), "ICS", 0, 35), "ICS");
    auto rest = item.substr(eq + 1);
    long long frames = frames_default;
    if (const auto at = rest.find('@'); at != std::string_view::npos) {
      frames = parse_int(rest.substr(at + 1), "FRAMES", 0, 255);
      rest = rest.substr(0, at);
    }
    rcb4::servo_position pos{};
    if (degrees) {
      const std::string str(rest);
      char* end = nullptr;
      const double d = std::strtod(str.c_str(), &end);
      if (str.empty() || end != str.c_str() + str.size() || !std::isfinite(d))
        throw usage_error(fmt::format("'{}' is not degrees", rest));
      if (std::abs(d) > servo_degrees)
        throw usage_error(
            fmt::format("ICS {}: {} degrees is beyond the servo's turn (±{:.0f})", ics.value(), rest, servo_degrees));
      pos = *rcb4::ops::from_degrees(d);
    } else {
      pos = checked<rcb4::servo_position>(parse_int(rest, "POS", 0, 16383), "POS");
      if (!pos.is_free() && !pos.is_hold() && (pos.value() < servo_low || pos.value() > servo_high))
        fmt::print(stderr, "rcb4 servo move: warning: ICS {}: {} is beyond a KRS servo's turn ({}..{}, ±135 deg)\n",
                   ics.value(), pos.value(), servo_low, servo_high);
    }
    if (targets.contains(ics)) throw usage_error(fmt::format("ICS {} is given twice", ics.value()));
    targets.insert(ics, {pos, checked<rcb4::frames>(frames, "FRAMES")});
  }
  return targets;
}

}  // namespace

void add_servo_commands(CLI::App& app, context& ctx) {
  auto* servo = app.add_subcommand("servo", "servos by ICS number (ICS = 2 x ID + SIO - 1): positions, moves, power");
  servo->require_subcommand(1);

  auto* list = servo->add_subcommand("list", "every allocated slot: trim, position, target, degrees");
  on_device(list, ctx, [&ctx](session& s) {
    print_states(states_of(s), ctx.g);
    return exit_ok;
  });

  auto* get = servo->add_subcommand("get", "the same for some servos");
  auto get_ics = std::make_shared<std::vector<std::string>>();
  get->add_option("ICS", *get_ics, "ICS numbers (0..35)")->required();
  get->callback([&ctx, get_ics] {
    const auto want = servos_of(*get_ics);
    if (!want) throw usage_error("name the servos (ICS numbers; servo list shows all)");
    ctx.action = [&ctx, want = *want] {
      session s(ctx.g);
      auto states = states_of(s);
      for (auto n : want)
        if (std::none_of(states.begin(), states.end(), [&](const auto& st) { return st.ics == n; }))
          throw failure(exit_board, fmt::format("ICS {} has no servo allocated", n.value()),
                        "rcb4 servo list shows the allocated slots");
      std::erase_if(states, [&](const auto& st) { return !want.contains(st.ics); });
      print_states(states, ctx.g);
      return exit_ok;
    };
  });

  auto* move = servo->add_subcommand("move", "move servos: ICS=POS[@FRAMES] ... (one CONST frame per duration)");
  struct move_options {
    std::vector<std::string> items;
    long long frames = 30;
    bool degrees = false;
  };
  auto mo = std::make_shared<move_options>();
  move->add_option("ICS=POS[@FRAMES]", mo->items,
                   "POS raw 0..16383 (7500 centre, 3500..11500 the servo's turn), or degrees with --deg; "
                   "FRAMES per servo, else --frames")
      ->required();
  move->add_option("--frames", mo->frames, "frames (servo output periods) for servos without @FRAMES (default 30)")
      ->check(int_range(0, 255));
  move->add_flag("--deg", mo->degrees, "POS is degrees from centre (±135)");
  move->footer("examples:\n  rcb4 servo move 0=8000@10 1=7000\n  rcb4 servo move --deg 3=45 5=-30");
  move->callback([&ctx, mo] {
    auto targets = targets_of(mo->items, mo->frames, mo->degrees);
    ctx.action = [&ctx, targets] {
      session s(ctx.g);
      require_allocated(s, targets.mask());
      const auto moved = s.run(rcb4::ops::move_servos(targets));
      if (ctx.g.json) {
        json j;
        j["moved"] = ics_list(moved);
        emit(j);
      } else {
        fmt::print("moving {}\n", plural(moved.size(), "servo"));
      }
      return exit_ok;
    };
  });

  for (const bool free : {true, false}) {
    auto* power = servo->add_subcommand(
        free ? "free" : "hold", free ? "torque off: the servos go limp" : "hold the present position with torque");
    auto which = std::make_shared<std::vector<std::string>>();
    power->add_option("ICS", *which, "ICS numbers, or all (the default: every allocated servo)");
    power->callback([&ctx, which, free] {
      const auto mask = servos_of(*which);
      ctx.action = [&ctx, mask, free] {
        session s(ctx.g);
        require_allocated(s, mask);
        const auto done =
            s.run(rcb4::ops::set_servo_power(free ? rcb4::ops::power_state::free : rcb4::ops::power_state::hold, mask));
        if (ctx.g.json) {
          json j;
          j[free ? "freed" : "holding"] = ics_list(done);
          emit(j);
        } else {
          fmt::print("{} {}\n", free ? "freed" : "holding", plural(done.size(), "servo"));
        }
        return exit_ok;
      };
    });
  }

  for (const bool speed : {true, false}) {
    auto* param = servo->add_subcommand(
        speed ? "speed" : "stretch",
        speed ? "the servos' speed parameter (ICS, 1..127)" : "the servos' stretch (holding stiffness, ICS, 1..127)");
    auto value = std::make_shared<long long>(0);
    auto which = std::make_shared<std::vector<std::string>>();
    param->add_option("VALUE", *value, "1..127")->required()->check(int_range(1, 127));
    param->add_option("ICS", *which, "ICS numbers, or all (the default: every allocated servo)");
    param->callback([&ctx, value, which, speed] {
      const auto mask = servos_of(*which);
      const auto v = checked<rcb4::servo_param>(*value, "VALUE");
      ctx.action = [&ctx, mask, v, speed] {
        session s(ctx.g);
        const std::string name = speed ? "speed" : "stretch";
        require_allocated(s, mask);
        const auto done =
            s.run(rcb4::ops::set_servo_param(speed ? rcb4::param_kind::speed : rcb4::param_kind::stretch, v, mask));
        if (ctx.g.json) {
          json j;
          j[name] = v.value();
          j["servos"] = ics_list(done);
          emit(j);
        } else {
          fmt::print("{} = {} on {}\n", name, v.value(), plural(done.size(), "servo"));
        }
        return exit_ok;
      };
    });
  }
}

}  // namespace cli
