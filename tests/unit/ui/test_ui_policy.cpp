// rcb4 ui's policy without a socket or a clock: the pages' messages, who controls, how fast and
// how far a page may move the robot, and what a lost page leaves. Expected values by hand.
// SPDX-License-Identifier: BSL-1.0
#include <catch2/catch.hpp>

#include "controller.hpp"
#include "messages.hpp"

#include <nlohmann/json.hpp>

#include <string>

using namespace cli::ui;
using namespace std::chrono_literals;
namespace robot = rcb4::robot;

namespace {

robot::model two_joints() {
  std::vector<robot::joint> js(2);
  js[0].name = "head_yaw";
  js[0].ics = rcb4::ics_number::make(0).value();
  js[0].lower = -90;
  js[0].upper = 90;
  js[1].name = "left_knee";
  js[1].ics = rcb4::ics_number::make(16).value();
  js[1].lower = -130;
  js[1].upper = 130;
  auto m = robot::model::make("TEST", js, {{"legs", {"left_knee"}}});
  return std::get<robot::model>(std::move(m));
}

nlohmann::json last_json(const effects& e) {
  REQUIRE(!e.letters.empty());
  return nlohmann::json::parse(e.letters.back().text);
}

std::string parse_failure(std::string_view text) {
  auto r = parse_message(text);
  REQUIRE(std::holds_alternative<parse_error>(r));
  return std::get<parse_error>(r).what;
}

}  // namespace

TEST_CASE("ui messages: every op parses with its fields", "[ui]") {
  auto r = parse_message(R"({"op":"move","id":7,"joints":{"left_knee":40.5,"head_yaw":-3},"ms":300})");
  REQUIRE(std::holds_alternative<message>(r));
  const auto& m = std::get<message>(r);
  CHECK(m.id == 7);
  const auto& mv = std::get<move_request>(m.body);
  REQUIRE(mv.joints.size() == 2);
  CHECK(mv.joints[0].first == "left_knee");  // the order the page gave
  CHECK(mv.joints[0].second == 40.5);
  CHECK(mv.joints[1].second == -3);
  CHECK(mv.ms == 300);

  const auto p =
      std::get<power_request>(std::get<message>(parse_message(R"({"op":"free","joints":["legs","all"]})")).body);
  CHECK(p.free);
  CHECK(p.words == std::vector<std::string>{"legs", "all"});
  CHECK(!std::get<power_request>(std::get<message>(parse_message(R"({"op":"hold","joints":["all"]})")).body).free);
  const auto c = std::get<capture_request>(
      std::get<message>(parse_message(R"({"op":"capture","name":"wave-2_b","force":true})")).body);
  CHECK(c.name == "wave-2_b");
  CHECK(c.force);
  const auto pp =
      std::get<play_pose_request>(std::get<message>(parse_message(R"({"op":"play_pose","name":"w"})")).body);
  CHECK(pp.name == "w");
  CHECK(!pp.ms);
  CHECK(
      std::get<motion_play_request>(std::get<message>(parse_message(R"({"op":"motion_play","slot":120})")).body).slot ==
      120);
  for (auto op : {"control", "release", "stop", "motion_stop", "refresh"}) {
    auto x = parse_message(std::string(R"({"op":")") + op + "\"}");
    REQUIRE(std::holds_alternative<message>(x));
    CHECK(op_name(std::get<message>(x).body) == op);
  }
}

