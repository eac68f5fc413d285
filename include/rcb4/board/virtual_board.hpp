// rcb4 — a sans-I/O emulator of an RCB-4HV: bytes in, reply bytes out, time advanced explicitly.
// SPDX-License-Identifier: BSL-1.0
//
// What it models (protocol.md §2–§9; the choices where sources are silent are marked "model"):
//  - RAM 0x0000–0x048F with HTH4 2.2 power-on values, 256 KiB ROM (default image: rom_image.hpp).
//  - Every command: MOV between all kinds (ICS fields through the allocation table at 0x0044),
//    AND/OR/XOR/NOT/SHIFT/ADD…MOD with Z/C in the config word and the S bit, JUMP/CALL/RETURN
//    with conditions and a 16-deep stack, SINGLE/CONST/SERIES with interpolation, FREE/HOLD,
//    SPEED/STRETCH stored per servo, VERSION, both pings.
//  - NACK where the board NACKs: bad checksum, address out of range, unallocated slot (SINGLE,
//    MOV on ICS), stack overflow, division by zero (model). Silence: incomplete frames, and with
//    strict timing a frame whose bytes arrive more than 150 µs apart (it is dropped).
//  - The disputed points of §11 are options; defaults follow the 2015 report's hardware findings:
//    SERIES reboots the board (no reply), SHIFT uses the measured encoding, arithmetic to COM NACKs.
//  - Timing model: everything happens on output-period ticks (10/15/20/25 ms, config bits 4-5).
//    Each tick moves every interpolating servo one step ((end − output) / steps remaining), clears
//    the update flag (0x0007) of servos that finished, then runs the ROM program (if config bit 1
//    is set) until it reaches a servo command whose flags are still set, a JUMP to itself (the
//    idle main loop), or a budget of 256 commands. The measured position (+4)
//    follows the output at once (model: ideal servos, no mixing). AD values get ±1 LSB of noise
//    per tick; timers count down every 100 ms.
//  - A write that changes the COM baud bits takes effect after its reply (line_baud()).
#pragma once

#include <rcb4/board/rom_image.hpp>
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

/** What the emulator does with SERIES (0x11), disputed in protocol.md §11.2. */
enum class series_behaviour : std::uint8_t {
  reboot,   ///< what the 2015 report saw on a real RCB-4HV: the board resets, no reply
  execute,  ///< move the servos, each with its own frames, and ACK
};

/** Emulator choices. */
struct options {
  shift_encoding shift = shift_encoding::measured_2015;  ///< §11.5
  bool allow_arith_to_com = false;                       ///< §11.6
  series_behaviour series = series_behaviour::reboot;    ///< §11.2
  bool strict_timing = false;                            ///< drop a partial frame after a 150 µs gap (DOC-FW "COM")
  std::uint32_t seed = 1;                                ///< AD noise
  servo_mask servos = khr3hv_servos;                     ///< the allocated slots (default: a KHR-3HV's)
  servo_mask unanswered{};                               ///< allocated slots whose servo never answers (+4 stays 0)
  std::optional<output_period>
      period{};  ///< boot with this output period, not the ROM config's (15 ms: HTH4's samples)
};

/** ICS 0..@p n−1 (at most 0..34): a board with @p n anonymous servo slots. */
constexpr servo_mask first_slots(unsigned n) noexcept {
  servo_mask m;
  for (unsigned k = 0; k < n && k < 35; ++k) m.insert(ics_number::make(k).value());
  return m;
}

/** Board time: microseconds since an epoch of the caller's choosing. */
using board_time = std::chrono::microseconds;

/**
 * The 32-byte VERSION field. The default is what a Python RCB-4 library checks for on an
 * RCB-4mini (protocol.md §4.10, §11.18): "CB-4 V1.0      090715          " followed by 0xC7.
 */
inline constexpr std::array<std::uint8_t, version_field_size> default_identity = {
    'C', 'B', '-', '4', ' ', 'V', '1', '.', '0', ' ', ' ', ' ', ' ', ' ', ' ', '0',
    '9', '0', '7', '1', '5', ' ', ' ', ' ', ' ', ' ', ' ', ' ', ' ', ' ', ' ', 0xC7};

