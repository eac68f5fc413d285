// An in-memory AsyncByteStream wired to a virtual board: writes go to the board, its replies are
// read back. Operation number `fail_at` (reads and writes counted together, from 1) fails with
// `failure`, the way Boost.Beast's test stream does; every other operation works. Pending reads
// honour per-operation cancellation (the client's deadline) and close().
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/board/virtual_board.hpp>

#include <boost/asio/any_completion_handler.hpp>
#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/associated_cancellation_slot.hpp>
#include <boost/asio/associated_executor.hpp>
#include <boost/asio/buffer.hpp>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/error.hpp>
#include <boost/asio/post.hpp>

#include <chrono>
#include <optional>

namespace rcb4::testing {

class fake_stream {
 public:
  using executor_type = boost::asio::any_io_executor;

  fake_stream(executor_type ex, board::virtual_board& b, std::size_t fail_at = 0,
              boost::system::error_code failure = boost::asio::error::connection_reset)
      : ex_(std::move(ex)), board_(&b), fail_at_(fail_at), failure_(failure) {}

  executor_type get_executor() const { return ex_; }
  std::size_t operations() const { return ops_; }
  void close(boost::system::error_code&) {
    if (pending_) finish_read(boost::asio::error::operation_aborted);
  }

  template <class Buffers, class Token>
  auto async_write_some(const Buffers& buffers, Token&& token) {
    return boost::asio::async_initiate<Token, void(boost::system::error_code, std::size_t)>(
        [this](auto handler, boost::asio::const_buffer b) {
          if (++ops_ == fail_at_) return post(std::move(handler), failure_, 0);
          std::vector<std::uint8_t> replies;
          board_->receive({static_cast<const std::uint8_t*>(b.data()), b.size()}, now(), replies);
          rx_.insert(rx_.end(), replies.begin(), replies.end());
          post(std::move(handler), {}, b.size());
          if (pending_ && !rx_.empty()) finish_read({});
        },
        token, boost::asio::const_buffer(*boost::asio::buffer_sequence_begin(buffers)));
  }

  template <class Buffers, class Token>
  auto async_read_some(const Buffers& buffers, Token&& token) {
    return boost::asio::async_initiate<Token, void(boost::system::error_code, std::size_t)>(
        [this](auto handler, boost::asio::mutable_buffer b) {
          if (++ops_ == fail_at_) return post(std::move(handler), failure_, 0);
          if (!rx_.empty()) {
            const std::size_t n = take(b);
            return post(std::move(handler), {}, n);
          }
          // Wrap first: any_completion_handler installs its own forwarding in the caller's slot,
          // so the cancellation hook goes on the wrapper's slot, after wrapping.
          pending_.emplace(pending_read{handler_type(std::move(handler)), b});
          auto slot = pending_->handler.get_cancellation_slot();
          if (slot.is_connected())
            slot.assign([this](boost::asio::cancellation_type) { finish_read(boost::asio::error::operation_aborted); });
        },
        token, boost::asio::mutable_buffer(*boost::asio::buffer_sequence_begin(buffers)));
  }

 private:
  using handler_type = boost::asio::any_completion_handler<void(boost::system::error_code, std::size_t)>;
  struct pending_read {
    handler_type handler;
    boost::asio::mutable_buffer buffer;
  };
  /** Completes @p h later (never inside the initiating call), through its associated executor. */
  template <class H>
  void post(H h, boost::system::error_code ec, std::size_t n) {
    boost::asio::post(ex_, [h = std::move(h), ec, n, fallback = ex_]() mutable {
      auto ex = boost::asio::get_associated_executor(h, fallback);
      boost::asio::dispatch(ex, [h = std::move(h), ec, n]() mutable { std::move(h)(ec, n); });
    });
  }
  std::size_t take(boost::asio::mutable_buffer b) {
    const std::size_t n = std::min(b.size(), rx_.size());
    std::copy_n(rx_.begin(), n, static_cast<std::uint8_t*>(b.data()));
    rx_.erase(rx_.begin(), rx_.begin() + static_cast<std::ptrdiff_t>(n));
    return n;
  }
  void finish_read(boost::system::error_code ec) {
    auto p = std::move(*pending_);
    pending_.reset();
    const std::size_t n = ec ? 0 : take(p.buffer);
    post(std::move(p.handler), ec, n);
  }
  /** Board time since the stream was made (the board starts at time 0). */
  board::board_time now() const {
    return std::chrono::duration_cast<board::board_time>(std::chrono::steady_clock::now() - start_);
  }

  executor_type ex_;
  board::virtual_board* board_;
  std::size_t fail_at_;
  boost::system::error_code failure_;
  std::size_t ops_ = 0;
  std::vector<std::uint8_t> rx_;
  std::optional<pending_read> pending_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace rcb4::testing
