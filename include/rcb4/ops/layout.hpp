// rcb4 — which HTH4 layout a board's ROM was written with, told from the ROM itself (protocol.md
// §8, §11.13): HTH4 2.2+ puts motion 1 at 0x000B80, 2.0–2.1 and 1.3 at 0x000BB8; 2.x has its main
// loop at 0x00044B, 1.3 at 0x0003FD.
// SPDX-License-Identifier: BSL-1.0
//
// Four reads of up to 128 bytes: where motion 1 starts in each layout, and where each main loop
// is. A place "holds a frame" when its SIZE byte is 3–128, its SUM checks and the codec parses it.
// Rules: a frame at 0x0B80 and none at 0x0BB8, or frames at both where following the frames from
// 0x0B80 lands on 0x0BB8 (one motion running across): 2.2. A frame at 0x0BB8 only: 2.0 when the
// 2.x main loop holds a frame and 1.3's does not, 1.3 the other way round. Anything else (no motion
// in slot 1 of any layout, or both readings possible) is not guessed: the caller names the layout.
#pragma once

#include <rcb4/ops/operation.hpp>

#include <array>
#include <string>
#include <vector>

namespace rcb4::ops {

/** The layout told from a ROM, or why it could not be. */
struct layout_guess {
  const rom_layout* layout = nullptr;  ///< nothing when it could not be told
  std::string reason;                  ///< what the ROM showed
};

namespace detail {
/** True when @p b starts with a whole frame that the codec parses. */
inline bool holds_frame(std::span<const std::uint8_t> b) {
  if (b.empty() || b[0] < 3 || b[0] > max_request_size || b[0] > b.size()) return false;
  return parse_command(b.first(b[0])).ok();
}
/** True when frames followed from the start of @p b (at @p from) reach @p to exactly. */
inline bool frames_reach(std::span<const std::uint8_t> b, std::uint32_t from, std::uint32_t to) {
  std::size_t at = 0;
  while (from + at < to && at < b.size() && holds_frame(b.subspan(at))) at += b[at];
  return from + at == to;
}
}  // namespace detail

/** Judges the layout from the bytes read at 0x0B80, 0x0BB8, 0x044B and 0x03FD (up to 128 each). */
inline layout_guess judge_layout(std::span<const std::uint8_t> at_0b80, std::span<const std::uint8_t> at_0bb8,
                                 std::span<const std::uint8_t> at_044b, std::span<const std::uint8_t> at_03fd) {
  const bool new_slot = detail::holds_frame(at_0b80), old_slot = detail::holds_frame(at_0bb8);
  if (new_slot && (!old_slot || detail::frames_reach(at_0b80, 0x0B80, 0x0BB8)))
    return {&hth4_2_2, "motion 1 starts at 0x000B80 (HTH4 2.2 and later)"};
  if (old_slot && !new_slot) {
    const bool loop_2x = detail::holds_frame(at_044b), loop_13 = detail::holds_frame(at_03fd);
    if (loop_2x && !loop_13) return {&hth4_2_0, "motion 1 starts at 0x000BB8 and the main loop is at 0x00044B"};
    if (loop_13 && !loop_2x) return {&hth4_1_3, "motion 1 starts at 0x000BB8 and the main loop is at 0x0003FD"};
    return {nullptr, "motion 1 starts at 0x000BB8 (HTH4 2.0-2.1 or 1.3), and the main loops do not tell which"};
  }
  if (new_slot) return {nullptr, "frames start at both 0x000B80 and 0x000BB8"};
  return {nullptr, "no motion 1 at 0x000B80 (HTH4 2.2+) nor at 0x000BB8 (HTH4 2.0-2.1, 1.3)"};
}

/** Reads the four places judge_layout() needs and judges. value(): the guess (its layout may be null). */
class detect_layout {
 public:
  /** The next read. */
  std::optional<command> next() {
    static constexpr std::uint32_t places[] = {0x000B80, 0x000BB8, 0x00044B, 0x0003FD};
    if (error_ != errc{} || step_ >= 4) return std::nullopt;
    return command{
        move::read_rom(rom_address::make(places[step_]).value(), transfer_size::make(read_size).value()).value()};
  }
  /** Takes a reply. */
  void on_reply(const reply& r) {
    if ((error_ = detail::check_reply(r, true, read_size)) != errc{}) return;
    bytes_[step_].assign(r.bytes().begin(), r.bytes().end());
    if (++step_ == 4) guess_ = judge_layout(bytes_[0], bytes_[1], bytes_[2], bytes_[3]);
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return error_; }
  /** The guess, once all four reads are in. */
  const layout_guess& value() const noexcept { return guess_; }

 private:
  static constexpr std::uint8_t read_size = 128;
  std::array<std::vector<std::uint8_t>, 4> bytes_;
  layout_guess guess_;
  unsigned step_ = 0;
  errc error_{};
};

}  // namespace rcb4::ops