/** Counters of what the board saw. */
struct statistics {
  std::uint64_t frames = 0;     ///< complete frames received
  std::uint64_t acks = 0;       ///< ACK replies sent
  std::uint64_t nacks = 0;      ///< NACK replies sent
  std::uint64_t data = 0;       ///< data replies sent
  std::uint64_t dropped = 0;    ///< bytes discarded (bad size byte, timing gaps)
  std::uint64_t reboots = 0;    ///< resets (SERIES with series_behaviour::reboot)
  std::uint64_t rom_steps = 0;  ///< commands executed from ROM
};

/** An emulated RCB-4HV. Not thread-safe: one owner feeds it. */
class virtual_board {
 public:
  static constexpr std::size_t stack_depth = 16;  ///< CALL nesting (DOC-CMD/DOC-FW)

  /** A board with the default ROM image, powered on at board time 0. */
  explicit virtual_board(options opt = {}) : opt_(opt), rom_(default_image()), rng_(opt.seed) { power_on(); }

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
      if (!execute_from_com(r.value, out)) return;  // rebooted: the input buffer is gone
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
  config_word config() const noexcept { return config_word::decode(ram16(ram::config.value())); }
  /** Bytes of an incomplete frame waiting for the rest. */
  std::size_t pending_bytes() const noexcept { return pending_.size(); }
  /** What the board saw. */
  const statistics& stats() const noexcept { return stats_; }
  /** The emulator's options. */
  const options& settings() const noexcept { return opt_; }

  /** RAM, read-only. */
  std::span<const std::uint8_t, ram_size> ram() const noexcept { return ram_; }
  /** ROM, read-only. */
  std::span<const std::uint8_t> rom() const noexcept { return rom_; }
  /** Replaces the ROM image (exactly 256 KiB) and powers the board on again. */
  result<void> load_rom(std::span<const std::uint8_t> image) {
    if (image.size() != rom_size) return errc::rom_address_out_of_range;
    rom_.assign(image.begin(), image.end());
    power_on();
    return {};
  }
  /** Resets RAM to the power-on state and boots from ROM (as after a power cycle). */
  void power_on() {
    ram_.fill(0);
    auto boot = config_word::decode(rom16(hth4_2_2.config.value()));
    if (opt_.period) boot.period = *opt_.period;
    put16(ram::config.value(), boot.encode());
    put24(ram::program_counter.value(), hth4_2_2.main_loop.value());
    put16(ram::pio_direction.value(), 0x03FF);
    for (unsigned k = 0; k < ram::timers; ++k) put16(ram::timer.value() + 2 * k, ram::timer_stopped);
    for (unsigned k = 0; k < ics_slots; ++k) {
      const auto n = ics_number::make(k).value();
      const bool servo = k < 35 && opt_.servos.contains(n);
      const std::uint16_t block = static_cast<std::uint16_t>(ram::user_area.value() + servo_block::size * k);
      put16(ram::ics_allocation.value() + 2 * k, servo || k == 35 ? block : ram::no_allocation);
      if (servo) {
        ram_[block + servo_block::id.offset] = static_cast<std::uint8_t>(k / 2);
        // The trim HTH4 keeps in ROM's servo image (protocol.md §8); erased (0xFFFF): none.
        const std::uint32_t t = hth4_rom::servo_image_of(static_cast<std::uint16_t>(block + 2u)).value();
        const auto trim = static_cast<std::uint16_t>(rom_[t] | (rom_[t + 1] << 8));
        put16(block + servo_block::trim.offset, trim == 0xFFFF ? 0 : trim);
        const bool answers = !opt_.unanswered.contains(n);
        put16(block + servo_block::position.offset, answers ? servo_position::centre_value : 0);
        put16(block + servo_block::target.offset, servo_position::centre_value);
        put16(block + servo_block::interp_end.offset, servo_position::centre_value);
      }
    }
    put16(ram::vector_table.value(), hth4_ram::vector_entries.value());
    battery_raw_ = 442;  // 10.8 V
    stack_size_ = 0;
    params_ = {};
    for (auto& p : params_) p = {127, 127};
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
    ram_[krr::buttons.value()] = b[0];
    ram_[krr::buttons.value() + 1] = b[1];
    for (unsigned i = 0; i < krr::analog_channels; ++i) ram_[krr::analog.value() + i] = analog[i] & 0x7Fu;
  }
  /**
   * Turns ICS @p n by hand to @p position (a free servo's measured position follows; a held or
   * driven one springs back on the next tick). False when the slot has no answering servo.
   */
  bool turn_by_hand(ics_number n, std::uint16_t position) {
    const auto b = block_of(n);
    if (!b || opt_.unanswered.contains(n)) return false;
    put16(*b + servo_block::position.offset, position);
    return true;
  }
  /** The speed (output limit) and stretch of ICS @p n, as last set by 0x12. */
  std::pair<std::uint8_t, std::uint8_t> servo_params_of(ics_number n) const noexcept {
    return {params_[n.value()].speed, params_[n.value()].stretch};
  }
  /** 16-bit word of RAM at @p addr (little-endian). */
  std::uint16_t ram16(std::uint32_t addr) const noexcept {
    return static_cast<std::uint16_t>(ram_[addr] | (ram_[addr + 1] << 8));
  }
  /** The RAM block address of ICS @p n, or nothing when unallocated (0xFFFF, or 0 as on a board without a project). */
  std::optional<std::uint16_t> block_of(ics_number n) const noexcept {
    const std::uint16_t a = allocation(n);
    if (a == ram::no_allocation || a == 0 || std::uint32_t{a} + servo_block::size > ram_size) return std::nullopt;
    return a;
  }

