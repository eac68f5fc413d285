// rcb4 — HTH4 motion flowcharts (.xml, hth4-files.md §5): read in either schema and compiled into a
// slot by HTH4's own layout rule (§5.6), so a flowchart becomes the bytes HTH4 would write.
// SPDX-License-Identifier: BSL-1.0
//
//   New schema (HTH4 2.2 beta re-saves, 2.4.0):      Old schema (HTH4 up to 2.1):
//   <CanvasData>                                      <ArrayOfAnyType>
//     <Lines><anyType xsi:type="LineData">              <anyType xsi:type="ActivityData">…</anyType>
//       <GUID/> <Path/> <ConnectMode>Normal|True|False  <anyType xsi:type="LineData"><Name/><StartPoint/>
//     <Activities><anyType xsi:type="ActivityData">       <EndPoint/><GUID/><LineType/></anyType>
//       <Name/> <GUID/> … <MotionFlag>Start|None          … mixed; a block's PriorityList "00 01 00 04"
//       <BaseName/> … <ConnectedGuids>l1,l2</…>           labels its four connection slots
//       <ConnectTypes>EndConnect,BeginConnect</…>         (04 True leaves here, 01 False, 00 plain)
//       <ProgramCode><anyType>08 07 02 57 …</anyType>…
//
// A line's source is the block naming it BeginConnect, its target the one naming it EndConnect,
// each exactly once (§5.3). A branching block's JUMP holds the placeholder target FF FF FF (§5.4);
// compile() puts the address of its True target there and makes the SUM again; a Wait block's
// JUMP back to its own SUB is recomputed for its new place; a call of another motion must name a
// slot's start (moved when it names one of the other 2.x layout).
#pragma once

#include <rcb4/memory_map.hpp>
#include <rcb4/robot/hth4/project.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace rcb4::robot::hth4 {

/** A block (an activity) of a flowchart (§5.2). */
struct flow_block {
  std::string name;                             ///< not unique
  std::string guid;                             ///< its identity
  std::string base_name;                        ///< the block type (Pos, Loop, CmpButton, Wait, MotionJump, ...: §5.5)
  std::string text;                             ///< Text: the label the user gave it (absent in some old files)
  std::optional<std::array<long, 2>> at;        ///< Location{X,Y}: its place on HTH4's canvas (GUI only)
  bool start = false;                           ///< MotionFlag Start
  std::vector<std::vector<std::uint8_t>> code;  ///< ProgramCode frames, each SIZE and SUM checked
  unsigned line = 0;                            ///< where it is in its file, for messages
};

/** A line between two blocks (§5.3). */
struct flow_line {
  enum class kind { plain, on_true, on_false };
  std::string guid;
  std::size_t from = 0, to = 0;  ///< block indices
  kind how = kind::plain;
};

/** A flowchart as read. */
struct flowchart {
  bool old_schema = false;  ///< ArrayOfAnyType rather than CanvasData
  std::vector<flow_block> blocks;
  std::vector<flow_line> lines;
};

/** Parses a flowchart's @p text; @p source names it in errors. Throws profile_error (file, line, element). */
flowchart parse_flowchart(std::string_view text, const std::string& source);
/** Reads and parses @p path (at most max_file_bytes). Throws profile_error. */
flowchart load_flowchart(const std::filesystem::path& path);

/** A flowchart compiled into a slot. */
struct compiled_flowchart {
  std::vector<std::vector<std::uint8_t>> frames;  ///< the frames as HTH4 lays them out, ending in 03 0D 10 FF
  std::vector<std::string> notes;                 ///< what was adjusted (a callee moved to @p layout)
  std::vector<std::pair<std::uint32_t, std::size_t>>
      placed;  ///< (ROM address of its first frame, block) of each block laid out
};

/**
 * Compiles @p f into the slot at @p address of @p layout by HTH4's rule (§5.6). Throws
 * profile_error (naming @p source and the block) for no or two Start blocks, a branch without its
 * True line or placeholder, two plain lines out of one block, a call that names no slot's start,
 * and code longer than the slot.
 */
compiled_flowchart compile_flowchart(const flowchart& f, std::uint32_t address, const rom_layout& layout,
                                     const std::string& source);

}  // namespace rcb4::robot::hth4