TEST_CASE("ui messages: bad ones are refused with the reason", "[ui]") {
  CHECK(parse_failure("") == "not a JSON text");
  CHECK(parse_failure("{\"op\":") == "not a JSON text");
  CHECK(parse_failure("[1,2]") == "a message is a JSON object with an \"op\"");
  CHECK(parse_failure(R"({"id":1})") == "a message needs \"op\": a string");
  CHECK(parse_failure(R"({"op":"dance"})").rfind("unknown op 'dance' (known: control,", 0) == 0);
  CHECK(parse_failure(R"({"op":"stop","speed":1})") == "stop: unknown key 'speed' (known: op, id)");
  CHECK(parse_failure(R"({"op":"move","joints":{"a":"10"}})") == "move: 'a' must be a number of degrees");
  CHECK(parse_failure(R"({"op":"move","joints":{"a":true}})") == "move: 'a' must be a number of degrees");
  CHECK(parse_failure(R"({"op":"move","joints":{}})") == "move: 'joints' must be an object of joint names and degrees");
  CHECK(parse_failure(R"({"op":"move","joints":{"a":1e999}})") == "not a JSON text");  // out of double's range
  CHECK(parse_failure(R"({"op":"move","joints":{"a":1},"ms":6376})") == "move: 'ms' is 6376, outside 0..6375");
  CHECK(parse_failure(R"({"op":"move","joints":{"a":1},"ms":-1})") == "move: 'ms' is -1, outside 0..6375");
  CHECK(parse_failure(R"({"op":"move","joints":{"a":1},"ms":1.5})") ==
        "move: 'ms' must be a whole number of milliseconds");
  CHECK(parse_failure(R"({"op":"free","joints":"all"})") ==
        "free: 'joints' must be a list of joint or group names, or [\"all\"]");
  CHECK(parse_failure(R"({"op":"capture","name":"../etc/passwd"})") ==
        "capture: a pose name uses A-Z, a-z, 0-9, _ and -");
  CHECK(parse_failure(R"({"op":"capture","name":"a.yaml"})") == "capture: a pose name uses A-Z, a-z, 0-9, _ and -");
  CHECK(parse_failure(R"({"op":"capture","name":""})") == "capture: 'name' must be 1..64 bytes");
  CHECK(parse_failure(R"({"op":"capture","name":"a","force":1})") == "capture: 'force' must be true or false");
  CHECK(parse_failure(R"({"op":"motion_play","slot":0})") == "motion_play: slot 0 is outside 1..120");
  CHECK(parse_failure(R"({"op":"motion_file","slot":121})") == "motion_file: slot 121 is outside 1..120");
  CHECK(parse_failure(R"({"op":"motion_file","slot":"2"})") == "motion_file: 'slot' must be a whole number");
  CHECK(parse_failure(R"({"op":"motion_play","slot":"2"})") == "motion_play: 'slot' must be a whole number");
  CHECK(parse_failure(R"({"op":"stop","op":"move"})") == "a key is given twice");
  CHECK(parse_failure(R"({"op":"move","joints":{"a":1,"a":2}})") == "a key is given twice");
  CHECK(parse_failure(R"({"op":"stop","id":"x"})") == "'id' must be a whole number");
  CHECK(parse_failure(R"({"op":"stop","x":[[[[1]]]]})") == "message nested too deeply");
  CHECK(parse_failure(std::string(max_message_bytes + 1, ' ')).find("at most " + std::to_string(max_message_bytes)) !=
        std::string::npos);

  // The id survives a refused body, so the page can match the answer.
  auto r = parse_message(R"({"op":"motion_play","id":42,"slot":500})");
  REQUIRE(std::holds_alternative<parse_error>(r));
  CHECK(std::get<parse_error>(r).id == 42);
}

TEST_CASE("ui controller: the first page controls, the others watch", "[ui]") {
  const auto m = two_joints();
  controller c(m);
  const auto a = c.join(1);
  CHECK(c.controlling() == 1u);
  CHECK(last_json(a)["role"] == "control");
  const auto b = c.join(2);
  CHECK(last_json(b)["role"] == "view");
  CHECK(last_json(b)["controlled"] == true);
  const auto t0 = clock::time_point{} + 1h;

  // A watching page changes nothing.
  auto e = c.receive(2, R"({"op":"move","id":3,"joints":{"left_knee":10}})", t0);
  CHECK(e.actions.empty());
  CHECK(last_json(e)["message"] == "this page only watches: take control first");
  CHECK(last_json(e)["id"] == 3);
  CHECK(!c.due_move(t0 + 1s));
  e = c.receive(2, R"({"op":"control"})", t0);
  CHECK(last_json(e)["type"] == "error");
  CHECK(c.controlling() == 1u);
  // Reading the lists is for anyone.
  e = c.receive(2, R"({"op":"refresh"})", t0);
  REQUIRE(e.actions.size() == 1);
  CHECK(std::holds_alternative<refresh_action>(e.actions[0].body));
  // And reading a motion slot as a motion file.
  e = c.receive(2, R"({"op":"motion_file","slot":2,"id":9})", t0);
  REQUIRE(e.actions.size() == 1);
  CHECK(std::get<motion_file_action>(e.actions[0].body).slot == 2u);
  CHECK(e.actions[0].id == 9);

  // Released: the watcher may take it; both pages hear the new roles.
  e = c.receive(1, R"({"op":"release","id":1})", t0);
  CHECK(!c.controlling());
  CHECK(e.actions.empty());  // releasing is not a stop
  e = c.receive(2, R"({"op":"control","id":2})", t0);
  CHECK(c.controlling() == 2u);
  int roles = 0;
  for (const auto& l : e.letters)
    if (nlohmann::json::parse(l.text)["type"] == "role") ++roles;
  CHECK(roles == 2);
}

