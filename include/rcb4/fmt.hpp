// rcb4 — {fmt} formatters for commands, replies, errors and frames (opt-in: link rcb4::fmt).
// SPDX-License-Identifier: BSL-1.0
//
//   fmt::print("{}\n", rcb4::command{rcb4::single_servo{0, 7500, 10}});
//       SINGLE ICS 0 → 7500 in 10 frames
//   fmt::print("{}\n", rcb4::hex(frame.bytes()));
//       07 0F 00 0A 4C 1D 89
#pragma once

#include <rcb4/rcb4.hpp>

#include <fmt/format.h>

#include <span>
#include <string_view>

namespace rcb4 {

/** A byte span printed as spaced upper-case hex ("0A 00 20"). */
struct hex_view {
  std::span<const std::uint8_t> bytes;  ///< what to print
};
/** Wraps @p b for printing as hex. */
constexpr hex_view hex(std::span<const std::uint8_t> b) noexcept { return {b}; }

/** The mnemonic of CMD byte @p code ("MOV", "CONST", ...), "?" when unknown. */
constexpr std::string_view command_name(std::uint8_t code) noexcept {
  switch (code) {
    case 0x00: return "MOV";
    case 0x01: return "AND";
    case 0x02: return "OR";
    case 0x03: return "XOR";
    case 0x04: return "NOT";
    case 0x05: return "SHIFT";
    case 0x06: return "ADD";
    case 0x07: return "SUB";
    case 0x08: return "MUL";
    case 0x09: return "DIV";
    case 0x0A: return "MOD";
    case 0x0B: return "JUMP";
    case 0x0C: return "CALL";
    case 0x0D: return "RETURN";
    case 0x0E: return "ICS";
    case 0x0F: return "SINGLE";
    case 0x10: return "CONST";
    case 0x11: return "SERIES";
    case 0x12: return "SPEED/STRETCH";
    case 0xFD: return "VERSION";
    case 0xFE: return "PING";
    default: return "?";
  }
}

namespace fmt_detail {
/**
 * Base of the rcb4 formatters: Derived::write renders the value, then the standard string
 * specs apply (width, fill, alignment: "{:<40}").
 */
template <class Derived, class T>
struct padded : fmt::formatter<std::string_view> {
  template <class Ctx>
  auto format(const T& value, Ctx& ctx) const {
    fmt::memory_buffer buf;
    Derived::write(fmt::appender(buf), value);
    return fmt::formatter<std::string_view>::format(std::string_view(buf.data(), buf.size()), ctx);
  }
};

template <class Out>
Out write_dst(Out out, const destination& d, std::size_t size) {
  switch (d.kind()) {
    case dst_kind::ram: return fmt::format_to(out, "RAM[0x{:04X}+{}]", d.address(), size);
    case dst_kind::ics: return fmt::format_to(out, "ICS {}[+{}, {}]", d.ics_slot().value(), d.address(), size);
    case dst_kind::com: return fmt::format_to(out, "COM");
    case dst_kind::rom: return fmt::format_to(out, "ROM[0x{:06X}+{}]", d.address(), size);
  }
  return out;
}
template <class Out>
Out write_src(Out out, const source& s) {
  switch (s.kind()) {
    case src_kind::ram: return fmt::format_to(out, "RAM[0x{:04X}+{}]", s.address(), s.size());
    case src_kind::ics: return fmt::format_to(out, "ICS {}[+{}, {}]", s.ics_slot().value(), s.address(), s.size());
    case src_kind::literal: return fmt::format_to(out, "literal {{{}}}", hex(s.literal_bytes()));
    case src_kind::rom: return fmt::format_to(out, "ROM[0x{:06X}+{}]", s.address(), s.size());
  }
  return out;
}
template <class Out>
Out write_position(Out out, servo_position p) {
  if (p.is_free()) return fmt::format_to(out, "FREE");
  if (p.is_hold()) return fmt::format_to(out, "HOLD");
  return fmt::format_to(out, "{}", p.value());
}
template <class Out>
Out write_cond(Out out, const condition& c) {
  if (!c.zero && !c.carry) return out;
  out = fmt::format_to(out, " if");
  if (c.zero) out = fmt::format_to(out, " Z={}", *c.zero ? 1 : 0);
  if (c.zero && c.carry) out = fmt::format_to(out, " {}", two_flag_jump == two_flag_rule::either ? "or" : "and");
  if (c.carry) out = fmt::format_to(out, " C={}", *c.carry ? 1 : 0);
  return out;
}
constexpr std::string_view flags_suffix(store_mode m) noexcept {
  return m == store_mode::flags_only ? " (flags only)" : "";
}
constexpr std::string_view update_suffix(update_flags f) noexcept {
  return f == update_flags::leave ? " (leave update flags)" : "";
}
}  // namespace fmt_detail
}  // namespace rcb4

