// rcb4 — the virtual board's default ROM: an HTH4 2.2-style layout with a main loop and demo motions.
// SPDX-License-Identifier: BSL-1.0
//
// Layout (protocol.md §8, HTH4 2.2+):
//   0x000000  boot: MOV ROM 0x0005DC → RAM 0x0000 (config word), then JUMP 0x000444
//   0x000444  StartupCmd: CALL 0x03CB80 (DefaultStartup, a RETURN: no start-up motion)
//   0x00044B  main loop: OR 0x08 into the config word (the vector switch on again, as HTH4's
//             main loop sets it: motions.md §4), JUMP 0x00044B; motions are CALLed
//   0x0005DC  ConfigDataRom: the config word loaded at power-on
//   0x000919  the vector table's RAM address (0x0357), 0x00091B: its entries (KRR UP plays
//             motion 2, DOWN motion 3: HTH4's button pattern, vector_entry::button)
//   0x000B80 + 2048·(n−1)  motion n: CONST poses, then RETURN
#pragma once

#include <rcb4/memory_map.hpp>
#include <rcb4/rcb4.hpp>
#include <rcb4/vector_entry.hpp>

#include <cstdint>
#include <initializer_list>
#include <span>
#include <string_view>
#include <vector>

namespace rcb4::board {

/**
 * The servo slots of the default robot, a KHR-3HV as profiles/khr-3hv.yaml assigns it: servo IDs
 * 0–4 and 6–10 on both connector sides, ICS 0–9 and 12–21 (ID 5, ICS 10 and 11, is unused).
 * A unit test checks that the built-in profile and this mask agree.
 */
inline constexpr servo_mask khr3hv_servos = servo_mask::from_bits(0x3FF3FFu).value();

/** Power-on config word of the default ROM: ICS on, ROM program on, vector jump on, 10 ms, COM 1.25 Mbaud. */
inline constexpr std::uint16_t default_config = 0x008B;

/** A demo motion: a name and its poses (each pose: frames, then ICS → position). */
struct demo_pose {
  std::uint8_t frames;
  std::initializer_list<std::pair<std::uint8_t, std::uint16_t>> targets;
};

/** Writes @p frame at @p addr of @p rom; returns the address after it. */
inline std::uint32_t put_frame(std::vector<std::uint8_t>& rom, std::uint32_t addr, const request_frame& frame) {
  for (std::size_t i = 0; i < frame.size(); ++i) rom[addr + i] = frame[i];
  return static_cast<std::uint32_t>(addr + frame.size());
}

/** Writes motion @p number of @p layout: one CONST per pose, then RETURN. */
inline void put_motion(std::vector<std::uint8_t>& rom, const rom_layout& layout, unsigned number,
                       std::initializer_list<demo_pose> poses) {
  std::uint32_t at = motion_address(layout, number).value().value();
  for (const auto& pose : poses) {
    servo_set<servo_position> set;
    for (auto [ics, pos] : pose.targets) set.insert(ics_number::make(ics).value(), servo_position::make(pos).value());
    at = put_frame(rom, at, encode(const_servo::make(set, frames::make(pose.frames).value()).value()));
  }
  put_frame(rom, at, encode(ret{}));
}

/** The demo's button assignments: KRR button word → motion number. */
inline constexpr std::pair<std::uint16_t, unsigned> demo_buttons[] = {{0x0001, 2}, {0x0002, 3}};

/** Names of the demo motions, 1-based (index 0 is motion 1). */
inline constexpr std::string_view demo_motion_names[] = {"home", "wave", "bow"};

/**
 * The default 256 KiB ROM image: boot, main loop, config word, and three demo motions:
 * 1 "home" (every servo of khr3hv_servos to 7500), 2 "wave" (right arm), 3 "bow" (hips' pitch and knees).
 */
inline std::vector<std::uint8_t> default_rom() {
  std::vector<std::uint8_t> rom(rom_size, 0xFF);  // erased EEPROM reads 0xFF
  const auto& l = hth4_2_2;
  std::uint32_t at = 0;
  at = put_frame(rom, at, encode(move::make(destination::ram(ram::config), source::rom(l.config, 2).value()).value()));
  put_frame(rom, at, encode(jump{l.startup}));
  // StartupCmd: CALL DefaultStartup, a RETURN after the last slot (DOC-PRG; hth4-files.md §3), as
  // HTH4 2.2 writes a board with no start-up motion; `rcb4 motion startup N` changes it.
  const auto default_startup = l.motion_base.value() + l.motion_count * l.slot_size;
  put_frame(rom, l.startup.value(), encode(call{rom_address::make(default_startup).value()}));
  put_frame(rom, default_startup, encode(ret{}));
  static constexpr std::uint8_t vector_bit[] = {0x08};  // config bit 3 (a literal is referenced, not copied)
  const auto vector_on = logic::make(logic_op::or_, destination::ram(ram::config), source::literal(vector_bit).value());
  put_frame(rom, put_frame(rom, l.main_loop.value(), encode(vector_on.value())), encode(jump{l.main_loop}));
  rom[0x0919] = static_cast<std::uint8_t>(hth4_ram::vector_entries.value() & 0xFF);
  rom[0x091A] = static_cast<std::uint8_t>(hth4_ram::vector_entries.value() >> 8);
  std::uint32_t entry = 0x091B;
  for (std::size_t j = 0; j < std::size(demo_buttons); ++j) {
    const auto [buttons, motion] = demo_buttons[j];
    const auto e = vector_entry::button(buttons, motion_address(l, motion).value(), j + 1 == std::size(demo_buttons));
    for (auto b : e.encode()) rom[entry++] = b;
  }
  rom[l.config.value()] = static_cast<std::uint8_t>(default_config & 0xFF);
  rom[l.config.value() + 1] = static_cast<std::uint8_t>(default_config >> 8);

  put_motion(rom, l, 1, {{30, {{0, 7500},  {1, 7500},  {2, 7500},  {3, 7500},  {4, 7500},  {5, 7500},  {6, 7500},
                               {7, 7500},  {8, 7500},  {9, 7500},  {12, 7500}, {13, 7500}, {14, 7500}, {15, 7500},
                               {16, 7500}, {17, 7500}, {18, 7500}, {19, 7500}, {20, 7500}, {21, 7500}}}});
  // Wave: the right shoulder's pitch (ICS 3) to +67.5°, its roll (ICS 5) between +94.5° and
  // +56.25°: inside the KHR-3HV profile's limits, so a pulled copy pushes back as it is.
  put_motion(rom, l, 2,
             {{20, {{3, 9500}, {5, 10300}}},
              {10, {{5, 9000}}},
              {10, {{5, 10300}}},
              {10, {{5, 9000}}},
              {20, {{3, 7500}, {5, 7500}}}});
  // Bow: both hips' pitch (ICS 14, 15) +33.75°, the knees (16, 17) +16.9°, the same on both sides
  // in the built-in profile's degrees, so the 3D view, balance and Mirror see a symmetric bow
  // (docs/browser.md, "Mirror and a real robot": the profile's senses are unchecked on a real robot).
  put_motion(rom, l, 3,
             {{25, {{14, 8500}, {15, 8500}, {16, 8000}, {17, 8000}}},
              {15, {{14, 8500}, {15, 8500}}},
              {25, {{14, 7500}, {15, 7500}, {16, 7500}, {17, 7500}}}});
  return rom;
}

}  // namespace rcb4::board
