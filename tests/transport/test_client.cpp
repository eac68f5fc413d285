// The client against the virtual board on a real pseudo-terminal: every API form, deadlines,
// faults on the line, many threads.
// SPDX-License-Identifier: BSL-1.0
#include "served_board.hpp"

#include <rcb4/transport/board_server.hpp>
#include <rcb4/transport/client.hpp>
#include <rcb4/transport/detect.hpp>
#include <rcb4/transport/operations.hpp>
#include <rcb4/transport/serial.hpp>
#include <rcb4/transport/tcp.hpp>

#include <boost/asio/deferred.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/use_future.hpp>
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <sys/ioctl.h>
#include <sys/stat.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <thread>

using namespace rcb4;
using namespace std::chrono_literals;
namespace t = rcb4::transport;
using rcb4::testing::served_board;

// Positive and negative concept checks.
static_assert(t::AsyncByteStream<boost::asio::serial_port>);
static_assert(t::AsyncByteStream<boost::asio::ip::tcp::socket>);
static_assert(t::AsyncByteStream<boost::asio::posix::stream_descriptor>);
static_assert(!t::AsyncByteStream<int>);
static_assert(!t::AsyncByteStream<std::vector<std::uint8_t>>);
struct read_only {
  using executor_type = boost::asio::any_io_executor;
  executor_type get_executor();
  template <class B, class H>
  void async_read_some(B, H);
};
static_assert(!t::AsyncByteStream<read_only>);

namespace {
auto open_client(t::io_thread& io, const std::string& path, t::client_options opt = {}) {
  return t::make_client(t::open_serial(io.context(), path, 1250000), std::move(opt));
}

/**
 * Whether some epoll instance of this process watches @p fd (matched by number and inode in
 * /proc/self/fdinfo): whether Asio's reactor would be woken by its input.
 */
bool watched_by_epoll(int fd) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) return false;
  char ino[32];
  std::snprintf(ino, sizeof ino, "ino:%lx ", static_cast<unsigned long>(st.st_ino));
  for (const auto& e : std::filesystem::directory_iterator("/proc/self/fd")) {
    std::error_code ec;
    if (std::filesystem::read_symlink(e.path(), ec).string() != "anon_inode:[eventpoll]") continue;
    std::ifstream info("/proc/self/fdinfo/" + e.path().filename().string());
    for (std::string line; std::getline(info, line);) {
      int n = -1;
      if (std::sscanf(line.c_str(), "tfd: %d", &n) == 1 && n == fd && line.find(ino) != std::string::npos) return true;
    }
  }
  return false;
}

/** One blocking exchange of @p cmd on @p c (its reply in @p reply, if given); how long it took. */
template <class Client>
std::chrono::steady_clock::duration timed_execute(Client& c, const command& cmd, t::error_code& ec,
                                                  t::response* reply = nullptr) {
  const auto start = std::chrono::steady_clock::now();
  auto r = c.execute(cmd, ec);
  const auto took = std::chrono::steady_clock::now() - start;
  if (reply) *reply = r;
  return took;
}
}  // namespace

TEST_CASE("client: sync execute against the virtual board", "[transport]") {
  served_board b;
  t::io_thread io;
  auto c = open_client(io, b.server->where());
  CHECK(c.execute(ping{}).kind == reply_kind::ack);
  CHECK(c.execute(move::read_ram(ram::config, 2).value()).u16() == board::default_config);
  const std::uint8_t bytes[] = {1, 2, 3};
  CHECK(c.execute(move::write_ram(0x0400, bytes).value()).kind == reply_kind::ack);
  const auto r = c.execute(move::read_ram(0x0400, 3).value());
  CHECK(r.data.size() == 3);
  CHECK(r.data[2] == 3);
  t::error_code ec;
  const auto n = c.execute(single_servo{30, 7500, 10}, ec);  // unallocated slot
  CHECK(ec == rcb4::errc::nack);
  CHECK(n.kind == reply_kind::nack);
  CHECK_THROWS_AS(c.execute(single_servo{30, 7500, 10}), t::system_error);
  CHECK(c.counters().exchanges == 6);
}

