// rcb4 — utility commands: ping / ACK check (0xFE), VERSION (0xFD), ICS exchange (0x0E).
// SPDX-License-Identifier: BSL-1.0
//
// Wire layouts (protocol.md §4.5, §4.10, §4.11):
//   PING (ACK check):  04 FE 06 08   (what every library sends)   or   03 FE 01   (DOC-CMD, 2015)
//                      reply 04 FE 06 08
//   VERSION:           03 FD 00      reply [23][FD][32-byte identification][SUM]
//   ICS (raw):         [09][0E][ics][txlen 1-64][txL][txH][rxL][rxH][SUM]   reply ACK
#pragma once

#include <rcb4/commands/common.hpp>
#include <rcb4/operand.hpp>
#include <rcb4/values.hpp>

namespace rcb4 {

/** The two request forms of the ACK check; both get `04 FE 06 08`. */
enum class ping_form : std::uint8_t {
  ack = 0,     ///< 04 FE 06 08: KONDO's libraries, IORY, GMU
  short_ = 1,  ///< 03 FE 01: DOC-CMD's primary form, the 2015 library's "new ping"
};

/** Ping: checks that a board answers. No effect on the board. */
class ping {
 public:
  static constexpr std::uint8_t command_code = 0xFE;  ///< CMD byte
  /** A ping of form @p f. */
  constexpr explicit ping(ping_form f = ping_form::ack) noexcept : form_(f) {}
  /** The request form. */
  constexpr ping_form form() const noexcept { return form_; }
  /** CMD byte. */
  constexpr std::uint8_t code() const noexcept { return command_code; }
  /** 4 or 3. */
  constexpr std::size_t wire_size() const noexcept { return form_ == ping_form::ack ? 4 : 3; }
  /** 06 for the ACK form, nothing for the short form. */
  constexpr void write_body(detail::writer& w) const noexcept {
    if (form_ == ping_form::ack) w.u8(ack_code);
  }
  /** ACK. */
  constexpr reply_shape expected_reply() const noexcept { return {command_code, false, 0}; }
  /** Reads either form from a checked frame. */
  static constexpr result<ping> parse(std::span<const std::uint8_t> f, const codec_options&) noexcept {
    if (f.size() == 3) return ping(ping_form::short_);
    if (f.size() != 4) return errc::bad_frame_size;
    if (f[2] != ack_code) return errc::reserved_bits_set;
    return ping(ping_form::ack);
  }
  friend constexpr bool operator==(ping, ping) noexcept = default;

 private:
  ping_form form_ = ping_form::ack;
};

/** Size of the identification field of the VERSION reply. */
inline constexpr std::uint8_t version_field_size = 32;

/** VERSION: asks for the 32-byte firmware identification (DOC-CMD p26). */
struct version {
  static constexpr std::uint8_t command_code = 0xFD;  ///< CMD byte
  /** CMD byte. */
  constexpr std::uint8_t code() const noexcept { return command_code; }
  /** Always 3. */
  constexpr std::size_t wire_size() const noexcept { return 3; }
  /** No body. */
  constexpr void write_body(detail::writer&) const noexcept {}
  /** Data: 32 bytes (a 35-byte frame). */
  constexpr reply_shape expected_reply() const noexcept { return {command_code, true, version_field_size}; }
  /** Reads VERSION from a checked frame. */
  static constexpr result<version> parse(std::span<const std::uint8_t> f, const codec_options&) noexcept {
    if (f.size() != 3) return errc::bad_frame_size;
    return version{};
  }
  friend constexpr bool operator==(version, version) noexcept = default;
};

/**
 * ICS (0x0E): sends @p tx_length bytes from RAM to ICS slot n's servo and stores its answer in
 * RAM. KONDO's manual says not to use it (仕様上問題があるため、使ってはいけません); it is
 * here for completeness and emulation only.
 */
class ics_exchange {
 public:
  static constexpr std::uint8_t command_code = 0x0E;  ///< CMD byte
  static constexpr std::uint8_t max_tx_length = 64;   ///< DOC-CMD p15
  /** Exchange with ICS @p n: @p tx_length (1–64) bytes from @p tx, answer stored at @p rx. */
  static constexpr result<ics_exchange> make(ics_number n, std::uint8_t tx_length, ram_address tx,
                                             ram_address rx) noexcept {
    if (tx_length < 1 || tx_length > max_tx_length) return errc::ics_length_out_of_range;
    if (tx.value() + std::size_t{tx_length} > ram_size) return errc::ram_address_out_of_range;
    return ics_exchange(n, tx_length, tx, rx);
  }
  /** The slot. */
  constexpr ics_number ics() const noexcept { return ics_; }
  /** Bytes sent. */
  constexpr std::uint8_t tx_length() const noexcept { return tx_length_; }
  /** RAM address of the bytes to send. */
  constexpr ram_address tx() const noexcept { return tx_; }
  /** RAM address for the servo's answer. */
  constexpr ram_address rx() const noexcept { return rx_; }

  /** CMD byte. */
  constexpr std::uint8_t code() const noexcept { return command_code; }
  /** Always 9. */
  constexpr std::size_t wire_size() const noexcept { return 9; }
  /** Writes ICS, length, tx and rx addresses. */
  constexpr void write_body(detail::writer& w) const noexcept {
    w.u8(ics_.value());
    w.u8(tx_length_);
    w.u16(tx_.value());
    w.u16(rx_.value());
  }
  /** ACK. */
  constexpr reply_shape expected_reply() const noexcept { return {command_code, false, 0}; }
  /** Reads ICS 0x0E from a checked frame. */
  static constexpr result<ics_exchange> parse(std::span<const std::uint8_t> f, const codec_options&) noexcept {
    if (f.size() != 9) return errc::bad_frame_size;
    auto n = ics_number::make(f[2]);
    if (!n) return n.error();
    auto tx = ram_address::make(f[4] | (f[5] << 8));
    if (!tx) return tx.error();
    auto rx = ram_address::make(f[6] | (f[7] << 8));
    if (!rx) return rx.error();
    return make(*n, f[3], *tx, *rx);
  }
  friend constexpr bool operator==(const ics_exchange&, const ics_exchange&) noexcept = default;
  /** No default: it talks to a servo, so every field is the caller's. */
  ics_exchange() = delete;

 private:
  constexpr ics_exchange(ics_number n, std::uint8_t len, ram_address tx, ram_address rx) noexcept
      : ics_(n), tx_length_(len), tx_(tx), rx_(rx) {}
  ics_number ics_{};
  std::uint8_t tx_length_ = 1;
  ram_address tx_ = detail::default_ram;
  ram_address rx_ = detail::default_ram;
};

}  // namespace rcb4
