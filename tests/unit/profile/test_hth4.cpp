// HTH4 project (.h4p) and trim (.h4t) files: the test files of tests/data/hth4 (written in HTH4's
// schema by make_fixtures.py, not by rcb4's writer) read to the values they hold, written back byte
// for byte, relocated between layouts as hth4-files.md §4 shows, and every kind of bad file
// refused with its file, line and element.
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/robot/hth4/flowchart.hpp>
#include <rcb4/robot/hth4/project.hpp>
#include <rcb4/robot/hth4/to_files.hpp>
#include <rcb4/robot/hth4/trim_file.hpp>

#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace rcb4::robot;
using namespace rcb4::robot::hth4;
using bytes = std::vector<std::uint8_t>;

namespace {
std::string data(const char* name) {
  std::ifstream in(std::string(RCB4_HTH4_DATA) + "/" + name, std::ios::binary);
  REQUIRE(in);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}
/** @p text with the first @p from replaced by @p to (which must be there). */
std::string edit(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  REQUIRE(at != std::string::npos);
  return text.replace(at, from.size(), to);
}
/** The error reading @p text as a project, or "" when it reads. */
std::string project_error(const std::string& text) {
  try {
    parse_project(text, "p.h4p");
  } catch (const profile_error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST_CASE("hth4: a project read to its values", "[hth4]") {
  const auto p = parse_project(data("three_motions.h4p"), "three_motions.h4p");
  CHECK(p.config == 0x801B);
  CHECK(p.adc_reference[1] == 273);
  CHECK(p.adc_reference[0] == 0);
  CHECK(p.kri3.id == 31);
  CHECK(p.kri3.ram_address == 0x034C);
  REQUIRE(p.motions.size() == 120);
  CHECK(&p.layout() == &rcb4::hth4_2_2);
  const auto& m1 = p.motions[0];
  CHECK(m1.name == "wave_twice");
  CHECK(m1.buttons == 516);
  CHECK(m1.compare == compare_type::equals);
  CHECK(m1.address == 0x0B80);
  REQUIRE(m1.frames.size() == 8);
  // hth4-files.md §2.6's loop test: JUMP to 0x000BAB when Z = 1.
  CHECK(m1.frames[3] == bytes{0x07, 0x0B, 0xAB, 0x0B, 0x00, 0x05, 0xCD});
  CHECK(m1.frames.back() == bytes{0x03, 0x0D, 0x10, 0xFF});
  CHECK(m1.code().size() == 63);  // the .csv's "bytes used" of §2.6's motion, its FF included (§7)
  CHECK(p.motions[2].name == "bow and home");
  CHECK(p.motions[2].frames[0] == bytes{0x07, 0x0C, 0x80, 0x13, 0x00, 0x00, 0xA6});  // CALL motion 2 at 0x001380
  CHECK(p.motions[3].frames.empty());
  CHECK(p.motions[3].name == "M004");
  REQUIRE(p.servos.size() == 35);
  CHECK(p.servos[16].name == "left_knee");
  CHECK(p.servos[16].trim == -1980);
  CHECK(p.servos[16].id == 8);
  CHECK(p.servos[16].port == servo_port::sio1);
  CHECK(p.servos[17].port == servo_port::sio2);
  CHECK(p.servos[16].mode == servo_mode::normal);
  CHECK(p.servos[20].mode == servo_mode::none);
  CHECK(p.servos[16].mixing1_address == 0xFFFF);
  CHECK(p.servo(3)->trim == 25);
  CHECK(p.startup_address == 0x0B80);
  REQUIRE(p.priority.size() == 14);
  REQUIRE(p.priority[0].value);
  CHECK(p.priority[0].value->value == 223);
  CHECK(p.priority[0].value->compare == compare_type::at_most);
  CHECK_FALSE(p.priority[1].value);
  CHECK(p.priority[13].key == "-1");
  CHECK(p.title == "rcb4 test");
  CHECK(p.path == "C:\\robots");
  CHECK(p.other_xml.empty());
}

TEST_CASE("hth4: a project written back is the file HTH4 wrote, byte for byte", "[hth4]") {
  for (const char* name : {"three_motions.h4p", "three_motions_2_0.h4p"}) {
    const auto text = data(name);
    const auto p = parse_project(text, name);
    const auto out = project_xml(p);
    CHECK(out == text);
    CHECK(parse_project(out, "again.h4p") == p);
  }
  // A fresh project, every slot empty, is one too.
  const auto e = empty_project();
  CHECK(parse_project(project_xml(e), "empty.h4p") == e);
  // Elements this reader does not know are kept.
  const auto more = edit(data("three_motions.h4p"), "  <Anchors />", "  <Anchors />\r\n  <Future>1</Future>");
  const auto p = parse_project(more, "more.h4p");
  REQUIRE(p.other_xml.size() == 1);
  CHECK(project_xml(p).find("<Future>1</Future>") != std::string::npos);
}

TEST_CASE("hth4: relocation between the 2.0 and 2.2 layouts (hth4-files.md §4)", "[hth4]") {
  const auto p22 = parse_project(data("three_motions.h4p"), "a.h4p");
  const auto p20 = parse_project(data("three_motions_2_0.h4p"), "b.h4p");
  CHECK(&p20.layout() == &rcb4::hth4_2_0);
  // §4's example: 07 0B AB 0B 00 05 CD in the 0x0B80 layout is 07 0B E3 0B 00 05 05 in 0x0BB8's.
  CHECK(p20.motions[0].frames[3] == bytes{0x07, 0x0B, 0xE3, 0x0B, 0x00, 0x05, 0x05});
  for (std::size_t i = 0; i < 3; ++i) {
    CHECK(relocate(p22.motions[i].frames, 0x0B80, 0x0BB8) == p20.motions[i].frames);
    CHECK(relocate(p20.motions[i].frames, 0x0BB8, 0x0B80) == p22.motions[i].frames);
  }
}

TEST_CASE("hth4: bad project files are refused with their file, line and element", "[hth4]") {
  const auto good = data("three_motions.h4p");
  struct bad {
    std::string text;
    std::vector<std::string> says;
  };
  std::string long_motion;  // 160 poses of 13 bytes: 2080 bytes, more than a slot
  for (int i = 0; i < 160; ++i)
    long_motion += "          <anyType xsi:type=\"xsd:string\">0D 10 0C 00 00 00 00 1E 4C 1D 4C 1D 19</anyType>\r\n";
  const std::vector<bad> cases = {
      {"hello", {"p.h4p:1", "not XML"}},
      {edit(good, "</Rcb4>", ""), {"p.h4p:", "not XML"}},
      {"<?xml version=\"1.0\"?>\r\n<CanvasData />",
       {"p.h4p:2", "root element is <CanvasData>", "not a HeartToHeart4 project"}},
      {edit(good,
            "  <Config>\r\n    <unsignedByte>27</unsignedByte>\r\n    <unsignedByte>128</unsignedByte>\r\n  "
            "</Config>\r\n",
            ""),
       {"p.h4p:2: <Rcb4>", "has no <Config>"}},
      {edit(good, "<unsignedByte>128</unsignedByte>", "<unsignedByte>300</unsignedByte>"),
       {"p.h4p:5: <unsignedByte>", "300 is out of range"}},
      // Line 61 holds motion 1's fourth frame.
      {edit(good, "07 0B AB 0B 00 05 CD", "07 0B AB 0B 00 05 CE"),
       {"p.h4p:61: <anyType> of motion M001 frame 4", "SUM"}},
      {edit(good, "08 00 02 57 04 00 02 67", "09 00 02 57 04 00 02 67"), {"p.h4p:58:", "SIZE byte says 9"}},
      {edit(good, "08 00 02 57 04 00 02 67", "08 00 02 57 04 00 02 6"), {"p.h4p:58:", "is not a frame"}},
      {edit(good, "03 0D 10 FF", "03 0D 10"), {"p.h4p:65:", "last frame of a motion is '03 0D 10 FF'"}},
      {edit(good, "          <anyType xsi:type=\"xsd:string\">03 0D 10 FF</anyType>",
            long_motion + "          <anyType xsi:type=\"xsd:string\">03 0D 10 FF</anyType>"),
       {"of motion M001", "longer than its 2048-byte slot"}},
      {edit(good, "<Address>4992</Address>", "<Address>2944</Address>"),
       {"of motion M002", "two motions at one address"}},
      {edit(edit(good, "<Address>2944</Address>", "<Address>100</Address>"), "<StartupMotionAddress>2944",
            "<StartupMotionAddress>-1"),
       {"of motion M001", "no HeartToHeart4 2.x layout"}},
      {edit(good, "07 0B 88 0B 00 00 A5", "07 0B 00 01 00 00 13"),
       {"p.h4p:62:", "JUMP to 0x000100: outside the motion area"}},
      {edit(good, "07 0B 88 0B 00 00 A5", "07 0B 89 0B 00 00 A6"), {"p.h4p:62:", "inside a frame of its own motion"}},
      {edit(good, "07 0C 80 13 00 00 A6", "07 0C 81 13 00 00 A7"),
       {"of motion M003 frame 1", "CALL to 0x001381: inside motion 2"}},
      {edit(good, "07 0C 80 13 00 00 A6", "07 0C 80 23 00 00 B6"), {"CALL to 0x002380: motion 4, which is empty"}},
      {edit(good, "07 0C 80 13 00 00 A6", "07 0C 80 13 00 10 B6"), {"of motion M003 frame 1", "condition"}},
      {edit(good, "<Mode>Normal</Mode>", "<Mode>Fast</Mode>"), {"<Mode>", "'Fast' is not a servo mode"}},
      {edit(good, "07 0C 80 13 00 00 A6", "07 0C 80 1B 00 00 AE"),
       {"of motion M003 frame 1", "the calls come back round (motion 3 -> 3)"}},
      {edit(good, "<Trim>-1980</Trim>", "<Trim>-5000</Trim>"), {"of servo ICS 16", "beyond a servo's travel"}},
      {edit(good, "<Name>head</Name>", "<Name>\x83\x77\x83\x62\x83\x68</Name>"), {"p.h4p:", "not UTF-8"}},
      {edit(good, "<Port>SIO1</Port>", "<Port>SIO3</Port>"), {"<Port>", "'SIO3' is not a servo port"}},
      {edit(good, "<CompareType>Equals</CompareType>", "<CompareType>Bigger</CompareType>"),
       {"<CompareType>", "'Bigger' is not a compare type"}},
      {edit(good, "<DeviceNumber>16</DeviceNumber>", "<DeviceNumber>15</DeviceNumber>"),
       {"of servo ICS 16", "DeviceNumber is 15, not 16"}},
      {edit(good, "<ID>8</ID>", "<ID>9</ID>"), {"of servo ICS 16", "not 2 x ID 9 (SIO1) = 18"}},
      {edit(good, "<StartupMotionAddress>2944", "<StartupMotionAddress>6000"),
       {"<StartupMotionAddress>", "not the start of a used motion slot"}},
      {edit(good, "<Key xsi:type=\"xsd:string\">M002</Key>", "<Key xsi:type=\"xsd:string\">M007</Key>"),
       {"<Key>", "not 'M002'"}},
      {edit(good, "<Value xsi:type=\"ServoItem\">", "<Value xsi:type=\"Servo\">"), {"<Value>", "xsi:type is 'Servo'"}},
      {edit(good, "<Trim>-40</Trim>", "<Trim>-4O</Trim>"), {"<Trim>", "'-4O' is not an integer"}},
      {edit(good, "<Key xsi:type=\"xsd:string\">head</Key>", "<Key xsi:type=\"xsd:string\">neck</Key>"),
       {"not the servo's Name 'head'"}},
      {edit(edit(good, "<Name>right_knee</Name>", "<Name>left_knee</Name>"), ">right_knee</Key>", ">left_knee</Key>"),
       {"of servo ICS 17", "'left_knee' is used twice"}},
  };
  for (const auto& c : cases) {
    const auto e = project_error(c.text);
    INFO(c.says.back() << " -> " << e);
    CHECK(e.rfind("p.h4p", 0) == 0);
    for (const auto& s : c.says) CHECK(e.find(s) != std::string::npos);
  }
  // A file of 17 MiB is refused before it is parsed.
  const auto e = project_error(std::string(17u << 20, ' '));
  CHECK(e.find("17 MiB") != std::string::npos);
}

TEST_CASE("hth4: a trim file read, written back byte for byte, and its mistakes", "[hth4]") {
  const auto text = data("trims.h4t");
  const auto t = parse_trim_file(text, "trims.h4t");
  REQUIRE(t.size() == 35);
  CHECK(t[16].name == "left_knee");
  CHECK(t[16].device_number == 16);
  CHECK(t[16].trim == -3960);
  CHECK(t[17].trim == 4000);
  CHECK(trim_file_xml(t) == text);
  // A project's trims are the file its servo window saves.
  const auto p = parse_project(data("three_motions.h4p"), "p.h4p");
  CHECK(trims_of(p)[16].trim == -1980);
  CHECK(parse_trim_file(trim_file_xml(trims_of(p)), "x.h4t") == trims_of(p));
  const auto error_of = [](const std::string& s) {
    try {
      parse_trim_file(s, "t.h4t");
    } catch (const profile_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CHECK(error_of(edit(text, "<DeviceNumber>17</DeviceNumber>", "<DeviceNumber>16</DeviceNumber>"))
            .find("ICS 16 has a second entry") != std::string::npos);
  CHECK(error_of(edit(text, "<DeviceNumber>17</DeviceNumber>", "<DeviceNumber>40</DeviceNumber>"))
            .find("40 is out of range") != std::string::npos);
  CHECK(error_of(edit(text, "PositionData", "ServoItem")).find("xsi:type is 'ServoItem'") != std::string::npos);
  CHECK(error_of(data("three_motions.h4p")).find("root element is <Rcb4>, not <ArrayOfDictionaryEntry>") !=
        std::string::npos);
}

TEST_CASE("hth4: flowcharts compile by HTH4's layout rule, in both schemas (hth4-files.md 5)", "[hth4]") {
  // §5.7: the four-block flowchart compiles at 0x0B80 to §2.6's MotionData, the placeholder filled.
  const auto project = parse_project(data("three_motions.h4p"), "p.h4p");
  for (const char* name : {"wave_twice.xml", "wave_twice_old.xml"}) {
    INFO(name);
    const auto f = parse_flowchart(data(name), name);
    CHECK(f.old_schema == (std::string(name) == "wave_twice_old.xml"));
    REQUIRE(f.blocks.size() == 4);
    CHECK(f.blocks[2].base_name == "Loop");
    const auto c = compile_flowchart(f, 0x0B80, rcb4::hth4_2_2, name);
    CHECK(c.frames == project.motions[0].frames);
    CHECK(c.notes.empty());
  }
  // A Wait's JUMP back goes to its own SUB where it now lies; a call of the 2.0 layout's motion 2
  // (0x0013B8) moves to 2.2's (0x001380).
  const auto w =
      compile_flowchart(parse_flowchart(data("wait_and_call.xml"), "w.xml"), 0x0B80, rcb4::hth4_2_2, "w.xml");
  REQUIRE(w.frames.size() == 8);
  CHECK(w.frames[1] == bytes{0x09, 0x00, 0x02, 0x3C, 0x00, 0x00, 0x08, 0x00, 0x4F});  // at 0x0B8D
  CHECK(w.frames[3] == bytes{0x07, 0x0B, 0x96, 0x0B, 0x00, 0x04, 0xB7});              // back to 0x0B96
  CHECK(w.frames[4] == bytes{0x07, 0x0C, 0x80, 0x13, 0x00, 0x00, 0xA6});              // CALL motion 2
  CHECK(w.frames[6] == bytes{0x03, 0x0D, 0x10});
  CHECK(w.frames[7] == bytes{0x03, 0x0D, 0x10, 0xFF});
  REQUIRE(w.notes.size() == 1);
  CHECK(w.notes[0].find("0x0013B8 moved to 0x001380") != std::string::npos);
}

TEST_CASE("hth4: bad flowcharts are refused with their file, line and block", "[hth4]") {
  const auto good = data("wave_twice.xml");
  const auto error_of = [](const std::string& text) {
    try {
      compile_flowchart(parse_flowchart(text, "f.xml"), 0x0B80, rcb4::hth4_2_2, "f.xml");
    } catch (const profile_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"<?xml version=\"1.0\"?>\r\n<Rcb4 />", "root element is <Rcb4>, not <CanvasData>"},
      {edit(good, "<MotionFlag>Start</MotionFlag>", "<MotionFlag>None</MotionFlag>"), "no block is the Start"},
      {edit(good, "<MotionFlag>None</MotionFlag>", "<MotionFlag>Start</MotionFlag>"), "a second Start block"},
      {edit(good, "<MotionFlag>None</MotionFlag>", "<MotionFlag>Begin</MotionFlag>"), "'Begin' is not Start or None"},
      {edit(good, "<ConnectMode>True</ConnectMode>", "<ConnectMode>Normal</ConnectMode>"),
       "two lines leave it the same way"},
      {edit(good, "<ConnectMode>True</ConnectMode>", "<ConnectMode>Maybe</ConnectMode>"),
       "'Maybe' is not Normal, True or False"},
      {edit(good, "07 0B FF FF FF 05 14", "07 0B FF FF FF 05 15"), "SIZE byte or SUM does not match"},
      {edit(good, "08 07 02 57 04 00 01 6D</anyType>\r\n        <anyType xsi:type=\"xsd:string\">07 0B FF FF FF 05 14",
            "08 07 02 57 04 00 01 6D"),
       "a True line leaves it, but its code has no JUMP waiting for it"},
      {edit(good, "EndConnect,BeginConnect,BeginConnect", "EndConnect,BeginConnect,EndConnect"),
       "each line joins exactly two"},
      {edit(good, "a0000000-0000-4000-8000-000000000004</GUID>", "a0000000-0000-4000-8000-000000000009</GUID>"),
       "which is not in the file"},
  };
  for (const auto& [text, says] : cases) {
    const auto e = error_of(text);
    INFO(says << " -> " << e);
    CHECK(e.rfind("f.xml", 0) == 0);
    CHECK(e.find(says) != std::string::npos);
  }
  // A call that names no slot's start.
  const auto w = edit(data("wait_and_call.xml"), "07 0C B8 13 00 00 DE", "07 0C B9 13 00 00 DF");
  CHECK(error_of(w).find("block 'MotionJump3' (MotionJump): 0x0013B9 is not the start of a motion slot") !=
        std::string::npos);
}

TEST_CASE("hth4: a project as rcb4's files", "[hth4]") {
  CHECK(identifier("Left Knee") == "left_knee");
  CHECK(identifier("2nd-arm") == "j_2nd_arm");
  CHECK(identifier("--") == "");
  const auto p = parse_project(data("three_motions.h4p"), "p.h4p");
  const auto f = project_as_files(p, "");
  std::vector<std::string> names;
  for (const auto& x : f.files) names.push_back(x.name);
  CHECK(names == std::vector<std::string>{"profile.yaml", "001-wave_twice.yaml", "002-bow.yaml",
                                          "003-bow_and_home.yaml", "buttons.yaml", "trims.h4t", "push.sh"});
  CHECK(f.files[4].text.find("right+s1: 1\n") != std::string::npos);
  // The profile reads, with the seven allocated servos as joints.
  const auto m = parse_profile(f.files[0].text, "profile.yaml");
  CHECK(m.name() == "three_motions");
  CHECK(m.joints().size() == 7);
  REQUIRE(m.find("left_knee"));
  CHECK(m.find("left_knee")->ics.value() == 16);
  // push.sh sets the period first and pushes motion 2 before motion 3, which calls it.
  const auto& sh = f.files.back().text;
  CHECK(sh.find("config set period=15 --persist") < sh.find("motion push"));
  CHECK(sh.find("002-bow.yaml 2") < sh.find("003-bow_and_home.yaml 3"));
  CHECK(sh.find("motion buttons set right+s1 1") != std::string::npos);
  // A project without an allocated servo describes no robot.
  auto none = p;
  for (auto& s : none.servos) s.mode = servo_mode::none;
  CHECK_THROWS_AS(project_as_files(none, ""), profile_error);
}
