// rcb4 — a sans-I/O emulator of an RCB-4HV: bytes in, reply bytes out, time advanced explicitly.
// SPDX-License-Identifier: BSL-1.0
//
// What it models (protocol.md §2–§9; the choices where sources are silent are marked "model"),
// in parts each testable on its own:
//  - memory.hpp: RAM 0x0000–0x048F with HTH4 2.2 power-on values, 256 KiB ROM (default image:
//    rom_image.hpp), operands through the ICS allocation table at 0x0044.
//  - program.hpp: every command, from COM and from ROM, with the NACKs of the board.
//  - servos.hpp: interpolation and the EEPROM update flags.
//  - vectors.hpp: the vector-jump table and the down-timers.
//  - Here: framing (silence for incomplete frames; with strict timing a frame whose bytes arrive
//    more than 150 µs apart is dropped), replies, power-on, and the clock: everything happens on
//    output-period ticks (10/15/20/25 ms, config bits 4-5). Each tick moves the servos one step and
//    clears the flags of those that finished, then, while the ROM program runs (config bit 1):
//    compares the vector table when the vector switch (bit 3) is on and fires the first entry that
//    holds (motions.md §2), then runs the program unless an update flag is set. AD values get ±1
//    LSB of noise per tick; timers count down every 100 ms.
//  - The disputed points of §11 are options; defaults follow the 2015 report's hardware findings:
//    SERIES reboots the board (no reply), SHIFT uses the measured encoding, arithmetic to COM NACKs.
//  - A write that changes the COM baud bits takes effect after its reply (line_baud()).
#pragma once

#include <rcb4/board/memory.hpp>
#include <rcb4/board/options.hpp>
#include <rcb4/board/program.hpp>
#include <rcb4/board/rom_image.hpp>
#include <rcb4/board/servos.hpp>
#include <rcb4/board/vectors.hpp>
#include <rcb4/memory_map.hpp>
#include <rcb4/rcb4.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <random>
#include <span>
#include <utility>
#include <variant>
#include <vector>

namespace rcb4::board {

/** An emulated RCB-4HV. Not thread-safe: one owner feeds it. */
class virtual_board {
 public:
  static constexpr std::size_t stack_depth = processor::stack_depth;  ///< CALL nesting (DOC-CMD/DOC-FW)

  /** A board with the default ROM image, powered on at board time 0. */
  explicit virtual_board(options opt = {}) : opt_(opt), servos_(opt.unanswered), cpu_(opt), rng_(opt.seed) {
    mem_.rom = default_image();
    power_on();
  }

  /**
   * Bytes @p in arrived at board time @p now. Complete frames are executed and their replies
   * appended to @p out; an incomplete frame waits for more bytes (silence, as the board).
   */
  void receive(std::span<const std::uint8_t> in, board_time now, std::vector<std::uint8_t>& out) {
    advance_to(now);
    if (opt_.strict_timing && !pending_.empty() && now - last_byte_ > std::chrono::microseconds(150)) {
      stats_.dropped += pending_.size();
      pending_.clear();
    }
    if (!in.empty()) last_byte_ = now;
    pending_.insert(pending_.end(), in.begin(), in.end());
    std::size_t used = 0;
    while (used < pending_.size()) {
      const auto r = parse_command(std::span(pending_).subspan(used), codec_options{opt_.shift, true});
      if (r.status == parse_status::need_more) break;
      if (r.status == parse_status::error && r.consumed == 1) {  // impossible SIZE byte: resync
        ++stats_.dropped;
        used += 1;
        continue;
      }
      ++stats_.frames;
      used += r.consumed;
      if (r.status == parse_status::error) {
        send(reply::nack(r.command), out);
        continue;
      }
      if (!execute_from_com(r.value(), out)) return;  // rebooted: the input buffer is gone
    }
    pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(used));
  }

  /** Advances board time to @p now, running every output-period tick in between. */
  void advance_to(board_time now) {
    if (now <= now_) return;
    while (next_tick_ <= now) {
      now_ = next_tick_;
      tick();
      next_tick_ += period();
    }
    now_ = now;
  }

  /** The board's clock. */
  board_time now() const noexcept { return now_; }
  /** The COM line rate the board listens at now (config bits 6-7). */
  std::uint32_t line_baud() const noexcept { return bits_per_second(config().com_baud); }
  /** The config register, decoded. */
  config_word config() const noexcept { return mem_.config(); }
  /** Bytes of an incomplete frame waiting for the rest. */
  std::size_t pending_bytes() const noexcept { return pending_.size(); }
  /** What the board saw. */
  const statistics& stats() const noexcept { return stats_; }
  /** The emulator's options. */
  const options& settings() const noexcept { return opt_; }

