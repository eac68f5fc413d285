// rcb4 — motions stored in ROM: play, status, stop (protocol.md §8).
// SPDX-License-Identifier: BSL-1.0
//
// Play is KONDO's four steps on a freshly read config word: suspend the ROM program, reset the
// program counter to the layout's main loop, CALL the motion, resume. The layout (HTH4 1.3,
// 2.0–2.1, 2.2+) says where the main loop and the motions are.
#pragma once

#include <rcb4/ops/operation.hpp>
#include <rcb4/ops/system.hpp>

#include <array>

namespace rcb4::ops {

/** What happens to the servos while the program is switched (the sources differ, §11.14). */
enum class servo_power : std::uint8_t {
  keep,     ///< leave the ICS switch on: a standing robot stays standing (KONDO's Arduino library)
  release,  ///< switch ICS off during the change, as KONDO's Python library does
};

namespace detail {
inline std::array<std::uint8_t, 2> le(std::uint16_t v) noexcept {
  return {static_cast<std::uint8_t>(v & 0xFFu), static_cast<std::uint8_t>(v >> 8)};
}
}  // namespace detail

/**
 * Plays motion @p n (1-based) of @p layout. value(): the config word it wrote last. Before
 * anything changes, the slot's first frame is read: an erased slot (0xFF, no frame) is
 * errc::motion_slot_empty, a first frame whose checksum fails (the slot address of another
 * layout lands inside a motion) is errc::motion_slot_not_a_frame, and nothing is sent. A CALL the board refuses (a full
 * stack, a bad address) does not leave the program stopped: the config word read at the start is written back (the main
 * loop runs again), then error() is errc::nack.
 */
class play_motion {
 public:
  /** Motion @p n of @p layout; an impossible number shows in error() at once. */
  explicit play_motion(unsigned n, const rom_layout& layout = hth4_2_2, servo_power power = servo_power::keep)
      : layout_(layout), power_(power) {
    auto a = motion_address(layout, n);
    if (!a)
      error_ = a.error();
    else
      target_ = *a;
    const std::uint32_t pc = layout.main_loop.value();
    reset_ = {static_cast<std::uint8_t>(pc & 0xFFu), static_cast<std::uint8_t>((pc >> 8) & 0xFFu),
              static_cast<std::uint8_t>((pc >> 16) & 0xFFu)};
  }
  /** The next step. */
  std::optional<command> next() {
    if (error_ != errc{}) return std::nullopt;
    switch (step_) {
      case 0: return command{move::read_ram(ram::config, 2).value()};
      case 1: return command{move::read_rom(target_, 2).value()};  // (2 bytes: a 1-byte read looks like a NACK)
      case 2: return command{move::read_rom(target_, first_size_).value()};  // the whole first frame
      case 3: return command{move::write_ram(ram::config, suspend_).value()};
      case 4: return command{move::write_ram(ram::program_counter, reset_).value()};
      case 5: return command{call{target_}};
      case 6: return command{move::write_ram(ram::config, refused_ ? original_ : resume_).value()};
      default: return std::nullopt;
    }
  }
  /** Takes a reply. */
  void on_reply(const reply& r) {
    if (step_ == 5 && r.is_nack()) {  // refused: restore the program's config, then report it
      refused_ = true;
      ++step_;
      return;
    }
    if ((error_ = detail::check_reply(r, step_ <= 2, step_ == 2 ? first_size_.value() : 2)) != errc{}) return;
    if (step_ == 0) {
      original_ = detail::le(r.u16());
      auto c = config_word::decode(r.u16());
      c.rom_program = c.vector_jump = c.interpolation_message = false;
      if (power_ == servo_power::release) c.ics_enabled = false;
      suspend_ = detail::le(c.encode());
      c.rom_program = c.vector_jump = c.ics_enabled = true;
      c.program_error = false;  // a fresh start: an error of the program that ran before is history
      resumed_ = c.encode();
      resume_ = detail::le(resumed_);
    } else if (step_ == 1) {
      const std::uint8_t size = r.bytes()[0];  // a program starts with a frame: SIZE 3..128 (§2.1)
      if (size < 3 || size > max_request_size)
        error_ = errc::motion_slot_empty;
      else
        first_size_ = transfer_size::make(size).value();
    } else if (step_ == 2) {
      // Its SUM is the low byte of the sum of the bytes before it (§2.1), as in every frame.
      unsigned sum = 0;
      const auto b = r.bytes();
      for (std::size_t i = 0; i + 1 < b.size(); ++i) sum += b[i];
      if ((sum & 0xFFu) != b.back()) error_ = errc::motion_slot_not_a_frame;
    } else if (step_ == 6 && refused_) {
      resumed_ = static_cast<std::uint16_t>(original_[0] | (original_[1] << 8));
      error_ = errc::nack;
    }
    ++step_;
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return error_; }
  /** The config word written at the end. */
  std::uint16_t value() const noexcept { return resumed_; }
  /** True when the board refused the CALL (then the config read at the start was restored). */
  bool refused() const noexcept { return refused_; }

