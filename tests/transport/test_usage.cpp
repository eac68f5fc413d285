// The ways users run Asio and the client, each ending cleanly: the context on the caller's
// thread (then the client destroyed, idle, with requests queued, with one on the wire), on
// io_thread, on a pool of threads; coroutines, futures, callbacks, the blocking API; cancellation
// through the completion token's slot; nobody running the executor.
// SPDX-License-Identifier: BSL-1.0
#include "served_board.hpp"

#include <rcb4/transport/adapters.hpp>
#include <rcb4/transport/client.hpp>
#include <rcb4/transport/serial.hpp>

#include <boost/asio/bind_cancellation_slot.hpp>
#include <boost/asio/cancellation_signal.hpp>
#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/experimental/awaitable_operators.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/thread_pool.hpp>

#include <boost/asio/use_awaitable.hpp>
#include <boost/asio/use_future.hpp>
#include <catch2/catch.hpp>
#include <fstream>
#include <iterator>
#include <string>

#include <atomic>
#include <thread>

using namespace rcb4;
using namespace std::chrono_literals;
namespace t = rcb4::transport;
using rcb4::testing::served_board;
using clock_type = std::chrono::steady_clock;

namespace {
/** A board that answers, or stays silent while `silent` is set. */
struct switchable_board {
  std::atomic<bool> silent{false};
  served_board b{[this] {
    t::serve_options so;
    so.tamper = [this](std::vector<std::uint8_t>& reply) {
      if (silent) reply.clear();
    };
    return so;
  }()};
  const std::string& path() const { return b.server->where(); }
};
}  // namespace

TEST_CASE("usage: io.run() on the main thread, then the client goes out of scope", "[transport][usage]") {
  served_board b;
  const auto start = clock_type::now();
  boost::asio::io_context io;
  int answered = 0;
  {
    auto c = t::make_client(t::open_serial(io, b.server->where(), 1250000));
    c.async_execute(ping{}, [&](t::error_code ec, t::response r) {
      CHECK_FALSE(ec);
      CHECK(r.kind == reply_kind::ack);
      c.async_execute(version{}, [&](t::error_code ec2, t::response r2) {  // a chain from a handler
        CHECK_FALSE(ec2);
        CHECK(r2.data.size() == 32);
        ++answered;
      });
      ++answered;
    });
    io.run();  // returns when both exchanges are done
  }            // the destructor must not wait for a strand nobody runs any more
  CHECK(answered == 2);
  CHECK(clock_type::now() - start < 5s);
}

TEST_CASE("usage: a client destroyed with requests queued before the context ever ran", "[transport][usage]") {
  served_board b;
  boost::asio::io_context io;
  t::error_code first, second;
  int called = 0;
  {
    auto c = t::make_client(t::open_serial(io, b.server->where(), 1250000));
    c.async_execute(ping{}, [&](t::error_code ec, t::response) {
      first = ec;
      ++called;
    });
    c.async_execute(ping{}, [&](t::error_code ec, t::response) {
      second = ec;
      ++called;
    });
  }
  io.run();  // the queued requests complete, cancelled; nothing touches the destroyed client
  CHECK(called == 2);
  CHECK(first == t::transport_errc::cancelled);
  CHECK(second == t::transport_errc::cancelled);
}

TEST_CASE("usage: a client and its context destroyed with requests queued, never run", "[transport][usage]") {
  served_board b;
  int called = 0;
  {
    boost::asio::io_context io;
    auto c = t::make_client(t::open_serial(io, b.server->where(), 1250000));
    c.async_execute(ping{}, [&](t::error_code, t::response) { ++called; });
  }  // the client, then the context: the handler is destroyed, never called, and nothing leaks (ASan)
  CHECK(called == 0);
}

TEST_CASE("usage: the client destroyed from a handler while an exchange is on the wire", "[transport][usage]") {
  switchable_board sb;
  sb.silent = true;
  boost::asio::io_context io;
  t::client_options opt;
  opt.turnaround = 30s;  // only the destruction can end it
  auto c = std::make_unique<t::basic_client<t::serial_port>>(t::open_serial(io, sb.path(), 1250000), opt);
  t::error_code got;
  bool called = false;
  c->async_execute(ping{}, [&](t::error_code ec, t::response) {
    got = ec;
    called = true;
  });
  boost::asio::steady_timer timer(io, 50ms);
  timer.async_wait([&](boost::system::error_code) { c.reset(); });  // on the context's own thread
  const auto start = clock_type::now();
  io.run();
  CHECK(called);
  CHECK(got == t::transport_errc::cancelled);
  CHECK(clock_type::now() - start < 5s);
}