#ifndef RCB4_DOXYGEN  // fmt::formatter specialisations: hex_view, errc, command, reply, config_word
template <>
struct fmt::formatter<rcb4::hex_view> : rcb4::fmt_detail::padded<fmt::formatter<rcb4::hex_view>, rcb4::hex_view> {
  template <class Out>
  static Out write(Out out_, const rcb4::hex_view& h) {
    auto out = out_;
    bool first = true;
    for (auto b : h.bytes) {
      if (!first) *out++ = ' ';
      out = fmt::format_to(out, "{:02X}", b);
      first = false;
    }
    return out;
  }
};

template <>
struct fmt::formatter<rcb4::errc> : rcb4::fmt_detail::padded<fmt::formatter<rcb4::errc>, rcb4::errc> {
  template <class Out>
  static Out write(Out out_, rcb4::errc e) {
    return fmt::format_to(out_, "{}", rcb4::message(e));
  }
};

template <>
struct fmt::formatter<rcb4::command> : rcb4::fmt_detail::padded<fmt::formatter<rcb4::command>, rcb4::command> {
  template <class Out>
  static Out write(Out out_, const rcb4::command& c) {
    using namespace rcb4;
    using namespace rcb4::fmt_detail;
    auto out = out_;
    return std::visit(
        [&](const auto& x) {
          using T = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<T, ping>) {
            return fmt::format_to(out, "PING ({} form)", x.form() == ping_form::ack ? "ACK" : "short");
          } else if constexpr (std::is_same_v<T, version>) {
            return fmt::format_to(out, "VERSION");
          } else if constexpr (std::is_same_v<T, move>) {
            out = fmt::format_to(out, "MOV ");
            out = write_src(out, x.src());
            out = fmt::format_to(out, " → ");
            return write_dst(out, x.dst(), x.src().size());
          } else if constexpr (std::is_same_v<T, logic> || std::is_same_v<T, arith>) {
            out = fmt::format_to(out, "{} ", command_name(x.code()));
            out = write_dst(out, x.dst(), x.src().size());
            out = fmt::format_to(out, " with ");
            out = write_src(out, x.src());
            return fmt::format_to(out, "{}", flags_suffix(x.mode()));
          } else if constexpr (std::is_same_v<T, bit_not>) {
            out = fmt::format_to(out, "NOT ");
            out = write_dst(out, x.dst(), x.size().value());
            return fmt::format_to(out, "{}", flags_suffix(x.mode()));
          } else if constexpr (std::is_same_v<T, shift>) {
            out = fmt::format_to(out, "SHIFT ");
            out = write_dst(out, x.dst(), x.size().value());
            const int n = x.count().value();
            return fmt::format_to(out, " {} {}{}", n >= 0 ? "left" : "right", n >= 0 ? n : -n, flags_suffix(x.mode()));
          } else if constexpr (std::is_same_v<T, jump> || std::is_same_v<T, call>) {
            out = fmt::format_to(out, "{} 0x{:06X}", command_name(x.code()), x.target().value());
            return write_cond(out, x.cond());
          } else if constexpr (std::is_same_v<T, ret>) {
            return fmt::format_to(out, "RETURN");
          } else if constexpr (std::is_same_v<T, ics_exchange>) {
            return fmt::format_to(out, "ICS exchange with ICS {}: {} bytes from RAM 0x{:04X}, answer to 0x{:04X}",
                                  x.ics().value(), x.tx_length(), x.tx().value(), x.rx().value());
          } else if constexpr (std::is_same_v<T, single_servo>) {
            out = fmt::format_to(out, "SINGLE ICS {} → ", x.ics().value());
            out = write_position(out, x.position());
            return fmt::format_to(out, " in {} frames{}", x.speed().value(), update_suffix(x.flags()));
          } else if constexpr (std::is_same_v<T, const_servo>) {
            out = fmt::format_to(out, "CONST {} servo{} in {} frames:", x.targets().size(),
                                 x.targets().size() == 1 ? "" : "s", x.speed().value());
            for (auto e : x.targets()) {
              out = fmt::format_to(out, " {}=", e.ics.value());
              out = write_position(out, e.value);
            }
            return fmt::format_to(out, "{}", update_suffix(x.flags()));
          } else if constexpr (std::is_same_v<T, series_servo>) {
            out = fmt::format_to(out, "SERIES {} servos:", x.targets().size());
            for (auto e : x.targets()) {
              out = fmt::format_to(out, " {}=", e.ics.value());
              out = write_position(out, e.value.position);
              out = fmt::format_to(out, "/{}f", e.value.speed.value());
            }
            return fmt::format_to(out, "{}", update_suffix(x.flags()));
          } else {
            static_assert(std::is_same_v<T, servo_params>);
            out = fmt::format_to(out, "{} {} servos:", x.kind() == param_kind::speed ? "SPEED" : "STRETCH",
                                 x.values().size());
            for (auto e : x.values()) out = fmt::format_to(out, " {}={}", e.ics.value(), e.value.value());
            return out;
          }
        },
        c);
  }
};