TEST_CASE("ui controller: slider moves are gathered, clamped and paced", "[ui]") {
  const auto m = two_joints();
  settings s;  // 90 degrees a second, one move per 40 ms
  controller c(m, s);
  c.join(1);
  const auto t0 = clock::time_point{} + 1h;
  const std::optional<double> at_zero[] = {0.0, 0.0};
  c.observe(at_zero, at_zero);

  // Three slider positions before the loop looks: only the last is sent.
  c.receive(1, R"({"op":"move","joints":{"left_knee":10}})", t0);
  c.receive(1, R"({"op":"move","joints":{"left_knee":20}})", t0 + 5ms);
  auto e = c.receive(1, R"({"op":"move","joints":{"left_knee":45,"head_yaw":-9}})", t0 + 10ms);
  CHECK(e.letters.empty());  // no id, nothing clamped: no answer
  auto mv = c.due_move(t0 + 10ms);
  REQUIRE(mv);
  auto& targets = std::get<move_action>(mv->body).targets;
  REQUIRE(targets.size() == 2);
  CHECK(targets[0].joint == "head_yaw");  // model order
  CHECK(targets[0].degrees == -9);
  CHECK(targets[0].time == 100ms);  // 9 degrees at 90/s
  CHECK(targets[1].joint == "left_knee");
  CHECK(targets[1].degrees == 45);
  CHECK(targets[1].time == 500ms);  // 45 degrees at 90/s

  // The next one waits for the move interval.
  c.receive(1, R"({"op":"move","joints":{"left_knee":46}})", t0 + 20ms);
  CHECK(!c.due_move(t0 + 49ms));
  mv = c.due_move(t0 + 50ms);
  REQUIRE(mv);
  // Timed from the farther of the board's target (0: not there yet) and the last sent (45).
  CHECK(std::get<move_action>(mv->body).targets[0].time == 512ms);
  CHECK(!c.due_move(t0 + 1s));  // nothing left

  // Beyond a limit: clamped, and the page is told.
  e = c.receive(1, R"({"op":"move","id":9,"joints":{"left_knee":500}})", t0 + 2s);
  const auto note = nlohmann::json::parse(e.letters.at(0).text);
  CHECK(note["type"] == "note");
  CHECK(note["clamped"][0] == "left_knee: 500 is beyond its upper limit 130: moved to 130");
  CHECK(e.letters.size() == 1);  // the move itself is answered by the board loop, once sent
  mv = c.due_move(t0 + 2s);
  REQUIRE(mv);
  CHECK(mv->id == 9);
  CHECK(std::get<move_action>(mv->body).targets[0].degrees == 130);

  // An unknown joint moves nothing, not even the others named with it.
  e = c.receive(1, R"({"op":"move","joints":{"left_knee":1,"tail":3}})", t0 + 3s);
  CHECK(last_json(e)["message"] == "no joint is called 'tail'");
  CHECK(!c.due_move(t0 + 4s));

  // The page's own time is kept when it is longer than the pace needs; a short one is lengthened.
  c.receive(1, R"({"op":"move","joints":{"head_yaw":-8},"ms":2000})", t0 + 5s);
  CHECK(std::get<move_action>(c.due_move(t0 + 5s)->body).targets[0].time == 2000ms);
  c.receive(1, R"({"op":"move","joints":{"head_yaw":90},"ms":0})", t0 + 6s);
  CHECK(std::get<move_action>(c.due_move(t0 + 6s)->body).targets[0].time == 1089ms);  // 98 degrees: ceil(1088.9)
}

