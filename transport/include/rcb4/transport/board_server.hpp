// rcb4 — serves a virtual board on a pseudo-terminal or a TCP port, so any client can talk to it.
// SPDX-License-Identifier: BSL-1.0
//
// One io_context thread owns the board: a reader loop feeds it the bytes of the current
// connection and writes its replies; a tick loop advances its clock every output period so
// motions play while nobody talks. Optional pacing delays each reply by the wire time of the
// request and the reply (11 bits per byte at the board's current COM rate) plus a latency,
// counted from the request's arrival. The pacer never writes before that time; it learns how
// late its timer wakes (timer slack, scheduling) and aims that much earlier, so that replies
// leave on time rather than some tens of µs after it.
#pragma once

#include <rcb4/board/virtual_board.hpp>
#include <rcb4/transport/options.hpp>
#include <rcb4/transport/pty.hpp>
#include <rcb4/transport/serial.hpp>

#include <boost/asio.hpp>

#include <algorithm>
#include <chrono>
#include <functional>
#include <future>
#include <memory>
#include <string>
#include <vector>

namespace rcb4::transport {

/** Part of a reply delivered by itself: @p bytes written after waiting @p delay. */
struct reply_piece {
  std::chrono::microseconds delay{0};  ///< wait before writing this piece
  std::size_t bytes = 0;               ///< how many bytes of the reply
};

/** How the server behaves on the wire. */
struct serve_options {
  bool pace = false;                     ///< deliver replies at the line's byte rate
  std::chrono::microseconds latency{0};  ///< extra delay before each reply (adapter, turnaround)
  /** Fault injection for testing clients: may change, drop (clear) or extend each reply. */
  std::function<void(std::vector<std::uint8_t>& reply)> tamper;
  /**
   * Fault injection for timing: splits each reply into pieces, each written after its delay
   * (a delayed reply is one piece with a long delay). Bytes past the pieces go out at the end.
   */
  std::function<std::vector<reply_piece>(std::size_t reply_size)> pieces;
  /**
   * On a pty: bytes sent at a rate other than the board's COM rate (its config word) are noise
   * to it and get no reply, as on a real line; without it the pty carries any rate.
   */
  bool strict_baud = false;
};

/** A virtual board served on a pty or TCP. Create with serve_pty() or serve_tcp(); run the io_context. */
class board_server : public std::enable_shared_from_this<board_server> {
 public:
  using clock = std::chrono::steady_clock;

  /** Serves @p board on a new pseudo-terminal; where() is its /dev/pts path. */
  static std::shared_ptr<board_server> serve_pty(boost::asio::io_context& io, board::virtual_board& board,
                                                 serve_options opt = {}) {
    auto s = std::shared_ptr<board_server>(new board_server(io, board, opt));
    s->pty_ = std::make_unique<pty_pair>();
    s->where_ = s->pty_->path();
    boost::asio::co_spawn(io, s->serve_pty_loop(), boost::asio::detached);
    boost::asio::co_spawn(io, s->tick_loop(), boost::asio::detached);
    return s;
  }
  /** Serves @p board on TCP @p endpoint (port 0 picks one); where() is "HOST:PORT". One client at a time: another is
   * closed at once. */
  static std::shared_ptr<board_server> serve_tcp(boost::asio::io_context& io, board::virtual_board& board,
                                                 const boost::asio::ip::tcp::endpoint& endpoint,
                                                 serve_options opt = {}) {
    auto s = std::shared_ptr<board_server>(new board_server(io, board, opt));
    s->acceptor_.emplace(io, endpoint);
    const auto local = s->acceptor_->local_endpoint();
    s->where_ = local.address().to_string() + ":" + std::to_string(local.port());
    boost::asio::co_spawn(io, s->accept_loop(), boost::asio::detached);
    boost::asio::co_spawn(io, s->tick_loop(), boost::asio::detached);
    return s;
  }

