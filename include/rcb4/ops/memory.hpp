// rcb4 — reading and writing RAM, ROM and ICS fields of any length, split into legal frames.
// SPDX-License-Identifier: BSL-1.0
//
// Reads go out as MOV → COM of at most 128 bytes; writes as MOV literal of at most 121 bytes
// (protocol.md §2.3). A read never asks for a single byte when it can avoid it: a 1-byte data
// reply has the same shape as a NACK (§2.2), so a last 1-byte piece is read as 2 bytes that
// overlap the previous piece (or, for a 1-byte request, the next byte of memory).
#pragma once

#include <rcb4/ops/operation.hpp>

#include <vector>

namespace rcb4::ops {

/** Which memory an operation addresses. */
enum class memory : std::uint8_t { ram, rom, ics };

/** Largest MOV → COM read and MOV literal write. */
inline constexpr std::size_t max_read = 128, max_write = max_literal_size;

namespace detail {
inline std::uint32_t memory_end(memory m) noexcept {
  return m == memory::ram ? ram_size : m == memory::rom ? rom_size : 256u;
}
/** errc{} when @p size (> 0) bytes at @p address fit memory @p m, else the memory's range error. */
inline errc check_range(memory m, std::uint32_t address, std::size_t size) noexcept {
  if (size > 0 && address + size <= memory_end(m)) return errc{};
  return m == memory::ram   ? errc::ram_address_out_of_range
         : m == memory::rom ? errc::rom_address_out_of_range
                            : errc::ics_offset_out_of_range;
}
inline result<move> read_piece(memory m, ics_number ics, std::uint32_t at, std::size_t n) {
  auto size = transfer_size::make(n);
  if (!size) return size.error();
  switch (m) {
    case memory::ram: {
      auto a = ram_address::make(at);
      if (!a) return a.error();
      return move::read_ram(*a, *size);
    }
    case memory::rom: {
      auto a = rom_address::make(at);
      if (!a) return a.error();
      return move::read_rom(*a, *size);
    }
    case memory::ics: return move::read_ics(ics, static_cast<std::uint8_t>(at), *size);
  }
  return errc::bad_type_byte;
}
inline result<move> write_piece(memory m, ics_number ics, std::uint32_t at, std::span<const std::uint8_t> b) {
  switch (m) {
    case memory::ram: {
      auto a = ram_address::make(at);
      if (!a) return a.error();
      return move::write_ram(*a, b);
    }
    case memory::rom: {
      auto a = rom_address::make(at);
      if (!a) return a.error();
      return move::write_rom(*a, b);
    }
    case memory::ics:
      if (at > 255) return errc::ics_offset_out_of_range;
      return move::write_ics(ics, static_cast<std::uint8_t>(at), b);
  }
  return errc::bad_type_byte;
}
}  // namespace detail

/** Reads @p size bytes at @p address of RAM, ROM, or (with @p ics) an ICS slot's fields. */
class read_memory {
 public:
  /** The read; errors (range) show in error() before anything is sent. */
  read_memory(memory m, std::uint32_t address, std::size_t size, ics_number ics = {})
      : mem_(m), ics_(ics), start_(address), size_(size) {
    error_ = detail::check_range(m, address, size);
    data_.reserve(size);
  }
  /** The next MOV → COM, or nothing when done or failed. */
  std::optional<command> next() {
    if (error_ != errc{} || data_.size() >= size_) return std::nullopt;
    auto [at, n] = piece();
    auto m = detail::read_piece(mem_, ics_, at, n);
    if (!m) {
      error_ = m.error();
      return std::nullopt;
    }
    return command{*m};
  }
  /** Takes the reply to next()'s command. */
  void on_reply(const reply& r) {
    auto [at, n] = piece();
    if (auto e = detail::check_reply(r, true, n); e != errc{}) {
      error_ = e;
      return;
    }
    // Keep only the bytes not read yet (a widened piece overlaps what we have).
    const std::uint32_t have_until = start_ + static_cast<std::uint32_t>(data_.size());
    for (std::size_t i = 0; i < n; ++i)
      if (at + i >= have_until && data_.size() < size_) data_.push_back(r.bytes()[i]);
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return error_; }
  /** The bytes read. */
  const std::vector<std::uint8_t>& value() const noexcept { return data_; }

 private:
  /** Address and length of the next read, never 1 byte when 2 are possible. */
  std::pair<std::uint32_t, std::size_t> piece() const noexcept {
    const std::uint32_t at = start_ + static_cast<std::uint32_t>(data_.size());
    std::size_t n = std::min(max_read, size_ - data_.size());
    if (n == 1) {
      if (!data_.empty()) return {at - 1, 2};                  // overlap the previous byte
      if (at + 2 <= detail::memory_end(mem_)) return {at, 2};  // read one byte further
      if (at >= 1) return {at - 1, 2};                         // last byte of memory
    }
    return {at, n};
  }
  memory mem_;
  ics_number ics_;
  std::uint32_t start_;
  std::size_t size_;
  std::vector<std::uint8_t> data_;
  errc error_{};
};

/** Writes @p bytes at @p address of RAM, ROM, or (with @p ics) an ICS slot's fields. */
class write_memory {
 public:
  /** The write; the bytes are copied. */
  write_memory(memory m, std::uint32_t address, std::span<const std::uint8_t> bytes, ics_number ics = {})
      : mem_(m), ics_(ics), start_(address), bytes_(bytes.begin(), bytes.end()) {
    error_ = detail::check_range(m, address, bytes.size());
  }
  /** The next MOV literal, or nothing when done or failed. */
  std::optional<command> next() {
    if (error_ != errc{} || done_ >= bytes_.size()) return std::nullopt;
    const std::size_t n = std::min(max_write, bytes_.size() - done_);
    auto m = detail::write_piece(mem_, ics_, start_ + static_cast<std::uint32_t>(done_),
                                 std::span(bytes_).subspan(done_, n));
    if (!m) {
      error_ = m.error();
      return std::nullopt;
    }
    pending_ = n;
    return command{*m};
  }
  /** Takes the ACK. */
  void on_reply(const reply& r) {
    if (auto e = detail::check_reply(r, false); e != errc{}) {
      error_ = e;
      return;
    }
    done_ += pending_;
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return error_; }
  /** Bytes written so far. */
  std::size_t value() const noexcept { return done_; }

 private:
  memory mem_;
  ics_number ics_;
  std::uint32_t start_;
  std::vector<std::uint8_t> bytes_;
  std::size_t done_ = 0, pending_ = 0;
  errc error_{};
};

}  // namespace rcb4::ops