TEST_CASE("client: a blocking call on an idle line does its I/O on the caller's thread", "[transport]") {
  served_board b;
  t::io_thread io;
  t::client_options opt;
  std::thread::id io_id;
  opt.trace = [&io_id](t::direction, std::chrono::steady_clock::time_point, std::span<const std::uint8_t>) {
    io_id = std::this_thread::get_id();
  };
  opt.direct_io = GENERATE(true, false);
  auto c = open_client(io, b.server->where(), opt);
  c.async_execute(ping{}, boost::asio::use_future).get();  // Asio makes the descriptor non-blocking, once
  // Right after an async completion the worker may still hold the line for a moment (it lingers
  // for the next async request): this call may be queued. The worker does not linger after a
  // blocked caller's exchange, so the next call finds the line idle.
  CHECK(c.execute(ping{}).kind == reply_kind::ack);
  CHECK(c.execute(ping{}).kind == reply_kind::ack);
  CHECK((io_id == std::this_thread::get_id()) == opt.direct_io);
  // The async API always runs on the executor's thread, on a non-blocking descriptor as Asio's
  // reactor requires (the caller-thread driver may have left it blocking).
  c.async_execute(ping{}, boost::asio::use_future).get();
  CHECK(io_id != std::this_thread::get_id());
  CHECK((::fcntl(c.stream().native_handle(), F_GETFL) & O_NONBLOCK) != 0);
  CHECK(c.counters().exchanges == 4);
  CHECK(c.counters().bytes_out == 16);
  CHECK(c.counters().bytes_in == 16);
}

TEST_CASE("client: while blocking calls use the line, the reactor does not watch it", "[transport]") {
  served_board b;
  t::io_thread io;
  t::client_options opt;
  opt.direct_io = GENERATE(true, false);
  auto port = t::open_serial(io.context(), b.server->where(), 1250000);
  const int fd = port.native_handle();
  REQUIRE(watched_by_epoll(fd));  // Asio registers a descriptor when the stream takes it
  auto c = t::make_client(std::move(port), opt);
  CHECK(c.execute(ping{}).kind == reply_kind::ack);
  // Parked on the caller's thread: its replies no longer wake the executor's thread as well.
  CHECK(watched_by_epoll(fd) == !opt.direct_io);
  CHECK(c.execute(ping{}).kind == reply_kind::ack);
  CHECK(watched_by_epoll(fd) == !opt.direct_io);
  // The worker takes it back (same descriptor) for the asynchronous API, then gives it up again.
  CHECK(c.async_execute(ping{}, boost::asio::use_future).get().kind == reply_kind::ack);
  CHECK(watched_by_epoll(fd));
  // Right after an async completion the worker may linger a moment (for a next async request),
  // so this call may still be queued to it; it does not linger after a blocked caller's.
  CHECK(c.execute(ping{}).kind == reply_kind::ack);
  CHECK(c.execute(ping{}).kind == reply_kind::ack);
  CHECK(watched_by_epoll(fd) == !opt.direct_io);
  // stream() gives it back to the stream, for settings.
  CHECK(c.stream().native_handle() == fd);
  CHECK(watched_by_epoll(fd));
  CHECK(c.execute(ping{}).kind == reply_kind::ack);
  CHECK(c.counters().exchanges == 6);
}

TEST_CASE("client: a parked socket goes back to the worker intact", "[transport]") {
  board::virtual_board vb;
  t::io_thread server_io;
  auto server = t::board_server::serve_tcp(server_io.context(), vb, {boost::asio::ip::make_address("127.0.0.1"), 0});
  {
    t::io_thread io;
    auto c = t::make_client(t::connect(io.context(), server->where()));
    for (int i = 0; i < 3; ++i) {
      CHECK(c.execute(ping{}).kind == reply_kind::ack);                                           // parked
      CHECK(c.async_execute(version{}, boost::asio::use_future).get().kind == reply_kind::data);  // assigned back
    }
    CHECK(c.stream().remote_endpoint().port() != 0);
  }
  t::board_server::shutdown(server);
}

