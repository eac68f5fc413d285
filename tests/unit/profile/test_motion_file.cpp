// Motion files: YAML in joint names, degrees and milliseconds, to the board's bytes and back.
// Golden bytes are written by hand from protocol.md §4 (MOV, SUB, JUMP, RETURN), §5 (CONST) and
// motions.md §1 (HTH4's SetCounter / Loop / CmpButton patterns), never from our own encoder.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/motion/disassemble.hpp>
#include <rcb4/robot/motion_file.hpp>

#include <catch2/catch.hpp>

#include <unistd.h>
#include <filesystem>
#include <fstream>

using namespace rcb4;
using namespace rcb4::robot;

namespace {
const model& khr() {
  static const model m = open_profile("khr-3hv");
  return m;
}
const motion::slot motion1{rom_address::make(0x0B80).value(), 2048};  // HTH4 2.2: motion 1

// Counter 3, then left_knee to +30 degrees in 300 ms, three times; again while UP is held.
const char* wave_text =
    "# a test motion\n"
    "robot: KHR-3HV\n"
    "period_ms: 15\n"
    "steps:\n"
    "  - set_counter: 3\n"
    "  - label: again\n"
    "  - pose: {left_knee: 30}\n"
    "    time_ms: 300\n"
    "  - loop: again\n"
    "  - if_buttons: up\n"
    "    goto: again\n"
    "  - end\n";

// By hand, slot at 0x0B80:
const std::vector<std::uint8_t> wave_bytes{
    // 0x0B80 MOV literal 3 -> RAM 0x0457 (1 byte): 08 00 02 57 04 00 03, SUM 0x68
    0x08, 0x00, 0x02, 0x57, 0x04, 0x00, 0x03, 0x68,
    // 0x0B88 CONST ICS 16 (mask byte 2 bit 0), update flags set, 20 frames of 15 ms,
    // 7500 + 30 x 8000/270 = 8389 = 0x20C5; SUM 0x115 -> 0x15
    0x0B, 0x10, 0x00, 0x00, 0x01, 0x00, 0x00, 0x14, 0xC5, 0x20, 0x15,
    // 0x0B93 SUB literal 1 from RAM 0x0457: 08 07 02 57 04 00 01, SUM 0x6D
    0x08, 0x07, 0x02, 0x57, 0x04, 0x00, 0x01, 0x6D,
    // 0x0B9B JUMP 0x000B88 when Z = 0 (compare Z, require 0: 0x04), SUM 0xA9
    0x07, 0x0B, 0x88, 0x0B, 0x00, 0x04, 0xA9,
    // 0x0BA2 SUB S of the button word 0x0350 (2 bytes): UP lies there as 00 01 (the receiver writes
    // the word high byte first, protocol.md §6), so the literal is 00 01: 09 07 82 50 03 00 00 01, SUM 0xE6
    0x09, 0x07, 0x82, 0x50, 0x03, 0x00, 0x00, 0x01, 0xE6,
    // 0x0BAB JUMP 0x000B88 when Z = 1 (0x05), SUM 0xAA
    0x07, 0x0B, 0x88, 0x0B, 0x00, 0x05, 0xAA,
    // 0x0BB2 RETURN
    0x03, 0x0D, 0x10};

std::vector<std::uint8_t> bytes_of(const motion_document& d, output_period board = output_period::ms15,
                                   bool rescale = false) {
  const auto c = to_program(d, khr(), hth4_2_2, board, rescale);
  REQUIRE(ok(c));
  const auto b = motion::assemble(std::get<compiled_motion>(c).program, motion1);
  REQUIRE(motion::ok(b));
  return std::get<std::vector<std::uint8_t>>(b);
}

std::string parse_error(const std::string& text) {
  try {
    parse_motion(text, "m.yaml", khr());
  } catch (const profile_error& e) {
    return e.what();
  }
  FAIL("the motion file was accepted:\n" << text);
  return {};
}

std::string program_problem(const std::string& text, output_period board = output_period::ms15) {
  const auto c = to_program(parse_motion(text, "m.yaml", khr()), khr(), hth4_2_2, board);
  REQUIRE_FALSE(ok(c));
  return std::get<problem>(c).message;
}

std::string with_steps(const std::string& steps, const std::string& period = "15") {
  return "robot: KHR-3HV\nperiod_ms: " + period + "\nsteps:\n" + steps;
}

std::filesystem::path temp_dir() {
  const auto d = std::filesystem::temp_directory_path() / ("rcb4-motion-file-test-" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d;
}
}  // namespace

TEST_CASE("motion file: the steps in joints and milliseconds become the bytes written by hand", "[motion_file]") {
  const auto d = parse_motion(wave_text, "wave.yaml", khr());
  CHECK(d.robot == "KHR-3HV");
  CHECK(d.period == output_period::ms15);
  REQUIRE(d.steps.size() == 6);
  CHECK(d.where[2] == "wave.yaml:7");
  CHECK(bytes_of(d) == wave_bytes);
}

TEST_CASE("motion file: a slot read back becomes the same file, and the file the same bytes", "[motion_file]") {
  const auto l = motion::disassemble(wave_bytes, motion1);
  const auto p = motion::lift(l);
  REQUIRE(motion::ok(p));
  const auto d = from_program(std::get<motion::program>(p), khr(), hth4_2_2, output_period::ms15);
  const std::string text = motion_yaml(d, "pulled from motion 1");
  CHECK(text.find("# pulled from motion 1\n") == 0);
  CHECK(text.find("- pose: {left_knee: 30}\n    time_ms: 300\n") != std::string::npos);
  CHECK(text.find("- loop: L0B88\n") != std::string::npos);
  CHECK(text.find("- if_buttons: \"up\"\n    goto: L0B88\n") != std::string::npos);
  const auto again = parse_motion(text, "pulled.yaml", khr());
  CHECK(again.steps == d.steps);
  CHECK(bytes_of(again) == wave_bytes);
}

TEST_CASE("motion file: every kind of step survives the round trip", "[motion_file]") {
  const std::string text = with_steps(
      "  - stretch: {legs: 60, head_yaw: 127}\n"
      "  - speed: {\"ics 30\": 10}\n"
      "  - label: top\n"
      "  - pose: {left_knee: -12.5, head_yaw: free, \"ics 11\": 7600, \"ics 10\": hold}\n"
      "    time_ms: 0\n"
      "  - count_down: out\n"
      "    when: zero\n"
      "    counter: 0x0460\n"
      "  - set_counter: 255\n"
      "    counter: 0x0461\n"
      "  - if_ram: 0x0460\n"
      "    size: 1\n"
      "    below: 3\n"
      "    goto: top\n"
      "  - if_ram: 0x0350\n"
      "    size: 2\n"
      "    at_least: 0x0100\n"
      "    goto: top\n"
      "  - unless_buttons: s1+up\n"
      "    goto: top\n"
      "  - call: 5\n"
      "  - call_address: 0x012345\n"
      "  - goto: top\n"
      "  - label: out\n"
      "  - end\n");
  const auto d = parse_motion(text, "all.yaml", khr());
  const auto bytes = bytes_of(d);
  const auto l = motion::disassemble(bytes, motion1);
  const auto p = motion::lift(l);
  REQUIRE(motion::ok(p));
  const auto back = from_program(std::get<motion::program>(p), khr(), hth4_2_2, output_period::ms15);
  const std::string yaml = motion_yaml(back);
  INFO(yaml);
  CHECK(bytes_of(parse_motion(yaml, "back.yaml", khr())) == bytes);
  // Calls by number where the address is a slot's start; others by address.
  CHECK(yaml.find("- call: 5\n") != std::string::npos);
  CHECK(yaml.find("- call_address: 0x012345\n") != std::string::npos);
  CHECK(yaml.find("head_yaw: free") != std::string::npos);
  CHECK(yaml.find("\"ics 10\": hold") != std::string::npos);
  CHECK(yaml.find("\"ics 11\": 7600") != std::string::npos);
  // Groups are written back joint by joint: the same servos, the same bytes.
  CHECK(yaml.find("left_knee: 60") != std::string::npos);
}

TEST_CASE("motion file: a pose over a limit is refused naming the step, its line, the joint and the limit",
          "[motion_file]") {
  const auto m =
      program_problem(with_steps("  - pose: {left_knee: 30}\n    time_ms: 100\n"
                                 "  - pose: {left_knee: 131}\n    time_ms: 100\n  - end\n"));
  CHECK(m.find("step 2 (m.yaml:6)") != std::string::npos);
  CHECK(m.find("left_knee: 131 degrees is beyond its upper limit 130") != std::string::npos);
}

TEST_CASE("motion file: times are frames of the period the file names, rescaled only on request", "[motion_file]") {
  const std::string text = with_steps("  - pose: {left_knee: 30}\n    time_ms: 300\n  - end\n");
  const auto d = parse_motion(text, "m.yaml", khr());
  // 300 ms at 10 ms: refused without --rescale (the motion would play 2/3 as long).
  const auto refused = to_program(d, khr(), hth4_2_2, output_period::ms10);
  REQUIRE_FALSE(ok(refused));
  CHECK(std::get<problem>(refused).message.find("made for 15 ms frames") != std::string::npos);
  CHECK(std::get<problem>(refused).message.find("--rescale") != std::string::npos);
  // Rescaled: 30 frames of 10 ms (byte 7 of the CONST), a note says so.
  const auto c = to_program(d, khr(), hth4_2_2, output_period::ms10, true);
  REQUIRE(ok(c));
  CHECK(std::get<compiled_motion>(c).notes.size() == 1);
  const auto& pose = std::get<motion::pose>(std::get<compiled_motion>(c).program.steps[0]);
  CHECK(pose.time.value() == 30);
  // 310 ms at 15 ms: 21 frames (315 ms), with a note.
  const auto odd =
      to_program(parse_motion(with_steps("  - pose: {left_knee: 30}\n    time_ms: 310\n  - end\n"), "m.yaml", khr()),
                 khr(), hth4_2_2, output_period::ms15);
  REQUIRE(ok(odd));
  CHECK(std::get<motion::pose>(std::get<compiled_motion>(odd).program.steps[0]).time.value() == 21);
  REQUIRE(std::get<compiled_motion>(odd).notes.size() == 1);
  CHECK(std::get<compiled_motion>(odd).notes[0].find("310 ms is 21 frames of 15 ms (315 ms)") != std::string::npos);
  // Beyond 255 frames: refused.
  CHECK(program_problem(with_steps("  - pose: {left_knee: 30}\n    time_ms: 4000\n  - end\n"))
            .find("at most 255 (3825 ms)") != std::string::npos);
}

TEST_CASE("motion file: a step after an end or a goto is noted as never running", "[motion_file]") {
  // The habit of ending every file with end, after a loop that jumps back for ever (found by
  // fuzzing: such an end is written, but a pull follows the code and does not show it).
  const auto d = parse_motion(with_steps("  - label: top\n  - pose: {left_knee: 30}\n    time_ms: 300\n"
                                         "  - goto: top\n  - end\n  - label: more\n  - end\n"),
                              "m.yaml", khr());
  const auto c = to_program(d, khr(), hth4_2_2, output_period::ms15);
  REQUIRE(ok(c));
  const auto& notes = std::get<compiled_motion>(c).notes;
  REQUIRE(notes.size() == 1);  // the end after the goto; the label after the end starts reachable code
  CHECK(notes[0].find("step 4 (m.yaml:") == 0);
  CHECK(notes[0].find("never runs: the step before it always jumps away") != std::string::npos);
  CHECK(std::get<compiled_motion>(c).program.steps.size() == 6);  // still written as the file says
}

TEST_CASE("motion file: pose files are read beside the motion file", "[motion_file]") {
  const auto dir = temp_dir();
  {
    std::ofstream(dir / "crouch.yaml") << "robot: KHR-3HV\ntime_ms: 450\njoints: {left_knee: 60, right_knee: -60}\n";
    std::ofstream(dir / "m.yaml") << with_steps(
        "  - pose: crouch.yaml\n  - pose: crouch.yaml\n    time_ms: 150\n"
        "  - end\n");
  }
  const auto d = load_motion(dir / "m.yaml", khr());
  REQUIRE(d.steps.size() == 3);
  const auto& first = std::get<motion_pose>(d.steps[0]);
  CHECK(first.time.count() == 450);  // the pose file's time
  CHECK(first.targets.size() == 2);
  CHECK(std::get<motion_pose>(d.steps[1]).time.count() == 150);  // the step's own
  // Written back as the same file reference.
  CHECK(motion_yaml(d).find("- pose: \"crouch.yaml\"\n    time_ms: 450\n") != std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST_CASE("motion file: mistakes name the file, the line and what is wrong", "[motion_file]") {
  CHECK(parse_error("robot: KHR-3HV\nsteps:\n  - end\n").find("period_ms: say which output period") !=
        std::string::npos);
  CHECK(parse_error(with_steps("  - end\n", "12")).find("10, 15, 20 and 25") != std::string::npos);
  CHECK(parse_error(with_steps("  - pose: {left_kneee: 3}\n    time_ms: 100\n")) ==
        "m.yaml:4:12: no joint of KHR-3HV is called 'left_kneee' (a servo outside the profile: \"ics N\")");
  CHECK(parse_error(with_steps("  - pose: {left_knee: 3}\n")).find("m.yaml:4:5: pose: time_ms says") == 0);
  CHECK(parse_error(with_steps("  - pose: {left_knee: 3}\n    time_ms: 100\n    label: x\n"))
            .find("one step does one thing: pose and label") != std::string::npos);
  CHECK(parse_error(with_steps("  - jump: x\n")).find("the step says what it does") != std::string::npos);
  CHECK(parse_error(with_steps("  - if_buttons: upp\n    goto: x\n")).find("m.yaml:4:17: if_buttons:") == 0);
  CHECK(parse_error(with_steps("  - if_ram: 0x0460\n    size: 1\n    equal: 300\n    goto: x\n")).find("0..255") !=
        std::string::npos);
  CHECK(parse_error(with_steps("  - call: 0\n")).find("1..120") != std::string::npos);
  CHECK(parse_error(with_steps("  - stretch: {legs: 200}\n")).find("1..127") != std::string::npos);
  CHECK(parse_error(with_steps("  - stretch: {wings: 20}\n")).find("wings") != std::string::npos);
  CHECK(parse_error("robot: KXR\nperiod_ms: 15\nsteps:\n  - end\n").find("this motion is KXR's, not KHR-3HV's") !=
        std::string::npos);
  CHECK(parse_error(with_steps("  - pose: missing.yaml\n    time_ms: 10\n")).find("missing.yaml") == 0);
  CHECK(program_problem(with_steps("  - goto: nowhere\n")) == "step 1 (m.yaml:4): no label is called 'nowhere'");
  CHECK(program_problem(with_steps("  - pose: {left_knee: 3}\n    time_ms: 10\n")) ==
        "step 1 (m.yaml:4): the last step is neither end nor goto: the board would run on into the bytes after the "
        "motion");
  CHECK(program_problem(with_steps("  - label: a\n  - label: a\n  - end\n")).find("'a' is defined twice") !=
        std::string::npos);
  CHECK(program_problem(with_steps("  - pose: {left_knee: 3, \"ics 16\": 7500}\n    time_ms: 10\n  - end\n"))
            .find("left_knee and ics 16 are the same servo (ICS 16)") != std::string::npos);
  CHECK(program_problem(with_steps("  - stretch: {legs: 20, left_knee: 30}\n  - end\n"))
            .find("legs and left_knee both set ICS 16") != std::string::npos);
}

TEST_CASE("motion file: written to a .yaml file and read back", "[motion_file]") {
  const auto dir = temp_dir();
  const auto d = parse_motion(wave_text, "wave.yaml", khr());
  save_motion(dir / "w.yaml", d, "saved");
  CHECK(bytes_of(load_motion(dir / "w.yaml", khr())) == wave_bytes);
  CHECK_THROWS_AS(save_motion(dir / "w.json", d), profile_error);
  CHECK_THROWS_AS(save_motion(dir / "no" / "such" / "w.yaml", d), profile_error);
  std::filesystem::remove_all(dir);
}

TEST_CASE("motion file: a step's name and flowchart place are kept, and the board never sees them", "[motion_file]") {
  const std::string text =
      "robot: KHR-3HV\n"
      "period_ms: 15\n"
      "steps:\n"
      "  - set_counter: 3\n"
      "    at: [8, 16]\n"
      "  - label: again\n"
      "  - pose: {left_knee: 30}\n"
      "    time_ms: 300\n"
      "    name: \"knee up\"\n"
      "    at: [8, 96]\n"
      "  - loop: again\n"
      "    name: twice more\n"
      "  - end\n";
  const auto d = parse_motion(text, "v.yaml", khr());
  REQUIRE(d.views.size() == 5);
  CHECK(d.views[0].at == std::array<long, 2>{8, 16});
  CHECK(d.views[0].name.empty());
  CHECK(d.views[1] == step_view{});
  CHECK(d.views[2].name == "knee up");
  CHECK(d.views[2].at == std::array<long, 2>{8, 96});
  CHECK(d.views[3].name == "twice more");
  CHECK_FALSE(d.views[3].at);
  // The same bytes as the file without them.
  std::string stripped;
  for (std::size_t at = 0; at < text.size();) {
    const auto nl = text.find('\n', at);
    const auto line = text.substr(at, nl - at + 1);
    if (line.find("name:") == std::string::npos && line.find("at:") == std::string::npos) stripped += line;
    at = nl + 1;
  }
  const auto plain = parse_motion(stripped, "p.yaml", khr());
  CHECK(bytes_of(d) == bytes_of(plain));
  // Written and read again: the same views; JSON carries them too.
  const auto yaml = motion_yaml(d);
  CHECK(yaml.find("    name: \"knee up\"\n    at: [8, 96]\n") != std::string::npos);
  CHECK(parse_motion(yaml, "again.yaml", khr()).views == d.views);
  CHECK(motion_json(d).find("\"at\":[8,96]") != std::string::npos);
  // A file without any keeps none.
  CHECK(plain.views.empty());
}

TEST_CASE("motion file: a bad name or place is refused with its line", "[motion_file]") {
  const auto bad = [](const std::string& step, const std::string& want) {
    const std::string text =
        "period_ms: 15\nsteps:\n  - pose: {left_knee: 30}\n    time_ms: 300\n" + step + "  - end\n";
    try {
      (void)parse_motion(text, "b.yaml", khr());
      FAIL("accepted: " << step);
    } catch (const profile_error& e) {
      CHECK_THAT(e.what(), Catch::Matchers::Contains(want));
      CHECK_THAT(e.what(), Catch::Matchers::Contains("b.yaml:"));
    }
  };
  bad("  - goto: x\n    at: [1]\n", "at: the flowchart block's place");
  bad("  - goto: x\n    at: [1, -5]\n", "at: y");
  bad("  - goto: x\n    at: {x: 1, y: 2}\n", "at: the flowchart block's place");
  bad("  - goto: x\n    name: \"" + std::string(81, 'n') + "\"\n", "name: at most 80 characters");
  bad("  - name: lonely\n", "the step says what it does");
}
