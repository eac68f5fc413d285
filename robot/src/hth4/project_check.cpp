// rcb4 — what a project must be before it is written anywhere (hth4-files.md §2.2–§2.3, §4), and
// the pieces of a project value every reader and writer shares.
// SPDX-License-Identifier: BSL-1.0
#include "project_check.hpp"

#include <rcb4/command.hpp>
#include <rcb4/frame.hpp>
#include <rcb4/motion/disassemble.hpp>

#include <algorithm>
#include <functional>
#include <map>
#include <set>

namespace rcb4::robot::hth4 {

namespace {
constexpr std::array<std::string_view, 8> compare_names{
    "Equals", "NotEquals", "GreaterThan", "LessThan", "GreaterThanOrEqualTo", "LessThanOrEqualTo", "Zero", "None"};
constexpr std::uint8_t tail[] = {0x03, 0x0D, 0x10, 0xFF};

std::string hex(std::uint32_t a) { return motion::hex_address(a); }
}  // namespace

std::string_view compare_name(compare_type c) { return compare_names[static_cast<std::size_t>(c)]; }

std::optional<compare_type> compare_from(std::string_view name) {
  for (std::size_t i = 0; i < compare_names.size(); ++i)
    if (compare_names[i] == name) return static_cast<compare_type>(i);
  return std::nullopt;
}

std::vector<std::uint8_t> motion_entry::code() const {
  std::vector<std::uint8_t> out;
  for (const auto& f : frames) out.insert(out.end(), f.begin(), f.end());
  return out;
}

const rom_layout& project::layout() const {
  return !motions.empty() && motions.front().address == hth4_2_0.motion_base.value() ? hth4_2_0 : hth4_2_2;
}

const servo_entry* project::servo(unsigned ics) const {
  for (const auto& s : servos)
    if (s.device_number == ics) return &s;
  return nullptr;
}

std::optional<std::vector<std::uint8_t>> parse_frame_text(std::string_view t) {
  std::vector<std::uint8_t> out;
  const auto digit = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    return -1;
  };
  for (std::size_t i = 0; i < t.size(); i += 3) {
    if (i + 2 > t.size() || (i + 2 < t.size() && t[i + 2] != ' ')) return std::nullopt;
    const int h = digit(t[i]), l = digit(t[i + 1]);
    if (h < 0 || l < 0) return std::nullopt;
    out.push_back(static_cast<std::uint8_t>(h * 16 + l));
    if (i + 2 == t.size() - 1) return std::nullopt;  // a trailing space
  }
  if (out.empty()) return std::nullopt;
  return out;
}

std::string frame_text(std::span<const std::uint8_t> bytes) {
  static constexpr char digits[] = "0123456789ABCDEF";
  std::string out;
  for (const auto b : bytes) {
    if (!out.empty()) out += ' ';
    out += digits[b >> 4];
    out += digits[b & 15];
  }
  return out;
}

std::vector<std::vector<std::uint8_t>> relocate(const std::vector<std::vector<std::uint8_t>>& frames,
                                                std::uint32_t from_base, std::uint32_t to_base) {
  auto out = frames;
  const std::uint32_t end = from_base + static_cast<std::uint32_t>(motion_count) * hth4_2_2.slot_size;
  for (auto& f : out) {
    if (!is_branch(f)) continue;
    const std::uint32_t t = branch_target(f);
    if (t >= from_base && t < end) set_branch_target(f, t - from_base + to_base);
  }
  return out;
}