TEST_CASE("board_server: a paced reply never comes before the wire would have carried it", "[transport][pace]") {
  t::serve_options so;
  so.pace = true;
  served_board b(so);
  t::io_thread io;
  auto c = open_client(io, b.server->where());
  const auto read = move::read_ram(0x0400, 128).value();  // 10 bytes out, 131 back
  const auto wire = t::wire_time(10 + 131, 1250000);      // the board's boot rate
  for (int i = 0; i < 20; ++i) {
    c.options().busy_poll = i % 2 ? 200us : 0us;  // the client's wait, sleeping or polling, changes nothing here
    t::error_code ec;
    t::response r;
    CHECK(timed_execute(c, read, ec, &r) >= wire);  // a lower bound the pacer guarantees
    CHECK_FALSE(ec);
    CHECK(r.data.size() == 128);
  }
}

namespace {
/** The measured positions (+4) of 20 servo blocks 20 bytes apart, as a KHR-3HV's reads want them. */
std::vector<ops::byte_range> khr3hv_positions() {
  std::vector<ops::byte_range> positions;
  for (std::uint32_t k = 0; k < 20; ++k) positions.push_back({0x0094 + 20 * k, 2});
  return positions;
}
}  // namespace

TEST_CASE("measure_link: a board behind 2 ms of latency costs at least that per exchange", "[transport][pace]") {
  t::serve_options so;
  so.pace = true;
  so.latency = 2000us;
  served_board b(so);
  t::io_thread io;
  auto c = open_client(io, b.server->where());
  c.options().baud = 1250000;
  t::error_code ec;
  // A measurement is timing: on a loaded machine a busy spell can shorten a pair's difference
  // (the short read waited, the long one did not), so it is measured up to five times and the
  // link must be seen paced in one of them (an unpaced one never is: the test below).
  auto cost = t::measure_link(c, ec, 5);
  REQUIRE_FALSE(ec);
  for (int again = 0; again < 4 && cost.byte_time != 8800ns; ++again) {
    cost = t::measure_link(c, ec, 5);
    REQUIRE_FALSE(ec);
  }
  CHECK(cost.exchange >= 2000us);   // the board never answers sooner; the wire time is not counted in it
  CHECK(cost.byte_time == 8800ns);  // 11 bits at 1.25 Mbaud
  // Behind such a link the planner reads the 20 servos' positions (+4, 20 bytes apart) in long reads.
  const auto positions = khr3hv_positions();
  CHECK(ops::plan_reads(positions, cost).size() == 3);  // 7 + 7 + 6 positions: a read of 128 bytes spans 7
  // The line failing is an error, not a cost (shutdown stops the server on its own thread).
  t::board_server::shutdown(b.server);
  t::measure_link(c, ec, 3);
  CHECK(ec);
}

TEST_CASE("measure_link: a board that is not paced is measured as it is, not as its baud", "[transport][pace]") {
  served_board b;  // no --pace: replies come as fast as the pty carries them, at any baud
  t::io_thread io;
  auto c = open_client(io, b.server->where());
  c.options().baud = 1250000;
  t::error_code ec;
  // 126 more bytes took less than half their 1.1 ms at 1.25 Mbaud: the bytes cost what was
  // measured, and so the planner merges, as it should on such a link (a read costs little more
  // for more bytes), instead of planning 20 reads for a rate the link does not have. A
  // measurement is timing: on a loaded machine one may come out slow, so it is measured up to
  // five times, and the link must be seen so in one of them (a paced link never is: the test above).
  const auto positions = khr3hv_positions();
  auto cost = t::measure_link(c, ec, 5);
  REQUIRE_FALSE(ec);
  for (int again = 0; again < 4 && (cost.byte_time >= 4400ns || ops::plan_reads(positions, cost).size() != 3);
       ++again) {
    cost = t::measure_link(c, ec, 5);
    REQUIRE_FALSE(ec);
  }
  CHECK(cost.byte_time < 4400ns);
  CHECK(cost.exchange > 0ns);  // an exchange still costs something: the round trip through the pty
  CHECK(ops::plan_reads(positions, cost).size() == 3);
}

