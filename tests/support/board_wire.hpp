// Drives a virtual board through frames only, as a client on the wire would: encode a command,
// feed it, parse the reply with the codec. Time advances by the frame's wire time at 1.25 Mbaud.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/board/virtual_board.hpp>

#include <catch2/catch.hpp>

#include <vector>

namespace rcb4::testing {

class board_wire {
 public:
  explicit board_wire(board::options opt = {}) : board_(opt) {}

  /** Sends @p c and returns the reply (a copy of its bytes is kept until the next call). */
  template <class C>
  reply send(const C& c) {
    const auto frame = encode(c);
    return send_raw(frame.bytes(), expected_reply(c));
  }
  /** Sends raw bytes and parses the reply against @p shape; fails the test if none comes. */
  reply send_raw(std::span<const std::uint8_t> bytes, reply_shape shape) {
    last_.clear();
    now_ += std::chrono::microseconds(9 * bytes.size());  // ~8.8 µs per byte at 1.25 Mbaud
    board_.receive(bytes, now_, last_);
    auto r = parse_reply(last_, shape);
    REQUIRE(r.ok());
    REQUIRE(r.consumed == last_.size());
    return r.value();
  }
  /** Sends bytes and returns whatever the board answered (possibly nothing). */
  std::vector<std::uint8_t> send_bytes(std::span<const std::uint8_t> bytes, std::chrono::microseconds gap = {}) {
    last_.clear();
    now_ += gap;
    board_.receive(bytes, now_, last_);
    return last_;
  }
  /** Reads @p n bytes of RAM at @p a with MOV RAM → COM. */
  std::vector<std::uint8_t> read_ram(std::uint16_t a, std::uint8_t n) {
    auto r = send(move::read_ram(ram_address::make(a).value(), transfer_size::make(n).value()).value());
    REQUIRE(r.kind() == reply_kind::data);
    return {r.bytes().begin(), r.bytes().end()};
  }
  /** A 16-bit RAM word read over the wire. */
  std::uint16_t read_word(std::uint16_t a) {
    auto b = read_ram(a, 2);
    return static_cast<std::uint16_t>(b[0] | (b[1] << 8));
  }
  /** Writes @p bytes to RAM at @p a with MOV literal → RAM; returns the reply. */
  reply write_ram(std::uint16_t a, std::vector<std::uint8_t> bytes) {
    return send(move::write_ram(ram_address::make(a).value(), bytes).value());
  }
  /** Lets @p d of board time pass. */
  void wait(std::chrono::microseconds d) {
    now_ += d;
    board_.advance_to(now_);
  }
  board::virtual_board& board() { return board_; }
  std::chrono::microseconds now() const { return now_; }

 private:
  board::virtual_board board_;
  std::vector<std::uint8_t> last_;
  std::chrono::microseconds now_{0};
};

/** Runs the sans-I/O operation @p op on @p w's board; returns the commands it sent. */
template <class Op>
std::vector<command> run(board_wire& w, Op& op) {
  std::vector<command> sent;
  while (auto c = op.next()) {
    sent.push_back(*c);
    op.on_reply(w.send(*c));
  }
  return sent;
}

}  // namespace rcb4::testing
