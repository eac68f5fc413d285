// rcb4 studio: the whole of `rcb4 ui` once its command line is read: the web server (server.hpp)
// listening, the board loop (board_loop.hpp) on its own thread, the port shared with the user's
// other programs (transport/share.hpp), until SIGINT or SIGTERM. The tool's `ui` command
// (tools/rcb4/cmd_ui.cpp) parses and checks the options and calls this.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include "board_loop.hpp"
#include "server.hpp"

#include <boost/asio/io_context.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace cli::ui {

/**
 * three.js's two modules for the 3D view, read once from @p dir (Debian's libjs-three), so that
 * nothing is read from disk while serving; none (and a line on stderr) when a file is missing:
 * the page works without its 3D view.
 */
std::vector<served_file> three_js_files(const std::filesystem::path& dir);

/** The URL a browser opens: http://HOST:PORT/ with ?token= when one is set. */
std::string url_of(const boost::asio::ip::tcp::endpoint& ep, const std::string& token);

/** One studio: listening from construction, serving the board from run(). */
class studio {
 public:
  /** Listens on @p so.listen now (a port in use fails before any board is opened: exit 3). */
  explicit studio(server_options so);
  ~studio();
  studio(const studio&) = delete;
  studio& operator=(const studio&) = delete;

  /** Where it listens (the real port when 0 was asked). */
  boost::asio::ip::tcp::endpoint local() const { return server_->local(); }

  /**
   * Serves robot @p m on @p s until SIGINT/SIGTERM: prints the URL as the first line of stdout,
   * shares the port with other programs when @p s holds it (@p share_name: the --device they
   * name), then runs the board loop with @p lo and the pages' limits @p limits. Returns exit_ok;
   * a board loop that fails ends it with failure(exit_board).
   */
  int run(session& s, const rcb4::robot::model& m, const settings& limits, loop_options lo,
          const std::string& share_name);

 private:
  boost::asio::io_context io_;
  server_options options_;
  std::optional<web_server> server_;
};

}  // namespace cli::ui
