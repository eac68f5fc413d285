// rcb4 — a client for any byte stream: async with any completion token, sync with deadlines.
// SPDX-License-Identifier: BSL-1.0
//
//   rcb4::transport::io_thread io;                        // or run your own io_context
//   auto c = rcb4::transport::make_client(open_serial(io.context(), "/dev/ttyUSB0", 1250000));
//   auto r = c.execute(rcb4::move::read_ram(rcb4::ram::config, 2).value());   // sync, throws
//   c.async_execute(rcb4::ping{}, [](boost::system::error_code ec, rcb4::transport::response r) { ... });
//   auto r2 = co_await c.async_execute(cmd, boost::asio::use_awaitable);
//
// Requests from any thread queue FIFO; one exchange is on the line at a time, so the bytes of two
// exchanges never interleave and no caller ever sees "busy". A worker coroutine on a strand of
// the stream's executor works through the queue; a blocking call that finds the line idle does
// its exchange on its own thread instead (no hand-off; client_options::direct_io). Both drive the
// same sans-I/O exchange (detail/exchange.hpp). Each exchange has a deadline computed from the
// wire (11 bits per byte at the configured baud) plus a turnaround allowance. After a timeout, a
// bad frame or stray bytes, the next exchange first resynchronises: it sends a ping and discards
// everything up to its ACK. Idempotent reads are retried by policy; a lost link can be reopened.
#pragma once

#include <rcb4/rcb4.hpp>
#include <rcb4/transport/concepts.hpp>
#include <rcb4/transport/detail/exchange.hpp>
#include <rcb4/transport/detail/fifo.hpp>
#include <rcb4/transport/detail/handler_memory.hpp>
#include <rcb4/transport/error.hpp>

#include <boost/asio/any_completion_handler.hpp>
#include <boost/asio/as_tuple.hpp>
#include <boost/asio/bind_allocator.hpp>
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

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <future>
#include <mutex>
#include <optional>
#include <system_error>
#include <thread>
#include <variant>

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
  /**
   * Blocking calls on an idle line do their I/O on the calling thread (streams with a
   * descriptor); false sends every exchange through the executor's thread.
   */
  bool direct_io = true;
  /**
   * With direct_io: busy-poll for a reply within this window either side of its expected
   * arrival (the wire time of request and reply at `baud`) instead of sleeping until it comes.
   * It saves the thread's wake-up latency (tens of µs on a busy or virtual machine) at the cost
   * of a busy core for up to twice this long per exchange. 0 (the default) always sleeps.
   */
  std::chrono::microseconds busy_poll{0};
  /** Called with every frame on the line (direction, monotonic time, bytes), on the thread doing the I/O. */
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

