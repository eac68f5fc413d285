// rcb4 — one request/reply exchange as a sans-I/O state machine (exchange_machine.hpp drives it).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/reply.hpp>

#include <array>
#include <cstddef>
#include <span>

namespace rcb4::link {

/**
 * Write the frame, then read until the reply parses. The machine never asks for more bytes than
 * the reply can still have (the first byte is its length), so it never eats the next reply.
 */
class exchange {
 public:
  /** What the driver must do next. */
  enum class step { write, read, done };

  /** An exchange of @p frame, whose successful reply has @p shape. */
  exchange(std::span<const std::uint8_t> frame, reply_shape shape) noexcept : frame_(frame), shape_(shape) {}

  /** The next thing to do. */
  step next() const noexcept {
    if (written_ < frame_.size()) return step::write;
    if (!finished_) return step::read;
    return step::done;
  }
  /** Bytes still to write. */
  std::span<const std::uint8_t> to_write() const noexcept { return frame_.subspan(written_); }
  /** @p n bytes were written. */
  void wrote(std::size_t n) noexcept { written_ += n; }
  /** Where the next read goes: exactly as many bytes as the reply may still have. */
  std::span<std::uint8_t> read_buffer() noexcept {
    const std::size_t want = got_ == 0 ? shape_.frame_size() : got_ + needed_;
    return std::span(buf_).subspan(got_, want - got_);
  }
  /** @p n bytes arrived in read_buffer(). */
  void received(std::size_t n) noexcept {
    got_ += n;
    result_ = parse_reply(std::span(buf_).first(got_), shape_);
    if (result_.status == parse_status::need_more) {
      needed_ = result_.needed;
      return;
    }
    finished_ = true;
  }
  /** With next() == done: the parse result (complete or error). */
  const parse_result<reply>& result() const noexcept { return result_; }
  /** The reply's bytes received so far. */
  std::span<const std::uint8_t> received_bytes() const noexcept { return std::span(buf_).first(got_); }
  /** The expected reply. */
  reply_shape shape() const noexcept { return shape_; }

 private:
  std::span<const std::uint8_t> frame_;
  reply_shape shape_;
  std::array<std::uint8_t, max_reply_size> buf_{};
  std::size_t written_ = 0, got_ = 0, needed_ = 0;
  bool finished_ = false;
  parse_result<reply> result_{};
};

}  // namespace rcb4::link
