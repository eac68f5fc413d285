// rcb4 studio: serving `rcb4 ui` (see studio.hpp).
// SPDX-License-Identifier: BSL-1.0
#include "studio.hpp"

#include <rcb4/transport/share.hpp>

#include <boost/asio/ip/host_name.hpp>
#include <boost/asio/signal_set.hpp>

#include <atomic>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <thread>

namespace cli::ui {

std::vector<served_file> three_js_files(const std::filesystem::path& dir) {
  // Served from Debian's copy (libjs-three), as Debian wants JavaScript libraries shared, not embedded.
  std::vector<served_file> out;
  for (const auto& [url, file] :
       {std::pair{"/vendor/three/build/three.module.js", "build/three.module.js"},
        std::pair{"/vendor/three/examples/jsm/controls/OrbitControls.js", "examples/jsm/controls/OrbitControls.js"}}) {
    std::ifstream in(dir / file, std::ios::binary);
    if (!in) {
      fmt::print(stderr, "rcb4 ui: no {} in {} (apt install libjs-three): the page works without its 3D view\n", file,
                 dir.string());
      return {};
    }
    std::ostringstream body;
    body << in.rdbuf();
    out.push_back({url, "text/javascript; charset=utf-8", body.str()});
  }
  return out;
}

std::string url_of(const boost::asio::ip::tcp::endpoint& ep, const std::string& token) {
  std::string host;
  if (ep.address().is_unspecified()) {
    boost::system::error_code ec;
    host = boost::asio::ip::host_name(ec);
    if (ec || host.empty()) host = "HOST";
  } else if (ep.address().is_v6()) {
    host = "[" + ep.address().to_string() + "]";
  } else {
    host = ep.address().to_string();
  }
  return fmt::format("http://{}:{}/{}", host, ep.port(), token.empty() ? "" : "?token=" + token);
}

studio::studio(server_options so) : options_(std::move(so)) {
  try {
    server_.emplace(io_, options_);
  } catch (const boost::system::system_error& e) {
    const auto& a = options_.listen.address();
    throw failure(exit_io,
                  fmt::format("cannot listen on {}{}{}:{}: {}", a.is_v6() ? "[" : "", a.to_string(),
                              a.is_v6() ? "]" : "", options_.listen.port(), e.code().message()),
                  e.code() == boost::asio::error::address_in_use
                      ? "another program has that port: --listen 127.0.0.1:0 picks a free one"
                      : "");
  }
}

studio::~studio() = default;

int studio::run(session& s, const rcb4::robot::model& m, const settings& limits, loop_options lo,
                const std::string& share_name) {
  auto& server = server_;
  hub h(m, limits, [&server](client_id to, std::string text) { server->send(to, std::move(text)); });
  lo.device = s.where();
  h.set_hello(hello_text(m, s, lo, limits));

  // The command line next to the studio: the port this studio holds is served to the user's other
  // programs (rcb4 --device PORT, pyrcb4), through the session's client and its one FIFO
  // (transport/share.hpp). The board loop re-reads what they may have changed.
  auto outside_writes = std::make_shared<std::atomic<std::uint64_t>>(0);  // the client's thread may outlive this frame
  std::shared_ptr<rcb4::transport::share_server<client>> share;
  if (s.holds_port()) {
    rcb4::transport::error_code ec;
    share = rcb4::transport::share_server<client>::start(
        io_, s.c(), share_name,
        [outside_writes](const rcb4::command& c, const rcb4::transport::error_code&, const rcb4::transport::response&) {
          if (!rcb4::transport::is_idempotent(c)) ++*outside_writes;
        },
        ec);
    if (ec)
      fmt::print(stderr, "rcb4 ui: cannot share {} with other programs ({}): they will find it busy\n", s.where(),
                 ec.message());
    lo.outside_writes = outside_writes.get();
  }
  struct share_stopper {
    std::shared_ptr<rcb4::transport::share_server<client>>& s;
    ~share_stopper() {
      if (s) s->stop();
    }
  } stop_share{share};

  // The first line of stdout is the URL (scripts read it); the rest goes to stderr.
  fmt::print("{}\n", url_of(server_->local(), options_.token));
  std::fflush(stdout);
  fmt::print(stderr, "rcb4 ui: {} on {}; poses in {}; Ctrl-C stops\n", m.name(), s.where(), lo.poses.string());
  if (share)
    fmt::print(stderr, "rcb4 ui: `rcb4 --device {}` and pyrcb4 reach the board through this studio\n", share_name);

  boost::asio::signal_set signals(io_, SIGINT, SIGTERM);
  std::string loop_failure;
  std::thread loop([&] {
    try {
      run_board_loop(s, m, h, lo);
    } catch (const std::exception& e) {
      loop_failure = e.what();
      boost::asio::post(io_, [&] {
        signals.cancel();
        server_->stop();
        if (share) share->stop();
      });
    }
  });
  // Whatever happens next, the loop thread ends before what it uses goes.
  struct joiner {
    hub& h;
    std::thread& t;
    ~joiner() {
      h.stop();
      if (t.joinable()) t.join();
    }
  } join_loop{h, loop};
  signals.async_wait([&](const boost::system::error_code& ec, int) {
    if (ec) return;
    h.stop();  // the loop ends after the exchange under way; joined once io.run() returns
    server_->stop();
    if (share) share->stop();  // its acceptor would keep io.run() going
  });
  server_->start(h);
  io_.run();
  h.stop();
  loop.join();
  if (!loop_failure.empty()) throw failure(exit_board, "the board loop stopped: " + loop_failure);
  fmt::print(stderr, "rcb4 ui: stopped\n");
  return exit_ok;
}

}  // namespace cli::ui