  /** Where clients connect: the pty path or "HOST:PORT". */
  const std::string& where() const noexcept { return where_; }
  /**
   * Stops @p s and waits until it has, then releases the pointer, so that the server goes away
   * while its io_context still lives. From another thread, the io_context must be running (the
   * stop runs there); on the io_context's own thread it stops at once.
   */
  static void shutdown(std::shared_ptr<board_server>& s) {
    if (!s) return;
    if (s->io_.get_executor().running_in_this_thread()) {
      s->stop();
    } else {
      std::promise<void> stopped;
      boost::asio::post(s->io_, [&] {
        s->stop();
        stopped.set_value();
      });
      stopped.get_future().wait();
    }
    s.reset();
  }

  /** Stops serving (pending operations end; the io_context can then run out). */
  void stop() {
    stopped_ = true;
    boost::system::error_code ignored;
    if (acceptor_) acceptor_->close(ignored);
    if (pty_stream_) pty_stream_->close(ignored);
    if (tcp_stream_) tcp_stream_->close(ignored);
    if (pacer_) pacer_->cancel();
    ticker_.cancel();
  }

 private:
  board_server(boost::asio::io_context& io, board::virtual_board& board, serve_options opt)
      : io_(io), board_(board), opt_(opt), start_(clock::now()), ticker_(io) {}

  board::board_time now() const {
    return std::chrono::duration_cast<board::board_time>(clock::now() - start_) + epoch_;
  }

  boost::asio::awaitable<void> tick_loop() {
    auto self = shared_from_this();
    while (!stopped_) {
      ticker_.expires_after(std::chrono::milliseconds(5));
      boost::system::error_code ec;
      co_await ticker_.async_wait(boost::asio::redirect_error(boost::asio::use_awaitable, ec));
      if (stopped_) break;
      board_.advance_to(now());
    }
  }

  template <class Stream>
  boost::asio::awaitable<void> serve_stream(Stream& stream) {
    std::array<std::uint8_t, 512> buf{};
    std::vector<std::uint8_t> out;
    out.reserve(max_reply_size * 4);
    boost::asio::steady_timer pacer(io_);
    // stop() cancels a reply's delay (a long --latency would otherwise hold the server that long).
    pacer_ = &pacer;
    struct forget {
      board_server& server;
      ~forget() { server.pacer_ = nullptr; }
    } forget_pacer{*this};
    while (!stopped_) {
      boost::system::error_code ec;
      const std::size_t n = co_await stream.async_read_some(
          boost::asio::buffer(buf), boost::asio::redirect_error(boost::asio::use_awaitable, ec));
      if (ec) co_return;
      const auto arrived = clock::now();
      out.clear();
      const std::uint32_t baud = board_.line_baud();  // the rate the request travelled at
      if (opt_.strict_baud && pty_stream_ && !detail::rate_close(detail::line_rate(pty_stream_->native_handle()), baud))
        continue;  // another rate: the board hears noise, not a frame
      board_.receive(std::span(buf).first(n), now(), out);
      if (opt_.tamper) opt_.tamper(out);
      if (out.empty()) continue;
      if (opt_.pace || opt_.latency.count() > 0) {
        // The reply is due when the wire would have carried the request and the reply. The
        // timer wakes this thread late by some tens of µs (timer slack, wake-up); the pacer
        // learns by how much on average and aims that much earlier, so replies leave on time.
        const auto due = arrived + opt_.latency +
                         (opt_.pace ? wire_time(n, baud) + wire_time(out.size(), baud) : std::chrono::nanoseconds{0});
        pacer.expires_at(due - wake_lateness_);
        co_await pacer.async_wait(boost::asio::redirect_error(boost::asio::use_awaitable, ec));
        if (stopped_) co_return;
        while (clock::now() < due) {  // woke early by a few µs: never before the wire allows
        }
        const auto late = clock::now() - (due - wake_lateness_);  // this wake-up's own lateness
        wake_lateness_ += (std::clamp(late, clock::duration{0}, max_lateness) - wake_lateness_) / 8;
      }
      std::size_t sent = 0;
      if (opt_.pieces)
        for (const auto& p : opt_.pieces(out.size())) {
          const std::size_t k = std::min(p.bytes, out.size() - sent);
          pacer.expires_after(p.delay);
          co_await pacer.async_wait(boost::asio::redirect_error(boost::asio::use_awaitable, ec));
          if (stopped_) co_return;
          co_await boost::asio::async_write(stream, boost::asio::buffer(out.data() + sent, k),
                                            boost::asio::redirect_error(boost::asio::use_awaitable, ec));
          if (ec) co_return;
          sent += k;
        }
      co_await boost::asio::async_write(stream, boost::asio::buffer(out.data() + sent, out.size() - sent),
                                        boost::asio::redirect_error(boost::asio::use_awaitable, ec));
      if (ec) co_return;
    }
  }