TEST_CASE("client: callback, future, coroutine and deferred completions", "[transport]") {
  served_board b;
  t::io_thread io;
  auto c = open_client(io, b.server->where());
  std::promise<t::error_code> p;
  c.async_execute(ping{}, [&p](boost::system::error_code ec, t::response) { p.set_value(ec); });
  CHECK(p.get_future().get() == t::error_code{});
  // use_future: the error arrives as an exception, the response as the value.
  auto f = c.async_execute(version{}, boost::asio::use_future);
  CHECK(f.get().data.size() == 32);
  auto fut = boost::asio::co_spawn(
      io.context(),
      [&c]() -> boost::asio::awaitable<std::uint16_t> {
        auto r = co_await c.async_execute(move::read_ram(ram::pio_direction, 2).value(), boost::asio::use_awaitable);
        co_return r.u16();
      },
      boost::asio::use_future);
  CHECK(fut.get() == 0x03FF);
  auto op = c.async_execute(ping{}, boost::asio::deferred);
  std::promise<bool> d;
  std::move(op)([&d](boost::system::error_code ec, t::response r) { d.set_value(!ec && r.kind == reply_kind::ack); });
  // use_future and use_awaitable throw on error, as everywhere in Asio.
  auto nack = c.async_execute(single_servo{30, 7500, 10}, boost::asio::use_future);
  CHECK_THROWS_AS(nack.get(), boost::system::system_error);
  CHECK(d.get_future().get());
}

TEST_CASE("client: a silent board times out within the deadline", "[transport]") {
  t::pty_pair silent;  // nobody answers on the other side
  t::io_thread io;
  t::client_options opt;
  opt.turnaround = 20ms;
  opt.direct_io = GENERATE(true, false);  // the caller's thread does the first attempt, or the executor's
  opt.busy_poll = GENERATE(0us, 300us);   // a busy-polling wait still ends at the deadline
  INFO("direct_io " << opt.direct_io << ", busy_poll " << opt.busy_poll.count() << " us");
  auto c = open_client(io, silent.path(), opt);
  t::error_code ec;
  const auto took = timed_execute(c, ping{}, ec);
  CHECK(ec == t::transport_errc::timeout);
  CHECK(c.counters().timeouts == 3);  // a ping is idempotent: 1 + 2 retries
  CHECK(c.counters().retries == 2);
  CHECK(took < 2s);                          // a hang check, not a speed target: 3 × (20 ms + wire time)
  c.execute(single_servo{0, 7500, 10}, ec);  // a write is not retried
  CHECK(ec == t::transport_errc::timeout);
  CHECK(c.counters().timeouts == 4);
}

TEST_CASE("client: a deadline earlier than the previous exchange's still holds", "[transport]") {
  // The worker's timer watches many exchanges with one wait while deadlines only move later; a
  // shorter deadline must replace that wait, or it would fire when the earlier, longer one ends.
  std::atomic<bool> silent{false};
  t::serve_options so;
  so.tamper = [&silent](std::vector<std::uint8_t>& reply) {
    if (silent) reply.clear();
  };
  served_board b(so);
  t::io_thread io;
  t::client_options opt;
  opt.direct_io = false;  // the worker (and its timer) runs every exchange
  opt.turnaround = 30s;
  auto c = open_client(io, b.server->where(), opt);
  CHECK(c.execute(ping{}).kind == reply_kind::ack);  // leaves a wait outstanding until ~30 s from now
  c.options().turnaround = 20ms;
  silent = true;
  t::error_code ec;
  const auto took = timed_execute(c, ping{}, ec);
  CHECK(ec == t::transport_errc::timeout);
  CHECK(c.counters().timeouts == 3);
  CHECK(took < 2s);  // a hang check: 3 × (20 ms + wire time), where the stale wait would take 30 s
  silent = false;
  CHECK(c.execute(ping{}).kind == reply_kind::ack);  // and the line recovers
}