 private:
  struct servo_params_t {
    std::uint8_t speed;
    std::uint8_t stretch;
  };
  enum class origin : std::uint8_t { com, rom };
  struct outcome {
    enum kind_t : std::uint8_t { ack, nack, data, silent } kind = ack;
    std::array<std::uint8_t, max_request_size> bytes{};
    std::size_t size = 0;
  };

  static const std::vector<std::uint8_t>& default_image() {
    static const std::vector<std::uint8_t> image = default_rom();
    return image;
  }
  board_time period() const noexcept { return std::chrono::milliseconds(milliseconds(config().period)); }
  std::uint16_t rom16(std::uint32_t a) const noexcept {
    return static_cast<std::uint16_t>(rom_[a] | (rom_[a + 1] << 8));
  }
  void put16(std::uint32_t a, std::uint16_t v) noexcept {
    ram_[a] = static_cast<std::uint8_t>(v & 0xFFu);
    ram_[a + 1] = static_cast<std::uint8_t>(v >> 8);
  }
  void put24(std::uint32_t a, std::uint32_t v) noexcept {
    put16(a, static_cast<std::uint16_t>(v & 0xFFFFu));
    ram_[a + 2] = static_cast<std::uint8_t>((v >> 16) & 0xFFu);
  }
  std::uint32_t pc() const noexcept { return ram_[2] | (std::uint32_t{ram_[3]} << 8) | (std::uint32_t{ram_[4]} << 16); }
  void set_flag_bits(bool z, std::optional<bool> c) noexcept {
    auto cfg = config();
    cfg.zero_flag = z;
    if (c) cfg.carry_flag = *c;
    put16(ram::config.value(), cfg.encode());
  }
  void set_rom_program(bool on) noexcept {
    auto cfg = config();
    cfg.rom_program = on;
    put16(ram::config.value(), cfg.encode());
  }

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
    const auto o = execute(c, origin::com);
    const std::uint8_t code = std::visit([](const auto& x) { return x.code(); }, c);
    switch (o.kind) {
      case outcome::ack: send(reply::ack(code), out); break;
      case outcome::nack: send(reply::nack(code), out); break;
      case outcome::data: send(reply::data(code, std::span(o.bytes).first(o.size)).value(), out); break;
      case outcome::silent: break;
    }
    return true;
  }

  // --- memory access through RAM, ICS slots and ROM -------------------------------------------
  /** Where @p size bytes of an ICS field live in RAM, or nothing (unallocated / out of RAM). */
  /** ICS @p n's allocation-table entry (0xFFFF: unallocated). */
  std::uint16_t allocation(ics_number n) const noexcept { return ram16(ram::allocation_entry(n).value()); }
  std::optional<std::uint32_t> ics_address(ics_number n, std::uint32_t offset, std::size_t size) const noexcept {
    const std::uint16_t a = allocation(n);
    if (a == ram::no_allocation || a + offset + size > ram_size) return std::nullopt;
    return a + offset;
  }
  bool read_source(const source& s, std::span<std::uint8_t> out) const noexcept {
    const std::size_t n = s.size();
    switch (s.kind()) {
      case src_kind::literal: std::copy_n(s.literal_bytes().begin(), n, out.begin()); return true;
      case src_kind::ram: std::copy_n(ram_.begin() + s.address(), n, out.begin()); return true;
      case src_kind::rom: std::copy_n(rom_.begin() + s.address(), n, out.begin()); return true;
      case src_kind::ics: {
        const auto a = ics_address(s.ics_slot(), s.address(), n);
        if (!a) return false;
        std::copy_n(ram_.begin() + *a, n, out.begin());
        return true;
      }
    }
    return false;
  }
  /** Reads the destination operand (for ALU ops); COM reads as zeros. */
  bool read_destination(const destination& d, std::span<std::uint8_t> out) const noexcept {
    switch (d.kind()) {
      case dst_kind::ram: std::copy_n(ram_.begin() + d.address(), out.size(), out.begin()); return true;
      case dst_kind::rom: std::copy_n(rom_.begin() + d.address(), out.size(), out.begin()); return true;
      case dst_kind::com: std::fill(out.begin(), out.end(), std::uint8_t{0}); return true;
      case dst_kind::ics: {
        const auto a = ics_address(d.ics_slot(), d.address(), out.size());
        if (!a) return false;
        std::copy_n(ram_.begin() + *a, out.size(), out.begin());
        return true;
      }
    }
    return false;
  }
  bool write_destination(const destination& d, std::span<const std::uint8_t> bytes) noexcept {
    switch (d.kind()) {
      case dst_kind::ram: std::copy(bytes.begin(), bytes.end(), ram_.begin() + d.address()); return true;
      case dst_kind::rom: std::copy(bytes.begin(), bytes.end(), rom_.begin() + d.address()); return true;
      case dst_kind::com: return true;
      case dst_kind::ics: {
        const auto a = ics_address(d.ics_slot(), d.address(), bytes.size());
        if (!a) return false;
        std::copy(bytes.begin(), bytes.end(), ram_.begin() + *a);
        return true;
      }
    }
    return false;
  }

  // --- command execution ------------------------------------------------------------------
  outcome execute(const command& c, origin from) {
    outcome o;
    std::visit([&](const auto& x) { o = run(x, from); }, c);
    return o;
  }
  static outcome nack() {
    outcome o;
    o.kind = outcome::nack;
    return o;
  }
  static outcome with_data(std::span<const std::uint8_t> b) {
    outcome o;
    o.kind = outcome::data;
    o.size = b.size();
    std::copy(b.begin(), b.end(), o.bytes.begin());
    return o;
  }

  outcome run(const ping&, origin) { return {}; }
  outcome run(const version&, origin) { return with_data(default_identity); }
  outcome run(const move& m, origin) {
    std::array<std::uint8_t, max_request_size> buf{};
    const auto data = std::span(buf).first(m.src().size());
    if (!read_source(m.src(), data)) return nack();
    if (m.dst().kind() == dst_kind::com) return with_data(data);
    if (!write_destination(m.dst(), data)) return nack();
    return {};
  }
  outcome run(const logic& l, origin) {
    std::array<std::uint8_t, max_request_size> a{}, b{};
    const std::size_t n = l.src().size();
    if (!read_destination(l.dst(), std::span(a).first(n)) || !read_source(l.src(), std::span(b).first(n)))
      return nack();
    for (std::size_t i = 0; i < n; ++i) {
      switch (l.op()) {
        case logic_op::and_: a[i] = static_cast<std::uint8_t>(a[i] & b[i]); break;
        case logic_op::or_: a[i] = static_cast<std::uint8_t>(a[i] | b[i]); break;
        case logic_op::xor_: a[i] = static_cast<std::uint8_t>(a[i] ^ b[i]); break;
      }
    }
    return finish_alu(l.dst(), l.mode(), std::span(a).first(n), std::nullopt);
  }
  outcome run(const bit_not& x, origin) {
    std::array<std::uint8_t, max_request_size> a{};
    const std::size_t n = x.size().value();
    if (!read_destination(x.dst(), std::span(a).first(n))) return nack();
    for (std::size_t i = 0; i < n; ++i) a[i] = static_cast<std::uint8_t>(~a[i]);
    return finish_alu(x.dst(), x.mode(), std::span(a).first(n), std::nullopt);
  }
  outcome run(const shift& x, origin) {
    // The operand is a little-endian integer of `size` bytes; C = the last bit shifted out (model).
    std::array<std::uint8_t, max_request_size> a{};
    const std::size_t n = x.size().value();
    if (!read_destination(x.dst(), std::span(a).first(n))) return nack();
    // The board decodes the count byte with its own encoding (options.shift).
    const auto count = shift::decode(shift::encode(x.count(), x.encoding()), opt_.shift).value().value();
    bool carry = false;
    for (int step = 0; step < (count < 0 ? -count : count); ++step) {
      if (count > 0) {  // left
        carry = (a[n - 1] & 0x80u) != 0;
        for (std::size_t i = n; i-- > 0;) a[i] = static_cast<std::uint8_t>((a[i] << 1) | (i > 0 ? (a[i - 1] >> 7) : 0));
      } else {  // right
        carry = (a[0] & 1u) != 0;
        for (std::size_t i = 0; i < n; ++i)
          a[i] = static_cast<std::uint8_t>((a[i] >> 1) | (i + 1 < n ? ((a[i + 1] & 1u) << 7) : 0));
      }
    }
    return finish_alu(x.dst(), x.mode(), std::span(a).first(n), count != 0 ? std::optional(carry) : std::nullopt);
  }
  outcome run(const arith& x, origin) {
    if (x.dst().kind() == dst_kind::com && !opt_.allow_arith_to_com) return nack();
    std::array<std::uint8_t, 2> a{}, b{};
    const std::size_t n = x.src().size();
    if (!read_destination(x.dst(), std::span(a).first(n)) || !read_source(x.src(), std::span(b).first(n)))
      return nack();
    const std::uint32_t mask = n == 1 ? 0xFFu : 0xFFFFu;
    const std::uint32_t l = a[0] | (std::uint32_t{a[1]} << 8), r = b[0] | (std::uint32_t{b[1]} << 8);
    std::uint32_t v = 0;
    bool carry = false;
    switch (x.op()) {
      case arith_op::add:
        v = l + r;
        carry = v > mask;
        break;
      case arith_op::sub:
        v = l - r;
        carry = l >= r;
        break;  // C = 0 on borrow (DOC-CMD)
      case arith_op::mul:
        v = l * r;
        carry = v > mask;
        break;
      case arith_op::div:
      case arith_op::mod:
        if (r == 0) return nack();  // model: the documents do not say
        v = x.op() == arith_op::div ? l / r : l % r;
        break;
    }
    v &= mask;
    const std::array<std::uint8_t, 2> res = {static_cast<std::uint8_t>(v & 0xFFu), static_cast<std::uint8_t>(v >> 8)};
    return finish_alu(x.dst(), x.mode(), std::span(res).first(n), carry);
  }
  /** Stores (unless flags-only) and sets Z (result all zero) and, when given, C. */
  outcome finish_alu(const destination& d, store_mode mode, std::span<const std::uint8_t> result,
                     std::optional<bool> carry) {
    const bool zero = std::all_of(result.begin(), result.end(), [](std::uint8_t b) { return b == 0; });
    if (mode == store_mode::store && !write_destination(d, result)) return nack();
    set_flag_bits(zero, carry);
    return with_data(result);
  }
  outcome run(const jump& j, origin) {
    const auto cfg = config();
    if (j.cond().holds(cfg.zero_flag, cfg.carry_flag)) put24(ram::program_counter.value(), j.target().value());
    return {};
  }
  outcome run(const call& c, origin from) {
    const auto cfg = config();
    if (!c.cond().holds(cfg.zero_flag, cfg.carry_flag)) return {};
    // The stack pointer counter in RAM is the stack's depth: KONDO's play sequence resets it by
    // writing 0 (protocol.md §8.1 step 2), and the stack then starts over.
    stack_size_ = std::min<std::size_t>(ram_[ram::stack_pointer.value()], stack_depth);
    if (stack_size_ >= stack_depth) return nack();
    // From ROM the PC already points past the CALL; from COM it is where the program stands.
    stack_[stack_size_++] = pc();
    ram_[ram::stack_pointer.value()] = static_cast<std::uint8_t>(stack_size_);
    put24(ram::program_counter.value(), c.target().value());
    (void)from;
    return {};
  }
  outcome run(const ret&, origin) {
    stack_size_ = std::min<std::size_t>(ram_[ram::stack_pointer.value()], stack_depth);  // (see CALL)
    if (stack_size_ == 0) {
      stack_size_ = 0;
      set_rom_program(false);  // RETURN without CALL stops the program (DOC-CMD)
      return {};
    }
    put24(ram::program_counter.value(), stack_[--stack_size_]);
    ram_[ram::stack_pointer.value()] = static_cast<std::uint8_t>(stack_size_);
    return {};
  }
  outcome run(const ics_exchange&, origin) {
    return nack();  // model: the virtual servos do not answer raw ICS (the board NACKs a silent servo)
  }
  /**
   * The update flags of a servo command: set for the commanded servos that have a slot, 0 for the
   * others (DOC-CMD p18; motions.md §5): a flag no interpolation will clear would stop the program
   * for ever, as a motion listing an unallocated ICS did on a board with fewer servos.
   */
  void set_update_flags(servo_mask commanded, update_flags mode) {
    if (mode == update_flags::leave) return;
    servo_mask allocated;
    for (auto n : commanded)
      if (block_of(n) && n.value() != 35) allocated.insert(n);
    for (unsigned i = 0; i < 5; ++i)
      ram_[ram::update_flags.value() + i] = static_cast<std::uint8_t>((allocated.bits() >> (8 * i)) & 0xFFu);
  }
  /** Starts interpolating ICS @p n's output to @p pos over @p speed frames; false if unallocated. */
  bool command_servo(ics_number n, servo_position pos, frames speed) {
    const auto block = block_of(n);
    if (!block || n.value() == 35) return false;
    const std::uint32_t b = *block;
    put16(b + servo_block::interp_end.offset, pos.value());
    ram_[b + servo_block::interp_speed.offset] = speed.value();
    // A free or held servo is where it was measured (moved by hand, perhaps): a move starts there.
    const auto out = servo_position::make(ram16(b + servo_block::target.offset));
    if (!out || out->is_free() || out->is_hold())
      put16(b + servo_block::target.offset, ram16(b + servo_block::position.offset));
    const bool immediate = speed.value() == 0 || pos.is_free() || pos.is_hold();
    if (immediate) {
      put16(b + servo_block::target.offset, pos.value());
      ram_[b + servo_block::interp_steps.offset] = 0;
      put16(b + servo_block::interp_width.offset, 0);
      follow(b);
    } else {
      ram_[b + servo_block::interp_steps.offset] = speed.value();
      const int width = int{pos.value()} - int{ram16(b + servo_block::target.offset)};
      put16(b + servo_block::interp_width.offset, static_cast<std::uint16_t>(width));
    }
    return true;
  }
  /** The measured position follows the output (ideal servo); FREE and HOLD leave it where it is. */
  void follow(std::uint32_t b) {
    if (!opt_.unanswered.empty())
      for (auto n : opt_.unanswered)
        if (block_of(n) == b) return;  // a servo that never answers: +4 stays 0
    const std::uint16_t out = ram16(b + servo_block::target.offset);
    if (out != servo_position::free_value && out != servo_position::hold_value)
      put16(b + servo_block::position.offset, out);
  }
  outcome run(const single_servo& s, origin) {
    if (!command_servo(s.ics(), s.position(), s.speed())) return nack();
    servo_mask m;
    m.insert(s.ics());
    set_update_flags(m, s.flags());
    return {};
  }
  outcome run(const const_servo& c, origin) {
    for (auto e : c.targets()) command_servo(e.ics, e.value, c.speed());  // unallocated: ignored (DOC-CMD)
    set_update_flags(c.targets().mask(), c.flags());
    return {};
  }
  outcome run(const series_servo& c, origin) {
    for (auto e : c.targets()) command_servo(e.ics, e.value.position, e.value.speed);
    set_update_flags(c.targets().mask(), c.flags());
    return {};
  }
  outcome run(const servo_params& p, origin) {
    for (auto e : p.values()) {
      if (!block_of(e.ics)) continue;  // unallocated: skipped (DOC-CMD)
      auto& s = params_[e.ics.value()];
      (p.kind() == param_kind::speed ? s.speed : s.stretch) = e.value.value();
    }
    return {};
  }

  // --- time -------------------------------------------------------------------------------
  void tick() {
    for (unsigned k = 0; k < 35; ++k) {
      const auto block = block_of(ics_number::make(k).value());
      if (!block) continue;
      const std::uint32_t b = *block;
      std::uint8_t steps = ram_[b + servo_block::interp_steps.offset];
      if (steps > 0) {
        const int out = static_cast<std::int16_t>(ram16(b + servo_block::target.offset));
        const int end = static_cast<std::int16_t>(ram16(b + servo_block::interp_end.offset));
        const int next = steps == 1 ? end : out + (end - out) / steps;
        put16(b + servo_block::target.offset, static_cast<std::uint16_t>(next));
        ram_[b + servo_block::interp_steps.offset] = --steps;
        follow(b);
      }
      if (steps == 0) ram_[ram::update_flags.value() + k / 8] &= static_cast<std::uint8_t>(~(1u << (k % 8)));
    }
    update_inputs();
    while (next_timer_ <= now_) {
      for (unsigned k = 0; k < ram::timers; ++k) {
        const std::uint32_t a = ram::timer.value() + 2 * k;
        const std::uint16_t t = ram16(a);
        if ((t & 0x8000u) == 0 && t > 0) put16(a, static_cast<std::uint16_t>(t - 1));
      }
      next_timer_ += std::chrono::milliseconds(100);
    }
    run_program();
  }
  bool flags_pending() const noexcept {
    for (unsigned i = 0; i < 5; ++i)
      if (ram_[ram::update_flags.value() + i] != 0) return true;
    return false;
  }
  void run_program() {
    for (int budget = 256; budget > 0 && config().rom_program && !flags_pending(); --budget) {
      const std::uint32_t at = pc();
      if (at + min_frame_size > rom_size) return program_error();
      const std::size_t size = rom_[at];
      if (size < min_frame_size || size > max_request_size || at + size > rom_size) return program_error();
      const auto r =
          parse_command(std::span(rom_).subspan(at, size), codec_options{opt_.shift, opt_.allow_arith_to_com});
      if (!r.ok()) return program_error();
      ++stats_.rom_steps;
      put24(ram::program_counter.value(), static_cast<std::uint32_t>(at + size));
      if (execute(r.value, origin::rom).kind == outcome::nack) {
        set_rom_program(false);  // an error in ROM clears ROM_F and stops the program (DOC-CMD)
        return;
      }
      if (pc() == at) return;  // a jump to itself (the idle main loop): nothing changes until the next tick
    }
  }
  void program_error() {
    auto cfg = config();
    cfg.rom_program = false;
    cfg.program_error = true;
    put16(ram::config.value(), cfg.encode());
  }
  void update_inputs() {
    std::uniform_int_distribution<int> noise(-1, 1);
    for (unsigned k = 0; k < ram::ad_channels; ++k) {
      const int raw = (k == 0 ? battery_raw_ : ad_raw_[k]) + noise(rng_);
      const int value = std::clamp(raw, 0, 1023) - ram16(ram::ad_reference.value() + 2 * k);
      put16(ram::ad_value.value() + 2 * k, static_cast<std::uint16_t>(value));
    }
    const std::uint16_t dir = ram16(ram::pio_direction.value());
    const std::uint16_t value = ram16(ram::pio_value.value());
    put16(ram::pio_value.value(), static_cast<std::uint16_t>(((value & dir) | (pio_inputs_ & ~dir)) & 0x03FFu));
  }

  options opt_;
  std::array<std::uint8_t, ram_size> ram_{};
  std::vector<std::uint8_t> rom_;
  std::array<std::uint32_t, stack_depth> stack_{};
  std::size_t stack_size_ = 0;
  std::array<servo_params_t, ics_slots> params_{};
  std::array<std::uint16_t, ram::ad_channels> ad_raw_{0, 512, 512, 512, 512, 512, 512, 512, 512, 512, 512};
  std::uint16_t battery_raw_ = 442;
  std::uint16_t pio_inputs_ = 0;
  std::vector<std::uint8_t> pending_;
  board_time now_{0}, next_tick_{0}, next_timer_{0}, last_byte_{0};
  std::mt19937 rng_;
  statistics stats_{};
};

}  // namespace rcb4::board