template <>
struct fmt::formatter<rcb4::reply> : rcb4::fmt_detail::padded<fmt::formatter<rcb4::reply>, rcb4::reply> {
  template <class Out>
  static Out write(Out out_, const rcb4::reply& r) {
    const auto name = rcb4::command_name(r.command());
    switch (r.kind()) {
      case rcb4::reply_kind::ack: return fmt::format_to(out_, "ACK to {}", name);
      case rcb4::reply_kind::nack: return fmt::format_to(out_, "NACK to {}", name);
      case rcb4::reply_kind::data: break;
    }
    return fmt::format_to(out_, "DATA from {}, {} bytes: {}", name, r.bytes().size(), rcb4::hex(r.bytes()));
  }
};

template <>
struct fmt::formatter<rcb4::config_word>
    : rcb4::fmt_detail::padded<fmt::formatter<rcb4::config_word>, rcb4::config_word> {
  template <class Out>
  static Out write(Out out_, const rcb4::config_word& c) {
    using namespace rcb4;
    return fmt::format_to(out_,
                          "0x{:04X}: ICS {}, ROM program {}, interpolation message {}, vector jump {}, "
                          "period {} ms, COM {} baud, ICS {} baud, Z={} C={}, program error {}, LED {}",
                          c.encode(), c.ics_enabled ? "on" : "off", c.rom_program ? "on" : "off",
                          c.interpolation_message ? "on" : "off", c.vector_jump ? "on" : "off", milliseconds(c.period),
                          bits_per_second(c.com_baud), bits_per_second(c.ics_baud), c.zero_flag ? 1 : 0,
                          c.carry_flag ? 1 : 0, c.program_error ? "yes" : "no", c.led ? "on" : "off");
  }
};
#endif  // RCB4_DOXYGEN
