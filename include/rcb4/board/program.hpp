// rcb4 — the virtual board's processor: executes commands from COM and runs the ROM program.
// SPDX-License-Identifier: BSL-1.0
//
// Model (protocol.md §3–§5, motions.md §2): MOV between all kinds, AND/OR/XOR/NOT/SHIFT and
// ADD…MOD with Z/C in the config word and the S (flags-only) bit, JUMP/CALL/RETURN with
// conditions and a 16-deep stack, SINGLE/CONST/SERIES through the servo bank, FREE/HOLD,
// SPEED/STRETCH, VERSION, both pings. NACK where the board NACKs: address out of range,
// unallocated slot (SINGLE, MOV on ICS), stack overflow, division by zero (model). From ROM, a
// NACK clears the ROM program switch (DOC-CMD); a frame that does not parse also sets the
// program-error bit. Each output period the program runs until a servo command leaves update
// flags set, the program comes back to a command it already ran in this period (a JUMP to
// itself, the idle main loop, a wait on a timer: nothing changes before the next period), or
// 256 commands.
#pragma once

#include <rcb4/board/memory.hpp>
#include <rcb4/board/options.hpp>
#include <rcb4/board/servos.hpp>
#include <rcb4/rcb4.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <variant>

namespace rcb4::board {

/**
 * The 32-byte VERSION field. The default is what a Python RCB-4 library checks for on an
 * RCB-4mini (protocol.md §4.10, §11.18): "CB-4 V1.0      090715          " followed by 0xC7.
 */
inline constexpr std::array<std::uint8_t, version_field_size> default_identity = {
    'C', 'B', '-', '4', ' ', 'V', '1', '.', '0', ' ', ' ', ' ', ' ', ' ', ' ', '0',
    '9', '0', '7', '1', '5', ' ', ' ', ' ', ' ', ' ', ' ', ' ', ' ', ' ', ' ', 0xC7};

/** What a command did: the reply the board owes (from COM). */
struct outcome {
  enum kind_t : std::uint8_t { ack, nack, data, silent } kind = ack;  ///< the reply's kind
  std::array<std::uint8_t, max_request_size> bytes{};                 ///< data bytes
  std::size_t size = 0;                                               ///< data size
};

/** Executes commands on a board's memory and servos; owns the CALL stack. */
class processor {
 public:
  static constexpr std::size_t stack_depth = 16;      ///< CALL nesting (DOC-CMD/DOC-FW)
  static constexpr std::size_t program_budget = 256;  ///< most commands run in one output period (model)

  /** A processor decoding with @p opt's SHIFT encoding and arithmetic-to-COM choice. */
  explicit processor(const options& opt = {}) : shift_(opt.shift), arith_to_com_(opt.allow_arith_to_com) {}

  /** Power-on: an empty stack. */
  void reset() noexcept { stack_size_ = 0; }

  /** Executes @p c (from COM: the PC is where the program stands). */
  outcome execute(memory& m, servo_bank& s, const command& c) {
    m_ = &m;
    s_ = &s;
    outcome o;
    std::visit([&](const auto& x) { o = run(x); }, c);
    return o;
  }

  /** What a vector entry does when it fires: CALL (the PC pushed) or JUMP; false on a full stack. */
  bool fire(memory& m, const vector_entry& e) {
    m_ = &m;
    if (e.action == vector_action::jump) {
      m.set_pc(e.target.value());
      return true;
    }
    return push_and_go(e.target.value());
  }

  /** One output period's run of the ROM program (config bit 1, no update flag set). */
  void run_program(memory& m, servo_bank& s, statistics& stats) {
    std::array<std::uint32_t, program_budget> ran;  // the commands run in this period
    std::size_t count = 0;
    while (count < program_budget && m.config().rom_program && !servo_bank::flags_pending(m)) {
      const std::uint32_t at = m.pc();
      ran[count++] = at;
      if (at + min_frame_size > rom_size) return program_error(m);
      const std::size_t size = m.rom[at];
      if (size < min_frame_size || size > max_request_size || at + size > rom_size) return program_error(m);
      const auto r = parse_command(std::span(m.rom).subspan(at, size), codec_options{shift_, arith_to_com_});
      if (!r.ok()) return program_error(m);
      ++stats.rom_steps;
      m.set_pc(static_cast<std::uint32_t>(at + size));
      if (execute(m, s, r.value()).kind == outcome::nack) {
        auto cfg = m.config();
        cfg.rom_program = false;  // an error in ROM clears ROM_F and stops the program (DOC-CMD)
        m.set_config(cfg);
        return;
      }
      if (std::find(ran.begin(), ran.begin() + static_cast<std::ptrdiff_t>(count), m.pc()) !=
          ran.begin() + static_cast<std::ptrdiff_t>(count))
        return;  // round again: nothing changes before the next period
    }
  }

