// rcb4 — a client for any byte stream: async with any completion token, sync with deadlines.
// SPDX-License-Identifier: BSL-1.0
//
//   rcb4::transport::io_thread io;                        // or run your own io_context
//   auto c = rcb4::transport::make_client(open_serial(io.context(), "/dev/ttyUSB0", 1250000));
//   auto r = c.execute(rcb4::move::read_ram(rcb4::ram::config, 2).value());   // sync, throws
//   c.async_execute(rcb4::ping{}, [](boost::system::error_code ec, rcb4::transport::response r) { ... });
//   auto r2 = co_await c.async_execute(cmd, boost::asio::use_awaitable);
//
// Requests from any thread queue FIFO on a strand; one exchange is on the line at a time, so the
// bytes of two exchanges never interleave and no caller ever sees "busy". Each exchange has a
// deadline computed from the wire (11 bits per byte at the configured baud) plus a turnaround
// allowance. After a timeout, a bad frame or stray bytes, the next exchange first drains the line
// until it has been quiet for a while. Idempotent reads are retried by policy.
#pragma once

#include <rcb4/rcb4.hpp>
#include <rcb4/transport/concepts.hpp>
#include <rcb4/transport/detail/exchange.hpp>
#include <rcb4/transport/error.hpp>

#include <boost/asio/any_completion_handler.hpp>
#include <boost/asio/as_tuple.hpp>
#include <boost/asio/bind_cancellation_slot.hpp>
#include <boost/asio/cancellation_signal.hpp>
#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/use_awaitable.hpp>
#include <boost/asio/write.hpp>

#include <sys/ioctl.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <mutex>
#include <system_error>
#include <thread>

namespace rcb4::transport {

/** A reply that owns its bytes (what the client hands back). */
struct response {
  reply_kind kind = reply_kind::ack;   ///< ACK, NACK or data
  std::uint8_t command = 0;            ///< the echoed CMD byte
  byte_buffer<max_reply_data> data{};  ///< data bytes (data replies)
  /** A view as a codec reply (valid while this response lives). */
  reply view() const noexcept {
    switch (kind) {
      case reply_kind::ack: return reply::ack(command);
      case reply_kind::nack: return reply::nack(command);
      case reply_kind::data: break;
    }
    return reply::data(command, data.bytes()).value();
  }
  /** Little-endian word at @p offset of the data. */
  std::uint16_t u16(std::size_t offset = 0) const noexcept {
    return static_cast<std::uint16_t>(data[offset] | (data[offset + 1] << 8));
  }
};

/** Direction of a traced frame. */
enum class direction : std::uint8_t { tx, rx };

/** Client behaviour. */
struct client_options {
  std::uint32_t baud = 115200;                ///< line rate used for deadlines (the slowest is the safe default)
  std::chrono::milliseconds turnaround{100};  ///< allowance for adapter latency, the board's reply, a busy host
  std::chrono::milliseconds quiet{5};         ///< silence that ends a drain after an error
  unsigned read_retries = 2;                  ///< extra attempts for idempotent reads (ping, VERSION, MOV → COM)
  bool retry_writes = false;  ///< also retry commands that change the board (only if you know they are safe)
  /** Called with every frame on the line (direction, monotonic time, bytes). */
  std::function<void(direction, std::chrono::steady_clock::time_point, std::span<const std::uint8_t>)> trace;
};

/**
 * How a client reopens a lost link (EOF, EIO, ENODEV: an unplugged adapter, a stopped server).
 * Attempts are spaced by a delay that starts at first_delay and doubles up to max_delay; after
 * give_up_after without success the exchange fails with errc::reconnect_failed, and the next
 * exchange starts trying again.
 */
struct reconnect_policy {
  std::chrono::milliseconds first_delay{50};      ///< wait after the first failed attempt
  std::chrono::milliseconds max_delay{1000};      ///< the longest wait between attempts
  std::chrono::milliseconds give_up_after{5000};  ///< total time one exchange spends reconnecting
};

/** True for errors that mean the link itself is gone (as opposed to a bad or missing reply). */
inline bool is_link_lost(const std::error_code& ec) noexcept {
  if (ec == errc::closed) return true;
  if (ec.category() != std::system_category() && ec.category() != std::generic_category()) return false;
  switch (ec.value()) {
    case EIO:
    case ENODEV:
    case ENXIO:
    case EBADF:
    case EPIPE:
    case ECONNRESET:
    case ECONNABORTED:
    case ENOTCONN:
    case ESHUTDOWN: return true;
    default: return false;
  }
}

/** What the client has done. */
struct client_counters {
  std::atomic<std::uint64_t> exchanges{0};   ///< requests completed (success or not)
  std::atomic<std::uint64_t> retries{0};     ///< extra attempts
  std::atomic<std::uint64_t> timeouts{0};    ///< deadlines missed
  std::atomic<std::uint64_t> errors{0};      ///< exchanges that ended in an error
  std::atomic<std::uint64_t> bytes_out{0};   ///< bytes written
  std::atomic<std::uint64_t> bytes_in{0};    ///< bytes read (drained bytes included)
  std::atomic<std::uint64_t> reconnects{0};  ///< links reopened after a loss
};

/** True for commands that can be repeated without changing the board: ping, VERSION, MOV → COM. */
inline bool is_idempotent(const command& c) noexcept {
  if (std::holds_alternative<ping>(c) || std::holds_alternative<version>(c)) return true;
  if (const auto* m = std::get_if<move>(&c)) return m->dst().kind() == dst_kind::com;
  return false;
}

/** An RCB-4 client over any AsyncByteStream. */
template <AsyncByteStream Stream>
class basic_client {
 public:
  using executor_type = typename Stream::executor_type;  ///< the stream's executor
  /**
   * Completion signature. boost::system::error_code so that use_awaitable and use_future throw
   * on error as everywhere in Asio; it carries rcb4::errc and transport::errc values (compare
   * with `std::error_code(ec) == rcb4::errc::nack`).
   */
  using signature = void(boost::system::error_code, response);