  /** RAM, read-only. */
  std::span<const std::uint8_t, ram_size> ram() const noexcept { return mem_.ram; }
  /** ROM, read-only. */
  std::span<const std::uint8_t> rom() const noexcept { return mem_.rom; }
  /** Replaces the ROM image (exactly 256 KiB) and powers the board on again. */
  result<void> load_rom(std::span<const std::uint8_t> image) {
    if (image.size() != rom_size) return errc::rom_address_out_of_range;
    mem_.rom.assign(image.begin(), image.end());
    power_on();
    return {};
  }
  /** Resets RAM to the power-on state and boots from ROM (as after a power cycle). */
  void power_on() {
    mem_.ram.fill(0);
    auto boot = config_word::decode(mem_.rom16(hth4_2_2.config.value()));
    if (opt_.period) boot.period = *opt_.period;
    mem_.set_config(boot);
    // HTH4 2.x's boot ends in StartupCmd, a CALL of the start-up motion just before the main loop
    // (hth4-files.md §3): run from there when the ROM has one, else from the main loop.
    const auto at = hth4_2_2.startup.value();
    const bool startup = call_target(std::span<const std::uint8_t>(mem_.rom).subspan(at)).has_value();
    mem_.set_pc(startup ? at : hth4_2_2.main_loop.value());
    mem_.put16(ram::pio_direction.value(), 0x03FF);
    for (unsigned k = 0; k < ram::timers; ++k) mem_.put16(ram::timer.value() + 2 * k, ram::timer_stopped);
    for (unsigned k = 0; k < ics_slots; ++k) {
      const auto n = ics_number::make(k).value();
      const bool servo = k < 35 && opt_.servos.contains(n);
      const std::uint16_t block = static_cast<std::uint16_t>(ram::user_area.value() + servo_block::size * k);
      mem_.put16(ram::ics_allocation.value() + 2 * k, servo || k == 35 ? block : ram::no_allocation);
      if (servo) {
        mem_.ram[block + servo_block::id.offset] = static_cast<std::uint8_t>(k / 2);
        // The trim HTH4 keeps in ROM's servo image (protocol.md §8); erased (0xFFFF): none.
        const std::uint16_t trim = mem_.rom16(hth4_rom::servo_image_of(static_cast<std::uint16_t>(block + 2u)).value());
        mem_.put16(block + servo_block::trim.offset, trim == 0xFFFF ? 0 : trim);
        mem_.put16(block + servo_block::position.offset, servos_.answers(n) ? servo_position::centre_value : 0);
        mem_.put16(block + servo_block::target.offset, servo_position::centre_value);
        mem_.put16(block + servo_block::interp_end.offset, servo_position::centre_value);
      }
    }
    load_vector_table(mem_);
    battery_raw_ = 442;  // 10.8 V
    cpu_.reset();
    servos_.reset();
    next_tick_ = now_ + period();
    next_timer_ = now_ + std::chrono::milliseconds(100);
    update_inputs();
  }

  // --- the outside world, for tests and demos ------------------------------------------------
  /** Sets the raw 10-bit reading of AD channel @p k (0 = supply / 5); noise is added per tick. */
  void set_ad_raw(unsigned k, std::uint16_t raw) {
    if (k == 0)
      battery_raw_ = raw;
    else if (k < ram::ad_channels)
      ad_raw_[k] = raw;
    update_inputs();
  }
  /** Sets the battery voltage (AD0 = V × 1024 / 25). */
  void set_battery_volts(double v) { set_ad_raw(0, static_cast<std::uint16_t>(v * 1024.0 / 25.0 + 0.5)); }
  /** Levels on the PIO pins configured as inputs. */
  void set_pio_inputs(std::uint16_t levels) {
    pio_inputs_ = levels;
    update_inputs();
  }
  /** What a KRR receiver reports: the button word and PA1–PA4 (7-bit). */
  void set_receiver(std::uint16_t buttons, std::array<std::uint8_t, krr::analog_channels> analog = {}) {
    const auto b = krr::encode_buttons(buttons);
    mem_.ram[krr::buttons.value()] = b[0];
    mem_.ram[krr::buttons.value() + 1] = b[1];
    for (unsigned i = 0; i < krr::analog_channels; ++i) mem_.ram[krr::analog.value() + i] = analog[i] & 0x7Fu;
  }
  /**
   * Turns ICS @p n by hand to @p position (a free servo's measured position follows; a held or
   * driven one springs back on the next tick). False when the slot has no answering servo.
   */
  bool turn_by_hand(ics_number n, std::uint16_t position) {
    const auto b = block_of(n);
    if (!b || !servos_.answers(n)) return false;
    mem_.put16(*b + servo_block::position.offset, position);
    return true;
  }
  /** The speed (output limit) and stretch of ICS @p n, as last set by 0x12. */
  std::pair<std::uint8_t, std::uint8_t> servo_params_of(ics_number n) const noexcept { return servos_.params_of(n); }
  /** 16-bit word of RAM at @p addr (little-endian). */
  std::uint16_t ram16(std::uint32_t addr) const noexcept { return mem_.ram16(addr); }
  /** The RAM block address of ICS @p n, or nothing when unallocated (0xFFFF, or 0 as on a board without a project). */
  std::optional<std::uint16_t> block_of(ics_number n) const noexcept { return mem_.block_of(n); }

