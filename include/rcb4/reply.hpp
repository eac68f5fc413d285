// rcb4 — replies: ACK, NACK and data frames, parsed on the host and built on the board.
// SPDX-License-Identifier: BSL-1.0
//
// Wire layouts (protocol.md §2.2):
//   ACK:  [04][CMD][06][SUM]          e.g. 04 FE 06 08
//   NACK: [04][CMD][15][SUM]          e.g. 04 FE 15 17
//   data: [N+3][CMD][N bytes][SUM]    N ≤ 252; e.g. a 126-byte MOV read answers with 129 bytes
// Byte 0 is the whole length (DOC-CMD prints 04h; every implementation uses the length, §11.1).
// A command that fails answers with the 4-byte NACK even where data was due.
#pragma once

#include <rcb4/commands/common.hpp>
#include <rcb4/parse_result.hpp>

#include <algorithm>
#include <span>

namespace rcb4 {

/** What kind of reply frame. */
enum class reply_kind : std::uint8_t { ack, nack, data };

/** A reply frame's content. A NACK is a value here; the transport decides if it is an error. */
class reply {
 public:
  /** ACK to command @p cmd. */
  static constexpr reply ack(std::uint8_t cmd) noexcept { return reply(reply_kind::ack, cmd); }
  /** NACK to command @p cmd. */
  static constexpr reply nack(std::uint8_t cmd) noexcept { return reply(reply_kind::nack, cmd); }
  /**
   * Data reply to @p cmd carrying @p bytes (1–252). The bytes are referenced, not copied: a
   * parsed reply points into the buffer it was parsed from (zero-copy, like std::span).
   */
  static constexpr result<reply> data(std::uint8_t cmd, std::span<const std::uint8_t> bytes) noexcept {
    if (bytes.empty() || bytes.size() > max_reply_data) return errc::frame_too_long;
    reply r(reply_kind::data, cmd);
    r.data_ = bytes;
    return r;
  }
  /** No default: a reply is an ACK, a NACK or data, always made by name or by a parser. */
  reply() = delete;

  /** ACK, NACK or data. */
  constexpr reply_kind kind() const noexcept { return kind_; }
  /** The CMD byte echoed. */
  constexpr std::uint8_t command() const noexcept { return cmd_; }
  /** The data bytes (empty for ACK/NACK). */
  constexpr std::span<const std::uint8_t> bytes() const noexcept { return data_; }
  /** True for ACK. */
  constexpr bool is_ack() const noexcept { return kind_ == reply_kind::ack; }
  /** True for NACK. */
  constexpr bool is_nack() const noexcept { return kind_ == reply_kind::nack; }
  /** Frame length: 4 for ACK/NACK, N + 3 for data. */
  constexpr std::size_t wire_size() const noexcept {
    return kind_ == reply_kind::data ? data_.size() + 3 : ack_frame_size;
  }
  /** A little-endian 16-bit word of the data at byte @p offset (offset + 1 < size). */
  constexpr std::uint16_t u16(std::size_t offset = 0) const noexcept {
    return static_cast<std::uint16_t>(data_[offset] | (data_[offset + 1] << 8));
  }
  /** Same kind and command; data compares by content. */
  friend constexpr bool operator==(const reply& a, const reply& b) noexcept {
    return a.kind_ == b.kind_ && a.cmd_ == b.cmd_ &&
           std::equal(a.data_.begin(), a.data_.end(), b.data_.begin(), b.data_.end());
  }

