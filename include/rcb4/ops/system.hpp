// rcb4 — identify the board and change its configuration: VERSION, the typed config register,
// switching the COM baud (protocol.md §4.10, §6, §9).
// SPDX-License-Identifier: BSL-1.0
//
// The config register is written read-modify-write: the operation reads the word, lets the
// caller change typed fields, and writes it back, so bits the caller did not mean to touch (the
// Z/C flags, the LED, bits 11-12) keep the board's values.
//
// A COM baud change takes effect after the board has acknowledged the write (§9); the host must
// then reopen at the new rate (rcb4::transport::switch_baud does both). The change lives in RAM
// only: a power cycle restores the rate stored in ROM.
#pragma once

#include <rcb4/ops/operation.hpp>

#include <algorithm>
#include <array>
#include <string>
#include <utility>

namespace rcb4::ops {

/**
 * Reads the 32-byte VERSION field. value() is its text: the printable ASCII up to the first other
 * byte, trailing spaces removed (an RCB-4mini answers 31 characters then 0xC7, §4.10); raw() is
 * the whole field.
 */
class read_version {
 public:
  /** The VERSION command, once. */
  std::optional<command> next() {
    if (done_) return std::nullopt;
    return command{version{}};
  }
  /** Takes its reply. */
  void on_reply(const reply& r) {
    done_ = true;
    if ((error_ = detail::check_reply(r, true, version_field_size)) != errc{}) return;
    const auto b = r.bytes();
    std::copy(b.begin(), b.end(), raw_.begin());
    for (auto c : b) {
      if (c < 0x20 || c > 0x7E) break;
      text_.push_back(static_cast<char>(c));
    }
    while (!text_.empty() && text_.back() == ' ') text_.pop_back();
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return error_; }
  /** The version text, e.g. "CB-4 V1.0      090715". */
  const std::string& value() const noexcept { return text_; }
  /** The 32 bytes as answered. */
  const std::array<std::uint8_t, version_field_size>& raw() const noexcept { return raw_; }

 private:
  bool done_ = false;
  std::array<std::uint8_t, version_field_size> raw_{};
  std::string text_;
  errc error_{};
};

namespace detail {
struct decode_config {
  config_word operator()(const reply& r) const { return config_word::decode(r.u16()); }
};
}  // namespace detail

/** Reads the config register (2 bytes at 0x0000), typed. */
using read_config = detail::single_read<config_word, 0x0000, 2, detail::decode_config>;

/**
 * Read-modify-write of the config register: reads it, calls @p change(config_word&), writes the
 * result. A change of the COM baud is refused (errc::baud_change_not_allowed) unless the
 * operation was made with allow_baud_change (switch_baud does that), because the host would lose
 * the board. value(): the word written.
 */
template <class Change>
class update_config {
 public:
  /** Changes the register with @p change; a @p refused error fails at once, sending nothing. */
  explicit update_config(Change change, bool allow_baud_change = false, errc refused = errc{})
      : change_(std::move(change)), allow_baud_(allow_baud_change), error_(refused) {}
  /** Read, then write. */
  std::optional<command> next() {
    if (error_ != errc{} || step_ > 1) return std::nullopt;
    if (step_ == 0) return command{move::read_ram(ram::config, 2).value()};
    return detail::write_u16(ram::config, written_.encode());
  }
  /** Takes a reply. */
  void on_reply(const reply& r) {
    if ((error_ = detail::check_reply(r, step_ == 0, 2)) != errc{}) return;
    if (step_ == 0) {
      before_ = config_word::decode(r.u16());
      written_ = before_;
      change_(written_);
      if (!allow_baud_ && bits_per_second(written_.com_baud) != bits_per_second(before_.com_baud)) {
        error_ = errc::baud_change_not_allowed;
        return;
      }
    }
    ++step_;
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return error_; }
  /** The word written (or that would have been written). */
  const config_word& value() const noexcept { return written_; }
  /** The word read before the change. */
  const config_word& before() const noexcept { return before_; }

 private:
  Change change_;
  bool allow_baud_;
  errc error_;
  config_word before_{}, written_{};
  unsigned step_ = 0;
};

/** Writes @p word as the config register, keeping the board's Z/C flags; same baud only. */
inline auto write_config(config_word word) {
  return update_config([word](config_word& c) {
    const bool z = c.zero_flag, carry = c.carry_flag;
    c = word;
    c.zero_flag = z;
    c.carry_flag = carry;
  });
}

/**
 * Switches the board's COM rate to @p bps (115200, 625000 or 1250000; anything else fails with
 * errc::unsupported_baud before sending). The write is acknowledged at the old rate; the host
 * must reopen at the new one afterwards. value(): the config word written.
 */
inline auto switch_baud(std::uint32_t bps) {
  const auto code = baud_code_of(bps);
  return update_config([c = code ? *code : baud_code::b115200](config_word& w) { w.com_baud = c; }, true,
                       code ? errc{} : code.error());
}

}  // namespace rcb4::ops
