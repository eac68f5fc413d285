// A virtual board served on a pty by its own io thread (tests and benchmarks).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/transport/board_server.hpp>
#include <rcb4/transport/client.hpp>

namespace rcb4::testing {

struct served_board {
  explicit served_board(transport::serve_options so = {}, board::options bo = {}) : board(bo) {
    server = transport::board_server::serve_pty(server_io.context(), board, std::move(so));
  }
  ~served_board() { transport::board_server::shutdown(server); }
  served_board(const served_board&) = delete;
  served_board& operator=(const served_board&) = delete;

  board::virtual_board board;
  transport::io_thread server_io;
  std::shared_ptr<transport::board_server> server;
};

}  // namespace rcb4::testing
