// rcb4 ui: the board loop (see board_loop.hpp).
// SPDX-License-Identifier: BSL-1.0
#include "board_loop.hpp"

#include "studio_ops.hpp"

#include <rcb4/motion/disassemble.hpp>
#include <rcb4/robot/motion_file.hpp>
#include <rcb4/robot/services/moves.hpp>
#include <rcb4/robot/services/slot_names.hpp>

#include <algorithm>
#include <cmath>
#include <system_error>

namespace cli::ui {
namespace {

namespace robot = rcb4::robot;
namespace ops = rcb4::ops;
namespace t = rcb4::transport;
using namespace std::chrono_literals;

/** A number for the page: rounded to hundredths, null when unknown. */
json degrees_json(std::optional<double> d) {
  if (!d || !std::isfinite(*d)) return nullptr;
  const double r = std::round(*d * 100) / 100;
  return r == 0 ? 0.0 : r;
}

/** An error for a page: the words of the failure, and its hint. */
std::string words_of(const std::error_code ec, std::string_view what) {
  const auto f = explain(ec, what);
  std::string s = fmt::format("{}: {}", what, plain_message(ec.message()));
  if (!f.hint.empty()) s += " (" + f.hint + ")";
  return s;
}

/** A failure while carrying out an action, with words for the page. */
struct refusal {
  std::string what;
};

class loop {
 public:
  loop(session& s, const robot::model& m, hub& h, const loop_options& o)
      : s_(s), m_(m), h_(h), o_(o), studio_(s, m, o) {
    angles_.resize(m.joints().size());
    targets_.resize(m.joints().size());
    modes_.resize(m.joints().size(), "unknown");
    last_rate_at_ = clock::now();
  }

  void run() {
    bool lists_sent = false;
    bool joints_next = false;
    auto poll_at = clock::now();
    while (!h_.stopped()) {
      const auto actions = h_.take();
      bool moved = false;
      for (const auto& a : actions) {
        if (h_.stopped()) return;
        moved = moved || std::holds_alternative<move_action>(a.body);
        carry_out(a);
      }
      if (h_.stopped()) return;
      notice_outside_writes();
      if (auto done = studio_.tick()) h_.tell(done->to, done->text);  // a motion played from the host
      // After a slider move the board shows it once it has taken its first step, one output period
      // on: the page hears then, not a page period later. Other work is shown at once.
      if (moved && answering_) {
        poll_at = clock::now() + std::chrono::milliseconds(rcb4::milliseconds(period_)) + 2ms;
        joints_next = true;  // that read only needs the joints
      } else if (!actions.empty()) {
        poll_at = clock::now();
        joints_next = false;
      }
      if (clock::now() >= poll_at) {
        const auto start = clock::now();
        poll(std::exchange(joints_next, false));
        if (answering_ && !lists_sent) {  // after the first state: a page shows the robot at once
          refresh_lists();
          lists_sent = true;
        }
        poll_at = start + (answering_ ? o_.period : 500ms);  // a silent board is tried twice a second
      }
      // A motion played from the host wakes the loop when its next pose is due, not a poll later.
      const auto wake = std::min(poll_at, studio_.due().value_or(poll_at));
      if (!h_.wait_until(wake)) break;
    }
  }

 private:
  /** Runs @p op; its value, or a default one with @p ec set. */
  template <class Op>
  auto run_ec(Op op, t::error_code& ec) {
    t::run(s_.c(), op, ec);
    return op.value();
  }

  /**
   * Another program changed the board through the studio's share of the port: once it has been
   * quiet for 300 ms (a push writes in many pieces), the lists are read again and pages told.
   */
  void notice_outside_writes() {
    if (!o_.outside_writes) return;
    const auto n = o_.outside_writes->load();
    if (n != outside_seen_) {
      outside_unseen_ += n - outside_seen_;
      outside_seen_ = n;
      outside_at_ = clock::now();
    } else if (outside_unseen_ > 0 && clock::now() - outside_at_ >= 300ms) {
      refresh_lists();
      json j;
      j["type"] = "note";
      j["text"] = fmt::format("another program (rcb4 or pyrcb4, through this studio) changed the board: {} write{}",
                              outside_unseen_, outside_unseen_ == 1 ? "" : "s");
      h_.tell(0, text_of(j));
      outside_unseen_ = 0;
    }
  }

