// Opening the line whatever state another program left it in, detection that names the real
// cause, and a peer that has gone never raising SIGPIPE.
// SPDX-License-Identifier: BSL-1.0
#include "pty_echo.hpp"
#include "served_board.hpp"

#include <rcb4/transport/client.hpp>
#include <rcb4/transport/detect.hpp>
#include <rcb4/transport/serial.hpp>
#include <rcb4/transport/tcp.hpp>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <signal.h>
#include <termios.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>

using namespace rcb4;
using namespace std::chrono_literals;
namespace t = rcb4::transport;
using rcb4::testing::served_board;

namespace {
/** What a raw C client does (librcb4, most C tools): raw, 8E1 at B115200 with tcsetattr, then close. */
void leave_like_a_c_client(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY);
  REQUIRE(fd >= 0);
  termios tio{};
  ::tcgetattr(fd, &tio);
  ::cfmakeraw(&tio);
  tio.c_cflag |= PARENB | CS8 | CLOCAL | CREAD;
  ::cfsetspeed(&tio, B115200);
  ::tcsetattr(fd, TCSANOW, &tio);  // (a pty drops PARENB; glibc may say EINVAL: the C client ignores it)
  ::close(fd);
}
/** What pyserial does for 1250000 baud: termios2 BOTHER with the rate, raw, even parity. */
void leave_like_pyserial(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
  REQUIRE(fd >= 0);
  termios tio{};
  ::tcgetattr(fd, &tio);
  ::cfmakeraw(&tio);
  tio.c_cflag |= PARENB | CS8 | CLOCAL | CREAD;
  ::tcsetattr(fd, TCSANOW, &tio);
  CHECK(t::detail::set_custom_baud(fd, 1250000).value_or(0) == 1250000);
  ::close(fd);
}
/** What a person at a shell does: `stty sane` (cooked: echo, line editing, CR/NL translation) at 9600. */
void leave_cooked_by_stty(const std::string& path) {
  REQUIRE(std::system(("stty -F " + path + " sane 9600").c_str()) == 0);
  // and odd framing on top (a pty keeps what it can; stty then says so on stderr)
  [[maybe_unused]] const int r = std::system(("stty -F " + path + " cs7 cstopb crtscts parodd 2>/dev/null").c_str());
}
}  // namespace

TEST_CASE("open_serial: a pty in whatever state another program left it opens and answers, 10 times in a row",
          "[transport][line]") {
  served_board b;
  t::io_thread io;
  const std::string& path = b.server->where();
  const auto state = GENERATE(0, 1, 2);
  const char* names[] = {"raw 8E1 at 115200 by a C client", "BOTHER at 1250000 by pyserial", "cooked by stty"};
  INFO(names[state]);
  for (int i = 0; i < 10; ++i) {
    if (state == 0) leave_like_a_c_client(path);
    if (state == 1) leave_like_pyserial(path);
    if (state == 2) leave_cooked_by_stty(path);
    t::error_code ec;
    t::serial_info info;
    const std::uint32_t rate = i % 2 == 0 ? 1250000 : 115200;
    auto port = t::open_serial(io.context(), path, rate, ec, &info);
    REQUIRE_FALSE(ec);
    CHECK(info.baud == rate);
    CHECK_FALSE(info.parity);  // a pty has no parity: said, not refused
    termios tio{};
    REQUIRE(::tcgetattr(port.native_handle(), &tio) == 0);
    CHECK((tio.c_lflag & (ICANON | ECHO | ISIG)) == 0);
    CHECK((tio.c_cflag & CSIZE) == CS8);
    CHECK((tio.c_cflag & (CSTOPB | CRTSCTS)) == 0);
    CHECK((tio.c_oflag & OPOST) == 0);
    CHECK((tio.c_iflag & (ICRNL | IXON)) == 0);
    CHECK(tio.c_cc[VMIN] == 1);
    t::client_options opt;
    opt.baud = rate;
    auto c = t::make_client(std::move(port), opt);
    CHECK(c.execute(ping{}).kind == reply_kind::ack);
    CHECK(c.execute(version{}).data.size() == 32);
  }
}