TEST_CASE("client: on a tty, a wait of whole tenths blocks in read() and still ends at its deadline", "[transport]") {
  t::pty_pair silent;
  t::io_thread io;
  t::client_options opt;
  opt.turnaround = 250ms;  // two tenths in a bounded read (the terminal's own timer), the rest in ppoll
  opt.read_retries = 0;
  auto c = open_client(io, silent.path(), opt);
  t::error_code ec;
  const auto took = timed_execute(c, ping{}, ec);
  CHECK(ec == t::transport_errc::timeout);
  CHECK(took >= 250ms);  // not before the deadline
  CHECK(took < 2s);      // a hang check, not a speed target
}

TEST_CASE("client: faults on the line never turn into wrong data, and the line recovers", "[transport]") {
  std::atomic<int> mode{0};
  t::serve_options so;
  so.tamper = [&mode](std::vector<std::uint8_t>& reply) {
    switch (mode.load()) {
      case 1: reply.clear(); break;                                          // dropped
      case 2: reply.back() ^= 0x01; break;                                   // corrupted checksum
      case 3: reply.insert(reply.begin(), {0xAA, 0x55}); break;              // garbage first
      case 4: reply.insert(reply.end(), reply.begin(), reply.end()); break;  // duplicated
      case 5: reply[2] ^= 0x10; break;                                       // a data bit flipped
      default: break;
    }
  };
  served_board b(so);
  t::io_thread io;
  t::client_options opt;
  opt.turnaround = 20ms;
  opt.read_retries = 0;
  opt.direct_io = GENERATE(true, false);
  INFO("direct_io " << opt.direct_io);
  auto c = open_client(io, b.server->where(), opt);
  const auto read = move::read_ram(ram::pio_direction, 2).value();
  for (int m : {1, 2, 3, 5}) {
    INFO("fault mode " << m);
    mode = m;
    t::error_code ec;
    const auto r = c.execute(read, ec);
    if (!ec)
      CHECK(r.u16() == 0x03FF);  // if anything is accepted, it is the right value
    else
      CHECK(r.data.empty());
    mode = 0;
    CHECK(c.execute(read).u16() == 0x03FF);  // the next exchange starts on a clean line
  }
  // Split and late replies (pieces written with delays, as a slow adapter or a busy board would).
  t::serve_options so2;
  std::atomic<int> timing{0};
  so2.pieces = [&timing](std::size_t size) -> std::vector<t::reply_piece> {
    switch (timing.load()) {
      case 1: return {{0us, 1}, {3ms, 2}, {3ms, size}};                          // split in three, in time
      case 2: return std::vector<t::reply_piece>(size, t::reply_piece{1ms, 1});  // byte by byte
      case 3: return {{250ms, size}};                                            // after the deadline
      case 4: return {{0us, size / 2}, {250ms, size}};                           // half, then late
      default: return {};
    }
  };
  served_board late(so2);
  // A deadline of 60 ms beyond the wire time: the pieces in time (6 ms of pauses) arrive well
  // within it on a loaded machine, the late ones (250 ms) well after it.
  auto opt2 = opt;
  opt2.turnaround = 60ms;
  auto c2 = open_client(io, late.server->where(), opt2);
  const auto config = move::read_ram(ram::config, 2).value();
  for (int m : {1, 2}) {
    INFO("timing mode " << m);
    timing = m;
    CHECK(c2.execute(read).u16() == 0x03FF);  // a reply in pieces is still one reply
  }
  for (int m : {3, 4}) {
    INFO("timing mode " << m);
    timing = m;
    t::error_code ec;
    c2.execute(read, ec);
    // Nothing in time is a timeout; half a reply, then nothing in time, says that it stopped short.
    CHECK(ec == (m == 3 ? t::error_code(t::transport_errc::timeout) : t::error_code(t::transport_errc::truncated)));
    timing = 0;
    // The late PIO reply has the same shape as the config reply: it must never be taken for it.
    // (The exchange right after may itself time out while the line resynchronises.)
    bool answered = false;
    for (int k = 0; k < 5 && !answered; ++k) {
      const auto r = c2.execute(config, ec);
      if (!ec) {
        CHECK(r.u16() == board::default_config);
        answered = true;
      }
    }
    CHECK(answered);
  }

  // A duplicated reply: the copy left on the line is drained, not taken as the next reply.
  mode = 4;
  CHECK(c.execute(ping{}).kind == reply_kind::ack);
  mode = 0;
  CHECK(c.execute(read).u16() == 0x03FF);
  CHECK(c.execute(move::read_ram(ram::config, 2).value()).u16() == board::default_config);
}