 private:
  rom_layout layout_;
  servo_power power_;
  rom_address target_{};
  std::array<std::uint8_t, 2> suspend_{}, resume_{}, original_{};
  std::array<std::uint8_t, 10> reset_{};
  std::uint16_t resumed_ = 0;
  transfer_size first_size_{};
  unsigned step_ = 0;
  bool refused_ = false;
  errc error_{};
};

/** Whether a motion runs, and which (protocol.md §8.2). */
struct motion_state {
  bool running = false;    ///< a CALL is pending (stack or update flags busy) and the ROM program runs
  bool suspended = false;  ///< a CALL is pending but the ROM program is off: stopped part way (motion stop, an error)
  std::optional<unsigned> motion;     ///< its number under the layout, when the PC is in a motion slot
  std::uint32_t program_counter = 0;  ///< where the ROM program is
  unsigned depth = 0;                 ///< the call stack's depth (RAM 0x0005): CALLs pending, the play's own included
  bool program_on =
      true;  ///< the ROM program runs (config bit 1): off after motion stop or a ROM restore, buttons play nothing
  friend bool operator==(const motion_state&, const motion_state&) = default;
};

/**
 * Reads the config word and the program counter block (12 bytes at 0x0000, one read) and decodes
 * the motion state: a CALL pending (protocol.md §8.2: SP or update flags non-zero) is running
 * while the ROM program runs (config bit 1), and suspended when it does not (after motion stop,
 * or when the board stopped the program on an error).
 */
class read_motion_state {
 public:
  /** For motions laid out as @p layout. */
  explicit read_motion_state(const rom_layout& layout = hth4_2_2) : layout_(layout) {}
  /** The read, once. */
  std::optional<command> next() {
    if (done_ || error_ != errc{}) return std::nullopt;
    return command{move::read_ram(ram::config, 12).value()};
  }
  /** Takes the reply. */
  void on_reply(const reply& r) {
    done_ = true;
    if ((error_ = detail::check_reply(r, true, 12)) != errc{}) return;
    const auto c = r.bytes();
    const bool program_on = config_word::decode(static_cast<std::uint16_t>(c[0] | (c[1] << 8))).rom_program;
    const auto b = c.subspan(2);  // the block at 0x0002
    state_.program_counter = b[0] | (std::uint32_t{b[1]} << 8) | (std::uint32_t{b[2]} << 16);
    const bool pending = (b[3] | b[4] | b[5] | b[6] | b[7]) != 0;  // SP, unused, first update flags
    state_.depth = b[3];
    state_.program_on = program_on;
    state_.running = pending && program_on;
    state_.suspended = pending && !program_on;
    const std::uint32_t base = layout_.motion_base.value();
    if (pending && state_.program_counter >= base) {
      const std::uint32_t n = (state_.program_counter - base) / layout_.slot_size + 1;
      if (n <= layout_.motion_count) state_.motion = n;
    }
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return error_; }
  /** The state read. */
  const motion_state& value() const noexcept { return state_; }

 private:
  rom_layout layout_;
  bool done_ = false;
  motion_state state_{};
  errc error_{};
};

/** Stops the ROM program (a running motion halts where it is): config bits 1 and 3 cleared. */
class stop_motion {
 public:
  /** Read the config word, then write it back suspended. */
  std::optional<command> next() {
    if (error_ != errc{} || step_ > 1) return std::nullopt;
    if (step_ == 0) return command{move::read_ram(ram::config, 2).value()};
    return command{move::write_ram(ram::config, word_).value()};
  }
  /** Takes a reply. */
  void on_reply(const reply& r) {
    if ((error_ = detail::check_reply(r, step_ == 0, 2)) != errc{}) return;
    if (step_ == 0) {
      auto c = config_word::decode(r.u16());
      c.rom_program = c.vector_jump = false;
      word_ = detail::le(c.encode());
    }
    ++step_;
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return error_; }
  /** The config word written. */
  std::uint16_t value() const noexcept { return static_cast<std::uint16_t>(word_[0] | (word_[1] << 8)); }

 private:
  std::array<std::uint8_t, 2> word_{};
  unsigned step_ = 0;
  errc error_{};
};

/** Suspends the ROM program: the same as stop_motion; resume_motion continues where it was. */
using suspend_motion = stop_motion;

/** Resumes a suspended ROM program where it stopped (config bits 0, 1 and 3 set). */
inline auto resume_motion() {
  return update_config([](config_word& c) { c.ics_enabled = c.rom_program = c.vector_jump = true; });
}

}  // namespace rcb4::ops
