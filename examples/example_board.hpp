// Shared by the examples: connect to the board named on the command line, or, with no argument,
// to a virtual RCB-4 served in this process on a pseudo-terminal (so every example runs anywhere).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/board/virtual_board.hpp>
#include <rcb4/transport/board_server.hpp>
#include <rcb4/transport/client.hpp>
#include <rcb4/transport/detect.hpp>
#include <rcb4/transport/serial.hpp>

#include <cstdio>
#include <memory>
#include <string>

namespace example {

/** A client on a serial port, plus the virtual board behind it when no device was given. */
struct connection {
  std::unique_ptr<rcb4::board::virtual_board> board;
  std::unique_ptr<rcb4::transport::io_thread> board_io;
  std::shared_ptr<rcb4::transport::board_server> server;
  rcb4::transport::io_thread io;
  std::unique_ptr<rcb4::transport::basic_client<rcb4::transport::serial_port>> client;

  /** argv[1] is the device (e.g. /dev/ttyUSB0); none: the virtual board. */
  connection(int argc, char** argv) {
    std::string path = argc > 1 ? argv[1] : "";
    if (path.empty()) {
      board = std::make_unique<rcb4::board::virtual_board>();
      board_io = std::make_unique<rcb4::transport::io_thread>();
      server = rcb4::transport::board_server::serve_pty(board_io->context(), *board);
      path = server->where();
      std::printf("(no device given: using a virtual RCB-4 on %s)\n", path.c_str());
    }
    rcb4::transport::error_code ec;
    const auto baud = rcb4::transport::detect_baud(io.context(), path, ec);  // 1250000, 115200 or 625000
    if (ec) throw rcb4::transport::system_error(ec, path);
    rcb4::transport::client_options opt;
    opt.baud = baud;
    client = std::make_unique<rcb4::transport::basic_client<rcb4::transport::serial_port>>(
        rcb4::transport::open_serial(io.context(), path, baud), opt);
  }
  ~connection() {
    client.reset();
    rcb4::transport::board_server::shutdown(server);  // before board_io's context goes
  }
  connection(const connection&) = delete;
  connection& operator=(const connection&) = delete;

  /** The client. */
  rcb4::transport::basic_client<rcb4::transport::serial_port>& operator*() { return *client; }
};

}  // namespace example
