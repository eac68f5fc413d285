// rcb4 — the Asio driver: a coroutine on the client's strand runs the exchange machine with
// asynchronous I/O, one timer for the deadlines and a cancellation signal to end an I/O early.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/transport/detail/exchange_machine.hpp>
#include <rcb4/transport/detail/handler_memory.hpp>
#include <rcb4/transport/detail/posix_driver.hpp>

#include <boost/asio/as_tuple.hpp>
#include <boost/asio/bind_allocator.hpp>
#include <boost/asio/bind_cancellation_slot.hpp>
#include <boost/asio/buffer.hpp>
#include <boost/asio/cancellation_signal.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/posix/descriptor_base.hpp>
#include <boost/asio/socket_base.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/use_awaitable.hpp>

#include <functional>
#include <memory>
#include <optional>

namespace rcb4::transport::detail {

/** Runs exchanges on the strand of a @p Stream's executor. */
template <class Stream>
class asio_driver {
 public:
  /** The stream's executor. */
  using executor_type = typename Stream::executor_type;
  // The coroutines, the timer and the I/O completions run on the strand's own type (not
  // any_io_executor): with a concrete stream executor (open_serial, connect) nothing is
  // type-erased, so nothing is allocated per resumption.
  /** The strand everything runs on. */
  using strand_type = boost::asio::strand<executor_type>;
  /** A coroutine on the strand. */
  template <class T>
  using task = boost::asio::awaitable<T, strand_type>;
  /** The token that awaits on the strand. */
  static constexpr boost::asio::use_awaitable_t<strand_type> use_task{};
  /** Reopens a lost link. */
  using reopen_function = std::function<void(Stream&, error_code&)>;

  /** A driver on @p strand taking its operations' memory from @p mem. */
  asio_driver(strand_type strand, std::shared_ptr<handler_memory> mem)
      : mem_(std::move(mem)), timer_(strand), backoff_(strand) {}

  /** How the driver's timer completions find it: only while it lives (set once by its owner). */
  void set_self(std::weak_ptr<asio_driver> self) { self_ = std::move(self); }

  /** Runs @p req to its end (on the strand, which owns the line); the reply is in @p m. */
  task<error_code> run(Stream& s, exchange_machine& m, const request& req, const reopen_function& reopen,
                       std::size_t stray) {
    aborted_.reset();
    m.set_marked(marked(s));
    auto a = m.start(req, clock::now(), stray);
    for (;;) {
      // (the I/O is awaited here, not in nested coroutines: each nesting costs a frame and two
      // switches per exchange)
      io_result r;
      switch (a.what) {
        case action::kind::write: {
          arm(a.deadline);
          auto st = write_now(s, a, r);
          if constexpr (has_descriptor) {
            while (st == write_state::wait) {  // no room yet
              auto [e] = co_await s.async_wait(wait_write(), token());
              st = e || timed_out_ ? write_state::done : write_now(s, a, r);
              if (e || timed_out_) r = finish_io(0, e);
            }
          }
          if (st == write_state::fallback) {
            auto [e, n] = co_await s.async_write_some(boost::asio::buffer(a.out.data(), a.out.size()), token());
            r = finish_io(n, e);
          }
          break;
        }
        case action::kind::read: {
          arm(a.deadline);
          auto [e, n] = co_await s.async_read_some(boost::asio::buffer(a.in.data(), a.in.size()), token());
          r = finish_io(n, e);
          break;
        }
        case action::kind::reopen:
          r = co_await reopen_line(s, a.deadline, reopen);
          if (!r.ec) m.set_marked(marked(s));
          break;
        case action::kind::done: co_return a.ec;
      }
      a = aborted_ ? m.cancel(*aborted_) : m.resume(r, clock::now());
    }
  }

  /** Ends the running exchange with @p ec (call on the strand): its I/O or pause is cancelled. */
  void abort(error_code ec) {
    aborted_ = ec;
    cancel_.emit(boost::asio::cancellation_type::terminal);
    backoff_.cancel();
  }
  /** The stream's descriptor may have been replaced or set up anew (call while the worker is idle). */
  void forget() noexcept { checked_fd_ = marks_fd_ = -1; }
  /** Stops the timers (call on the strand, or when nothing else can touch them). */
  void stop() {
    ++generation_;
    waiting_ = false;
    timer_.cancel();
    backoff_.cancel();
  }
  /** The pool's allocator (for the owner's posts). */
  handler_allocator<void> alloc() const noexcept { return handler_allocator<void>(mem_); }

 private:
  using timer_type = boost::asio::basic_waitable_timer<clock, boost::asio::wait_traits<clock>, strand_type>;

  auto token() {
    return boost::asio::bind_cancellation_slot(cancel_.slot(),
                                               boost::asio::as_tuple(boost::asio::bind_allocator(alloc(), use_task)));
  }

  enum class write_state { done, wait, fallback };
  /**
   * A frame is small and the line is idle: written at once with one system call, it needs no
   * completion round trip through the scheduler (the bare Asio loop pays one per write). A
   * socket, also one wrapped as a plain descriptor (which Asio would write() with SIGPIPE when
   * the peer has gone), is written with send(MSG_NOSIGNAL). Streams without a descriptor fall
   * back to Asio's write.
   */
  write_state write_now(Stream& s, const action& a, io_result& r) {
    if constexpr (has_descriptor) {
      const int fd = s.native_handle();
      if (fd < 0 || !prepare(s, fd)) return write_state::fallback;
      const auto w = try_write(fd, fd_socket_, a.out);
      if (!w) return write_state::wait;
      r = finish_io(w->n, w->ec);
      return write_state::done;
    } else {
      (void)s, (void)a, (void)r;
      return write_state::fallback;
    }
  }