TEST_CASE("detect_baud: the real cause when no board answers, and the frames in the trace", "[transport][line]") {
  t::io_thread io;
  t::error_code ec;
  SECTION("not a board at all: the OS's word, at once") {
    CHECK(t::detect_baud(io.context(), "/dev/null", ec) == 0);
    CHECK(ec == std::errc::inappropriate_io_control_operation);
    CHECK(t::detect_baud(io.context(), "/dev/does-not-exist", ec) == 0);
    CHECK(ec == std::errc::no_such_file_or_directory);
    CHECK(t::detect_baud(io.context(), std::filesystem::temp_directory_path().string(), ec) == 0);
    CHECK(ec == std::errc::is_a_directory);
    const auto file = std::filesystem::temp_directory_path() / "rcb4-detect-regular-file";
    std::ofstream(file) << "not a tty";
    CHECK(t::detect_baud(io.context(), file.string(), ec) == 0);
    CHECK(ec == std::errc::inappropriate_io_control_operation);
    std::filesystem::remove(file);
  }
  SECTION("a port another program holds") {
    served_board b;
    auto holder = t::open_serial(io.context(), b.server->where(), 115200);
    CHECK(t::detect_baud(io.context(), b.server->where(), ec) == 0);
    CHECK(ec == t::transport_errc::port_busy);
  }
  SECTION("a board that answers NACK") {
    t::serve_options so;
    so.tamper = [](std::vector<std::uint8_t>& reply) { reply = {0x04, 0xFE, 0x15, 0x17}; };  // protocol.md §2.2
    served_board b(so);
    CHECK(t::detect_baud(io.context(), b.server->where(), ec) == 0);
    CHECK(ec == rcb4::errc::nack);
  }
  SECTION("replies with bad checksums") {
    t::serve_options so;
    so.tamper = [](std::vector<std::uint8_t>& reply) { reply.back() ^= 0x5A; };
    served_board b(so);
    CHECK(t::detect_baud(io.context(), b.server->where(), ec) == 0);
    CHECK(ec == rcb4::errc::bad_checksum);
  }
  SECTION("a loopback (a pty that echoes): never a board") {
    rcb4::testing::pty_echo echo(io.context());
    CHECK(t::detect_baud(io.context(), echo.path(), ec) == 0);
    CHECK(ec == t::transport_errc::echo);
  }
  SECTION("silence at every rate, and the trace shows each rate's pings") {
    t::pty_pair silent;
    t::detect_options how;
    how.turnaround = 20ms;
    std::vector<std::vector<std::uint8_t>> sent;
    how.trace = [&sent](t::direction d, std::chrono::steady_clock::time_point, std::span<const std::uint8_t> b) {
      if (d == t::direction::tx) sent.emplace_back(b.begin(), b.end());
    };
    CHECK(t::detect_baud(io.context(), silent.path(), ec, how) == 0);
    CHECK(ec == t::transport_errc::no_board);
    REQUIRE(sent.size() >= 6);                                     // 3 rates × 2 pings at least (resyncs come on top)
    const std::vector<std::uint8_t> short_ping{0x03, 0xFE, 0x01};  // protocol.md §4.11
    CHECK(sent.front() == short_ping);
  }
  SECTION("a board answers: its rate") {
    served_board b;
    CHECK(t::detect_baud(io.context(), b.server->where(), ec) == 1250000);  // a pty answers at the first rate
    CHECK_FALSE(ec);
  }
}

namespace {
int sigpipes = 0;
extern "C" void count_sigpipe(int) { ++sigpipes; }

/** Counts SIGPIPE while it lives (a process left with the default action would die of it). */
struct sigpipe_counter {
  struct sigaction old {};
  sigpipe_counter() {
    sigpipes = 0;
    struct sigaction sa {};
    sa.sa_handler = count_sigpipe;
    ::sigaction(SIGPIPE, &sa, &old);
  }
  ~sigpipe_counter() { ::sigaction(SIGPIPE, &old, nullptr); }
  sigpipe_counter(const sigpipe_counter&) = delete;
  sigpipe_counter& operator=(const sigpipe_counter&) = delete;
};
}  // namespace

