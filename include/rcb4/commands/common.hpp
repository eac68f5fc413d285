// rcb4 — what every command type provides, and the options of the disputed behaviours.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/frame.hpp>
#include <rcb4/result.hpp>

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <span>

namespace rcb4 {

/** What the board answers to a command (protocol.md §2.2): an ACK, or data of a known size. */
struct reply_shape {
  std::uint8_t command = 0;    ///< the CMD byte the reply echoes
  bool data = false;           ///< true: a data frame [N+3][CMD][N bytes][SUM]; false: ACK
  std::uint8_t data_size = 0;  ///< N, for data replies
  /** Length of the successful reply frame. A failure is always the 4-byte NACK. */
  constexpr std::size_t frame_size() const noexcept { return data ? data_size + 3u : ack_frame_size; }
  friend constexpr bool operator==(reply_shape, reply_shape) noexcept = default;
};

/**
 * How SHIFT counts go on the wire; the sources disagree (protocol.md §11.5).
 * measured_2015 is what the 2015 library measured on a real board and is the default.
 */
enum class shift_encoding : std::uint8_t {
  measured_2015,  ///< left n → n (1–127), right n → 256 − n (the 2015 report, tested on hardware)
  kondo_manual,   ///< right n → n (1–127), left n → 256 − n (DOC-CMD as printed)
};

/** Board-side parsing choices for the disputed points of protocol.md §11. */
struct codec_options {
  shift_encoding shift = shift_encoding::measured_2015;  ///< §11.5
  bool allow_arith_to_com = false;  ///< §11.6: DOC-CMD allows, the 2015 report says the board refuses
};

/** The S bit of ALU commands (TYPE bit 7). */
enum class store_mode : std::uint8_t {
  store = 0,       ///< write the result to the destination and update Z/C
  flags_only = 1,  ///< only update Z/C (not allowed on MOV)
};

/** The update-flag bit of SINGLE (ICS byte bit 7) and CONST/SERIES (mask byte 4 bit 7), §4.6. */
enum class update_flags : std::uint8_t {
  replace = 0,  ///< set these servos' ROM_UPD flags and clear all others (what every library sends)
  leave = 1,    ///< leave the update flags as they are
};

/**
 * A command type: a constexpr value that knows its CMD byte, its wire size, how to write the
 * bytes between CMD and SUM, what reply it expects, and how to read itself from a checked frame.
 * Copyable and comparable, but not necessarily default-constructible: a command that acts (moves
 * a servo, writes memory, jumps) has no default, so none is ever sent by accident.
 */
template <class T>
concept Command = std::copyable<T> && std::equality_comparable<T> &&
    requires(const T& c, detail::writer& w, std::span<const std::uint8_t> frame, const codec_options& opt) {
  { c.code() } -> std::same_as<std::uint8_t>;
  { c.wire_size() } -> std::same_as<std::size_t>;
  {c.write_body(w)};
  { c.expected_reply() } -> std::same_as<reply_shape>;
  { T::parse(frame, opt) } -> std::same_as<result<T>>;
};

}  // namespace rcb4
