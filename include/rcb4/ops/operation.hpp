// rcb4 — operations: what a robot program does, as sans-I/O scripts of commands plus a decoder.
// SPDX-License-Identifier: BSL-1.0
//
// An operation hands out one command at a time and digests each reply; it never touches I/O,
// so the same code runs on rcb4::transport's client, on the virtual board, or in a user's own
// UART loop on a microcontroller:
//
//   ops::read_memory op(ops::memory::ram, 0x0090, 720);
//   while (auto c = op.next()) op.on_reply(exchange(*c));   // your I/O here
//   if (op.error() == errc{}) use(op.value());
#pragma once

#include <rcb4/rcb4.hpp>

#include <concepts>
#include <optional>
#include <vector>

namespace rcb4::ops {

/**
 * An operation: next() gives the command to send (nothing when finished), on_reply() takes its
 * reply, error() says whether it failed (errc{} if not) and value() is the result.
 */
template <class Op>
concept Operation = requires(Op op, const reply& r) {
  { op.next() } -> std::same_as<std::optional<command>>;
  {op.on_reply(r)};
  { op.error() } -> std::same_as<errc>;
  op.value();
};

namespace detail {
/** Checks a reply for the common failures: NACK, or an unexpected kind. */
constexpr errc check_reply(const reply& r, bool want_data, std::size_t size = 0) noexcept {
  if (r.is_nack()) return errc::nack;
  if (want_data && (r.kind() != reply_kind::data || r.bytes().size() != size)) return errc::bad_reply_length;
  if (!want_data && !r.is_ack()) return errc::unexpected_ack;
  return errc{};
}

/** A single read of @p Size bytes at RAM @p Address, decoded into T by @p Decode. */
template <class T, std::uint16_t Address, std::uint8_t Size, class Decode>
class single_read {
 public:
  /** The read, once. */
  std::optional<command> next() {
    if (done_) return std::nullopt;
    return command{move::read_ram(ram_address::make(Address).value(), transfer_size::make(Size).value()).value()};
  }
  /** Takes its reply. */
  void on_reply(const reply& r) {
    done_ = true;
    if ((error_ = check_reply(r, true, Size)) == errc{}) value_ = Decode{}(r);
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return error_; }
  /** The decoded value. */
  const T& value() const noexcept { return value_; }

 private:
  bool done_ = false;
  T value_{};
  errc error_{};
};

/** Commands sent in order, each answered by ACK; value() is how many were acknowledged. */
class ack_sequence {
 public:
  ack_sequence() = default;
  /** Sends @p commands; @p refused (not errc{}) fails at once without sending anything. */
  explicit ack_sequence(std::vector<command> commands, errc refused = errc{})
      : commands_(std::move(commands)), error_(refused) {}
  /** The next command. */
  std::optional<command> next() {
    if (error_ != errc{} || done_ >= commands_.size()) return std::nullopt;
    return commands_[done_];
  }
  /** Takes a reply. */
  void on_reply(const reply& r) {
    if ((error_ = check_reply(r, false)) == errc{}) ++done_;
  }
  /** errc{} or what went wrong. */
  errc error() const noexcept { return error_; }
  /** Commands acknowledged so far. */
  std::size_t value() const noexcept { return done_; }

 protected:
  std::vector<command> commands_;
  std::size_t done_ = 0;
  errc error_{};
};

/** MOV literal → RAM of a little-endian 16-bit value (the literal lives in the command). */
inline command write_u16(ram_address a, std::uint16_t v) {
  return command{move::make(destination::ram(a), source::literal_u16(v)).value()};
}
/** MOV literal → RAM of one byte. */
inline command write_u8(ram_address a, std::uint8_t v) {
  return command{move::make(destination::ram(a), source::literal_u8(v)).value()};
}
/** RAM address @p base + @p offset (the caller keeps it inside RAM). */
inline ram_address ram_at(ram_address base, unsigned offset) {
  return ram_address::make(base.value() + offset).value();
}
}  // namespace detail

}  // namespace rcb4::ops