  io_result finish_io(std::size_t n, error_code e) {
    guarding_ = false;  // the wait stays, for the next I/O
    return io_result{n, timed_out_ ? error_code{} : e, timed_out_};
  }

  task<io_result> reopen_line(Stream& s, clock::time_point not_before, const reopen_function& reopen) {
    if (clock::now() < not_before) {
      backoff_.expires_at(not_before);
      co_await backoff_.async_wait(boost::asio::as_tuple(boost::asio::bind_allocator(alloc(), use_task)));
    }
    if (aborted_) co_return io_result{};
    error_code ec;
    checked_fd_ = marks_fd_ = -1;  // a new descriptor, maybe with the old number
    reopen(s, ec);
    co_return io_result{0, ec};
  }

  static constexpr auto wait_write() {
    if constexpr (posix_driver<Stream>::is_socket)
      return boost::asio::socket_base::wait_write;
    else
      return boost::asio::posix::descriptor_base::wait_write;
  }
  // Sockets too: after a peer has gone, an Asio write queued behind the hang-up's edge (epoll is
  // edge triggered) would wait for an edge that never comes; a direct send says EPIPE every time.
  static constexpr bool has_descriptor = posix_driver<Stream>::has_descriptor && requires(Stream & s) {
    s.async_wait(wait_write(), boost::asio::detached);
    s.native_non_blocking(true);
  };
  /** Whether the stream's reads are PARMRK-marked (a serial line open_serial set up): once per descriptor. */
  bool marked(Stream& s) {
    if constexpr (posix_driver<Stream>::has_descriptor) {
      const int fd = s.native_handle();
      if (fd != marks_fd_) {
        marks_fd_ = fd;
        fd_marked_ = fd >= 0 && !posix_driver<Stream>::is_socket && !is_socket_fd(fd) && is_marked_tty(fd);
      }
      return fd_marked_;
    } else {
      (void)s;
      return false;
    }
  }

  /** Once per descriptor: non-blocking (so a direct write never blocks), and whether it is a socket. */
  bool prepare(Stream& s, int fd) {
    if (fd != checked_fd_) {
      boost::system::error_code e;
      s.native_non_blocking(true, e);
      if (e) return false;  // Asio's own write then
      checked_fd_ = fd;
      fd_socket_ = is_socket_fd(fd);
    }
    return true;
  }

  // --- deadlines: one wait on the timer watches many I/Os ---------------------------------------
  // A new deadline later than the outstanding wait's (the usual case: exchanges follow one
  // another) leaves the wait alone; when it fires during a later I/O it waits again, for that
  // I/O's deadline. So the timer is set about once per turnaround allowance instead of twice per
  // exchange (each time a timerfd system call, and a cancelled wait's completion on the strand).

  void arm(clock::time_point deadline) {
    timed_out_ = false;
    deadline_ = deadline;
    guarding_ = true;
    if (!waiting_ || wait_until_ > deadline_) watch_until(deadline_);
  }

  /** Waits until @p t, replacing an outstanding wait (whose completion is then stale). */
  void watch_until(clock::time_point t) {
    const auto gen = ++generation_;
    waiting_ = true;
    wait_until_ = t;
    timer_.expires_at(t);
    timer_.async_wait(boost::asio::bind_allocator(alloc(), [w = self_, gen](boost::system::error_code ec) {
      const auto self = w.lock();
      if (!self || gen != self->generation_) return;  // the driver has gone, or a newer wait replaced this one
      self->waiting_ = false;
      if (!ec) self->deadline_reached();
    }));
  }

  /** The wait fired: the running I/O's deadline has passed, or it waits again for it. */
  void deadline_reached() {
    if (!guarding_) return;  // between I/Os: the next arm() starts a new wait
    if (clock::now() < deadline_) {
      watch_until(deadline_);
      return;
    }
    timed_out_ = true;
    cancel_.emit(boost::asio::cancellation_type::terminal);
  }

  std::shared_ptr<handler_memory> mem_;  // first: it outlives the timers' operations
  std::weak_ptr<asio_driver> self_;
  timer_type timer_;    // the I/Os' deadlines
  timer_type backoff_;  // reconnect's pauses
  boost::asio::cancellation_signal cancel_;
  std::optional<error_code> aborted_;  // the running exchange was abandoned (cancellation, closing)
  clock::time_point deadline_{};       // the running I/O's deadline
  bool timed_out_ = false;             // ... has passed, and the I/O was cancelled
  bool guarding_ = false;              // an I/O runs under deadline_
  bool waiting_ = false;               // a wait is outstanding on timer_ ...
  clock::time_point wait_until_{};     // ... until then
  std::uint64_t generation_ = 0;       // that wait's number: completions of replaced waits are stale
  int checked_fd_ = -1;                // the descriptor prepared (non-blocking; fd_socket_ says what it is)
  bool fd_socket_ = false;
  int marks_fd_ = -1;       // the descriptor whose marking fd_marked_ says
  bool fd_marked_ = false;  // its reads are PARMRK-marked
};

}  // namespace rcb4::transport::detail