TEST_CASE("ui controller: a free joint is not driven by a slider value still waiting", "[ui]") {
  const auto m = two_joints();
  controller c(m);
  c.join(1);
  const auto t0 = clock::time_point{} + 1h;
  c.receive(1, R"({"op":"move","joints":{"left_knee":30}})", t0);
  auto e = c.receive(1, R"({"op":"free","id":4,"joints":["legs"]})", t0);
  REQUIRE(e.actions.size() == 1);
  const auto& p = std::get<power_action>(e.actions[0].body);
  CHECK(p.free);
  REQUIRE(p.joints.size() == 1);
  CHECK(p.joints[0]->name == "left_knee");
  CHECK(e.actions[0].id == 4);
  CHECK(!c.due_move(t0 + 1s));
  e = c.receive(1, R"({"op":"hold","joints":["arms"]})", t0);
  CHECK(last_json(e)["message"] == "no joint or group is called 'arms'");
}

TEST_CASE("ui controller: a lost controlling page stops what it moved", "[ui]") {
  const auto m = two_joints();
  controller c(m);
  c.join(1);
  c.join(2);
  const auto t0 = clock::time_point{} + 1h;
  c.receive(1, R"({"op":"move","joints":{"left_knee":30}})", t0);
  REQUIRE(c.due_move(t0));
  c.receive(1, R"({"op":"motion_play","slot":2})", t0);
  c.receive(1, R"({"op":"move","joints":{"head_yaw":30}})", t0 + 1ms);  // still waiting when the page goes

  // A watcher leaving changes nothing.
  CHECK(c.leave(2).actions.empty());
  c.join(3);
  const auto e = c.leave(1);
  REQUIRE(e.actions.size() == 1);
  const auto& stop = std::get<stop_action>(e.actions[0].body);
  // it had started a motion: every joint holds (the motion's pose under way would run on)
  REQUIRE(stop.joints.size() == 2);
  CHECK(stop.motion);
  CHECK(!c.due_move(t0 + 1s));
  CHECK(!c.controlling());  // nobody is handed control: a page must ask
  CHECK(last_json(e)["controlled"] == false);
  CHECK(c.leave(1).actions.empty());  // twice: nothing
}

TEST_CASE("ui controller: a lost page that only moved joints holds those alone", "[ui]") {
  const auto m = two_joints();
  controller c(m);
  c.join(1);
  const auto t0 = clock::time_point{} + 1h;
  c.receive(1, R"({"op":"move","joints":{"left_knee":30}})", t0);
  REQUIRE(c.due_move(t0));
  const auto e = c.leave(1);
  REQUIRE(e.actions.size() == 1);
  const auto& stop = std::get<stop_action>(e.actions[0].body);
  REQUIRE(stop.joints.size() == 1);  // the knee it moved
  CHECK(stop.joints[0]->name == "left_knee");
  CHECK_FALSE(stop.motion);
}

TEST_CASE("ui controller: a watching page may stop, and nothing else that writes", "[ui]") {
  const auto m = two_joints();
  controller c(m);
  c.join(1);
  c.join(2);
  const auto t0 = clock::time_point{} + 1h;
  const auto stop = c.receive(2, R"({"op":"stop","id":3})", t0);
  REQUIRE(stop.actions.size() == 1);
  CHECK(std::holds_alternative<stop_action>(stop.actions[0].body));
  CHECK(std::get<stop_action>(stop.actions[0].body).motion);
  const auto mstop = c.receive(2, R"({"op":"motion_stop","id":4})", t0);
  REQUIRE(mstop.actions.size() == 1);
  CHECK(std::holds_alternative<motion_stop_action>(mstop.actions[0].body));
  CHECK(c.receive(2, R"({"op":"motion_play","slot":2,"id":5})", t0).actions.empty());  // watching: refused
}

