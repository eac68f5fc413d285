// rcb4 — what a board holds: which servo slots are allocated and answer, which motion slots are used.
// SPDX-License-Identifier: BSL-1.0
//
// scan_slots reads the ICS allocation table (protocol.md §6) and every allocated block's measured
// position (+4, §7). The board writes +4 from the servo's answers; a block whose measured position
// is still 0 has never heard from its servo (the test iory/rcb4's search_servo_ids makes, §10).
//
// list_motions reads the first bytes of every motion slot of a ROM layout (§8): an erased slot
// reads 0xFF. A used slot is walked frame by frame (each frame's SIZE byte and checksum, §2.1) up
// to its first RETURN, in reads of up to 128 bytes: its size is the bytes up to and including it.
#pragma once

#include <rcb4/ops/planner.hpp>
#include <rcb4/ops/servos.hpp>

#include <vector>

namespace rcb4::ops {

/** An allocated slot, and whether its servo has answered. */
struct slot_probe {
  ics_number ics{};            ///< the slot
  std::uint16_t address = 0;   ///< its block
  std::uint16_t position = 0;  ///< +4, the measured position
  /** True when the board has a measured position for it (non-zero). */
  bool answers() const noexcept { return position != 0; }
};

/** Scans the allocation table, then every allocated block's measured position (planned reads). */
class scan_slots {
 public:
  /** Plans the position reads for @p cost. */
  explicit scan_slots(link_cost cost = {}) : reads_(4, 2, cost) {}
  /** The next read. */
  std::optional<command> next() const { return reads_.next(); }
  /** Takes a reply. */
  void on_reply(const reply& r) {
    if (!reads_.on_reply(r)) return;
    for (const auto& s : reads_.slots()) probes_.push_back({s.ics, s.address, reads_.word(s.address + 4u)});
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return reads_.error(); }
  /** The allocated slots, ascending, with their measured positions. */
  const std::vector<slot_probe>& value() const noexcept { return probes_; }

 private:
  detail::table_then_reads reads_;
  std::vector<slot_probe> probes_;
};

/** A used motion slot. */
struct motion_slot {
  unsigned number = 0;             ///< 1-based
  std::uint32_t address = 0;       ///< its first byte in ROM
  std::uint32_t size = 0;          ///< bytes up to and including the first RETURN (or the last valid frame)
  unsigned frames = 0;             ///< frames walked
  bool ends = false;               ///< true when a RETURN was found; false: the walk met a byte that starts no frame
  bool readable = true;            ///< false: the first frame fails its checksum (another ROM layout?)
  std::vector<std::uint8_t> code;  ///< its bytes up to and including the first RETURN (size bytes)
};

/** Lists the used motion slots of @p layout (see the file comment). */
class list_motions {
 public:
  /** Every slot of @p layout. */
  explicit list_motions(const rom_layout& layout = hth4_2_2) : layout_(layout) {}
  /** The next read. */
  std::optional<command> next() const {
    if (error_ != errc{} || slot_ > layout_.motion_count) return std::nullopt;
    const std::uint32_t base = slot_base();
    if (!walking_) return command{move::read_rom(rom_address::make(base).value(), 2).value()};
    const std::uint32_t at = base + static_cast<std::uint32_t>(data_.size());
    const std::uint32_t n = std::min<std::uint32_t>(128, layout_.slot_size - static_cast<std::uint32_t>(data_.size()));
    return command{move::read_rom(rom_address::make(at).value(), transfer_size::make(n).value()).value()};
  }
  /** Takes a reply. */
  void on_reply(const reply& r) {
    if (!walking_) {
      if ((error_ = detail::check_reply(r, true, 2)) != errc{}) return;
      const std::uint8_t size = r.bytes()[0];
      if (size >= 3 && size <= max_request_size) {
        walking_ = true;
        data_.clear();
        current_ = {slot_, slot_base(), 0, 0, false, true, {}};
      } else {
        ++slot_;
      }
      return;
    }
    const std::uint32_t asked =
        std::min<std::uint32_t>(128, layout_.slot_size - static_cast<std::uint32_t>(data_.size()));
    if ((error_ = detail::check_reply(r, true, asked)) != errc{}) return;
    data_.insert(data_.end(), r.bytes().begin(), r.bytes().end());
    walk();
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return error_; }
  /** The used slots, ascending. */
  const std::vector<motion_slot>& value() const noexcept { return slots_; }
  /** Slots looked at so far (progress: of layout.motion_count). */
  unsigned slots_done() const noexcept { return slot_ - 1; }

 private:
  std::uint32_t slot_base() const { return layout_.motion_base.value() + (slot_ - 1) * layout_.slot_size; }
  void finish() {
    current_.code.assign(data_.begin(), data_.begin() + std::min<std::ptrdiff_t>(current_.size, std::ssize(data_)));
    slots_.push_back(current_);
    walking_ = false;
    ++slot_;
  }
  void walk() {
    while (true) {
      const std::uint32_t at = current_.size;
      if (at >= layout_.slot_size) return finish();
      if (at >= data_.size()) return;  // read on
      const std::uint8_t size = data_[at];
      if (size < 3 || size > max_request_size || at + size > layout_.slot_size) return finish();
      if (at + size > data_.size()) return;  // the frame continues in the next read
      unsigned sum = 0;
      for (std::uint32_t i = at; i + 1 < at + size; ++i) sum += data_[i];
      if ((sum & 0xFFu) != data_[at + size - 1u]) {
        if (current_.frames == 0) current_.readable = false;
        return finish();
      }
      current_.size += size;
      ++current_.frames;
      if (size == 3 && data_[at + 1] == 0x0D) {  // RETURN (§4.4): the motion's end
        current_.ends = true;
        return finish();
      }
    }
  }
  rom_layout layout_;
  unsigned slot_ = 1;
  bool walking_ = false;
  std::vector<std::uint8_t> data_;
  motion_slot current_;
  std::vector<motion_slot> slots_;
  errc error_{};
};

}  // namespace rcb4::ops