  /** A client that owns @p stream. */
  explicit basic_client(Stream stream, client_options opt = {})
      : stream_(std::move(stream)), opt_(std::move(opt)), strand_(stream_.get_executor()), timer_(strand_) {}
  basic_client(const basic_client&) = delete;
  basic_client& operator=(const basic_client&) = delete;
  /**
   * Closes the stream. If an exchange is still in flight and this is not the executor's thread,
   * waits until the worker has left (it ends quickly: the close cancels its I/O). Requests still
   * queued then fail with errc::cancelled.
   */
  ~basic_client() {
    if (running_here()) return;  // the executor's own thread: nothing can be in flight concurrently
    std::promise<void> idle;
    auto done = idle.get_future();
    boost::asio::dispatch(strand_, [this, &idle] {
      closing_ = true;
      boost::system::error_code ignored;
      stream_.close(ignored);
      timer_.cancel();
      for (auto& p : queue_) complete(std::move(p.handler), errc::cancelled, response{});
      queue_.clear();
      if (busy_)
        idle_ = &idle;
      else
        idle.set_value();
    });
    done.wait();
  }

  /**
   * Sends @p c and completes with its reply. Errors: rcb4::errc::nack when the board refused,
   * other rcb4::errc values for malformed replies, transport::errc::timeout / closed, or Asio's.
   */
  template <class Token = boost::asio::default_completion_token_t<executor_type>>
  auto async_execute(const command& c, Token&& token = {}) {
    return boost::asio::async_initiate<Token, signature>(
        [this](auto handler, request r) {
          boost::asio::dispatch(strand_, [this, r, h = std::move(handler)]() mutable {
            queue_.push_back(pending{r, handler_type(std::move(h))});
            if (!busy_) {
              busy_ = true;
              boost::asio::co_spawn(strand_, run(), boost::asio::detached);
            }
          });
        },
        token, request{encode(c), expected_reply(c), is_idempotent(c)});
  }