namespace detail {
/** A socket's protocol (to assign a released descriptor back), or nothing for other streams. */
template <class Stream>
struct protocol_of {
  using type = std::monostate;
};
template <class Stream>
requires requires { typename Stream::protocol_type; }
struct protocol_of<Stream> {
  using type = std::optional<typename Stream::protocol_type>;
};
}  // namespace detail

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
      : stream_(std::move(stream)),
        opt_(std::move(opt)),
        strand_(stream_.get_executor()),
        timer_(strand_),
        backoff_(strand_) {}
  basic_client(const basic_client&) = delete;
  basic_client& operator=(const basic_client&) = delete;
  /**
   * Closes the stream. If an exchange is still in flight and this is not the executor's thread,
   * waits until the worker has left (it ends quickly: the close cancels its I/O). Requests still
   * queued then fail with errc::cancelled. No blocking execute() may be running in another thread.
   */
  ~basic_client() {
    if (running_here()) {  // the executor's own thread: nothing can be in flight concurrently
      watch_->owner = nullptr;
      let_go_of_line();
      return;
    }
    std::promise<void> idle;
    auto done = idle.get_future();
    boost::asio::dispatch(strand_, [this, &idle] {
      bool idle_now = false;
      {
        std::lock_guard lock(m_);
        closing_ = true;
        let_go_of_line();  // (the worker's I/O now ends at once: no deadline is needed any more)
        watch_->owner = nullptr;
        timer_.cancel();
        backoff_.cancel();
        while (!queue_.empty()) complete(queue_.pop_front().handler, errc::cancelled, response{});
        if (busy_)
          idle_ = &idle;
        else
          idle_now = true;
      }
      if (idle_now) idle.set_value();  // after unlocking: the waiting destructor then frees m_
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
        [this](auto handler, const request& r) {
          enqueue(pending{r, erase(std::move(handler)), 0});
        },
        token, request{encode(c), expected_reply(c), is_idempotent(c)});
  }

  /**
   * Blocking: sends @p c and waits for its reply or its deadline. When the line is idle and the
   * stream has a descriptor (serial port, pty, socket), the exchange runs on the calling thread
   * (client_options::direct_io), with no hand-off to the executor; otherwise, and for any retry
   * after an error, it queues behind the others and the executor's thread runs it. Either way the
   * executor must be run by another thread (see io_thread): from that thread this fails with
   * errc::would_deadlock.
   */
  response execute(const command& c, std::error_code& ec) {
    if (running_here()) {
      ec = errc::would_deadlock;
      return {};
    }
    const request req{encode(c), expected_reply(c), is_idempotent(c)};
    if constexpr (has_descriptor) {
      if (opt_.direct_io && claim_idle_line()) {
        park();
        if (bytes_waiting() > 0) {  // stray bytes (a late or duplicated reply): the worker resyncs first
          dirty_ = true;
          return wait_for(req, 0, true, ec);
        }
        response out;
        std::error_code e;
        detail::exchange ex(req.frame.bytes(), req.shape);
        const bool again = judge(direct_attempt(ex, req), e, out);
        if (!again || attempts(req) == 1) {
          release_line(e);
          ec = e;
          return out;
        }
        return wait_for(req, 1, true, ec);  // the worker retries: it resynchronises the line first
      }
    }
    return wait_for(req, 0, false, ec);
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

  /**
   * The stream (for settings such as the baud rate; do not read or write it directly). Call it
   * only while no exchange runs: a descriptor the caller-thread driver had taken out of the
   * reactor goes back to the stream first.
   */
  Stream& stream() {
    std::lock_guard lock(m_);
    if (!busy_) unpark();
    return stream_;
  }
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
    bool idempotent = false;
  };
  using handler_type = boost::asio::any_completion_handler<signature>;
  struct pending {
    request req;
    handler_type handler;
    unsigned attempts_done = 0;   ///< attempts already made by the caller's thread
    bool blocked_caller = false;  ///< a blocking execute() waits for it (its next call comes from that thread)
  };
  /** How one attempt on the line ended (before judging it). */
  struct attempt_result {
    std::error_code line;    ///< the stream failed (read, write, end of file)
    bool timed_out = false;  ///< the deadline passed first
    const detail::exchange* ex = nullptr;
  };
  using clock = std::chrono::steady_clock;
  // The worker's coroutines, its timer and its I/O completions run on the strand's own type (not
  // any_io_executor): with a concrete stream executor (open_serial, connect) nothing is
  // type-erased, so nothing is allocated per resumption.
  using strand_type = boost::asio::strand<executor_type>;
  template <class T>
  using task = boost::asio::awaitable<T, strand_type>;
  static constexpr boost::asio::use_awaitable_t<strand_type> use_task{};
  using timer_type = boost::asio::basic_waitable_timer<clock, boost::asio::wait_traits<clock>, strand_type>;

  /** The client's pool for its operations' memory. */
  detail::handler_allocator<void> alloc() const noexcept { return detail::handler_allocator<void>(memory_); }

  /** A queued handler, type-erased; one with no allocator of its own takes its memory from the pool. */
  template <class Handler>
  handler_type erase(Handler&& h) {
    if constexpr (std::is_same_v<boost::asio::associated_allocator_t<std::decay_t<Handler>>, std::allocator<void>>)
      return handler_type(boost::asio::bind_allocator(alloc(), std::forward<Handler>(h)));
    else
      return handler_type(std::forward<Handler>(h));
  }

  /** Streams with a descriptor: blocking calls can do their I/O on the caller's thread. */
  static constexpr bool has_descriptor = requires(Stream & s) {
    { s.native_handle() } -> std::convertible_to<int>;
  };
  /** Sockets are written with send(MSG_NOSIGNAL): a closed peer is an error, not SIGPIPE. */
  static constexpr bool is_socket = requires(Stream & s) { s.remote_endpoint(); };
  /**
   * Streams whose descriptor can leave the reactor and come back (stream descriptors, sockets):
   * while blocking calls use it on their own threads, the descriptor is parked, so that its
   * replies do not also wake the executor's thread (see park).
   */
  static constexpr bool can_park = has_descriptor && requires(Stream & s) {
    { s.release() } -> std::convertible_to<int>;
  };

  bool running_here() const {
    if constexpr (requires { stream_.get_executor().running_in_this_thread(); })
      return stream_.get_executor().running_in_this_thread();
    else
      return false;
  }

  unsigned attempts(const request& r) const noexcept {
    return 1 + ((r.idempotent || opt_.retry_writes) ? opt_.read_retries : 0);
  }

  // --- the queue: any thread may add; one worker at a time (busy_) owns the line ----------------

  /**
   * Queues @p p and starts the worker if the line is free. With @p holding_line the calling
   * thread owns the line (a caller-thread attempt failed): @p p goes first and the worker
   * takes the line over.
   */
  void enqueue(pending p, bool holding_line = false) {
    bool start = false;
    {
      std::lock_guard lock(m_);
      if (closing_) {
        complete(std::move(p.handler), errc::cancelled, response{});
      } else if (holding_line) {
        queue_.push_front(std::move(p));
      } else {
        queue_.push_back(std::move(p));
        start = !busy_;
        busy_ = true;
      }
    }
    if (holding_line)
      hand_over_line();
    else if (start)
      start_worker();  // this thread owns the idle line until the worker starts
  }

  /**
   * Gives the line, which the calling thread owns, to a new worker. Never under m_ (the worker
   * may start inline); the descriptor goes back to non-blocking first, as Asio's reactor needs.
   */
  void start_worker() {
    unpark();
    nonblocking_for_worker();
    boost::asio::co_spawn(strand_, run(), boost::asio::detached);
  }

  /** Takes the line for the calling thread if nothing runs or waits and it needs no resync. */
  bool claim_idle_line() {
    std::lock_guard lock(m_);
    if (busy_ || closing_ || dirty_ || lost_) return false;  // (dirty_/lost_ are read only while idle)
    if constexpr (requires { stream_.is_open(); })
      if (parked_ < 0 && !stream_.is_open()) return false;  // the worker reports (or reopens) it
    busy_ = true;
    return true;
  }

  /** Ends a caller-thread exchange: counts it, then hands the line to the queue, if any waits. */
  void release_line(const std::error_code& ec) {
    ++counters_.exchanges;
    if (ec) ++counters_.errors;
    hand_over_line();
  }

  /** The owner of the line lets it go: to a new worker if requests wait, else it is idle. */
  void hand_over_line() {
    std::promise<void>* idle = nullptr;
    bool start = false;
    {
      std::lock_guard lock(m_);
      if (queue_.empty() || closing_) {
        busy_ = false;
        idle = idle_;
      } else {
        start = true;  // busy_ passes to the worker
      }
    }
    if (start)
      start_worker();
    else if (idle)
      idle->set_value();  // the last touch of `this`: a destructor is waiting
  }

  /**
   * Queues @p req, with @p done attempts already made, and blocks until it completes. With
   * @p holding_line this thread owns the line and @p req goes first. The result waits in a slot
   * on this stack: nothing shared to allocate.
   */
  response wait_for(const request& req, unsigned done, bool holding_line, std::error_code& ec) {
    struct slot {
      std::error_code ec;
      response r;
      bool done = false;
      std::mutex m;
      std::condition_variable cv;
    } s;
    auto h = [&s](boost::system::error_code e, response r) {
      std::lock_guard lock(s.m);  // notify under the lock: the waiter cannot leave (and free s) before unlock
      s.ec = e;
      s.r = r;
      s.done = true;
      s.cv.notify_one();
    };
    enqueue(pending{req, erase(std::move(h)), done, true}, holding_line);
    std::unique_lock lock(s.m);
    s.cv.wait(lock, [&s] { return s.done; });
    ec = s.ec;
    return s.r;
  }

  /** Bytes already waiting on the line (0 when the stream cannot tell). */
  std::size_t bytes_waiting() {
    if constexpr (has_descriptor) {
      int n = 0;  // serial ports, descriptors, sockets: ask the driver
      return ::ioctl(line_fd(), FIONREAD, &n) == 0 && n > 0 ? static_cast<std::size_t>(n) : 0;
    } else if constexpr (requires(boost::system::error_code & e) { stream_.available(e); }) {
      boost::system::error_code e;
      return stream_.available(e);
    } else {
      return 0;
    }
  }

  /** The wire time of @p r's request and reply at opt_.baud (11 bits per byte). */
  clock::duration wire(const request& r) const {
    const auto bytes = r.frame.size() + r.shape.frame_size();
    return std::chrono::nanoseconds(static_cast<std::int64_t>(bytes) * 11 * 1'000'000'000 / opt_.baud);
  }
  /** How long an exchange of @p r may take: its wire time plus the turnaround allowance. */
  clock::duration budget(const request& r) const { return wire(r) + opt_.turnaround; }

  void trace(direction d, std::span<const std::uint8_t> b) {
    if (opt_.trace && !b.empty()) opt_.trace(d, clock::now(), b);
  }

  /**
   * The bookkeeping after one attempt, shared by both drivers. Fills @p out and sets @p ec to
   * the exchange's outcome; returns true when another attempt may help (a timeout, a bad frame,
   * a lost link that can be reopened), false when @p ec is final. Marks the line for a resync
   * after any error.
   */
  bool judge(const attempt_result& a, std::error_code& ec, response& out) {
    if (a.line) {
      dirty_ = true;
      ec = a.line;
      if (!is_link_lost(ec)) return false;
      lost_ = true;
      return reopen_ && !closing_;  // a retriable read tries again on a new link
    }
    if (a.timed_out) {
      ++counters_.timeouts;
      dirty_ = true;
      ec = errc::timeout;
      return true;
    }
    const auto& r = a.ex->result();
    if (r.status == parse_status::error) {
      dirty_ = true;  // stray or corrupted bytes: resync before the next exchange
      ec = r.error;
      return true;
    }
    out.kind = r.value.kind();
    out.command = r.value.command();
    out.data = byte_buffer<max_reply_data>(r.value.bytes());
    ec = out.kind == reply_kind::nack ? std::error_code(rcb4::errc::nack) : std::error_code{};
    return false;
  }

  // --- the caller-thread driver: the exchange machine on the descriptor, ppoll for deadlines ------

  /**
   * Waits until @p fd is ready for @p events; false when @p deadline passes first. Between
   * @p spin_from and @p spin_until it polls without sleeping.
   */
  static bool ready_before(int fd, short events, clock::time_point deadline, std::error_code& ec,
                           clock::time_point spin_from = {}, clock::time_point spin_until = {}) {
    for (;;) {
      const auto now = clock::now();
      if (now >= deadline) return false;
      const auto until = now < spin_from ? std::min(spin_from, deadline) : now < spin_until ? now : deadline;
      const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(until - now).count();
      const timespec ts{static_cast<time_t>(left / 1'000'000'000), static_cast<long>(left % 1'000'000'000)};
      pollfd p{fd, events, 0};
      const int r = ::ppoll(&p, 1, &ts, nullptr);
      if (r > 0) {
        if (p.revents & POLLNVAL) ec = std::error_code(EBADF, std::generic_category());
        return true;  // readable, writable, or an error/hang-up that the read or write reports
      }
      if (r < 0 && errno != EINTR) {
        ec = std::error_code(errno, std::generic_category());
        return true;
      }
    }
  }

  /** The descriptor's settings the caller-thread driver relies on, checked once per descriptor. */
  struct direct_fd {
    int fd = -1;
    int flags = 0;          // file status flags, O_NONBLOCK included
    bool tty = false;       // a terminal: reads can block with a VTIME bound
    cc_t vtime = 0;         // the VTIME last set (VMIN is 0 once any is set)
    bool blocking = false;  // O_NONBLOCK is off (left so by bounded reads until the worker needs it)
  };

  /** The line's descriptor, parked or in the stream. */
  int line_fd() {
    if constexpr (can_park)
      if (parked_ >= 0) return parked_;
    return stream_.native_handle();
  }

  /**
   * Takes the descriptor out of the reactor while the calling thread owns the line. Asio
   * watches a descriptor from the moment its stream opens it; left there, every reply that a
   * caller's blocking read takes would also wake the executor's thread in epoll_wait (edge
   * triggered, for nothing): on a fast line that second wake-up costs about as much as the
   * client's own work. The stream releases it (the number stays the same) and the worker
   * assigns it back before its first operation (unpark).
   */
  void park() {
    if constexpr (can_park) {
      if (parked_ >= 0 || !stream_.is_open()) return;
      boost::system::error_code e;
      if constexpr (is_socket) protocol_.emplace(stream_.local_endpoint(e).protocol());
      if (e) return;  // stays in the stream: the worker will report what is wrong with it
      if constexpr (requires { stream_.release(e); })
        parked_ = stream_.release(e);  // (a socket's; it fails on no POSIX system)
      else
        parked_ = stream_.release();  // (a descriptor's; it cannot fail)
      if (e) parked_ = -1;
    }
  }
  /** Gives a parked descriptor back to the stream (and the reactor); the owner of the line calls it. */
  void unpark() {
    if constexpr (can_park) {
      if (parked_ < 0) return;
      boost::system::error_code e;
      if constexpr (is_socket)
        stream_.assign(*protocol_, parked_, e);
      else
        stream_.assign(parked_, e);
      if (e) ::close(parked_);  // the stream stays closed: the next exchange reports errc::closed
      parked_ = -1;
    }
  }
  /**
   * The client is going away: a terminal's exclusive mode (TIOCEXCL, which open_serial sets)
   * is cleared, since it outlives this descriptor while anyone else holds the terminal open (a
   * pty's server, for one) and would turn the next open by a user without root into EBUSY; then
   * the stream, or its parked descriptor, is closed.
   */
  void let_go_of_line() {
    if constexpr (has_descriptor) {
      const int fd = line_fd();
      if (fd >= 0 && ::isatty(fd) == 1) ::ioctl(fd, TIOCNXCL);
    }
    if constexpr (can_park) {
      if (parked_ >= 0) ::close(parked_);
      parked_ = -1;
    }
    boost::system::error_code ignored;
    stream_.close(ignored);
  }

  /** The descriptor back to non-blocking if a caller's bounded read left it blocking (see start_worker). */
  void nonblocking_for_worker() {
    if (!direct_.blocking) return;
    ::fcntl(direct_.fd, F_SETFL, direct_.flags);
    direct_.blocking = false;
  }

  /**
   * A tty read that blocks (a blocking read wakes sooner than ppoll then read) for at most
   * @p tenths of a second, the terminal's own timer (VMIN 0, VTIME): -2 when that passed
   * with nothing read, otherwise read()'s result. The descriptor stays blocking for the
   * callers' next exchanges (their writes cannot block: the previous request has left, since
   * its reply came, and after any timeout the line goes to the worker); the worker makes it
   * non-blocking again when it takes the line.
   */
  ssize_t bounded_tty_read(std::span<std::uint8_t> buf, cc_t tenths) {
    const int fd = direct_.fd;
    if (direct_.vtime != tenths) {
      termios t{};
      if (::tcgetattr(fd, &t) != 0) return -1;
      t.c_cc[VMIN] = 0;
      t.c_cc[VTIME] = tenths;
      if (::tcsetattr(fd, TCSANOW, &t) != 0) return -1;
      direct_.vtime = tenths;
    }
    if (!direct_.blocking) {
      if (::fcntl(fd, F_SETFL, direct_.flags & ~O_NONBLOCK) != 0) return -1;
      direct_.blocking = true;
    }
    const auto began = clock::now();
    const ssize_t n = ::read(fd, buf.data(), buf.size());
    if (n != 0) return n;
    // Nothing: the timer ran out, or the terminal hung up (then read returns 0 at once).
    return clock::now() - began >= std::chrono::milliseconds(100 * tenths - 20) ? -2 : 0;
  }

  /** One attempt of @p req on this thread, driving @p ex (the caller holds the line). */
  attempt_result direct_attempt(detail::exchange& ex, const request& req) {
    const int fd = line_fd();
    if (fd != direct_.fd) {  // once per descriptor: non-blocking, so that every wait has a deadline
      direct_ = direct_fd{fd, ::fcntl(fd, F_GETFL), !is_socket && ::isatty(fd) == 1, 0};
      if (direct_.flags >= 0 && (direct_.flags & O_NONBLOCK) == 0) ::fcntl(fd, F_SETFL, direct_.flags | O_NONBLOCK);
      direct_.flags |= O_NONBLOCK;
    }
    attempt_result a{{}, false, &ex};
    const auto start = clock::now();
    const auto deadline = start + budget(req);
    clock::time_point spin_from{}, spin_until{};  // none: sleep until the reply comes
    if (opt_.busy_poll.count() > 0) {
      const auto expected = start + wire(req);  // busy_poll's window is centred here
      spin_from = expected - opt_.busy_poll;
      spin_until = expected + opt_.busy_poll;
    }
    trace(direction::tx, req.frame.bytes());
    while (ex.next() != detail::exchange::step::done) {
      const bool writing = ex.next() == detail::exchange::step::write;
      ssize_t n;
      if (writing) {
        const auto w = ex.to_write();
        if constexpr (is_socket)
          n = ::send(fd, w.data(), w.size(), MSG_NOSIGNAL);
        else
          n = ::write(fd, w.data(), w.size());
      } else {
        const auto buf = ex.read_buffer();
        // A tty with whole tenths of a second left blocks in read() for at most those tenths;
        // anything else (sockets, the last fraction, busy polling) waits in ppoll.
        const auto tenths =
            direct_.tty && opt_.busy_poll.count() == 0
                ? std::min<std::int64_t>(255, (deadline - clock::now()) / std::chrono::milliseconds(100))
                : 0;
        if (tenths > 0) {
          n = bounded_tty_read(buf, static_cast<cc_t>(tenths));
          if (n == -2) continue;  // its tenths passed: the rest of the time goes to ppoll
        } else {
          if (!ready_before(fd, POLLIN, deadline, a.line, spin_from, spin_until)) {  // never there yet
            a.timed_out = true;
            break;
          }
          if (a.line) break;
          n = ::read(fd, buf.data(), buf.size());
        }
      }
      if (n > 0) {
        const auto k = static_cast<std::size_t>(n);
        if (writing) {
          counters_.bytes_out += k;
          ex.wrote(k);
        } else {
          counters_.bytes_in += k;
          trace(direction::rx, ex.read_buffer().first(k));
          ex.received(k);
        }
      } else if (n == 0 && !writing) {
        a.line = errc::closed;  // end of file: the other side has gone
        break;
      } else if (n == 0 || errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) {
        if (writing && !ready_before(fd, POLLOUT, deadline, a.line)) {
          a.timed_out = true;
          break;
        }
        if (a.line) break;
      } else {
        a.line = std::error_code(errno, std::generic_category());
        break;
      }
    }
    return a;
  }

  // --- the executor's driver: one coroutine works through the queue -----------------------------

  task<void> run() {
    for (;;) {
      pending p = [this] {
        std::lock_guard lock(m_);
        return queue_.pop_front();
      }();
      response r;
      const std::error_code ec = co_await perform(p.req, r, p.attempts_done);
      ++counters_.exchanges;
      if (ec) ++counters_.errors;
      // The completion runs on the strand only after this coroutine suspends or returns, so the
      // caller cannot see it before the line is released; releasing it is the last touch of
      // `this` (a destructor may be waiting for it).
      complete(std::move(p.handler), ec, r);
      if (more_queued()) continue;
      // After an asynchronous completion, linger for one turn of the strand: the completion just
      // posted runs first, and a request its handler makes (a callback chain, a coroutine's next
      // co_await) finds this worker still here instead of spawning a new one (whose frames would
      // be allocated again). A blocked caller's next request comes from its own thread and should
      // find the line idle, for the caller-thread driver: no lingering for it.
      if (!p.blocked_caller) co_await boost::asio::post(strand_, boost::asio::bind_allocator(alloc(), use_task));
      std::promise<void>* idle = nullptr;
      {
        std::lock_guard lock(m_);
        if (!queue_.empty() && !closing_) continue;
        busy_ = false;
        idle = idle_;
      }
      if (idle) idle->set_value();
      co_return;
    }
  }

  bool more_queued() {
    std::lock_guard lock(m_);
    return !queue_.empty() && !closing_;
  }

  /**
   * Queues @p h's completion on the strand, where it runs only once the worker has suspended or
   * finished, then on the handler's own executor.
   */
  void complete(handler_type h, std::error_code ec, const response& r) {
    boost::asio::post(
        strand_, boost::asio::bind_allocator(alloc(), [h = std::move(h), ec, r, s = strand_, a = alloc()]() mutable {
          auto ex = boost::asio::get_associated_executor(h, s);
          boost::asio::dispatch(ex, boost::asio::bind_allocator(a, [h = std::move(h), ec, r]() mutable {
                                  std::move(h)(boost::system::error_code(ec), r);
                                }));
        }));
  }

  /**
   * Starts the exchange's deadline: when it passes, the pending read or write is cancelled. One
   * wait on the timer watches many exchanges: a new deadline later than the wait's expiry (the
   * usual case: the exchanges follow one another) leaves the wait alone, and when it fires
   * during a later exchange it waits again, for that exchange's deadline. So the timer is set
   * about once per turnaround allowance instead of twice per exchange (each time a timerfd
   * system call, and a cancelled wait's completion through the strand).
   */
  void arm(clock::duration d) {
    timed_out_ = false;
    deadline_ = clock::now() + d;
    guarding_ = true;
    if (!waiting_ || wait_until_ > deadline_) watch_until(deadline_);
  }
  /** The exchange has ended: its deadline no longer applies (the wait stays, for the next one). */
  void disarm() { guarding_ = false; }

  /** What a timer wait's completion may touch after its client has gone: nothing, then. */
  struct deadline_watch {
    basic_client* owner;  // null once the client is going away (set on the strand)
  };

  /** Waits on the timer until @p t, replacing an outstanding wait (whose completion is then stale). */
  void watch_until(clock::time_point t) {
    const auto gen = ++generation_;
    waiting_ = true;
    wait_until_ = t;
    timer_.expires_at(t);
    timer_.async_wait(boost::asio::bind_allocator(alloc(), [w = watch_, gen](boost::system::error_code ec) {
      basic_client* self = w->owner;
      if (!self || gen != self->generation_) return;  // the client has gone, or a newer wait replaced this one
      self->waiting_ = false;
      if (!ec) self->deadline_reached();
    }));
  }
  /** The wait fired: the running exchange's deadline has passed, or it waits again for it. */
  void deadline_reached() {
    if (!guarding_) return;  // between exchanges: the next arm() starts a new wait
    if (clock::now() < deadline_) {
      watch_until(deadline_);
      return;
    }
    timed_out_ = true;
    cancel_.emit(boost::asio::cancellation_type::terminal);
  }
  auto token() {
    return boost::asio::bind_cancellation_slot(cancel_.slot(),
                                               boost::asio::as_tuple(boost::asio::bind_allocator(alloc(), use_task)));
  }

  /**
   * Brings the line back to a known state after an error. The board answers in order, so a ping
   * sent now is answered after every byte it still owed (a late reply, the rest of a split one):
   * everything up to that ACK is discarded, then the line must stay quiet for opt_.quiet. No ACK
   * within the ping's budget is errc::timeout: the line stays dirty, and the exchange counts it
   * as a timed-out attempt (a write is then not sent at all).
   */
  task<std::error_code> drain() {
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
  task<std::error_code> reconnect() {
    const auto give_up = clock::now() + policy_.give_up_after;
    auto delay = policy_.first_delay;
    for (;;) {
      if (closing_) co_return errc::cancelled;
      std::error_code e;
      reopen_(stream_, e);
      direct_ = direct_fd{};  // a new descriptor (possibly with the old number)
      if (!e) {
        lost_ = false;
        dirty_ = false;
        ++counters_.reconnects;
        co_return std::error_code{};
      }
      const auto now = clock::now();
      if (now >= give_up) co_return errc::reconnect_failed;
      backoff_.expires_at(std::min(give_up, now + delay));
      co_await backoff_.async_wait(boost::asio::as_tuple(use_task));
      delay = std::min(policy_.max_delay, delay * 2);
    }
  }

  /** Runs @p req's remaining attempts (after @p first made elsewhere). */
  task<std::error_code> perform(const request& req, response& out, unsigned first) {
    std::error_code ec = first > 0 ? std::error_code(errc::timeout) : std::error_code{};
    for (unsigned attempt = first; attempt < attempts(req); ++attempt) {
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
      detail::exchange ex(req.frame.bytes(), req.shape);
      attempt_result a{{}, false, &ex};
      trace(direction::tx, req.frame.bytes());
      arm(budget(req));
      while (ex.next() != detail::exchange::step::done && !a.line && !timed_out_) {
        if (ex.next() == detail::exchange::step::write) {
          const auto w = ex.to_write();
          auto [e, n] = co_await boost::asio::async_write(stream_, boost::asio::buffer(w.data(), w.size()), token());
          counters_.bytes_out += n;
          ex.wrote(n);
          if (e && !timed_out_) a.line = line_error(e);
        } else {
          const auto buf = ex.read_buffer();
          auto [e, n] = co_await stream_.async_read_some(boost::asio::buffer(buf.data(), buf.size()), token());
          counters_.bytes_in += n;
          trace(direction::rx, buf.first(n));
          if (n > 0) ex.received(n);
          if (e && !timed_out_) a.line = line_error(e);
        }
      }
      disarm();
      a.timed_out = timed_out_ && !a.line;
      if (!judge(a, ec, out)) co_return ec;
    }
    co_return ec;
  }

  // The pool is shared with the operations it serves, and declared first so that it also
  // outlives the stream's and the timer's own operations here.
  std::shared_ptr<detail::handler_memory> memory_ = std::make_shared<detail::handler_memory>();
  Stream stream_;
  client_options opt_;
  strand_type strand_;
  timer_type timer_;             // the exchanges' deadlines (see arm)
  timer_type backoff_;           // reconnect's pauses
  std::mutex m_;                 // guards queue_, busy_, closing_, idle_
  detail::fifo<pending> queue_;  // requests waiting for the line
  bool busy_ = false;            // a worker or a calling thread owns the line
  bool closing_ = false;
  std::promise<void>* idle_ = nullptr;
  // The line's state: touched only by whoever owns the line (busy_ hands it over under m_).
  bool dirty_ = false;
  bool lost_ = false;
  bool timed_out_ = false;
  direct_fd direct_;  // the caller-thread driver's view of the descriptor
  int parked_ = -1;   // the descriptor while out of the reactor (see park), else -1
  [[no_unique_address]] typename detail::protocol_of<Stream>::type protocol_{};  // a parked socket's
  std::function<void(Stream&, std::error_code&)> reopen_;
  reconnect_policy policy_;
  // The deadline watch: touched only on the strand (by the worker and the timer's completions).
  std::shared_ptr<deadline_watch> watch_ = std::make_shared<deadline_watch>(deadline_watch{this});
  clock::time_point deadline_{};    // the running exchange's deadline
  bool guarding_ = false;           // an exchange runs under deadline_
  bool waiting_ = false;            // a wait is outstanding on timer_ ...
  clock::time_point wait_until_{};  // ... until then
  std::uint64_t generation_ = 0;    // that wait's number: completions of replaced waits are stale
  boost::asio::cancellation_signal cancel_;
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