 private:
  static void program_error(memory& m) noexcept {
    auto cfg = m.config();
    cfg.rom_program = false;
    cfg.program_error = true;
    m.set_config(cfg);
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
  void set_flag_bits(bool z, std::optional<bool> c) noexcept {
    auto cfg = m_->config();
    cfg.zero_flag = z;
    if (c) cfg.carry_flag = *c;
    m_->set_config(cfg);
  }

  outcome run(const ping&) { return {}; }
  outcome run(const version&) { return with_data(default_identity); }
  outcome run(const move& x) {
    std::array<std::uint8_t, max_request_size> buf{};
    const auto data = std::span(buf).first(x.src().size());
    if (!m_->read_source(x.src(), data)) return nack();
    if (x.dst().kind() == dst_kind::com) return with_data(data);
    if (!m_->write_destination(x.dst(), data)) return nack();
    return {};
  }
  outcome run(const logic& l) {
    std::array<std::uint8_t, max_request_size> a{}, b{};
    const std::size_t n = l.src().size();
    if (!m_->read_destination(l.dst(), std::span(a).first(n)) || !m_->read_source(l.src(), std::span(b).first(n)))
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
  outcome run(const bit_not& x) {
    std::array<std::uint8_t, max_request_size> a{};
    const std::size_t n = x.size().value();
    if (!m_->read_destination(x.dst(), std::span(a).first(n))) return nack();
    for (std::size_t i = 0; i < n; ++i) a[i] = static_cast<std::uint8_t>(~a[i]);
    return finish_alu(x.dst(), x.mode(), std::span(a).first(n), std::nullopt);
  }
  outcome run(const shift& x) {
    // The operand is a little-endian integer of `size` bytes; C = the last bit shifted out (model).
    std::array<std::uint8_t, max_request_size> a{};
    const std::size_t n = x.size().value();
    if (!m_->read_destination(x.dst(), std::span(a).first(n))) return nack();
    // The board decodes the count byte with its own encoding (options.shift).
    const auto count = shift::decode(shift::encode(x.count(), x.encoding()), shift_).value().value();
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
  outcome run(const arith& x) {
    if (x.dst().kind() == dst_kind::com && !arith_to_com_) return nack();
    std::array<std::uint8_t, 2> a{}, b{};
    const std::size_t n = x.src().size();
    if (!m_->read_destination(x.dst(), std::span(a).first(n)) || !m_->read_source(x.src(), std::span(b).first(n)))
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
    if (mode == store_mode::store && !m_->write_destination(d, result)) return nack();
    set_flag_bits(zero, carry);
    return with_data(result);
  }
  outcome run(const jump& j) {
    const auto cfg = m_->config();
    if (j.cond().holds(cfg.zero_flag, cfg.carry_flag)) m_->set_pc(j.target().value());
    return {};
  }
  outcome run(const call& c) {
    const auto cfg = m_->config();
    if (!c.cond().holds(cfg.zero_flag, cfg.carry_flag)) return {};
    // From ROM the PC already points past the CALL; from COM it is where the program stands.
    return push_and_go(c.target().value()) ? outcome{} : nack();
  }
  bool push_and_go(std::uint32_t target) noexcept {
    // The stack pointer counter in RAM is the stack's depth: KONDO's play sequence resets it by
    // writing 0 (protocol.md §8.1 step 2), and the stack then starts over.
    stack_size_ = std::min<std::size_t>(m_->ram[ram::stack_pointer.value()], stack_depth);
    if (stack_size_ >= stack_depth) return false;
    stack_[stack_size_++] = m_->pc();
    m_->ram[ram::stack_pointer.value()] = static_cast<std::uint8_t>(stack_size_);
    m_->set_pc(target);
    return true;
  }
  outcome run(const ret&) {
    stack_size_ = std::min<std::size_t>(m_->ram[ram::stack_pointer.value()], stack_depth);  // (see CALL)
    if (stack_size_ == 0) {
      auto cfg = m_->config();
      cfg.rom_program = false;  // RETURN without CALL stops the program (DOC-CMD)
      m_->set_config(cfg);
      return {};
    }
    m_->set_pc(stack_[--stack_size_]);
    m_->ram[ram::stack_pointer.value()] = static_cast<std::uint8_t>(stack_size_);
    return {};
  }
  outcome run(const ics_exchange&) {
    return nack();  // model: the virtual servos do not answer raw ICS (the board NACKs a silent servo)
  }
  outcome run(const single_servo& x) {
    if (!s_->command(*m_, x.ics(), x.position(), x.speed())) return nack();
    servo_mask mask;
    mask.insert(x.ics());
    servo_bank::set_update_flags(*m_, mask, x.flags());
    return {};
  }
  outcome run(const const_servo& c) {
    for (auto e : c.targets()) s_->command(*m_, e.ics, e.value, c.speed());  // unallocated: ignored (DOC-CMD)
    servo_bank::set_update_flags(*m_, c.targets().mask(), c.flags());
    return {};
  }
  outcome run(const series_servo& c) {
    for (auto e : c.targets()) s_->command(*m_, e.ics, e.value.position, e.value.speed);
    servo_bank::set_update_flags(*m_, c.targets().mask(), c.flags());
    return {};
  }
  outcome run(const servo_params& p) {
    s_->set_params(*m_, p);
    return {};
  }

  shift_encoding shift_;
  bool arith_to_com_;
  std::array<std::uint32_t, stack_depth> stack_{};
  std::size_t stack_size_ = 0;
  memory* m_ = nullptr;      // the memory of the call in progress
  servo_bank* s_ = nullptr;  // the servos of the call in progress
};

}  // namespace rcb4::board
