// rcb4 — what a client shares with its worker: the line, the queue, who owns the line, and how
// the client goes away in whatever state it is in.
// SPDX-License-Identifier: BSL-1.0
//
// One owner at a time has the line (busy_, handed over under m_): the worker coroutine on the
// strand (asynchronous requests, and blocking ones that found the line busy), or a thread in a
// blocking call that found it idle (the caller-thread driver). The exchange machine holds the
// line's state between owners. The core lives in a shared_ptr that the worker holds too, so a
// client destroyed while its executor is not running (a single-threaded program after
// io.run() returned, or before it ran) leaves nothing behind that could touch freed memory.
#pragma once

#include <rcb4/transport/detail/asio_driver.hpp>
#include <rcb4/transport/detail/exchange_machine.hpp>
#include <rcb4/transport/detail/fifo.hpp>
#include <rcb4/transport/detail/handler_memory.hpp>
#include <rcb4/transport/detail/posix_driver.hpp>

#include <boost/asio/any_completion_handler.hpp>
#include <boost/asio/associated_cancellation_slot.hpp>
#include <boost/asio/associated_executor.hpp>
#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/post.hpp>

#include <condition_variable>
#include <memory>
#include <mutex>

namespace rcb4::transport::detail {

/** The completion signature of the client's asynchronous operations. */
using exchange_signature = void(error_code, response);

/** The shared state of one client. */
template <class Stream>
class client_core : public std::enable_shared_from_this<client_core<Stream>> {
 public:
  using asio_type = asio_driver<Stream>;                                         ///< the worker's driver
  using posix_type = posix_driver<Stream>;                                       ///< the caller-thread driver
  using strand_type = typename asio_type::strand_type;                           ///< where the worker runs
  using handler_type = boost::asio::any_completion_handler<exchange_signature>;  ///< a queued completion
  using reopen_function = std::function<void(Stream&, error_code&)>;             ///< set_reconnect's

  /** A request waiting for the line. */
  struct pending {
    request req;
    handler_type handler;
    std::uint64_t id = 0;
    boost::asio::cancellation_slot slot{};  // the caller's per-operation cancellation, if connected
    bool nack_is_error = true;              // execute (a NACK is errc::nack) or exchange (a NACK is a reply)
    bool blocked_caller = false;            // a blocking call waits for it: its next call comes from that thread
  };

  /** A core owning @p s (use create()). */
  client_core(Stream s, client_options opt)
      : stream_(std::move(s)),
        opt_(std::move(opt)),
        machine_(opt_, counters_),
        strand_(stream_.get_executor()),
        asio_(strand_, memory_) {}
  client_core(const client_core&) = delete;
  client_core& operator=(const client_core&) = delete;
  ~client_core() { direct_.let_go(stream_); }

  /** A shared core owning @p s. */
  static std::shared_ptr<client_core> create(Stream s, client_options opt) {
    auto c = std::make_shared<client_core>(std::move(s), std::move(opt));
    c->asio_.set_self(std::shared_ptr<asio_type>(c, &c->asio_));
    return c;
  }

  // --- asynchronous requests --------------------------------------------------------------------

  /**
   * Queues @p p (its handler completes on its own executor) and starts the worker if the line is
   * free. Returns the request's number (0 when the client is closing: it completes cancelled).
   */
  std::uint64_t enqueue(pending p) {
    bool start = false;
    std::uint64_t id = 0;
    {
      std::lock_guard lock(m_);
      if (closing_) {
        complete(std::move(p), transport_errc::cancelled, response{});
        return 0;
      }
      p.id = id = ++next_id_;
      if (p.slot.is_connected()) p.slot.template emplace<cancel_handler>(this->weak_from_this(), p.id);
      queue_.push_back(std::move(p));
      start = !busy_;
      busy_ = true;
    }
    if (start) start_worker();
    return id;
  }

  // --- blocking requests --------------------------------------------------------------------------

  /**
   * Runs @p req and waits for its end: on this thread if the line is idle and the stream has a
   * descriptor, otherwise through the queue and the worker (waiting at most as long as every
   * request ahead could take: then transport_errc::executor_not_running).
   */
  response execute(const request& req, bool nack_is_error, error_code& ec) {
    if (running_here()) {
      ec = transport_errc::would_deadlock;
      return {};
    }
    if constexpr (posix_type::has_descriptor) {
      if (opt_.direct_io && claim_idle_line()) {
        ec = direct_.run(stream_, machine_, opt_, req, reopen_);
        response r = ec ? response{} : machine_.reply();
        ec = outcome(nack_is_error, ec, r);
        release_line();
        return r;
      }
    }
    return wait_for(req, nack_is_error, ec);
  }