  /**
   * Blocking: sends @p c and waits for its reply or its deadline. The client's executor must be
   * run by another thread (see io_thread); from that thread it fails with errc::would_deadlock.
   */
  response execute(const command& c, std::error_code& ec) {
    if (running_here()) {
      ec = errc::would_deadlock;
      return {};
    }
    struct slot {
      std::error_code ec;
      response r;
      bool done = false;
      std::mutex m;
      std::condition_variable cv;
    } s;  // on this stack: no shared state to allocate
    async_execute(c, [&s](boost::system::error_code e, response r) {
      std::lock_guard lock(s.m);  // notify under the lock: the waiter cannot leave (and free s) before unlock
      s.ec = e;
      s.r = r;
      s.done = true;
      s.cv.notify_one();
    });
    std::unique_lock lock(s.m);
    s.cv.wait(lock, [&s] { return s.done; });
    ec = s.ec;
    return s.r;
  }
  /** Blocking; throws std::system_error on any error (a NACK included). */
  response execute(const command& c) {
    std::error_code ec;
    auto r = execute(c, ec);
    if (ec) throw std::system_error(ec, "rcb4");
    return r;
  }

  /**
   * Reopens the link after a loss: @p reopen(stream, ec) replaces the stream (e.g. with
   * open_serial on the same path) or sets ec. Call before the first exchange. The exchange that
   * met the loss fails, unless it is a retriable read, which is retried on the new link.
   */
  void set_reconnect(std::function<void(Stream&, std::error_code&)> reopen, reconnect_policy policy = {}) {
    reopen_ = std::move(reopen);
    policy_ = policy;
  }

  /** The stream (for settings such as the baud rate; do not read or write it directly). */
  Stream& stream() noexcept { return stream_; }
  /** The options; change them only while no exchange runs. */
  client_options& options() noexcept { return opt_; }
  /** What the client has done so far. */
  const client_counters& counters() const noexcept { return counters_; }
  /** The stream's executor (exchanges run on a strand of it). */
  executor_type get_executor() const noexcept { return strand_.get_inner_executor(); }

 private:
  struct request {
    request_frame frame;
    reply_shape shape;
    bool idempotent;
  };
  using handler_type = boost::asio::any_completion_handler<signature>;
  struct pending {
    request req;
    handler_type handler;
  };

  bool running_here() const {
    if constexpr (requires { stream_.get_executor().running_in_this_thread(); })
      return stream_.get_executor().running_in_this_thread();
    else
      return false;
  }

  /** Bytes already waiting on the line (0 when the stream cannot tell). */
  std::size_t bytes_waiting() {
    if constexpr (requires(boost::system::error_code & e) { stream_.available(e); }) {
      boost::system::error_code e;
      return stream_.available(e);
    } else if constexpr (requires {
                           { stream_.native_handle() } -> std::convertible_to<int>;
                         }) {
      int n = 0;  // serial ports and descriptors: ask the driver
      return ::ioctl(stream_.native_handle(), FIONREAD, &n) == 0 && n > 0 ? static_cast<std::size_t>(n) : 0;
    } else {
      return 0;
    }
  }

