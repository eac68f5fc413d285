// tcp_bridge: talk to a board behind a TCP serial bridge such as ser2net (e.g. a Raspberry Pi
// wired to the robot). Run: rcb4_tcp_bridge [HOST:PORT]
// With no address, the example serves a virtual board on 127.0.0.1 (like `rcb4 serve --tcp`).
// SPDX-License-Identifier: BSL-1.0
#include <rcb4/board/virtual_board.hpp>
#include <rcb4/transport/board_server.hpp>
#include <rcb4/transport/operations.hpp>
#include <rcb4/transport/tcp.hpp>

#include <cstdio>

int main(int argc, char** argv) try {
  using namespace rcb4;
  std::string where = argc > 1 ? argv[1] : "";
  board::virtual_board vboard;
  transport::io_thread server_io;
  std::shared_ptr<transport::board_server> server;
  if (where.empty()) {
    server =
        transport::board_server::serve_tcp(server_io.context(), vboard, {boost::asio::ip::address_v4::loopback(), 0});
    where = server->where();
    std::printf("(no address given: a virtual RCB-4 on %s)\n", where.c_str());
  }
  transport::io_thread io;
  transport::client_options opt;
  opt.baud = 115200;  // the bridge's serial rate is not visible over TCP: the slowest gives safe deadlines
  auto c = transport::make_client(transport::connect(io.context(), where), opt);
  c.execute(ping{});
  std::printf("over TCP: %s\n", transport::run(c, ops::read_version{}).c_str());
  const auto states = transport::run(c, ops::read_servo_states{});
  std::printf("%zu servos; ICS 0 at %u\n", states.size(), states.empty() ? 0u : states[0].position);
  std::printf("%llu exchanges, %llu bytes out, %llu bytes in\n",
              static_cast<unsigned long long>(c.counters().exchanges.load()),
              static_cast<unsigned long long>(c.counters().bytes_out.load()),
              static_cast<unsigned long long>(c.counters().bytes_in.load()));
  transport::board_server::shutdown(server);  // before server_io's context goes
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "tcp_bridge: %s\n", e.what());
  return 1;
}