 private:
  constexpr reply(reply_kind k, std::uint8_t cmd) noexcept : kind_(k), cmd_(cmd) {}
  reply_kind kind_ = reply_kind::ack;
  std::uint8_t cmd_ = 0xFE;
  std::span<const std::uint8_t> data_{};
};

/** Board side: writes @p r into @p out; returns the length or errc::buffer_too_small. */
constexpr result<std::size_t> serialize(const reply& r, std::span<std::uint8_t> out) noexcept {
  const std::size_t n = r.wire_size();
  if (out.size() < n) return errc::buffer_too_small;
  detail::writer w(out);
  w.u8(static_cast<std::uint8_t>(n));
  w.u8(r.command());
  if (r.kind() == reply_kind::data)
    w.bytes(r.bytes());
  else
    w.u8(r.kind() == reply_kind::ack ? ack_code : nack_code);
  out[n - 1] = checksum(out.first(n - 1));
  return n;
}

/** Board side: the frame of @p r in a 255-byte inline buffer. */
constexpr reply_frame encode(const reply& r) noexcept {
  reply_frame f;
  f.commit(serialize(r, f.storage()).value());  // every reply fits 255 bytes
  return f;
}

namespace detail {
/** Shared tail of the reply parsers: length known, frame present. */
constexpr parse_result<reply> finish_reply(std::span<const std::uint8_t> frame, bool status_frame,
                                           bool ack_allowed) noexcept {
  parse_result<reply> r;
  r.command = frame[1];
  r.consumed = frame.size();
  r.status = parse_status::error;
  if (!checksum_ok(frame)) {
    r.error = errc::bad_checksum;
    return r;
  }
  if (status_frame) {
    if (frame[2] == nack_code)
      r.complete(reply::nack(frame[1]));
    else if (frame[2] == ack_code && ack_allowed)
      r.complete(reply::ack(frame[1]));
    else
      r.error = frame[2] == ack_code ? errc::unexpected_ack : errc::bad_ack_code;
    return r;
  } else {
    // A data frame carries 1-252 bytes (protocol.md §2.2): a 3-byte frame carries none and is
    // refused here, never trapped on (a parser on a serial line must not trap on any input).
    const auto d = reply::data(frame[1], frame.subspan(2, frame.size() - 3));
    if (!d) {
      r.error = errc::frame_too_short;
      return r;
    }
    r.complete(d.value());
  }
  return r;
}
}  // namespace detail

/**
 * Host side: parses the reply to a command whose success answer is @p expected, from the start
 * of @p in. Checks the length byte (the expected length, or 4 for NACK), the CMD echo and the
 * checksum. need_more tells how many bytes to read next, so a reader never over-reads.
 *
 * A 1-byte data reply ([04][CMD][d][SUM]) has the shape of a NACK; it parses as data because
 * that is what was asked for (a data byte 0x15 and a NACK are indistinguishable on the wire).
 * The operations layer avoids 1-byte reads for that reason.
 */
constexpr parse_result<reply> parse_reply(std::span<const std::uint8_t> in, reply_shape expected) noexcept {
  parse_result<reply> r;
  // A shape no board can answer (data of 0 bytes, or more than 252): refused, whatever came in.
  if (expected.data && (expected.data_size == 0 || expected.data_size > max_reply_data)) {
    r.status = parse_status::error;
    r.error = errc::bad_reply_length;
    r.consumed = in.size();
    return r;
  }
  const std::size_t want = expected.frame_size();
  if (in.empty()) {
    r.needed = ack_frame_size;  // every reply is at least 4 bytes
    return r;
  }
  const std::size_t size = in[0];
  if (size != want && size != ack_frame_size) {
    r.status = parse_status::error;
    r.error = errc::bad_reply_length;
    r.consumed = 1;
    return r;
  }
  if (in.size() >= 2 && in[1] != expected.command) {
    r.status = parse_status::error;
    r.error = errc::echo_mismatch;
    r.command = in[1];
    r.consumed = std::min(in.size(), size);
    return r;
  }
  if (in.size() < size) {
    r.needed = size - in.size();
    if (in.size() >= 2) r.command = in[1];
    return r;
  }
  const bool status_frame = size == ack_frame_size && !(expected.data && expected.data_size == 1);
  return detail::finish_reply(in.first(size), status_frame, !expected.data);
}

/**
 * Parses a reply frame without knowing the command (for decoding captures). A 4-byte frame
 * whose third byte is 06 or 15 is taken as ACK/NACK, anything else as data.
 */
constexpr parse_result<reply> parse_reply_frame(std::span<const std::uint8_t> in) noexcept {
  parse_result<reply> r;
  if (in.empty()) {
    r.needed = ack_frame_size;
    return r;
  }
  const std::size_t size = in[0];
  if (size < ack_frame_size) {
    r.status = parse_status::error;
    r.error = errc::frame_too_short;
    r.consumed = 1;
    return r;
  }
  if (in.size() < size) {
    r.needed = size - in.size();
    if (in.size() >= 2) r.command = in[1];
    return r;
  }
  const bool status_frame = size == ack_frame_size && (in[2] == ack_code || in[2] == nack_code);
  return detail::finish_reply(in.first(size), status_frame, true);
}

}  // namespace rcb4
