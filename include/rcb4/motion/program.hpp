// rcb4 — motion programs: what a ROM motion slot holds, as steps with labels (motions.md §1-§2,
// protocol.md §4, §8). assemble.hpp turns them into the board's bytes, disassemble.hpp reads
// bytes back.
// SPDX-License-Identifier: BSL-1.0
//
// A slot holds code from its first byte (no header, motions.md §1). The steps and the frames
// they become, every frame through the codec's own encoders:
//
//   pose            CONST (0x10), update flags set: the board fetches nothing more until the
//                   listed servos have arrived, so poses follow each other with no wait (§2)
//                   e.g. [0B][10][01 00 00 00 00][frames][pos lo][pos hi][SUM]
//   set_counter     MOV literal -> RAM, 1 byte:  [08][00][02][addr lo][addr hi][00][n][SUM]
//                   HTH4's counter C1 at 0x0457: 08 00 02 57 04 00 0A 6F (n = 10)
//   count_down      SUB 1 from the counter, then JUMP when it is not 0 (back to the loop's
//                   start), or when it is 0 (HTH4's Loop: out of the loop; a go_to loops back)
//                   08 07 02 57 04 00 01 6D, then [07][0B][target 24-bit][04 or 05][SUM]
//   branch_if       SUB with the S bit (flags only) of a literal from a RAM value, then JUMP on
//                   the flags: HTH4's CmpButton is 09 07 82 50 03 00 00 00 E5 + JUMP cond 04
//   go_to           JUMP cond 00
//   call_motion     CALL cond 00 to another slot's first byte: 07 0C B8 43 01 00 0F (0x0143B8)
//   servo_parameter SPEED/STRETCH (0x12) of a set of servos
//   end             RETURN: 03 0D 10
//
// A flags-only SUB sets Z when the value equals the literal and C when it does not borrow
// (value >= literal, DOC-CMD; the virtual board does the same).
#pragma once

#include <rcb4/memory_map.hpp>
#include <rcb4/rcb4.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace rcb4::motion {

/** HeartToHeart4's loop counter C1 (motions.md §1: SetCounter and Loop use RAM 0x0457). */
inline constexpr ram_address hth4_counter{0x0457};
/** The KRR receiver's button word (protocol.md §6), what HTH4's CmpButton compares. */
inline constexpr ram_address button_word{0x0350};

/** A name that jumps and loops refer to; it marks the address of the step after it. */
struct label {
  std::string name;  ///< unique within the program
  friend bool operator==(const label&, const label&) = default;
};
/** The listed servos to their positions over @p time frames of the output period. */
struct pose {
  servo_set<servo_position> targets;  ///< at least one servo
  frames time{};                      ///< 0-255 frames
  friend bool operator==(const pose&, const pose&) = default;
};
/** A 1-byte RAM counter set to @p value. */
struct set_counter {
  ram_address counter = hth4_counter;  ///< where
  std::uint8_t value = 0;              ///< what
  friend bool operator==(const set_counter&, const set_counter&) = default;
};
/**
 * The counter minus 1, then a jump to @p to: while it is not 0 (a loop back, the compact form),
 * or once it is 0 (@p when_zero: HTH4's form, the loop's exit).
 */
struct count_down {
  ram_address counter = hth4_counter;  ///< the 1-byte counter
  std::string to;                      ///< a label
  bool when_zero = false;              ///< jump when it reached 0 instead of while it has not
  friend bool operator==(const count_down&, const count_down&) = default;
};
/** How a RAM value compares with a literal (unsigned). */
enum class compare : std::uint8_t {
  equal,      ///< Z = 1
  not_equal,  ///< Z = 0
  below,      ///< C = 0 (a borrow)
  at_least,   ///< C = 1
  at_most,    ///< Z = 1 or C = 0: COND 0D, HTH4's "≤" (rcb4::two_flag_jump: either flag)
};
/** A jump to @p to when the 1- or 2-byte RAM value at @p address compares so with @p value. */
struct branch_if {
  ram_address address = button_word;  ///< the value
  std::uint8_t size = 2;              ///< 1 or 2 bytes, little-endian
  std::uint16_t value = 0;            ///< the literal
  compare how = compare::equal;       ///< the test
  std::string to;                     ///< a label
  /**
   * A jump when the KRR button word is (or, with @p equal false, is not) @p buttons. The receiver
   * leaves the word high byte first at 0x0350 (krr::encode_buttons, protocol.md §6) and a 2-byte
   * SUB reads RAM low byte first, so the literal is the word with its bytes swapped: UP (0x0001)
   * lies as 00 01 and compares with the literal 0x0100.
   */
  static branch_if buttons(std::uint16_t buttons, std::string to, bool equal = true) {
    return {button_word, 2, as_ram_value(buttons), equal ? compare::equal : compare::not_equal, std::move(to)};
  }
  /** The button word @p buttons as a 2-byte read of 0x0350 gives it (its bytes swapped). */
  static constexpr std::uint16_t as_ram_value(std::uint16_t buttons) noexcept {
    return static_cast<std::uint16_t>((buttons >> 8) | ((buttons & 0xFFu) << 8));
  }
  /** The buttons of a branch on the button word (buttons() undone). */
  std::uint16_t buttons_of() const noexcept { return as_ram_value(value); }
  friend bool operator==(const branch_if&, const branch_if&) = default;
};
/** An unconditional jump to a label. */
struct go_to {
  std::string to;  ///< a label
  friend bool operator==(const go_to&, const go_to&) = default;
};
/** A call of the code at @p address (another motion's slot), which returns here. */
struct call_motion {
  rom_address address{};  ///< the callee's first byte
  friend bool operator==(const call_motion&, const call_motion&) = default;
};
/** The ICS speed or stretch parameter of a set of servos (0x12). */
struct servo_parameter {
  param_kind kind = param_kind::stretch;  ///< speed or stretch
  servo_set<servo_param> values;          ///< per servo, 1-127
  friend bool operator==(const servo_parameter&, const servo_parameter&) = default;
};
/** RETURN: back to the caller (the main loop, or a motion that called this one). */
struct end {
  friend bool operator==(const end&, const end&) = default;
};

/** One step of a motion program. */
using step = std::variant<label, pose, set_counter, count_down, branch_if, go_to, call_motion, servo_parameter, end>;

/** A motion: its steps in the order they are laid out in the slot. */
struct program {
  std::vector<step> steps;  ///< the first runs first
  friend bool operator==(const program&, const program&) = default;
};

/** Why a program cannot be assembled, or bytes cannot be read back as one. */
struct failure {
  std::string message;  ///< names the step (0-based) or the address
};
/** A value or a failure. */
template <class T>
using outcome = std::variant<T, failure>;
/** True when @p o holds a value. */
template <class T>
bool ok(const outcome<T>& o) noexcept {
  return std::holds_alternative<T>(o);
}

/** What a slot is and may hold. */
struct slot {
  rom_address address{};      ///< its first byte
  std::uint32_t size = 2048;  ///< bytes it may hold (HTH4 2.x: 2,048)
};

/** The slot of motion @p n (1-based) in @p layout; nothing outside its slots. */
inline std::optional<slot> slot_of(const rom_layout& layout, unsigned n) {
  const auto a = motion_address(layout, n);
  if (!a) return std::nullopt;
  return slot{*a, layout.slot_size};
}

}  // namespace rcb4::motion