  // --- settings -----------------------------------------------------------------------------------

  /** Sets how a lost link is reopened (before the first exchange). */
  void set_reconnect(reopen_function reopen, reconnect_policy policy) {
    std::lock_guard lock(m_);
    reopen_ = std::move(reopen);
    worker_reopen_ = [this](Stream& s, error_code& ec) {
      direct_.forget();  // a new descriptor, maybe with the old number
      reopen_(s, ec);
    };
    policy_ = policy;
    machine_.set_reopen(static_cast<bool>(reopen_), policy);
  }
  /** The stream; while the line is idle a parked descriptor goes back into it first. */
  Stream& stream() {
    std::lock_guard lock(m_);
    if (!busy_) {
      direct_.unpark(stream_);
      direct_.forget();  // the caller may change the descriptor's settings
      asio_.forget();
    }
    return stream_;
  }
  client_options& options() noexcept { return opt_; }                     ///< the options
  const client_counters& counters() const noexcept { return counters_; }  ///< what was done
  const strand_type& strand() const noexcept { return strand_; }          ///< the worker's strand

  /**
   * The client is going away: queued requests end with transport_errc::cancelled, the running
   * one is cancelled, the line is closed. Waits for the worker to leave when another thread
   * runs the executor (so the port is closed when this returns); returns at once when the
   * executor is not running or this thread runs it (the worker then ends the next time the
   * executor runs, or with the executor's context).
   */
  void shut_down() {
    std::unique_lock lock(m_);
    closing_ = true;
    while (!queue_.empty()) complete(queue_.pop_front(), transport_errc::cancelled, response{});
    if (!busy_ || !worker_started_) {  // nobody on the line, or a worker that has not started yet
      direct_.let_go(stream_);
      return;
    }
    lock.unlock();
    boost::asio::dispatch(strand_, boost::asio::bind_allocator(asio_.alloc(), [self = this->shared_from_this()] {
                            {
                              std::lock_guard l(self->m_);
                              self->abort_ran_ = true;
                              self->idle_.notify_all();
                            }
                            self->asio_.abort(transport_errc::cancelled);
                            self->asio_.stop();
                            self->direct_.let_go(self->stream_);  // ends any I/O at once
                          }));
    if (running_here() || executor_stopped()) return;
    // Someone runs the executor if the abort starts soon (a post on an idle context runs within
    // microseconds); then the worker leaves at once. If it does not start, nobody is running the
    // executor (a program between io.poll() calls): waiting longer would only freeze the caller.
    lock.lock();
    if (!idle_.wait_for(lock, std::chrono::milliseconds(100), [this] { return abort_ran_ || !busy_; })) return;
    idle_.wait_for(lock, opt_.turnaround + std::chrono::seconds(1), [this] { return !busy_; });
  }

 private:
  using clock = std::chrono::steady_clock;

  /** Per-operation cancellation: a queued request leaves the queue; the one on the wire is abandoned. */
  struct cancel_handler {
    std::weak_ptr<client_core> core;
    std::uint64_t id;
    void operator()(boost::asio::cancellation_type type) const {
      if (auto c = core.lock())
        boost::asio::dispatch(
            c->strand_, boost::asio::bind_allocator(c->asio_.alloc(), [c, id = id, type] { c->cancel(id, type); }));
    }
  };
  void cancel(std::uint64_t id, boost::asio::cancellation_type type) {
    std::unique_lock lock(m_);
    if (auto p = queue_.take_if([id](const pending& q) { return q.id == id; })) {
      lock.unlock();
      complete(std::move(*p), boost::asio::error::operation_aborted, response{});
    } else if (running_ == id &&
               (type & boost::asio::cancellation_type::terminal) != boost::asio::cancellation_type::none) {
      asio_.abort(boost::asio::error::operation_aborted);  // (only terminal: a write may be on the wire)
    }
  }