TEST_CASE("ui controller: a page that floods is slowed, then heard again", "[ui]") {
  const auto m = two_joints();
  settings s;
  s.messages_per_second = 10;
  s.message_burst = 5;
  controller c(m, s);
  c.join(1);
  const auto t0 = clock::time_point{} + 1h;
  int refused = 0, heard = 0;
  for (int i = 0; i < 20; ++i) {
    const auto e = c.receive(1, R"({"op":"refresh"})", t0);
    heard += static_cast<int>(e.actions.size());
    for (const auto& l : e.letters)
      if (nlohmann::json::parse(l.text)["message"].get<std::string>().rfind("too many messages", 0) == 0) ++refused;
  }
  CHECK(heard == 5);
  CHECK(refused == 1);                                                 // told once, not once per message
  const auto later = c.receive(1, R"({"op":"refresh"})", t0 + 200ms);  // 2 tokens back
  CHECK(later.actions.size() == 1);
  // Stop is never dropped: a flooded robot needs it most.
  for (int i = 0; i < 20; ++i) c.receive(1, R"({"op":"move","joints":{"left_knee":1}})", t0 + 200ms);
  const auto stop = c.receive(1, R"({"op":"stop","id":999})", t0 + 200ms);
  REQUIRE(stop.actions.size() == 1);
  CHECK(std::holds_alternative<stop_action>(stop.actions[0].body));
}

TEST_CASE("ui controller: malformed text gets an error, never an action", "[ui]") {
  const auto m = two_joints();
  controller c(m);
  c.join(1);
  const auto t0 = clock::time_point{} + 1h;
  for (std::string_view bad :
       {"", "\xff\xfe", "null", "{\"op\":\"move\",\"joints\":{\"\xff\":1}}", "{{{{", "[[[[[[[[[["}) {
    const auto e = c.receive(1, bad, t0);
    CHECK(e.actions.empty());
    REQUIRE(e.letters.size() == 1);
    CHECK(nlohmann::json::parse(e.letters[0].text)["type"] == "error");  // valid JSON even for bad bytes
  }
  CHECK(c.receive(99, R"({"op":"stop"})", t0).letters.empty());  // an unknown page: ignored
}

TEST_CASE("ui paced_time: at least one move interval, at most the longest move", "[ui]") {
  settings s;
  CHECK(paced_time(0, s) == 40ms);
  CHECK(paced_time(-45, s) == 500ms);
  CHECK(paced_time(10000, s) == 6375ms);
}

TEST_CASE("ui controller: a move longer than the board's longest goes part way at the speed limit", "[ui]") {
  const auto m = two_joints();
  controller c(m);  // 90 degrees a second
  c.join(1);
  const auto t0 = clock::time_point{} + 1h;
  const std::optional<double> start[] = {-90.0, 0.0};
  c.observe(start, start, 2550ms);                                // a 10 ms board: 255 frames
  c.receive(1, R"({"op":"move","joints":{"head_yaw":90}})", t0);  // 180 degrees: 2 s, fits
  auto mv = c.due_move(t0);
  REQUIRE(mv);
  CHECK(std::get<move_action>(mv->body).targets[0].degrees == 90);
  CHECK(std::get<move_action>(mv->body).targets[0].time == 2000ms);

  const std::optional<double> far[] = {0.0, -130.0};
  c.observe(far, far, 2550ms);
  c.receive(1, R"({"op":"move","joints":{"left_knee":130},"ms":100})", t0 + 1s);  // 260 degrees: 2.9 s
  mv = c.due_move(t0 + 1s);
  REQUIRE(mv);
  const auto& first = std::get<move_action>(mv->body).targets[0];
  CHECK(first.degrees == Approx(-130 + 229.5));  // 90 degrees a second for 2.55 s
  CHECK(first.time == 2550ms);
  // The rest follows from where the board is then.
  const std::optional<double> later[] = {0.0, 80.0};
  c.observe(later, later, 2550ms);
  mv = c.due_move(t0 + 1s + 40ms);
  REQUIRE(mv);
  CHECK(std::get<move_action>(mv->body).targets[0].degrees == 130);
  CHECK(std::get<move_action>(mv->body).targets[0].time == 556ms);  // 50 degrees from 80: ceil(555.6)
  CHECK(!c.due_move(t0 + 2s));
}