  // --- reading -------------------------------------------------------------------------------
  /** Reads the robot and sends the state; @p joints_only (the read after a slider move) keeps the rest as last read. */
  void poll(bool joints_only = false) {
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

  void locate(t::error_code& ec) {
    auto op = robot::locate_joints(m_);
    s_.run_steps(op, ec, [] {});
    if (ec) return;
    map_ = op.value();
    reader_.emplace(map_, robot::fields::state, ops::link_cost::at(s_.baud(), 1ms));
  }

  std::string state_text() {
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
      a.push_back(degrees_json(angles_[i]));
      g.push_back(degrees_json(targets_[i]));
      md.push_back(answering_ ? modes_[i] : "unknown");
    }
    j["angles"] = std::move(a);
    j["targets"] = std::move(g);
    j["modes"] = std::move(md);
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
  std::vector<std::string> pose_names() const {
    std::vector<std::string> out;
    t::error_code ec;
    for (auto it = std::filesystem::directory_iterator(o_.poses, ec);
         !ec && it != std::filesystem::directory_iterator(); it.increment(ec)) {
      const auto& p = it->path();
      if (!(p.extension() == ".yaml" || p.extension() == ".json") || !it->is_regular_file(ec)) continue;
      const auto stem = p.stem().string();
      if (valid_pose_name(stem) && std::find(out.begin(), out.end(), stem) == out.end()) out.push_back(stem);
    }
    std::sort(out.begin(), out.end());
    return out;
  }

  void refresh_lists() {
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

  // --- actions -------------------------------------------------------------------------------
  void carry_out(const action& a) {
    const std::string_view op = std::visit(
        [](const auto& b) -> std::string_view {
          using B = std::decay_t<decltype(b)>;
          if constexpr (std::is_same_v<B, move_action>)
            return "move";
          else if constexpr (std::is_same_v<B, power_action>)
            return b.free ? "free" : "hold";
          else if constexpr (std::is_same_v<B, stop_action>)
            return "stop";
          else if constexpr (std::is_same_v<B, capture_action>)
            return "capture";
          else if constexpr (std::is_same_v<B, play_pose_action>)
            return "play_pose";
          else if constexpr (std::is_same_v<B, motion_play_action>)
            return "motion_play";
          else if constexpr (std::is_same_v<B, motion_stop_action>)
            return "motion_stop";
          else if constexpr (std::is_same_v<B, motion_file_action>)
            return "motion_file";
          else if constexpr (std::is_same_v<B, studio_action>)
            return b.op;
          else
            return "refresh";
        },
        a.body);
    try {
      json extra;
      if (const auto* st = std::get_if<studio_action>(&a.body)) {
        try {
          extra = studio_.act(*st, a.from);
        } catch (const studio_refusal& r) {
          throw refusal{r.what()};
        }
        if (st->op == "motion_push" || st->op == "motion_erase" || st->op == "motion_put_back") refresh_lists();
      } else {
        extra = std::visit([&](const auto& b) { return act(b); }, a.body);
      }
      // Slider moves come without an id; they are answered only when they fail.
      if (a.id || !std::holds_alternative<move_action>(a.body))
        if (a.from) h_.tell(a.from, reply_text(a.id, op, extra.is_null() ? std::string() : text_of(extra)));
    } catch (const refusal& r) {
      if (a.from) h_.tell(a.from, error_text(a.id, op, r.what));
    } catch (
        const std::exception& e) {  // a failure nothing above turned into words: the page hears it, the loop goes on
      answering_ = false;
      if (a.from) h_.tell(a.from, error_text(a.id, op, plain_message(e.what())));
    }
  }

  /** Runs @p op on the board; a failure is a refusal in the page's words. */
  template <class Op>
  auto must(Op op, std::string_view what) {
    t::error_code ec;
    auto v = run_ec(std::move(op), ec);
    if (ec) {
      if (std::error_code(ec).category() != rcb4::codec_category()) answering_ = false;
      throw refusal{words_of(ec, what)};
    }
    return v;
  }

  void located() {
    if (reader_) return;
    t::error_code ec;
    locate(ec);
    if (ec) throw refusal{words_of(ec, "locating the joints")};
  }

  void refuse_during_motion() {
    // The one rule (rcb4/robot/services/moves.hpp), on the state this loop keeps.
    if (!rom_program_) return;
    if (const auto why = rcb4::robot::services::move_refusal(motion_)) throw refusal{*why + " (stop it first)"};
  }

  /** The longest move the board makes: 255 frames of its output period (protocol.md §5). */
  std::chrono::milliseconds slowest() const { return std::chrono::milliseconds(255 * rcb4::milliseconds(period_)); }

  /** Moves @p targets (checked here again: nothing from a page is trusted). */
  json move(std::vector<robot::joint_target> targets) {
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
    move_at_ms_ =
        std::chrono::duration<double, std::milli>(std::chrono::system_clock::now().time_since_epoch()).count();
    std::chrono::milliseconds longest{0};
    for (const auto& mv : op.value())
      longest = std::max(longest, std::chrono::milliseconds(mv.frames * rcb4::milliseconds(op.period())));
    return json{{"ms", longest.count()}, {"joints", op.value().size()}};
  }

  json act(const move_action& a) { return move(a.targets); }

  rcb4::servo_mask mask_of(const std::vector<const robot::joint*>& joints, std::vector<std::string>* missing) {
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

  json act(const power_action& a) {
    std::vector<std::string> missing;
    const auto mask = mask_of(a.joints, &missing);
    if (mask.empty()) throw refusal{"none of these joints has a servo block on the board (see rcb4 scan)"};
    must(ops::set_servo_power(a.free ? ops::power_state::free : ops::power_state::hold, mask),
         a.free ? "free" : "hold");
    return json{{"joints", a.joints.size() - missing.size()}, {"missing", missing}};
  }

  /** Runs @p make()'s operation up to three times (a stop must get through a lossy line). */
  template <class Make>
  void insist(Make make, std::string_view what) {
    for (int attempt = 1;; ++attempt) {
      try {
        must(make(), what);
        return;
      } catch (const refusal&) {
        if (attempt == 3) throw;
      }
    }
  }

  json act(const studio_action&) { return nullptr; }  // carried out by carry_out, which knows the page

  json act(const stop_action& a) {
    json out;
    // A motion played from the host stops first: its next pose must not follow the hold.
    try {
      studio_.stop();
    } catch (const std::exception&) {  // the board may not answer: the hold below is tried anyway
    }
    // The state is read now, not taken from the last poll: a motion started since must stop too.
    // Stopping it comes first (it would drive the joints again), then the hold.
    if (a.motion) {
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
    }
    const auto mask = mask_of(a.joints, nullptr);
    if (!mask.empty()) insist([&] { return ops::set_servo_power(ops::power_state::hold, mask); }, "hold");
    out["held"] = a.joints.size();
    return out;
  }

  std::filesystem::path pose_path(const std::string& name, bool for_reading) const {
    try {
      return ui::pose_path(o_.poses, name, for_reading);
    } catch (const studio_refusal& e) {
      throw refusal{e.what()};
    }
  }

  json act(const capture_action& a) {
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
          clamped.push_back(
              fmt::format("{} {} (at {:.1f}, beyond its limit)", r.j->name, robot::number_text(within), h));
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

  json act(const play_pose_action& a) {
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
      throw refusal{
          fmt::format("a move takes at most 255 output periods: {} ms at this board's {} ms period, not {} ms",
                      slowest().count(), rcb4::milliseconds(period_), time.count())};
    time = std::max(time, paced_time(span, h_.limits()));
    std::vector<robot::joint_target> targets;
    for (const auto& [name, d] : p.joints) targets.push_back({name, d, time});
    auto out = move(std::move(targets));
    out["name"] = a.name;
    return out;
  }

  json act(const motion_play_action& a) {
    must(ops::play_motion(a.slot, *o_.layout, ops::servo_power::keep), "play the motion");
    return json{{"slot", a.slot}};
  }

  json act(const motion_stop_action&) {
    must(ops::stop_motion{}, "stop the motion");
    return nullptr;
  }

  json act(const refresh_action&) {
    refresh_lists();
    return nullptr;
  }

  /** The slot read back as `rcb4 motion pull` writes it. */
  json act(const motion_file_action& a) {
    const auto where = rcb4::motion::slot_of(*o_.layout, a.slot);
    if (!where || a.slot > o_.layout->motion_count)
      throw refusal{
          fmt::format("motion {} is outside this board's layout ({} slots)", a.slot, o_.layout->motion_count)};
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

  session& s_;
  const robot::model& m_;
  hub& h_;
  const loop_options& o_;
  robot::joint_map map_;
  std::optional<robot::read_joints> reader_;
  std::vector<std::optional<double>> angles_, targets_;
  std::vector<std::string> modes_;
  ops::analog_inputs analog_{};
  ops::motion_state motion_{};
  bool rom_program_ = false;
  rcb4::output_period period_ = rcb4::output_period::ms10;
  std::optional<double> move_at_ms_;  // when the board acknowledged the last move (system clock, ms)
  std::vector<ops::motion_slot> motions_;
  bool answering_ = false;
  std::string error_;
  std::uint64_t seq_ = 0;
  studio_ops studio_;
  std::uint64_t last_exchanges_ = 0;
  double rate_ = 0;
  clock::time_point last_rate_at_;
  std::uint64_t outside_seen_ = 0;    // o_.outside_writes when last looked at
  std::uint64_t outside_unseen_ = 0;  // writes not yet told to the pages
  clock::time_point outside_at_;      // when the last of them was seen
};

}  // namespace

void run_board_loop(session& s, const robot::model& m, hub& h, const loop_options& o) { loop(s, m, h, o).run(); }

}  // namespace cli::ui