TEST_CASE("a peer that has gone is an error, never SIGPIPE, on every stream type", "[transport][line]") {
  sigpipe_counter counter;
  t::io_thread io;
  const bool direct = GENERATE(true, false);  // the caller-thread driver, or the worker
  INFO("direct_io " << direct);
  t::client_options opt;
  opt.direct_io = direct;
  opt.turnaround = 50ms;
  SECTION("a TCP socket whose peer closed, as a socket and wrapped as a descriptor (the CLI's tcp:)") {
    boost::asio::ip::tcp::acceptor acceptor(io.context(), {boost::asio::ip::make_address("127.0.0.1"), 0});
    const auto where = "127.0.0.1:" + std::to_string(acceptor.local_endpoint().port());
    for (const bool wrapped : {false, true}) {
      INFO("wrapped " << wrapped);
      auto socket = t::connect(io.context(), where);
      acceptor.accept().close();  // the peer goes: a write after its reset raises SIGPIPE with write()
      std::this_thread::sleep_for(20ms);
      const auto three_writes = [](auto c) {
        for (int i = 0; i < 3; ++i) {  // the first write may still leave; its reply is a reset or EOF
          t::error_code ec;
          c.execute(single_servo{0, 7500, 10}, ec);
          CHECK(ec);
        }
      };
      if (wrapped)
        three_writes(
            t::make_client(boost::asio::posix::stream_descriptor(io.context(), ::dup(socket.native_handle())), opt));
      else
        three_writes(t::make_client(std::move(socket), opt));
    }
  }
  SECTION("a pty whose master side closed") {
    t::pty_pair pty;
    const int master = pty.release_master();
    auto port = t::open_serial(io.context(), pty.path(), 1250000);
    ::close(master);
    auto c = t::make_client(std::move(port), opt);
    t::error_code ec;
    c.execute(single_servo{0, 7500, 10}, ec);
    CHECK(ec);
    CHECK(t::is_link_lost(ec));
  }
  CHECK(sigpipes == 0);
}

TEST_CASE("a TCP peer that has gone: every later exchange says so at once, never a timeout", "[transport][line]") {
  t::io_thread io;
  boost::asio::ip::tcp::acceptor acceptor(io.context(), {boost::asio::ip::make_address("127.0.0.1"), 0});
  auto socket = t::connect(io.context(), "127.0.0.1:" + std::to_string(acceptor.local_endpoint().port()));
  acceptor.accept().close();
  std::this_thread::sleep_for(20ms);
  t::client_options opt;
  opt.turnaround = 200ms;
  auto c = t::make_client(std::move(socket), opt);
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 6; ++i) {
    INFO("exchange " << i);
    t::error_code ec;
    if (i % 2 == 0) {
      std::promise<t::error_code> done;
      c.async_execute(ping{}, [&done](t::error_code e, t::response) { done.set_value(e); });
      ec = done.get_future().get();
    } else {
      c.execute(ping{}, ec);
    }
    CHECK(ec);
    CHECK(t::is_link_lost(ec));  // (an edge-triggered write waiting for a hang-up seen before gave timeouts)
  }
  CHECK(c.counters().timeouts == 0);
  CHECK(std::chrono::steady_clock::now() - start < 1s);
}

TEST_CASE("a client on a pty's master side (a test harness's setup) still has its deadlines", "[transport][line]") {
  // The master's termios belongs to the slave: a VTIME bound set on it would not limit a read.
  t::pty_pair pty;  // nobody answers on the slave side
  t::io_thread io;
  t::client_options opt;
  opt.turnaround = 300ms;  // whole tenths: a terminal's read would be bounded by VTIME
  opt.read_retries = 0;
  auto c = t::make_client(boost::asio::posix::stream_descriptor(io.context(), pty.release_master()), opt);
  const auto start = std::chrono::steady_clock::now();
  t::error_code ec;
  c.execute(ping{}, ec);
  CHECK(ec == t::transport_errc::timeout);
  CHECK(std::chrono::steady_clock::now() - start < 2s);
}

TEST_CASE("connect: a missing, empty, non-numeric or too large port is refused, not wrapped", "[transport][line]") {
  t::io_thread io;
  for (const char* where : {"127.0.0.1", "127.0.0.1:", "127.0.0.1:http", "127.0.0.1:99999", "127.0.0.1:123456"}) {
    INFO(where);
    t::error_code ec;
    t::connect(io.context(), where, ec);
    CHECK(ec == std::errc::invalid_argument);
  }
  CHECK_THROWS_AS(t::connect(io.context(), "127.0.0.1:99999"), t::system_error);
}