TEST_CASE("client: 8 threads, every reply reaches its caller", "[transport][threads]") {
  served_board b;
  t::io_thread io;
  t::client_options opt;
  opt.turnaround = 2s;  // this test is about matching replies to callers, not latency (sanitizers, 2 cores)
  auto c = open_client(io, b.server->where(), opt);
  constexpr int threads = 8, per_thread = 10000;
  std::atomic<int> wrong{0}, failed{0};
  std::vector<std::thread> workers;
  for (int k = 0; k < threads; ++k) {
    workers.emplace_back([&, k] {
      const auto addr = ram_address::make(0x0400 + 2 * k).value();
      for (int i = 0; i < per_thread; ++i) {
        const std::uint16_t v = static_cast<std::uint16_t>(k * 4096 + i);
        const std::uint8_t bytes[] = {static_cast<std::uint8_t>(v & 0xFF), static_cast<std::uint8_t>(v >> 8)};
        // Even threads block (their exchanges run on their own thread when the line is idle);
        // odd threads use the async API (queued for the executor's worker): the two interleave.
        const auto exchange = [&](const command& cmd, t::error_code& ec) {
          if (k % 2 == 0) return c.execute(cmd, ec);
          std::promise<std::pair<t::error_code, t::response>> done;
          c.async_execute(cmd, [&done](boost::system::error_code e, t::response r) { done.set_value({e, r}); });
          auto [e, r] = done.get_future().get();
          ec = e;
          return r;
        };
        t::error_code ec;
        if (i % 2 == 0) {
          exchange(move::write_ram(addr, bytes).value(), ec);
        } else {
          const auto r = exchange(move::read_ram(addr, 2).value(), ec);
          if (!ec && r.u16() != static_cast<std::uint16_t>(v - 1)) ++wrong;
        }
        if (ec) ++failed;
      }
    });
  }
  for (auto& w : workers) w.join();
  CHECK(wrong == 0);
  CHECK(failed == 0);
  CHECK(c.counters().exchanges == threads * per_thread);
}

TEST_CASE("client: destroying a client with exchanges in flight ends them, no hang", "[transport]") {
  t::pty_pair silent;
  t::io_thread io;
  std::promise<boost::system::error_code> first, second;
  const auto start = std::chrono::steady_clock::now();
  {
    t::client_options opt;
    opt.turnaround = 10s;  // the deadline is far away: only the destructor can end these
    auto c = open_client(io, silent.path(), opt);
    c.async_execute(ping{}, [&](boost::system::error_code ec, t::response) { first.set_value(ec); });
    c.async_execute(ping{}, [&](boost::system::error_code ec, t::response) { second.set_value(ec); });
  }
  const auto e1 = first.get_future().get();
  const auto e2 = second.get_future().get();
  CHECK(e1);
  CHECK(e2 == t::transport_errc::cancelled);
  CHECK(std::chrono::steady_clock::now() - start < 5s);
}