TEST_CASE("usage: the client destroyed while io_thread runs an exchange on the wire", "[transport][usage]") {
  switchable_board sb;
  sb.silent = true;
  t::io_thread io;
  std::promise<t::error_code> done;
  const auto start = clock_type::now();
  {
    t::client_options opt;
    opt.turnaround = 30s;
    auto c = t::make_client(t::open_serial(io.context(), sb.path(), 1250000), opt);
    c.async_execute(ping{}, [&](t::error_code ec, t::response) { done.set_value(ec); });
    std::this_thread::sleep_for(20ms);  // (test pacing: let the request reach the wire)
  }
  CHECK(done.get_future().get() == t::transport_errc::cancelled);
  CHECK(clock_type::now() - start < 5s);
  // The port was closed by the time the destructor returned: it opens again at once.
  t::error_code ec;
  auto again = t::open_serial(io.context(), sb.path(), 1250000, ec);
  CHECK_FALSE(ec);
}

TEST_CASE("usage: a pool of threads runs the context, requests come from many threads", "[transport][usage]") {
  served_board b;
  boost::asio::thread_pool pool(4);
  boost::asio::io_context io;
  auto guard = boost::asio::make_work_guard(io);
  std::vector<std::thread> runners;
  for (int i = 0; i < 3; ++i) runners.emplace_back([&io] { io.run(); });
  std::atomic<int> ok{0}, failed{0};
  {
    auto c = t::make_client(t::open_serial(io, b.server->where(), 1250000));
    std::vector<std::future<void>> senders;
    for (int s = 0; s < 4; ++s)
      senders.push_back(boost::asio::post(pool, boost::asio::use_future([&c, &ok, &failed] {
                                            std::vector<std::future<t::response>> replies;
                                            for (int i = 0; i < 25; ++i)
                                              replies.push_back(c.async_execute(ping{}, boost::asio::use_future));
                                            for (auto& r : replies) try {
                                                if (r.get().kind == reply_kind::ack) ++ok;
                                              } catch (const std::exception&) {
                                                ++failed;
                                              }
                                          })));
    for (auto& s : senders) s.get();
    // And destroyed with requests still queued from the pool's threads: they end, cancelled.
    for (int i = 0; i < 20; ++i) c.async_execute(ping{}, [](t::error_code, t::response) {});
  }
  guard.reset();
  for (auto& r : runners) r.join();
  pool.join();
  CHECK(ok == 100);
  CHECK(failed == 0);
}

TEST_CASE("usage: coroutines with use_awaitable on the caller's thread", "[transport][usage]") {
  served_board b;
  boost::asio::io_context io;
  int pings = 0;
  {
    auto c = t::make_client(t::open_serial(io, b.server->where(), 1250000));
    boost::asio::co_spawn(
        io,
        [&]() -> boost::asio::awaitable<void> {
          for (int i = 0; i < 10; ++i) {
            const auto r = co_await c.async_execute(ping{}, boost::asio::use_awaitable);
            if (r.kind == reply_kind::ack) ++pings;
          }
          // A NACK throws, as every error does with use_awaitable (ICS 30 is not allocated).
          try {
            co_await c.async_execute(single_servo{30, 7500, 10}, boost::asio::use_awaitable);
          } catch (const boost::system::system_error& e) {
            if (e.code() == rcb4::errc::nack) ++pings;
          }
          // async_exchange hands the NACK back as a reply.
          const auto n = co_await c.async_exchange(single_servo{30, 7500, 10}, boost::asio::use_awaitable);
          if (n.kind == reply_kind::nack) ++pings;
        },
        boost::asio::detached);
    io.run();
  }
  CHECK(pings == 12);
}