  // (through the strand's copy of the executor: a descriptor's get_executor() is not const)
  bool running_here() const {
    if constexpr (requires { strand_.get_inner_executor().running_in_this_thread(); })
      return strand_.get_inner_executor().running_in_this_thread();
    else
      return false;
  }
  bool executor_stopped() const {
    if constexpr (requires { strand_.get_inner_executor().context().stopped(); })
      return strand_.get_inner_executor().context().stopped();
    else
      return false;
  }

  /** Gives the line, which the calling thread owns, to a new worker. */
  void start_worker() {
    direct_.unpark(stream_);
    boost::asio::co_spawn(strand_, work(this->shared_from_this()), boost::asio::detached);
  }

  /** The worker: takes requests from the queue until it is empty (or the client closes). */
  typename asio_type::template task<void> work(
      [[maybe_unused]] std::shared_ptr<client_core> self) {  // (self: the core outlives the worker)
    for (;;) {
      std::optional<pending> p;
      {
        std::lock_guard lock(m_);
        worker_started_ = true;
        if (closing_ || queue_.empty()) {
          // The deadline timer's wait would keep the context busy (io.run() from returning) until
          // it fired: the line is idle, so it goes.
          asio_.stop();
          busy_ = worker_started_ = false;
          idle_.notify_all();
          co_return;
        }
        p.emplace(queue_.pop_front());
        running_ = p->id;
      }
      const auto ec = co_await asio_.run(stream_, machine_, p->req, worker_reopen_, direct_.bytes_waiting(stream_));
      {
        std::lock_guard lock(m_);
        running_ = 0;
      }
      if (p->blocked_caller) {
        // Through the strand: the blocked caller's next call must find the line idle, and the
        // completion runs only after this coroutine has suspended or returned.
        complete(std::move(*p), ec, machine_.reply());
      } else {
        // At once, on the handler's executor (inline when that is this thread's: a callback, a
        // coroutine on this context): a request its handler makes is queued before this loop
        // looks at the queue again, so the worker goes on with it, with no post in between.
        complete_here(std::move(*p), ec, machine_.reply());
      }
    }
  }

  /** What the caller sees: for execute, a NACK is errc::nack (the board refused what was to succeed). */
  static error_code outcome(bool nack_is_error, error_code ec, const response& r) {
    return !ec && nack_is_error && r.kind == reply_kind::nack ? error_code(rcb4::errc::nack) : ec;
  }

  /**
   * Calls @p h with (@p ec, @p r) on its own executor (@p fallback when it has none): inline when
   * that is this thread's, else posted there, with memory from @p a. Its cancellation slot is
   * cleared first: a signal emitted later finds nothing to cancel.
   */
  static void deliver(handler_type h, boost::asio::cancellation_slot slot, error_code ec, const response& r,
                      const strand_type& fallback, const handler_allocator<void>& a) {
    auto ex = boost::asio::get_associated_executor(h, fallback);
    boost::asio::dispatch(ex, boost::asio::bind_allocator(a, [h = std::move(h), slot, ec, r]() mutable {
                            if (slot.is_connected()) slot.clear();
                            std::move(h)(ec, r);
                          }));
  }

  /** Completes @p p now, from the worker. */
  void complete_here(pending p, error_code ec, const response& r) {
    deliver(std::move(p.handler), p.slot, outcome(p.nack_is_error, ec, r), r, strand_, asio_.alloc());
  }

  /** Completes @p p with @p ec / @p r on its handler's executor, after the strand's current turn. */
  void complete(pending p, error_code ec, const response& r) {
    const auto a = asio_.alloc();
    boost::asio::post(strand_, boost::asio::bind_allocator(
                                   a, [h = std::move(p.handler), slot = p.slot, ec = outcome(p.nack_is_error, ec, r), r,
                                       s = strand_, a]() mutable { deliver(std::move(h), slot, ec, r, s, a); }));
  }

  bool claim_idle_line() {
    std::lock_guard lock(m_);
    if (busy_ || closing_) return false;
    busy_ = true;
    return true;
  }
  /** The calling thread lets the line go: to a new worker if requests wait, else it is idle. */
  void release_line() {
    bool start = false;
    {
      std::lock_guard lock(m_);
      start = !queue_.empty() && !closing_;
      if (!start) {
        busy_ = false;
        idle_.notify_all();
      }
    }
    if (start) start_worker();
  }