TEST_CASE("client: TCP through Debian's ser2net bridging to the board's pty", "[transport][ser2net]") {
  if (std::system("command -v ser2net > /dev/null 2>&1") != 0) {
    WARN("ser2net is not installed (cmake/install-deps.sh installs it): skipped");
    return;
  }
  served_board b;
  // A free loopback port: bind to 0, read it, release it for ser2net.
  boost::asio::io_context probe;
  boost::asio::ip::tcp::acceptor a(probe, {boost::asio::ip::make_address("127.0.0.1"), 0});
  const auto port = a.local_endpoint().port();
  a.close();
  const std::string dir = std::filesystem::temp_directory_path() / ("rcb4-ser2net-" + std::to_string(port));
  std::filesystem::create_directories(dir);
  {
    std::ofstream cfg(dir + "/ser2net.yaml");
    cfg << "connection: &rcb4\n  accepter: tcp,127.0.0.1," << port << "\n  connector: serialdev," << b.server->where()
        << ",115200e81,local\n  options:\n    kickolduser: true\n";
  }
  const std::string cmd = "ser2net -n -d -c " + dir + "/ser2net.yaml -P " + dir + "/pid > " + dir +
                          "/log 2>&1 & echo $! > " + dir + "/child";
  REQUIRE(std::system(cmd.c_str()) == 0);
  t::io_thread io;
  t::error_code ec;
  t::tcp_socket s(io.context());
  for (int i = 0; i < 100; ++i) {  // ser2net needs a moment to listen; bounded
    s = t::connect(io.context(), "127.0.0.1:" + std::to_string(port), ec);
    if (!ec) break;
    std::this_thread::sleep_for(20ms);
  }
  REQUIRE_FALSE(ec);
  {
    auto c = t::make_client(std::move(s));
    CHECK(c.execute(ping{}).kind == reply_kind::ack);
    CHECK(c.execute(move::read_ram(ram::config, 2).value()).u16() == board::default_config);
    CHECK(t::run(c, ops::read_analog{}).battery_volts == Approx(10.8).margin(0.1));
  }
  // Stop ser2net and wait (bounded) until it has gone: it removes its pid file on the way out.
  std::system(("p=$(cat " + dir +
               "/child); kill $p 2>/dev/null; for i in $(seq 100); do kill -0 $p 2>/dev/null || break; " +
               "sleep 0.02; done")
                  .c_str());
  t::error_code rm;
  std::filesystem::remove_all(dir, rm);
}

TEST_CASE("client: operations run on the client, baud detection, bad addresses", "[transport]") {
  served_board b;
  t::io_thread io;
  t::error_code ec;
  CHECK(t::detect_baud(io.context(), b.server->where(), ec) == 1250000);  // a pty answers at the first rate
  CHECK_FALSE(ec);
  CHECK(t::detect_baud(io.context(), "/dev/does-not-exist", ec) == 0);
  CHECK(ec == std::errc::no_such_file_or_directory);
  auto c = open_client(io, b.server->where());
  const auto states = t::run(c, ops::read_servo_states{});
  CHECK(states.size() == 20);
  auto fut = boost::asio::co_spawn(io.context(), t::async_run(c, ops::read_motion_state{}), boost::asio::use_future);
  CHECK_FALSE(fut.get().running);
  // Any completion token: a callback, a future, deferred; the operation's own error arrives as the code.
  std::promise<std::pair<t::error_code, std::size_t>> called;
  t::async_run(c, ops::read_servo_states{}, [&](t::error_code e, auto s) { called.set_value({e, s.size()}); });
  const auto [called_ec, called_n] = called.get_future().get();
  CHECK_FALSE(called_ec);
  CHECK(called_n == 20);
  auto version_fut = t::async_run(c, ops::read_version{}, boost::asio::use_future);
  CHECK_FALSE(version_fut.get().empty());
  std::promise<std::pair<t::error_code, bool>> refused;  // (no Catch assertion off the test's thread)
  t::async_run(c, ops::read_memory(ops::memory::ram, 0x0480, 32),
               boost::asio::deferred)([&](t::error_code e, const std::vector<std::uint8_t>& data) {
    refused.set_value({e, data.empty()});
  });
  const auto [refused_ec, no_data] = refused.get_future().get();
  CHECK(refused_ec == rcb4::errc::ram_address_out_of_range);
  CHECK(no_data);  // no partial value with an error
  ops::read_memory bad(ops::memory::ram, 0x0480, 32);
  t::run(c, bad, ec);
  CHECK(ec == rcb4::errc::ram_address_out_of_range);
  t::connect(io.context(), "no-port", ec);
  CHECK(ec);
  t::connect(io.context(), "127.0.0.1:1", ec);  // nothing listens there
  CHECK(ec);
}