TEST_CASE("usage: per-operation cancellation of a queued request and of the one on the wire", "[transport][usage]") {
  switchable_board sb;
  t::io_thread io;
  t::client_options opt;
  opt.turnaround = 30s;
  auto c = t::make_client(t::open_serial(io.context(), sb.path(), 1250000), opt);
  sb.silent = true;
  boost::asio::cancellation_signal on_wire, queued;
  std::promise<t::error_code> first, second, third;
  c.async_execute(ping{}, boost::asio::bind_cancellation_slot(
                              on_wire.slot(), [&](t::error_code ec, t::response) { first.set_value(ec); }));
  c.async_execute(ping{}, boost::asio::bind_cancellation_slot(
                              queued.slot(), [&](t::error_code ec, t::response) { second.set_value(ec); }));
  c.async_execute(ping{}, [&](t::error_code ec, t::response) { third.set_value(ec); });
  const auto start = clock_type::now();
  // Signals are emitted where their handlers run: on the client's executor.
  boost::asio::post(io.context(), [&] { queued.emit(boost::asio::cancellation_type::total); });
  CHECK(second.get_future().get() == boost::asio::error::operation_aborted);  // left the queue
  sb.silent = false;  // the third will be answered once the first is out of the way
  boost::asio::post(io.context(), [&] { on_wire.emit(boost::asio::cancellation_type::terminal); });
  CHECK(first.get_future().get() == boost::asio::error::operation_aborted);
  CHECK_FALSE(third.get_future().get());  // after a resync, the line works
  CHECK(clock_type::now() - start < 5s);
  CHECK(c.counters().resyncs >= 1);
}

TEST_CASE("usage: a request raced against a timer with awaitable operators", "[transport][usage]") {
  using namespace boost::asio::experimental::awaitable_operators;
  switchable_board sb;
  sb.silent = true;
  boost::asio::io_context io;
  t::client_options opt;
  opt.turnaround = 30s;
  auto c = t::make_client(t::open_serial(io, sb.path(), 1250000), opt);
  bool timer_won = false, recovered = false;
  boost::asio::co_spawn(
      io,
      [&]() -> boost::asio::awaitable<void> {
        boost::asio::steady_timer timer(co_await boost::asio::this_coro::executor, 100ms);
        auto winner = co_await (c.async_execute(ping{}, boost::asio::use_awaitable) ||
                                timer.async_wait(boost::asio::use_awaitable));
        timer_won = winner.index() == 1;
        sb.silent = false;
        recovered = (co_await c.async_execute(ping{}, boost::asio::use_awaitable)).kind == reply_kind::ack;
      },
      boost::asio::detached);
  const auto start = clock_type::now();
  io.run();
  CHECK(timer_won);
  CHECK(recovered);
  CHECK(clock_type::now() - start < 5s);
}

TEST_CASE("usage: blocking calls with io_thread, and with nobody running the executor", "[transport][usage]") {
  served_board b;
  SECTION("io_thread: blocking and asynchronous calls mixed") {
    t::io_thread io;
    auto c = t::make_client(t::open_serial(io.context(), b.server->where(), 1250000));
    auto f = c.async_execute(version{}, boost::asio::use_future);
    CHECK(c.execute(ping{}).kind == reply_kind::ack);
    CHECK(f.get().data.size() == 32);
    t::error_code ec;
    CHECK(c.execute(single_servo{30, 7500, 10}, ec).kind == reply_kind::nack);
    CHECK(ec == rcb4::errc::nack);
    CHECK(c.exchange(single_servo{30, 7500, 10}, ec).kind == reply_kind::nack);
    CHECK_FALSE(ec);
  }
  SECTION("a context nobody runs: an idle line still works on the caller's thread") {
    boost::asio::io_context io;
    auto c = t::make_client(t::open_serial(io, b.server->where(), 1250000));
    CHECK(c.execute(ping{}).kind == reply_kind::ack);
  }
  SECTION("a context nobody runs and a request that needs it: an error, not a hang") {
    boost::asio::io_context io;
    t::client_options opt;
    opt.direct_io = false;  // every exchange needs the executor
    opt.turnaround = 20ms;
    opt.read_retries = 0;
    auto c = t::make_client(t::open_serial(io, b.server->where(), 1250000), opt);
    const auto start = clock_type::now();
    t::error_code ec;
    c.execute(ping{}, ec);
    CHECK(ec == t::transport_errc::executor_not_running);
    CHECK(clock_type::now() - start < 3s);  // a turnaround and a second, not every request's worst case
  }
  SECTION("from the executor's own thread: would_deadlock") {
    boost::asio::io_context io;
    auto c = t::make_client(t::open_serial(io, b.server->where(), 1250000));
    t::error_code ec;
    boost::asio::post(io, [&] { c.execute(ping{}, ec); });
    io.run();
    CHECK(ec == t::transport_errc::would_deadlock);
  }
}