  std::chrono::steady_clock::duration budget(const request& r) const {
    const auto bytes = r.frame.size() + r.shape.frame_size();
    return std::chrono::nanoseconds(static_cast<std::int64_t>(bytes) * 11 * 1'000'000'000 / opt_.baud) +
           opt_.turnaround;
  }

  void trace(direction d, std::span<const std::uint8_t> b) {
    if (opt_.trace && !b.empty()) opt_.trace(d, std::chrono::steady_clock::now(), b);
  }

  boost::asio::awaitable<void> run() {
    for (;;) {
      pending p = std::move(queue_.front());
      queue_.pop_front();
      response r;
      const std::error_code ec = co_await perform(p.req, r);
      ++counters_.exchanges;
      if (ec) ++counters_.errors;
      const bool more = !queue_.empty() && !closing_;
      // The completion runs on the strand only after this coroutine suspends or returns, so the
      // caller cannot see it before finish_worker(); finish_worker() is the last touch of `this`
      // (a destructor may be waiting for it).
      complete(std::move(p.handler), ec, r);
      if (!more) {
        finish_worker();
        co_return;
      }
    }
  }

  /**
   * Queues @p h's completion on the strand, where it runs only once the worker has suspended or
   * finished, then on the handler's own executor.
   */
  void complete(handler_type h, std::error_code ec, const response& r) {
    boost::asio::post(strand_, [h = std::move(h), ec, r, s = strand_]() mutable {
      auto ex = boost::asio::get_associated_executor(h, s);
      boost::asio::dispatch(ex,
                            [h = std::move(h), ec, r]() mutable { std::move(h)(boost::system::error_code(ec), r); });
    });
  }

  void finish_worker() {
    busy_ = false;
    if (idle_) idle_->set_value();
  }

  /** Starts the exchange's deadline: when it expires, the pending read or write is cancelled. */
  void arm(std::chrono::steady_clock::duration d) {
    timed_out_ = false;
    const auto gen = ++generation_;
    timer_.expires_after(d);
    timer_.async_wait([this, gen](boost::system::error_code ec) {
      if (ec || gen != generation_) return;  // cancelled, or a stale timer of an earlier exchange
      timed_out_ = true;
      cancel_.emit(boost::asio::cancellation_type::terminal);
    });
  }
  void disarm() {
    ++generation_;
    timer_.cancel();
  }
  auto token() {
    return boost::asio::bind_cancellation_slot(cancel_.slot(), boost::asio::as_tuple(boost::asio::use_awaitable));
  }

  /**
   * Brings the line back to a known state after an error. The board answers in order, so a ping
   * sent now is answered after every byte it still owed (a late reply, the rest of a split one):
   * everything up to that ACK is discarded, then the line must stay quiet for opt_.quiet. No ACK
   * within the ping's budget is errc::timeout: the line stays dirty, and the exchange counts it
   * as a timed-out attempt (a write is then not sent at all).
   */
  boost::asio::awaitable<std::error_code> drain() {
    static constexpr std::array<std::uint8_t, 4> ack{0x04, 0xFE, 0x06, 0x08};
    static const auto ping_frame = encode(ping{});
    const request sync{ping_frame, expected_reply(ping{}), true};
    std::array<std::uint8_t, 256> junk{};
    std::array<std::uint8_t, 4> tail{};  // the last 4 bytes seen, newest last
    std::size_t seen = 0;
    unsigned rearmed = 0;
    {
      trace(direction::tx, ping_frame.bytes());
      arm(budget(sync));
      auto [we, wn] = co_await boost::asio::async_write(
          stream_, boost::asio::buffer(ping_frame.bytes().data(), ping_frame.size()), token());
      counters_.bytes_out += wn;
      if (we && !timed_out_) {
        disarm();
        co_return line_error(we);
      }
      bool synced = false;
      while (!timed_out_) {
        auto [e, n] = co_await stream_.async_read_some(boost::asio::buffer(junk), token());
        if (timed_out_) break;
        if (e) {
          disarm();
          co_return line_error(e);
        }
        counters_.bytes_in += n;
        trace(direction::rx, std::span(junk).first(n));
        for (std::size_t i = 0; i < n; ++i) {
          std::rotate(tail.begin(), tail.begin() + 1, tail.end());
          tail.back() = junk[i];
          ++seen;
        }
        if (seen >= 4 && tail == ack) {  // our ACK, unless more bytes follow it
          disarm();
          arm(opt_.quiet);
          synced = true;
        } else if (synced) {
          synced = false;  // more came after an ACK-like tail: keep reading until the real one
          disarm();
          if (++rearmed > 8) break;  // a line that never settles
          arm(budget(sync));
        }
      }
      disarm();
      if (synced) {
        dirty_ = false;
        co_return std::error_code{};
      }
    }
    co_return errc::timeout;
  }

  /** An I/O error as the client reports it: end of file is errc::closed. */
  static std::error_code line_error(const boost::system::error_code& e) {
    return e == boost::asio::error::eof ? std::error_code(errc::closed) : std::error_code(e);
  }

  /** Reopens the link with backoff until policy_.give_up_after. */
  boost::asio::awaitable<std::error_code> reconnect() {
    const auto give_up = std::chrono::steady_clock::now() + policy_.give_up_after;
    auto delay = policy_.first_delay;
    for (;;) {
      if (closing_) co_return errc::cancelled;
      std::error_code e;
      reopen_(stream_, e);
      if (!e) {
        lost_ = false;
        dirty_ = false;
        ++counters_.reconnects;
        co_return std::error_code{};
      }
      const auto now = std::chrono::steady_clock::now();
      if (now >= give_up) co_return errc::reconnect_failed;
      timer_.expires_at(std::min(give_up, now + delay));
      co_await timer_.async_wait(boost::asio::as_tuple(boost::asio::use_awaitable));
      delay = std::min(policy_.max_delay, delay * 2);
    }
  }

  boost::asio::awaitable<std::error_code> perform(const request& req, response& out) {
    const unsigned attempts = 1 + ((req.idempotent || opt_.retry_writes) ? opt_.read_retries : 0);
    std::error_code ec;
    for (unsigned attempt = 0; attempt < attempts; ++attempt) {
      if (attempt > 0) ++counters_.retries;
      if (lost_ && reopen_) {
        ec = co_await reconnect();
        if (ec) co_return ec;
      }
      if (bytes_waiting() > 0) dirty_ = true;  // stray bytes (a late or duplicated reply)
      if (dirty_) {
        ec = co_await drain();
        if (ec == errc::timeout) {
          ++counters_.timeouts;
          continue;
        }
        if (ec) {
          if (is_link_lost(ec)) lost_ = true;
          co_return ec;
        }
      }
      ec.clear();  // this attempt's own outcome
      detail::exchange ex(req.frame.bytes(), req.shape);
      trace(direction::tx, req.frame.bytes());
      arm(budget(req));
      while (ex.next() != detail::exchange::step::done && !ec && !timed_out_) {
        if (ex.next() == detail::exchange::step::write) {
          const auto w = ex.to_write();
          auto [e, n] = co_await boost::asio::async_write(stream_, boost::asio::buffer(w.data(), w.size()), token());
          counters_.bytes_out += n;
          ex.wrote(n);
          if (e && !timed_out_) ec = line_error(e);
        } else {
          const auto buf = ex.read_buffer();
          auto [e, n] = co_await stream_.async_read_some(boost::asio::buffer(buf.data(), buf.size()), token());
          counters_.bytes_in += n;
          trace(direction::rx, buf.first(n));
          if (n > 0) ex.received(n);
          if (e && !timed_out_) ec = line_error(e);
        }
      }
      disarm();
      if (ec) {
        dirty_ = true;
        if (is_link_lost(ec)) {
          lost_ = true;
          if (reopen_ && !closing_) continue;  // a retriable read tries again on a new link
        }
        co_return ec;  // the line itself failed
      }
      if (timed_out_) {
        ++counters_.timeouts;
        dirty_ = true;
        ec = errc::timeout;
        continue;
      }
      const auto& r = ex.result();
      if (r.status == parse_status::error) {
        dirty_ = true;  // stray or corrupted bytes: resync before the next exchange
        ec = r.error;
        continue;
      }
      out.kind = r.value.kind();
      out.command = r.value.command();
      out.data = byte_buffer<max_reply_data>(r.value.bytes());
      co_return out.kind == reply_kind::nack ? std::error_code(rcb4::errc::nack) : std::error_code{};
    }
    co_return ec;
  }

  Stream stream_;
  client_options opt_;
  boost::asio::strand<executor_type> strand_;
  boost::asio::steady_timer timer_;
  std::deque<pending> queue_;
  bool busy_ = false;
  bool dirty_ = false;
  bool closing_ = false;
  bool timed_out_ = false;
  bool lost_ = false;
  std::function<void(Stream&, std::error_code&)> reopen_;
  reconnect_policy policy_;
  std::uint64_t generation_ = 0;
  boost::asio::cancellation_signal cancel_;
  std::promise<void>* idle_ = nullptr;
  client_counters counters_;
};

/** A client for @p stream, deducing the stream type. */
template <AsyncByteStream Stream>
basic_client<Stream> make_client(Stream stream, client_options opt = {}) {
  return basic_client<Stream>(std::move(stream), std::move(opt));
}

/** An io_context with its own thread, for the blocking API. Joins on destruction. */
class io_thread {
 public:
  /** Starts the thread. */
  io_thread() : work_(io_.get_executor()), thread_([this] { io_.run(); }) {}
  io_thread(const io_thread&) = delete;
  io_thread& operator=(const io_thread&) = delete;
  /** Stops the context and joins the thread. */
  ~io_thread() {
    work_.reset();
    io_.stop();
    thread_.join();
  }
  /** The context the thread runs. */
  boost::asio::io_context& context() noexcept { return io_; }

 private:
  boost::asio::io_context io_;
  boost::asio::executor_work_guard<boost::asio::io_context::executor_type> work_;
  std::thread thread_;
};

}  // namespace rcb4::transport