void check_project(const project& p, const where_fn& where) {
  if (p.motions.size() != motion_count)
    throw profile_error(where({place::in_root}),
                        "has " + std::to_string(p.motions.size()) + " motions, not " + std::to_string(motion_count));
  // §4: one base for all 120 slots, and a layout the board knows.
  const std::uint32_t slot = hth4_2_2.slot_size;
  const std::uint32_t base = p.motions.front().address;
  if (base != hth4_2_2.motion_base.value() && base != hth4_2_0.motion_base.value())
    throw profile_error(where({place::in_motion, 0}), "motion 1 is at " + hex(base) +
                                                          ": no HeartToHeart4 2.x layout puts it there (0x000B80 for "
                                                          "2.2 and later, 0x000BB8 for 2.0-2.1)");
  const std::uint32_t end = base + static_cast<std::uint32_t>(motion_count) * slot;
  // Every frame's address, to check targets against.
  std::vector<std::set<std::uint32_t>> starts(motion_count);
  for (std::size_t i = 0; i < motion_count; ++i) {
    const auto& m = p.motions[i];
    const place here{place::in_motion, static_cast<unsigned>(i)};
    if (m.number != i)
      throw profile_error(where(here), "Number is " + std::to_string(m.number) + ", not " + std::to_string(i) +
                                           " (the entries are M001..M120 in order, Number 0..119)");
    if (m.address != base + static_cast<std::uint32_t>(i) * slot)
      throw profile_error(where(here), "Address is " + hex(m.address) + ", not " +
                                           hex(base + static_cast<std::uint32_t>(i) * slot) + " (motion 1 at " +
                                           hex(base) +
                                           " plus 2048 per slot): two motions at one address, or a "
                                           "slot out of place");
    std::uint32_t at = m.address;
    for (std::size_t j = 0; j < m.frames.size(); ++j) {
      const auto& f = m.frames[j];
      const place fr{place::in_frame, static_cast<unsigned>(i), static_cast<unsigned>(j)};
      const bool last = j + 1 == m.frames.size();
      if (last) {
        if (!std::equal(f.begin(), f.end(), std::begin(tail), std::end(tail)))
          throw profile_error(where(fr), "the last frame of a motion is '03 0D 10 FF' (a RETURN and one FF), not '" +
                                             frame_text(f) + "'");
      } else {
        if (f.size() < min_frame_size || f[0] != f.size())
          throw profile_error(where(fr), "'" + frame_text(f) + "': its SIZE byte says " + std::to_string(f[0]) +
                                             " bytes, the frame has " + std::to_string(f.size()));
        if (!checksum_ok(f))
          throw profile_error(where(fr),
                              "'" + frame_text(f) + "': the SUM byte is " + hex(f.back()).substr(6) +
                                  ", the bytes before it add up to " +
                                  hex(checksum(std::span<const std::uint8_t>(f).first(f.size() - 1))).substr(6));
        if (f[1] == jump::command_code || f[1] == call::command_code) {
          const auto r = parse_command(f);
          if (!r.ok()) throw profile_error(where(fr), "'" + frame_text(f) + "': " + std::string(message(r.error)));
        }
      }
      starts[i].insert(at);
      at += static_cast<std::uint32_t>(f.size());
    }
    if (at - m.address > slot)
      throw profile_error(where(here), "motion " + std::to_string(i + 1) + " is " + std::to_string(at - m.address) +
                                           " bytes, longer than its 2048-byte slot");
  }
  // §4 "Where targets point": inside its own slot on a frame, or the first byte of a used slot.
  const auto target_ok = [&](std::size_t own, std::uint32_t t) -> std::string {
    if (t < base || t >= end) return "outside the motion area (" + hex(base) + ".." + hex(end - 1) + ")";
    const std::size_t s = (t - base) / slot;
    if (s == own) return starts[s].count(t) ? std::string() : "inside a frame of its own motion, not on one";
    if (t != base + s * slot) return "inside motion " + std::to_string(s + 1) + ", not at its start";
    if (p.motions[s].frames.empty()) return "motion " + std::to_string(s + 1) + ", which is empty";
    return {};
  };
  for (std::size_t i = 0; i < motion_count; ++i)
    for (std::size_t j = 0; j + 1 < p.motions[i].frames.size(); ++j) {
      const auto& f = p.motions[i].frames[j];
      if (!is_branch(f)) continue;
      const std::uint32_t t = branch_target(f);
      if (const auto why = target_ok(i, t); !why.empty())
        throw profile_error(where({place::in_frame, static_cast<unsigned>(i), static_cast<unsigned>(j)}),
                            std::string(f[1] == jump::command_code ? "JUMP" : "CALL") + " to " + hex(t) + ": " + why);
    }
  // Calls (and terminal JUMPs to another slot) must not come back round, and must nest no deeper
  // than the board's 16-level stack with the main loop's CALL (protocol.md §4.4): what a push refuses.
  std::vector<std::vector<std::size_t>> callees(motion_count);
  std::vector<std::vector<std::size_t>> via(motion_count);  // the frame of each call, for messages
  for (std::size_t i = 0; i < motion_count; ++i)
    for (std::size_t j = 0; j + 1 < p.motions[i].frames.size(); ++j) {
      const auto& f = p.motions[i].frames[j];
      if (!is_branch(f)) continue;
      const std::uint32_t t = branch_target(f);
      const std::size_t s = (t - base) / slot;
      if (s != i || f[1] == call::command_code) {
        callees[i].push_back(s);
        via[i].push_back(j);
      }
    }
  std::vector<int> state(motion_count, 0);  // 0 new, 1 on the path, 2 done
  std::vector<unsigned> depth(motion_count, 0);
  std::vector<std::size_t> path;
  const std::function<void(std::size_t)> visit = [&](std::size_t i) {
    state[i] = 1;
    path.push_back(i);
    unsigned d = 0;
    for (std::size_t k = 0; k < callees[i].size(); ++k) {
      const auto c = callees[i][k];
      if (state[c] == 1) {
        std::string chain;
        for (auto it = std::find(path.begin(), path.end(), c); it != path.end(); ++it)
          chain += std::to_string(*it + 1) + " -> ";
        throw profile_error(where({place::in_frame, static_cast<unsigned>(i), static_cast<unsigned>(via[i][k])}),
                            "the calls come back round (motion " + chain + std::to_string(c + 1) +
                                "): the board's 16-level stack would overflow");
      }
      if (state[c] == 0) visit(c);
      d = std::max(d, depth[c]);
    }
    depth[i] = d + 1;
    if (depth[i] + 1 > 16)
      throw profile_error(
          where({place::in_motion, static_cast<unsigned>(i)}),
          "its calls nest " + std::to_string(depth[i] + 1) + " deep with the main loop's: the board's stack holds 16");
    path.pop_back();
    state[i] = 2;
  };
  for (std::size_t i = 0; i < motion_count; ++i)
    if (state[i] == 0 && !p.motions[i].frames.empty()) visit(i);
  // The start-up and priority motions: none, or a used slot (the end of the area is 2.2's
  // DefaultStartup, a RETURN: DOC-PRG).
  const auto slot_start = [&](long a) {
    if (a == -1 || a == static_cast<long>(end)) return true;
    if (a < static_cast<long>(base) || a >= static_cast<long>(end)) return false;
    const auto s = (static_cast<std::uint32_t>(a) - base) / slot;
    return static_cast<std::uint32_t>(a) == base + s * slot && !p.motions[s].frames.empty();
  };
  if (!slot_start(p.startup_address))
    throw profile_error(where({place::in_startup}), "StartupMotionAddress " + std::to_string(p.startup_address) +
                                                        " is not the start of a used motion slot (nor -1)");
  for (std::size_t k = 0; k < p.priority.size(); ++k)
    if (p.priority[k].value && !slot_start(p.priority[k].value->address))
      throw profile_error(where({place::in_priority, static_cast<unsigned>(k)}),
                          "Address " + std::to_string(p.priority[k].value->address) +
                              " is not the start of a used motion slot (nor -1)");
  // §2.3: 35 servos in ICS order, their blocks where k says, DeviceNumber = 2 × ID + (SIO2).
  if (p.servos.size() != servo_count)
    throw profile_error(where({place::in_root}), "has " + std::to_string(p.servos.size()) + " servo entries, not " +
                                                     std::to_string(servo_count) + " (ICS 0..34)");
  std::set<std::string> names;
  for (std::size_t k = 0; k < servo_count; ++k) {
    const auto& s = p.servos[k];
    const place here{place::in_servo, static_cast<unsigned>(k)};
    if (s.device_number != k)
      throw profile_error(where(here), "DeviceNumber is " + std::to_string(s.device_number) + ", not " +
                                           std::to_string(k) + " (the entries are in ICS order 0..34)");
    const unsigned expect = 2 * s.id + (s.port == servo_port::sio2 ? 1u : 0u);
    if (s.device_number != expect)
      throw profile_error(
          where(here), "DeviceNumber " + std::to_string(s.device_number) + " is not 2 x ID " + std::to_string(s.id) +
                           (s.port == servo_port::sio2 ? " + 1 (SIO2)" : " (SIO1)") + " = " + std::to_string(expect));
    if (s.count != 20 || s.rom_address != 0x0626 + 20 * k || s.ram_address != 0x0090 + 20 * k)
      throw profile_error(where(here), "the block is Count " + std::to_string(s.count) + " at RomAddress " +
                                           std::to_string(s.rom_address) + ", RamAddress " +
                                           std::to_string(s.ram_address) + "; ICS " + std::to_string(k) +
                                           "'s is 20 bytes at " + std::to_string(0x0626 + 20 * k) + " and " +
                                           std::to_string(0x0090 + 20 * k));
    if (s.mode == servo_mode::normal && (s.trim < -4000 || s.trim > 4000))
      throw profile_error(where(here),
                          "Trim " + std::to_string(s.trim) + " is beyond a servo's travel (+-4000 counts, 135 deg)");
    if (s.name.empty() || !names.insert(s.name).second)
      throw profile_error(where(here),
                          "the servo name '" + s.name + "' is " + (s.name.empty() ? "empty" : "used twice"));
  }
}

