// The failure matrix: for every n, the n-th read or write on the line fails (connection reset, or
// end of file as when a cable is pulled). Each exchange must
// end (no hang), never deliver wrong data, and the exchanges after the failure must succeed.
// SPDX-License-Identifier: BSL-1.0
#include "fake_stream.hpp"

#include <rcb4/transport/client.hpp>

#include <catch2/catch.hpp>

using namespace rcb4;
using namespace std::chrono_literals;
namespace t = rcb4::transport;

static_assert(t::AsyncByteStream<rcb4::testing::fake_stream>);

TEST_CASE("client: fail the n-th read or write, for every n", "[transport][matrix]") {
  const std::uint8_t bytes[] = {0x12, 0x34};
  const std::vector<command> script = {ping{},
                                       move::write_ram(0x0400, bytes).value(),
                                       move::read_ram(0x0400, 2).value(),
                                       version{},
                                       single_servo{0, 8000, 0},
                                       move::read_ram(ram::config, 2).value()};
  // A clean run first, to know how many operations the script takes.
  std::size_t total_ops = 0;
  {
    board::virtual_board b;
    t::io_thread io;
    t::basic_client<rcb4::testing::fake_stream> c(rcb4::testing::fake_stream(io.context().get_executor(), b));
    for (const auto& cmd : script) {
      t::error_code ec;
      const auto r = c.exchange(cmd, ec);  // the board's answer as it came: a NACK would show here
      CHECK_FALSE(ec);
      CHECK(r.kind != reply_kind::nack);
    }
    total_ops = c.stream().operations();
  }
  REQUIRE(total_ops >= 2 * script.size());
  const boost::system::error_code failures_to_inject[] = {boost::asio::error::connection_reset,
                                                          boost::asio::error::eof};
  for (const auto failure : failures_to_inject)
    for (std::size_t n = 1; n <= total_ops; ++n) {
      INFO("operation " << n << " of " << total_ops << " fails with " << failure.message());
      board::virtual_board b;
      t::io_thread io;
      t::client_options opt;
      opt.turnaround = 50ms;
      opt.quiet = 2ms;
      t::basic_client<rcb4::testing::fake_stream> c(
          rcb4::testing::fake_stream(io.context().get_executor(), b, n, failure), opt);
      int failures = 0;
      for (const auto& cmd : script) {
        t::error_code ec;
        const auto r = c.execute(cmd, ec);  // every call returns: a hang would stop the test here
        if (ec) {
          ++failures;
          continue;
        }
        // Whatever succeeds carries the right answer: exactly what the board holds (the write
        // before it may or may not have reached the board, depending on which operation failed).
        if (const auto* m = std::get_if<move>(&cmd);
            m && m->src().kind() == src_kind::ram && m->src().address() == 0x0400) {
          const auto held = b.ram16(0x0400);  // the exchange is over: the io thread is idle
          CHECK(r.u16() == held);
          CHECK((held == 0x3412 || held == 0));
        }
        if (std::holds_alternative<version>(cmd)) CHECK(r.data.size() == 32);
      }
      CHECK(failures <= 1);  // one broken operation costs at most the exchange it belonged to
      // And the line is usable afterwards.
      CHECK(c.execute(move::read_ram(ram::config, 2).value()).u16() == board::default_config);
    }
}