TEST_CASE("usage: a program between io.poll() calls destroys its client with an exchange on the wire",
          "[transport][usage]") {
  switchable_board sb;
  sb.silent = true;
  boost::asio::io_context io;
  t::client_options opt;
  opt.turnaround = 30s;
  bool called = false;
  auto c = std::make_unique<t::basic_client<t::serial_port>>(t::open_serial(io, sb.path(), 1250000), opt);
  c->async_execute(ping{}, [&](t::error_code, t::response) { called = true; });
  for (int i = 0; i < 5; ++i) io.poll();  // the request goes on the wire; nobody runs the context now
  const auto start = clock_type::now();
  c.reset();  // the worker is suspended in its read: nobody will resume it until the context runs
  CHECK(clock_type::now() - start < 1s);  // no freeze of turnaround + 1 s
  io.run();                               // the next run ends it
  CHECK(called);
}

// KONDO's USB ids, as ics.md §6 lists them (written here by hand from the table).
static_assert(t::find_kondo_adapter(0x165C, 0x0008)->line == t::adapter_line::com_or_ics);
static_assert(t::find_kondo_adapter(0x165C, 0x0002)->line == t::adapter_line::com);
static_assert(t::find_kondo_adapter(0x165C, 0x0005)->line == t::adapter_line::com);
static_assert(t::find_kondo_adapter(0x165C, 0x0007)->line == t::adapter_line::com);
static_assert(t::find_kondo_adapter(0x165C, 0x0001)->line == t::adapter_line::ics);
static_assert(t::find_kondo_adapter(0x165C, 0x0006)->line == t::adapter_line::ics);
static_assert(t::find_kondo_adapter(0x165C, 0x0009)->line == t::adapter_line::not_servos);
static_assert(!t::find_kondo_adapter(0x165C, 0x000A));
static_assert(!t::find_kondo_adapter(0x0403, 0x6001));  // a plain FTDI chip is not KONDO's

namespace {
/** The digits of the idProduct=="000[...]" pattern on the first line of @p rule that holds @p marker. */
std::string products_on(const std::string& rule, std::string_view marker) {
  std::size_t at = rule.find(marker);
  if (at == std::string::npos) return {};
  const auto start = rule.rfind("\n\n", at);  // the rule's paragraph: its lines continue with a backslash
  const auto end = rule.find("\n\n", at);
  const auto para =
      rule.substr(start == std::string::npos ? 0 : start, end == std::string::npos ? std::string::npos : end - start);
  const std::string key = "ATTRS{idProduct}==\"000[";
  const auto k = para.find(key);
  if (k == std::string::npos) return {};
  return para.substr(k + key.size(), para.find(']', k) - k - key.size());
}
}  // namespace

TEST_CASE("usage: the udev rule names every KONDO adapter that carries an RCB-4's COM or ICS line",
          "[transport][usage]") {
  std::ifstream in(RCB4_SOURCE_DIR "/cmake/udev/60-rcb4.rules");
  REQUIRE(in);
  const std::string rule{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const auto bind = products_on(rule, "new_id"), tty = products_on(rule, "SUBSYSTEM==\"tty\""),
             latency = products_on(rule, "latency_timer");
  for (const auto& a : t::kondo_adapters) {
    if (a.line == t::adapter_line::not_servos) continue;
    INFO(a.name);
    const char digit = static_cast<char>('0' + a.product);
    CHECK(tty.find(digit) != std::string::npos);
    CHECK(latency.find(digit) != std::string::npos);
    // The kernel's ftdi_sio table has 0002 itself; every other one is bound by new_id.
    CHECK((bind.find(digit) != std::string::npos) == (a.product != 0x0002));
  }
}