TEST_CASE("ui controller: after free, a move is timed from the measured angle", "[ui]") {
  const auto m = two_joints();
  controller c(m);
  c.join(1);
  const auto t0 = clock::time_point{} + 1h;
  const std::optional<double> zero[] = {0.0, 0.0};
  c.observe(zero, zero);
  c.receive(1, R"({"op":"move","joints":{"head_yaw":0}})", t0);
  REQUIRE(c.due_move(t0));
  c.receive(1, R"({"op":"free","joints":["head_yaw"]})", t0);
  // Moved by hand to 80 while free: the board shows no target, the measured angle 80.
  const std::optional<double> targets[] = {std::nullopt, 0.0};
  const std::optional<double> angles[] = {80.0, 0.0};
  c.observe(targets, angles);
  c.receive(1, R"({"op":"move","joints":{"head_yaw":1}})", t0 + 1s);
  const auto mv = c.due_move(t0 + 1s);
  REQUIRE(mv);
  CHECK(std::get<move_action>(mv->body).targets[0].time == 878ms);  // 79 degrees, not 1
}

TEST_CASE("ui studio messages: each op's fields checked and only the controlling page writes", "[ui]") {
  // Fields checked before anything reaches the board loop.
  CHECK(parse_failure(R"({"op":"motion_push","slot":10})") == "motion_push: 'text' is missing");
  CHECK(parse_failure(R"({"op":"motion_push","slot":0,"text":"x"})") == "motion_push: slot 0 is outside 1..120");
  CHECK(parse_failure(R"({"op":"motion_push","slot":3,"text":7})") ==
        "motion_push: 'text' must be a motion file's text (YAML or JSON)");
  CHECK(parse_failure(R"({"op":"motion_pull","slot":3,"force":true})").find("motion_pull: unknown key 'force'") == 0);
  CHECK(parse_failure(R"({"op":"trim_set","joints":{"left_knee":"1"}})") ==
        "trim_set: 'left_knee' must be a number of degrees");
  CHECK(parse_failure(R"({"op":"button_press","buttons":"up","hold":1})") ==
        "button_press: 'hold' must be true or false");
  CHECK(parse_failure(R"({"op":"hand","joint":"left_knee"})") == "hand: 'degrees' is missing");
  CHECK(parse_failure(R"({"op":"motion_check","text":")" + std::string(max_text_bytes + 1, 'x') + R"("})")
            .find("longer than") != std::string::npos);
  CHECK(parse_failure(R"({"op":"frobnicate"})").find("motion_push") != std::string::npos);  // the known ops listed
  CHECK(parse_failure(R"({"op":"motion_put_back","slot":10,"base64":"%%"})") ==
        "motion_put_back: 'base64' must be 1 to 60,000 characters of base64");
  CHECK(parse_failure(R"({"op":"motion_put_back","slot":10})") == "motion_put_back: 'base64' is missing");
  CHECK(parse_failure(R"({"op":"motion_put_back","slot":121,"base64":"AA=="})") ==
        "motion_put_back: slot 121 is outside 1..120");

  const auto m = two_joints();
  controller c(m);
  c.join(1);
  c.join(2);
  const auto t0 = clock::time_point{} + 1h;
  // Reading: any page; the action carries the checked fields.
  auto e = c.receive(2, R"({"op":"motion_pull","slot":7,"id":4})", t0);
  REQUIRE(e.actions.size() == 1);
  const auto& pull = std::get<studio_action>(e.actions[0].body);
  CHECK(pull.op == "motion_pull");
  CHECK(nlohmann::json::parse(pull.args) == nlohmann::json{{"slot", 7}});
  // Writing: the watcher is refused, the controller heard.
  e = c.receive(2, R"({"op":"motion_erase","slot":7,"id":5})", t0);
  CHECK(e.actions.empty());
  CHECK(last_json(e)["message"] == "this page only watches: take control first");
  e = c.receive(1, R"({"op":"play_motion","text":"robot: TEST","id":6})", t0);
  REQUIRE(e.actions.size() == 1);
  CHECK(std::get<studio_action>(e.actions[0].body).op == "play_motion");
  // A page that played a motion from the host and goes: it is stopped.
  e = c.leave(1);
  REQUIRE(e.actions.size() == 1);
  CHECK(std::get<stop_action>(e.actions[0].body).motion);
}