  boost::asio::awaitable<void> serve_pty_loop() {
    auto self = shared_from_this();
    pty_stream_.emplace(io_, pty_->release_master());
    co_await serve_stream(*pty_stream_);
  }

  boost::asio::awaitable<void> accept_loop() {
    auto self = shared_from_this();
    while (!stopped_) {
      boost::system::error_code ec;
      auto socket = co_await acceptor_->async_accept(boost::asio::redirect_error(boost::asio::use_awaitable, ec));
      if (ec) co_return;
      if (tcp_stream_)
        boost::asio::co_spawn(io_, take_when_free(std::move(socket)), boost::asio::detached);
      else
        start_client(std::move(socket));
    }
  }

  /** Serves @p socket as the one client. */
  void start_client(boost::asio::ip::tcp::socket socket) {
    boost::system::error_code ec;
    socket.set_option(boost::asio::ip::tcp::no_delay(true), ec);
    tcp_stream_.emplace(std::move(socket));
    boost::asio::co_spawn(io_, serve_client(), boost::asio::detached);
  }

  /**
   * One client at a time: a connection that arrives while another is served waits up to 250 ms
   * for it to go (a program that reconnects at once after closing), then is closed, never left
   * unanswered.
   */
  boost::asio::awaitable<void> take_when_free(boost::asio::ip::tcp::socket socket) {
    auto self = shared_from_this();
    boost::asio::steady_timer wait(io_);
    boost::system::error_code ec;
    for (int i = 0; i < 25 && tcp_stream_ && !stopped_; ++i) {
      wait.expires_after(std::chrono::milliseconds(10));
      co_await wait.async_wait(boost::asio::redirect_error(boost::asio::use_awaitable, ec));
    }
    if (tcp_stream_ || stopped_)
      socket.close(ec);
    else
      start_client(std::move(socket));
  }

  /** Serves the current client until it goes. */
  boost::asio::awaitable<void> serve_client() {
    auto self = shared_from_this();
    co_await serve_stream(*tcp_stream_);
    tcp_stream_.reset();
  }

  boost::asio::io_context& io_;
  board::virtual_board& board_;
  serve_options opt_;
  clock::time_point start_;
  board::board_time epoch_{board_.now()};
  boost::asio::steady_timer ticker_;
  std::unique_ptr<pty_pair> pty_;
  std::optional<boost::asio::posix::stream_descriptor> pty_stream_;
  std::optional<boost::asio::ip::tcp::acceptor> acceptor_;
  std::optional<boost::asio::ip::tcp::socket> tcp_stream_;
  std::string where_;
  bool stopped_ = false;
  clock::duration wake_lateness_{0};            // how late the pacer's timer fires, on average
  boost::asio::steady_timer* pacer_ = nullptr;  // the serving stream's reply delay, while one is served
  static constexpr clock::duration max_lateness = std::chrono::milliseconds(1);
};

}  // namespace rcb4::transport