TEST_CASE("open_serial: 8E1, raw, the rate read back, exclusive, and clear errors", "[transport]") {
  served_board b;
  t::io_thread io;
  t::serial_info info;
  auto port = t::open_serial(io.context(), b.server->where(), 625000, &info);
  CHECK(info.baud == 625000);
  termios tio{};
  REQUIRE(::tcgetattr(port.native_handle(), &tio) == 0);
  CHECK((tio.c_cflag & CSIZE) == CS8);  // 8 data bits
  // Even parity (protocol.md §1): a pty's driver drops PARENB (ptys have no parity), so only
  // "not odd" shows here; the hardware tier (tests/hardware) checks PARENB on a real adapter.
  CHECK((tio.c_cflag & PARODD) == 0);
  CHECK((tio.c_cflag & CSTOPB) == 0);  // 1 stop bit
  CHECK((tio.c_cflag & (CREAD | CLOCAL)) == (CREAD | CLOCAL));
  CHECK((tio.c_cflag & CRTSCTS) == 0);                 // no flow control
  CHECK((tio.c_iflag & (IXON | IXOFF | ICRNL)) == 0);  // no XON/XOFF, no translation
  CHECK((tio.c_lflag & (ICANON | ECHO | ISIG)) == 0);  // raw
  CHECK((tio.c_oflag & OPOST) == 0);
  CHECK(tio.c_cc[VMIN] == 1);  // an empty non-blocking read is EAGAIN, not an end of file
  t::error_code ec;
  t::open_serial(io.context(), b.server->where(), 625000, ec);  // a second opener
  CHECK(ec == t::transport_errc::port_busy);
  t::open_serial(io.context(), "/dev/null", 115200, ec);  // not a terminal
  CHECK(ec == std::errc::inappropriate_io_control_operation);
  t::open_serial(io.context(), "/dev/does-not-exist", 115200, ec);
  CHECK(ec == std::errc::no_such_file_or_directory);
  // Exclusive mode is the terminal's, not the descriptor's: it must end with the client, or the
  // next open by a user without root fails with EBUSY while the pty's server holds it open.
  int other = ::open(b.server->where().c_str(), O_RDWR | O_NOCTTY);  // root may open it anyway
  int exclusive = -1;
  if (other < 0) {
    CHECK(errno == EBUSY);  // not root: exclusive mode refuses a second opener
  } else {
    REQUIRE(::ioctl(other, TIOCGEXCL, &exclusive) == 0);
    CHECK(exclusive == 1);
  }
  {
    // The port works through the client at the rate it was opened at.
    t::client_options opt;
    opt.baud = 625000;
    auto c = t::make_client(std::move(port), opt);
    CHECK(c.execute(ping{}).kind == reply_kind::ack);  // (the descriptor is parked when the client goes)
  }
  if (other < 0) other = ::open(b.server->where().c_str(), O_RDWR | O_NOCTTY);
  REQUIRE(other >= 0);
  REQUIRE(::ioctl(other, TIOCGEXCL, &exclusive) == 0);
  CHECK(exclusive == 0);
  ::close(other);
}
