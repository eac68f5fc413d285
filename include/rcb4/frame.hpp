// rcb4 — framing primitives: sizes, checksum, a fixed-capacity byte buffer, a bounds-checked writer.
// SPDX-License-Identifier: BSL-1.0
//
// Every frame, both directions (protocol.md §2):
//   [SIZE][CMD][payload ...][SUM]      SIZE = whole frame length, SUM = low byte of the sum
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace rcb4 {

inline constexpr std::size_t min_frame_size = 3;                   ///< [SIZE][CMD][SUM]
inline constexpr std::size_t max_request_size = 128;               ///< the board's receive limit (DOC-FW "COM")
inline constexpr std::size_t max_reply_size = 255;                 ///< largest SIZE byte
inline constexpr std::size_t max_reply_data = max_reply_size - 3;  ///< data bytes in a reply
inline constexpr std::size_t ack_frame_size = 4;                   ///< [04][CMD][06|15][SUM]
inline constexpr std::uint8_t ack_code = 0x06;                     ///< ACK status byte
inline constexpr std::uint8_t nack_code = 0x15;                    ///< NACK status byte

/** Low byte of the sum of @p bytes: the SUM of a frame over everything before it (§2.1). */
constexpr std::uint8_t checksum(std::span<const std::uint8_t> bytes) noexcept {
  unsigned sum = 0;
  for (auto b : bytes) sum += b;
  return static_cast<std::uint8_t>(sum & 0xFFu);
}

/** True when @p frame is at least 3 bytes and its last byte is the checksum of the rest. */
constexpr bool checksum_ok(std::span<const std::uint8_t> frame) noexcept {
  return frame.size() >= min_frame_size && checksum(frame.first(frame.size() - 1)) == frame.back();
}

/**
 * Up to Capacity bytes stored inline (no heap), with a size. Used for frames and for data
 * payloads; compares by content.
 */
template <std::size_t Capacity>
class byte_buffer {
 public:
  static constexpr std::size_t capacity = Capacity;  ///< the most bytes it can hold
  /** Empty. */
  constexpr byte_buffer() noexcept = default;
  /** A copy of @p bytes; the caller guarantees bytes.size() <= Capacity (extra bytes are cut). */
  constexpr explicit byte_buffer(std::span<const std::uint8_t> bytes) noexcept
      : size_(std::min(bytes.size(), Capacity)) {
    std::copy_n(bytes.begin(), size_, bytes_.begin());
  }
  /** Appends @p b; returns false (and changes nothing) when full. */
  constexpr bool push_back(std::uint8_t b) noexcept {
    if (size_ == Capacity) return false;
    bytes_[size_++] = b;
    return true;
  }
  /** Resizes to @p n bytes (new bytes are zero); @p n is cut to the capacity. */
  constexpr void resize(std::size_t n) noexcept {
    n = std::min(n, Capacity);
    for (std::size_t i = size_; i < n; ++i) bytes_[i] = 0;
    size_ = n;
  }
  /** Number of bytes held. */
  constexpr std::size_t size() const noexcept { return size_; }
  /** True when no byte is held. */
  constexpr bool empty() const noexcept { return size_ == 0; }
  /** Byte @p i (unchecked, i < size()). */
  constexpr std::uint8_t operator[](std::size_t i) const noexcept { return bytes_[i]; }
  /** Writable byte @p i (unchecked, i < size()). */
  constexpr std::uint8_t& operator[](std::size_t i) noexcept { return bytes_[i]; }
  /** The held bytes. */
  constexpr std::span<const std::uint8_t> bytes() const noexcept { return {bytes_.data(), size_}; }
  /** The held bytes, writable. */
  constexpr std::span<std::uint8_t> bytes() noexcept { return {bytes_.data(), size_}; }
  /** Marks the first @p n bytes of storage() as held, keeping their content (cut to capacity). */
  constexpr void commit(std::size_t n) noexcept { size_ = std::min(n, Capacity); }
  /** The whole storage, for serializing into before commit(). */
  constexpr std::span<std::uint8_t, Capacity> storage() noexcept { return bytes_; }
  /** Iterator to the first byte. */
  constexpr const std::uint8_t* begin() const noexcept { return bytes_.data(); }
  /** Iterator past the last byte. */
  constexpr const std::uint8_t* end() const noexcept { return bytes_.data() + size_; }
  /** Content equality. */
  constexpr bool operator==(const byte_buffer& other) const noexcept {
    return std::equal(begin(), end(), other.begin(), other.end());
  }

 private:
  std::array<std::uint8_t, Capacity> bytes_{};
  std::size_t size_ = 0;
};

/** A request frame: at most 128 bytes. */
using request_frame = byte_buffer<max_request_size>;
/** A reply frame: at most 255 bytes. */
using reply_frame = byte_buffer<max_reply_size>;

namespace detail {

/**
 * Appends bytes to a span. Unchecked: serialize() verifies that the span holds the command's
 * wire_size() before writing, and the tests and fuzzers check that wire_size() is exactly what
 * write_body() produces. (In a constant expression an overrun is a compile error.)
 */
class writer {
 public:
  constexpr explicit writer(std::span<std::uint8_t> out) noexcept : out_(out.data()) {}
  constexpr void u8(std::uint8_t b) noexcept { out_[pos_++] = b; }
  constexpr void u16(std::uint16_t v) noexcept {  // little-endian
    u8(static_cast<std::uint8_t>(v & 0xFFu));
    u8(static_cast<std::uint8_t>(v >> 8));
  }
  constexpr void u24(std::uint32_t v) noexcept {  // little-endian
    u16(static_cast<std::uint16_t>(v & 0xFFFFu));
    u8(static_cast<std::uint8_t>((v >> 16) & 0xFFu));
  }
  constexpr void bytes(std::span<const std::uint8_t> b) noexcept {
    for (auto x : b) u8(x);
  }
  constexpr std::size_t position() const noexcept { return pos_; }

 private:
  std::uint8_t* out_;
  std::size_t pos_ = 0;
};

/** Reads little-endian values from a span the caller has already length-checked. */
class reader {
 public:
  constexpr explicit reader(std::span<const std::uint8_t> in) noexcept : in_(in) {}
  constexpr std::uint8_t u8() noexcept { return in_[pos_++]; }
  constexpr std::uint16_t u16() noexcept {
    const auto lo = u8();
    return static_cast<std::uint16_t>(lo | (u8() << 8));
  }
  constexpr std::uint32_t u24() noexcept {
    const std::uint32_t lo = u16();
    return lo | (std::uint32_t{u8()} << 16);
  }
  constexpr std::span<const std::uint8_t> rest() const noexcept { return in_.subspan(pos_); }
  constexpr std::size_t remaining() const noexcept { return in_.size() - pos_; }

 private:
  std::span<const std::uint8_t> in_;
  std::size_t pos_ = 0;
};

}  // namespace detail
}  // namespace rcb4
