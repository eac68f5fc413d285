// rcb4 — HTH4 motion flowcharts (see rcb4/robot/hth4/flowchart.hpp; hth4-files.md §5).
// SPDX-License-Identifier: BSL-1.0
#include "project_check.hpp"
#include "xml.hpp"

#include <rcb4/frame.hpp>
#include <rcb4/motion/disassemble.hpp>
#include <rcb4/robot/hth4/flowchart.hpp>

#include <map>
#include <set>

namespace rcb4::robot::hth4 {

namespace {

using detail::xml_in;

std::vector<std::string> split(std::string_view s) {
  std::vector<std::string> out;
  if (s.empty()) return out;
  for (std::size_t b = 0;;) {
    const auto e = s.find(',', b);
    out.emplace_back(s.substr(b, e == std::string_view::npos ? std::string_view::npos : e - b));
    if (e == std::string_view::npos) return out;
    b = e + 1;
  }
}

constexpr std::string_view no_guid = "00000000-0000-0000-0000-000000000000";

/** One block's connections as written: (line GUID, Begin/End) in slot order, and the old schema's labels. */
struct ends {
  std::vector<std::string> guids, types;
  std::vector<std::uint8_t> labels;  // old schema: PriorityList, one byte per slot
};

flow_block read_block(const xml_in& x, const pugi::xml_node& a, bool old_schema, ends& e) {
  flow_block b;
  b.name = x.text(a, "Name");
  b.guid = x.text(a, "GUID");
  b.base_name = x.text(a, "BaseName");
  if (const auto t = a.child("Text")) b.text = t.child_value();
  if (const auto l = a.child("Location"))
    b.at = std::array<long, 2>{static_cast<long>(x.integer(l, "X", -100000, 100000)),
                               static_cast<long>(x.integer(l, "Y", -100000, 100000))};
  const auto flag = x.text(a, "MotionFlag");
  if (flag != "Start" && flag != "None") x.fail(a.child("MotionFlag"), "'" + flag + "' is not Start or None");
  b.start = flag == "Start";
  b.line = x.line_of(a);
  e.guids = split(x.text(a, "ConnectedGuids"));
  e.types = split(x.text(a, "ConnectTypes"));
  if (e.guids.size() != e.types.size())
    x.fail(a.child("ConnectTypes"), "names " + std::to_string(e.types.size()) + " connections, ConnectedGuids " +
                                        std::to_string(e.guids.size()));
  for (const auto& t : e.types)
    if (t != "BeginConnect" && t != "EndConnect" && t != "NotConnected")
      x.fail(a.child("ConnectTypes"), "'" + t + "' is not BeginConnect, EndConnect or NotConnected");
  if (old_schema) {
    const auto list = x.need(a, "PriorityList");
    const auto item = list.child("anyType");
    const auto bytes = item ? parse_frame_text(item.child_value()) : std::nullopt;
    if (!bytes || bytes->size() != e.guids.size())
      x.fail(list, "holds one string of a hex byte per connection slot (" + std::to_string(e.guids.size()) + ")");
    e.labels = *bytes;
  }
  for (auto f = x.need(a, "ProgramCode").child("anyType"); f; f = f.next_sibling("anyType")) {
    auto bytes = parse_frame_text(f.child_value());
    // (Messages built with +=: GCC 12 -O3 warns falsely about "'" + a temporary string, -Wrestrict.)
    std::string what = "'";
    if (!bytes) {
      what += std::string(f.child_value()).substr(0, 60);
      what += "' is not a frame (hex byte pairs)";
      x.fail(f, what);
    }
    if (bytes->size() < min_frame_size || (*bytes)[0] != bytes->size() || !checksum_ok(*bytes)) {
      what += frame_text(*bytes);
      what += "': its SIZE byte or SUM does not match the frame";
      x.fail(f, what);
    }
    b.code.push_back(std::move(*bytes));
  }
  return b;
}

constexpr std::uint32_t placeholder = 0xFFFFFF;

}  // namespace

flowchart parse_flowchart(std::string_view text, const std::string& source) {
  const xml_in x(text, source, "CanvasData|ArrayOfAnyType", "a HeartToHeart4 motion flowchart (.xml)");
  flowchart f;
  f.old_schema = std::string_view(x.root().name()) == "ArrayOfAnyType";
  std::vector<pugi::xml_node> activities, lines;
  const auto collect = [&](const pugi::xml_node& parent) {
    for (auto c = parent.child("anyType"); c; c = c.next_sibling("anyType")) {
      const auto t = xml_in::type_of(c);
      if (t == "ActivityData")
        activities.push_back(c);
      else if (t == "LineData")
        lines.push_back(c);
      else
        x.fail(c, "xsi:type is '" + std::string(t) + "', not ActivityData or LineData");
    }
  };
  if (f.old_schema) {
    collect(x.root());
  } else {
    collect(x.need(x.root(), "Activities"));
    collect(x.need(x.root(), "Lines"));
  }
  std::map<std::string, std::size_t> line_at;
  for (const auto& l : lines) {
    flow_line fl;
    fl.guid = x.text(l, "GUID");
    if (!f.old_schema) {
      const auto mode = x.text(l, "ConnectMode");
      if (mode == "True")
        fl.how = flow_line::kind::on_true;
      else if (mode == "False")
        fl.how = flow_line::kind::on_false;
      else if (mode != "Normal")
        x.fail(l.child("ConnectMode"), "'" + mode + "' is not Normal, True or False");
    }
    if (!line_at.emplace(fl.guid, f.lines.size()).second) x.fail(l, "a second line with GUID " + fl.guid);
    f.lines.push_back(fl);
  }
  std::vector<int> begins(f.lines.size(), 0), ends_n(f.lines.size(), 0);
  std::set<std::string> block_guids;
  for (const auto& a : activities) {
    ends e;
    f.blocks.push_back(read_block(x, a, f.old_schema, e));
    if (!block_guids.insert(f.blocks.back().guid).second) x.fail(a, "a second block with GUID " + f.blocks.back().guid);
    for (std::size_t k = 0; k < e.guids.size(); ++k) {
      if (e.types[k] == "NotConnected" || e.guids[k] == no_guid) continue;
      const auto it = line_at.find(e.guids[k]);
      if (it == line_at.end())
        x.fail(a.child("ConnectedGuids"), "names the line " + e.guids[k] + ", which is not in the file");
      auto& l = f.lines[it->second];
      if (e.types[k] == "BeginConnect") {
        l.from = f.blocks.size() - 1;
        ++begins[it->second];
        if (f.old_schema)
          l.how = e.labels[k] == 0x04   ? flow_line::kind::on_true
                  : e.labels[k] == 0x01 ? flow_line::kind::on_false
                                        : flow_line::kind::plain;
      } else {
        l.to = f.blocks.size() - 1;
        ++ends_n[it->second];
      }
    }
  }
  for (std::size_t i = 0; i < f.lines.size(); ++i)
    if (begins[i] != 1 || ends_n[i] != 1)
      x.fail(lines[i], "line " + f.lines[i].guid + " leaves " + std::to_string(begins[i]) +
                           " block(s) and arrives at " + std::to_string(ends_n[i]) +
                           " (each line joins exactly two: §5.3)");
  return f;
}

flowchart load_flowchart(const std::filesystem::path& path) {
  return parse_flowchart(detail::read_file(path, "a HeartToHeart4 motion flowchart"), path.string());
}

compiled_flowchart compile_flowchart(const flowchart& f, std::uint32_t address, const rom_layout& layout,
                                     const std::string& source) {
  const auto fail = [&](const flow_block* b, const std::string& what) -> void {
    throw profile_error(
        b ? source + ":" + std::to_string(b->line) + ": block '" + b->name + "' (" + b->base_name + ")" : source, what);
  };
  std::size_t start = f.blocks.size();
  for (std::size_t i = 0; i < f.blocks.size(); ++i)
    if (f.blocks[i].start) {
      if (start != f.blocks.size())
        fail(&f.blocks[i], "a second Start block (the first is '" + f.blocks[start].name + "')");
      start = i;
    }
  if (start == f.blocks.size()) fail(nullptr, "no block is the Start (MotionFlag Start)");
  // Each block's successors.
  struct next_t {
    std::optional<std::size_t> plain, on_true;
  };
  std::vector<next_t> next(f.blocks.size());
  for (const auto& l : f.lines) {
    auto& n = next[l.from];
    auto& slot = l.how == flow_line::kind::on_true ? n.on_true : n.plain;  // False is the fall-through
    if (slot)
      fail(&f.blocks[l.from], "two lines leave it the same way (" +
                                  std::string(l.how == flow_line::kind::on_true ? "True" : "plain or False") + ")");
    slot = l.to;
  }
  compiled_flowchart out;
  std::vector<std::optional<std::uint32_t>> placed(f.blocks.size());
  std::vector<std::pair<std::size_t, std::size_t>> fixups;  // (frame, True target block)
  std::vector<std::size_t> stack;
  std::uint32_t at = address;
  const auto emit = [&](std::vector<std::uint8_t> frame) {
    at += static_cast<std::uint32_t>(frame.size());
    out.frames.push_back(std::move(frame));
  };
  const auto jump_to = [&](std::uint32_t t) {
    std::vector<std::uint8_t> j{0x07, jump::command_code, 0, 0, 0, 0x00, 0};
    set_branch_target(j, t);
    emit(std::move(j));
  };
  const std::uint32_t base = layout.motion_base.value(), end = base + layout.motion_count * layout.slot_size;
  const std::uint32_t other =
      base == hth4_2_2.motion_base.value() ? hth4_2_0.motion_base.value() : hth4_2_2.motion_base.value();
  const auto slot_start = [&](std::uint32_t t, std::uint32_t b) {
    return t >= b && t < b + layout.motion_count * layout.slot_size && (t - b) % layout.slot_size == 0;
  };
  // Step 1 and 2 of §5.6 from block @p b on.
  const auto run_from = [&](std::size_t b) {
    for (;;) {
      const auto& blk = f.blocks[b];
      placed[b] = at;
      bool has_placeholder = false;
      for (std::size_t k = 0; k < blk.code.size(); ++k) {
        auto frame = blk.code[k];
        if (is_branch(frame)) {
          const auto t = branch_target(frame);
          if (t == placeholder) {
            if (!next[b].on_true) fail(&blk, "its JUMP waits for a True line, and none leaves it");
            has_placeholder = true;
            fixups.push_back({out.frames.size(), *next[b].on_true});
          } else if (blk.base_name == "Wait" && frame[1] == jump::command_code && k > 0) {
            set_branch_target(frame,
                              *placed[b] + static_cast<std::uint32_t>(blk.code[0].size()));  // back to its SUB (§5.4)
          } else if (!slot_start(t, base) && t != end) {
            if (!slot_start(t, other)) fail(&blk, motion::hex_address(t) + " is not the start of a motion slot");
            const auto moved = t - other + base;
            out.notes.push_back("block '" + blk.name + "': its " + (frame[1] == call::command_code ? "CALL" : "JUMP") +
                                " to " + motion::hex_address(t) + " moved to " + motion::hex_address(moved) +
                                " (the other 2.x layout's slot)");
            set_branch_target(frame, moved);
          }
        }
        emit(std::move(frame));
      }
      if (next[b].on_true && !has_placeholder)
        fail(&blk, "a True line leaves it, but its code has no JUMP waiting for it");
      if (next[b].on_true) stack.push_back(*next[b].on_true);
      const auto n = next[b].plain;
      if (!n) {
        emit({0x03, 0x0D, 0x10});
        return;
      }
      if (placed[*n]) {
        jump_to(*placed[*n]);
        return;
      }
      b = *n;
    }
  };
  run_from(start);
  while (!stack.empty()) {  // step 3
    const auto t = stack.back();
    stack.pop_back();
    if (!placed[t])
      run_from(t);
    else
      jump_to(*placed[t]);
  }
  emit({0x03, 0x0D, 0x10, 0xFF});
  for (std::size_t b = 0; b < placed.size(); ++b)
    if (placed[b]) out.placed.push_back({*placed[b], b});
  for (const auto& [frame, target] : fixups) set_branch_target(out.frames[frame], *placed[target]);  // step 4
  if (at - address > layout.slot_size)
    fail(nullptr, "compiles to " + std::to_string(at - address) + " bytes, more than a " +
                      std::to_string(layout.slot_size) + "-byte slot");
  return out;
}

}  // namespace rcb4::robot::hth4