 private:
  static const std::vector<std::uint8_t>& default_image() {
    static const std::vector<std::uint8_t> image = default_rom();
    return image;
  }
  board_time period() const noexcept { return std::chrono::milliseconds(milliseconds(config().period)); }

  void send(const reply& r, std::vector<std::uint8_t>& out) {
    const auto f = encode(r);
    out.insert(out.end(), f.begin(), f.end());
    if (r.is_ack())
      ++stats_.acks;
    else if (r.is_nack())
      ++stats_.nacks;
    else
      ++stats_.data;
  }

  /** Executes @p c and queues its reply; false when the board rebooted (pending input is lost). */
  bool execute_from_com(const command& c, std::vector<std::uint8_t>& out) {
    if (std::holds_alternative<series_servo>(c) && opt_.series == series_behaviour::reboot) {
      ++stats_.reboots;  // what the 2015 report saw: the board restarts and says nothing
      pending_.clear();
      power_on();
      return false;
    }
    const auto o = cpu_.execute(mem_, servos_, c);
    const std::uint8_t code = std::visit([](const auto& x) { return x.code(); }, c);
    switch (o.kind) {
      case outcome::ack: send(reply::ack(code), out); break;
      case outcome::nack: send(reply::nack(code), out); break;
      case outcome::data: send(reply::data(code, std::span(o.bytes).first(o.size)).value(), out); break;
      case outcome::silent: break;
    }
    return true;
  }

  /** One output period (DOC-FW p7): servos, inputs, timers, then vectors and the program. */
  void tick() {
    servos_.step(mem_);
    update_inputs();
    while (next_timer_ <= now_) {
      count_down_timers(mem_);
      next_timer_ += std::chrono::milliseconds(100);
    }
    auto cfg = mem_.config();
    if (!cfg.rom_program) return;
    if (cfg.vector_jump) {
      if (const auto e = firing_vector(mem_)) {
        ++stats_.vectors;
        cfg.vector_jump = false;  // cleared when a vector fires (DOC-FW p13)
        mem_.set_config(cfg);
        if (!cpu_.fire(mem_, *e)) {  // a CALL on a full stack: an error in the program (model)
          cfg.rom_program = false;
          mem_.set_config(cfg);
          return;
        }
      }
    }
    cpu_.run_program(mem_, servos_, stats_);
  }
  void update_inputs() {
    std::uniform_int_distribution<int> noise(-1, 1);
    for (unsigned k = 0; k < ram::ad_channels; ++k) {
      const int raw = (k == 0 ? battery_raw_ : ad_raw_[k]) + noise(rng_);
      const int value = std::clamp(raw, 0, 1023) - mem_.ram16(ram::ad_reference.value() + 2 * k);
      mem_.put16(ram::ad_value.value() + 2 * k, static_cast<std::uint16_t>(value));
    }
    const std::uint16_t dir = mem_.ram16(ram::pio_direction.value());
    const std::uint16_t value = mem_.ram16(ram::pio_value.value());
    mem_.put16(ram::pio_value.value(), static_cast<std::uint16_t>(((value & dir) | (pio_inputs_ & ~dir)) & 0x03FFu));
  }

  options opt_;
  memory mem_;
  servo_bank servos_;
  processor cpu_;
  std::array<std::uint16_t, ram::ad_channels> ad_raw_{0, 512, 512, 512, 512, 512, 512, 512, 512, 512, 512};
  std::uint16_t battery_raw_ = 442;
  std::uint16_t pio_inputs_ = 0;
  std::vector<std::uint8_t> pending_;
  board_time now_{0}, next_tick_{0}, next_timer_{0}, last_byte_{0};
  std::mt19937 rng_;
  statistics stats_{};
};

}  // namespace rcb4::board