  /** Queues @p req for the worker and waits for it, within a bound (see execute). */
  response wait_for(const request& req, bool nack_is_error, error_code& ec) {
    struct slot {
      std::mutex m;
      std::condition_variable cv;
      bool done = false;
      error_code ec;
      response r;
    };
    // Shared with the handler: a wait that gives up leaves it something valid to complete.
    auto s = std::allocate_shared<slot>(handler_allocator<slot>(memory_));
    std::size_t ahead = 0;
    {
      std::lock_guard lock(m_);
      ahead = queue_.size() + (busy_ ? 1 : 0);
    }
    const auto id = enqueue(pending{req,
                                    erase([s](error_code e, response r) {
                                      std::lock_guard lock(s->m);
                                      s->ec = e;
                                      s->r = r;
                                      s->done = true;
                                      s->cv.notify_one();
                                    }),
                                    0,
                                    {},
                                    nack_is_error,
                                    true});
    if (id == 0) {
      ec = transport_errc::cancelled;
      return {};
    }
    std::unique_lock lock(s->m);
    // A worker that has not started within a turnaround and a second will not: nobody runs the
    // executor. One that has started works through the queue within its deadlines.
    clock::duration patience = opt_.turnaround + std::chrono::seconds(1);
    for (int round = 0; !s->cv.wait_for(lock, patience, [&s] { return s->done; }); ++round) {
      lock.unlock();
      {
        std::lock_guard q(m_);
        const bool stalled = !worker_started_ || round > 0;
        if (stalled && queue_.take_if([id](const pending& p) { return p.id == id; })) {
          ec = transport_errc::executor_not_running;  // still queued: nobody ran the executor
          return {};
        }
        if (round > 0) {  // it ran, and has not ended within every request's deadlines
          ec = transport_errc::executor_not_running;
          return {};
        }
      }
      patience = static_cast<clock::rep>(ahead + 1) * longest_exchange();
      lock.lock();
    }
    ec = s->ec;
    return s->r;
  }
  /** An upper bound of one exchange: every attempt with its resync, a reconnect's patience, a margin. */
  clock::duration longest_exchange() const {
    const auto attempt =
        2 * (wire_time(128 + max_reply_size, opt_.baud) + opt_.turnaround) + 10 * (opt_.quiet + opt_.turnaround);
    const clock::duration reconnect =
        reopen_ ? clock::duration(policy_.give_up_after + policy_.max_delay) : clock::duration{};
    return (1 + opt_.read_retries) * attempt + reconnect + std::chrono::seconds(1);
  }

  template <class Handler>
  handler_type erase(Handler&& h) {
    if constexpr (std::is_same_v<boost::asio::associated_allocator_t<std::decay_t<Handler>>, std::allocator<void>>)
      return handler_type(boost::asio::bind_allocator(asio_.alloc(), std::forward<Handler>(h)));
    else
      return handler_type(std::forward<Handler>(h));
  }

 public:
  /** A handler made ready for the queue (its memory from the client's pool when it has no allocator of its own). */
  template <class Handler>
  pending make_pending(const request& req, Handler&& h, bool nack_is_error) {
    auto slot = boost::asio::get_associated_cancellation_slot(h);
    return pending{req, erase(std::forward<Handler>(h)), 0, slot, nack_is_error, false};
  }

 private:
  // The pool is shared with the operations it serves, and declared first so that it also
  // outlives the stream's and the timer's own operations here.
  std::shared_ptr<handler_memory> memory_ = std::make_shared<handler_memory>();
  Stream stream_;
  client_options opt_;
  client_counters counters_;
  exchange_machine machine_;  // the line's state: touched only by the line's owner
  strand_type strand_;
  asio_type asio_;
  posix_type direct_;
  reopen_function reopen_, worker_reopen_;
  reconnect_policy policy_{};
  std::mutex m_;  // guards what follows
  std::condition_variable idle_;
  fifo<pending> queue_;
  bool busy_ = false;            // an owner has the line (the worker or a calling thread)
  bool worker_started_ = false;  // the worker has run (it holds the line on the strand)
  bool closing_ = false;
  bool abort_ran_ = false;  // shut_down's abort has started on the strand
  std::uint64_t next_id_ = 0;
  std::uint64_t running_ = 0;  // the worker's request
};

}  // namespace rcb4::transport::detail