void check_project(const project& p, const std::string& source) {
  check_project(p, [&](const place& pl) { return source + ": " + describe(pl); });
}

std::string describe(const place& pl) {
  char key[8];
  std::snprintf(key, sizeof key, "M%03u", (pl.index + 1) % 1000);
  switch (pl.kind) {
    case place::in_motion: return std::string("motion ") + key;
    case place::in_frame: return std::string("motion ") + key + " frame " + std::to_string(pl.frame + 1);
    case place::in_servo: return "servo ICS " + std::to_string(pl.index);
    case place::in_startup: return "StartupMotionAddress";
    case place::in_priority: return "priority motion " + std::to_string(pl.index);
    case place::in_root: break;
  }
  return "the project";
}

project empty_project(const rom_layout& layout) {
  project p;
  p.config = 0x801B;
  for (unsigned i = 0; i < motion_count; ++i) {
    motion_entry m;
    m.number = i;
    char key[8];
    std::snprintf(key, sizeof key, "M%03u", i + 1);
    m.name = key;
    m.date = "2000-01-01T00:00:00";
    m.address = layout.motion_base.value() + i * layout.slot_size;
    p.motions.push_back(std::move(m));
  }
  for (unsigned k = 0; k < servo_count; ++k) {
    servo_entry s;
    s.name = "ICS" + std::to_string(k);
    s.device_number = k;
    s.id = k / 2;
    s.port = k % 2 ? servo_port::sio2 : servo_port::sio1;
    s.rom_address = 0x0626 + 20 * k;
    s.ram_address = 0x0090 + 20 * k;
    p.servos.push_back(std::move(s));
  }
  for (int k = 0; k <= 12; ++k) p.priority.push_back({std::to_string(k), "xsd:int", std::nullopt});
  p.priority.push_back({"-1", "xsd:int", std::nullopt});
  return p;
}

}  // namespace rcb4::robot::hth4
