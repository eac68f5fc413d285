// rcb4 command-line tool: ui (the robot in a browser: joints, poses, motions, sensors, link).
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"
#include "ui/board_loop.hpp"
#include "ui/server.hpp"

#include <rcb4/transport/share.hpp>

#include <boost/asio/ip/host_name.hpp>
#include <boost/asio/signal_set.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

namespace cli {
namespace {

struct ui_options {
  std::string listen = "127.0.0.1:8080";
  std::string token;
  std::string poses = "poses";
  std::string three = "/usr/share/javascript/three";  ///< Debian's libjs-three
  std::string layout = "auto";
  double speed = 90;
};

boost::asio::ip::tcp::endpoint endpoint_of(const std::string& text) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0)
    throw usage_error(fmt::format("--listen: expected HOST:PORT (e.g. 127.0.0.1:8080, [::1]:0), not '{}'", text));
  auto host = text.substr(0, colon);
  if (host.size() > 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  const auto port = parse_int(std::string_view(text).substr(colon + 1), "--listen port", 0, 65535);
  boost::system::error_code ec;
  const auto address =
      host == "localhost" ? boost::asio::ip::make_address("127.0.0.1") : boost::asio::ip::make_address(host, ec);
  if (ec) throw usage_error(fmt::format("--listen: '{}' is not an IP address (or localhost)", host));
  return {address, static_cast<unsigned short>(port)};
}

/** 128 random bits as 32 hex digits. */
std::string new_token() {
  std::random_device rd;
  std::string out;
  for (int i = 0; i < 4; ++i) out += fmt::format("{:08x}", rd());
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

int run_ui(context& ctx, const ui_options& o, bool token_given) {
  // NaN passes a range check (every comparison is false): it would switch the speed limit off.
  if (!(o.speed >= 1 && o.speed <= 1000)) throw usage_error("--speed: degrees per second, 1 to 1000");
  if (token_given && o.token.size() < 16)
    throw usage_error("--token: at least 16 letters or digits (it is the only lock on a network address)");
  {
    std::error_code ec;
    if (o.poses.empty()) throw usage_error("--poses: an empty folder name");
    if (std::filesystem::exists(o.poses, ec) && !std::filesystem::is_directory(o.poses, ec))
      throw usage_error(fmt::format("--poses {}: not a folder", o.poses));
  }
  const auto& m = robot_of(ctx.g);
  ui::server_options so;
  so.listen = endpoint_of(o.listen);
  so.token = o.token;
  if (!so.listen.address().is_loopback() && so.token.empty()) so.token = new_token();
  for (char c : so.token)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_')
      throw usage_error("--token: use letters, digits, - and _ (it goes in a URL and a cookie)");

  // three.js for the 3D view, served from Debian's copy (libjs-three) as Debian wants JavaScript
  // libraries shared, not embedded: read once here, so nothing is read from disk while serving.
  for (const auto& [url, file] :
       {std::pair{"/vendor/three/build/three.module.js", "build/three.module.js"},
        std::pair{"/vendor/three/examples/jsm/controls/OrbitControls.js", "examples/jsm/controls/OrbitControls.js"}}) {
    std::ifstream in(std::filesystem::path(o.three) / file, std::ios::binary);
    if (!in) {
      fmt::print(stderr, "rcb4 ui: no {} in {} (apt install libjs-three): the page works without its 3D view\n", file,
                 o.three);
      so.vendor.clear();
      break;
    }
    std::ostringstream body;
    body << in.rdbuf();
    so.vendor.push_back({url, "text/javascript; charset=utf-8", body.str()});
  }

  boost::asio::io_context io;
  std::optional<ui::web_server> server;
  try {
    server.emplace(io, so);
  } catch (const boost::system::system_error& e) {
    throw failure(exit_io, fmt::format("cannot listen on {}: {}", o.listen, e.code().message()),
                  e.code() == boost::asio::error::address_in_use
                      ? "another program has that port: --listen 127.0.0.1:0 "
                        "picks a free one"
                      : "");
  }

  session s(ctx.g);  // the device (or the in-process virtual robot): its failures exit 1/3/4 as everywhere
  if (s.shared())
    throw failure(exit_io, fmt::format("{} is held by another rcb4 ui: {}", ctx.g.device, s.where()),
                  "open that studio's page (one studio per board), or stop it first");

  ui::settings limits;
  limits.max_speed = o.speed;
  ui::hub h(m, limits, [&server](ui::client_id to, std::string text) { server->send(to, std::move(text)); });
  ui::loop_options lo;
  lo.poses = o.poses;
  try {
    lo.layout = &layout_for(s, motion_options{o.layout});
  } catch (const failure& f) {  // a board without motion 1: the page still works; say what motions will assume
    if (f.exit != exit_board) throw;
    fmt::print(stderr, "rcb4 ui: {}; motions are played as HTH4 2.2+ (--layout names another)\n", f.what());
    lo.layout = &rcb4::hth4_2_2;
  }
  lo.device = s.where();
  h.set_hello(ui::hello_text(m, s, lo, limits));

  // The command line next to the studio: the port this studio holds is served to the user's other
  // programs (rcb4 --device PORT, pyrcb4), through the session's client and its one FIFO
  // (transport/share.hpp). The board loop re-reads what they may have changed.
  auto outside_writes = std::make_shared<std::atomic<std::uint64_t>>(0);  // the client's thread may outlive this frame
  std::shared_ptr<rcb4::transport::share_server<client>> share;
  if (s.holds_port()) {
    rcb4::transport::error_code ec;
    share = rcb4::transport::share_server<client>::start(
        io, s.c(), ctx.g.device,
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
  fmt::print("{}\n", url_of(server->local(), so.token));
  std::fflush(stdout);
  fmt::print(stderr, "rcb4 ui: {} on {}; poses in {}; Ctrl-C stops\n", m.name(), s.where(), o.poses);
  if (share)
    fmt::print(stderr, "rcb4 ui: `rcb4 --device {}` and pyrcb4 reach the board through this studio\n", ctx.g.device);

  boost::asio::signal_set signals(io, SIGINT, SIGTERM);
  std::string loop_failure;
  std::thread loop([&] {
    try {
      ui::run_board_loop(s, m, h, lo);
    } catch (const std::exception& e) {
      loop_failure = e.what();
      boost::asio::post(io, [&] {
        signals.cancel();
        server->stop();
        if (share) share->stop();
      });
    }
  });
  // Whatever happens next, the loop thread ends before what it uses goes.
  struct joiner {
    ui::hub& h;
    std::thread& t;
    ~joiner() {
      h.stop();
      if (t.joinable()) t.join();
    }
  } join_loop{h, loop};
  signals.async_wait([&](const boost::system::error_code& ec, int) {
    if (ec) return;
    h.stop();  // the loop ends after the exchange under way; joined once io.run() returns
    server->stop();
    if (share) share->stop();  // its acceptor would keep io.run() going
  });
  server->start(h);
  io.run();
  h.stop();
  loop.join();
  if (!loop_failure.empty()) throw failure(exit_board, "the board loop stopped: " + loop_failure);
  fmt::print(stderr, "rcb4 ui: stopped\n");
  return exit_ok;
}

}  // namespace

void add_ui_command(CLI::App& app, context& ctx) {
  auto* cmd = app.add_subcommand(
      "ui", "the robot in a browser: live joints, sliders, free/hold, poses, motions, sensors and the link");
  auto o = std::make_shared<ui_options>();
  cmd->add_option("--listen", o->listen,
                  "HOST:PORT to serve on (default 127.0.0.1:8080; port 0 picks a free one). Any address other "
                  "than loopback needs a token")
      ->type_name("HOST:PORT");
  cmd->add_option("--token", o->token,
                  "the secret every request must carry (?token=, then a cookie); generated and printed in the URL "
                  "when --listen is not loopback and none is given")
      ->type_name("T");
  cmd->add_option("--three", o->three,
                  "where three.js is (Debian's libjs-three: /usr/share/javascript/three), for the 3D view")
      ->type_name("DIR");
  cmd->add_option("--poses", o->poses, "where poses are saved and found (NAME.yaml; default ./poses)")
      ->type_name("DIR");
  cmd->add_option("--speed", o->speed, "the fastest a page may move a joint, degrees per second (default 90)")
      ->type_name("DEG_PER_S")
      ->check(CLI::Range(1.0, 1000.0));
  cmd->add_option("--layout", o->layout,
                  "the HeartToHeart4 version that wrote the motions: auto (default: told from the ROM), 2.2, 2.0, "
                  "2.1, 1.3 (see motion play)")
      ->check(CLI::IsMember({"auto", "1.3", "2.0", "2.1", "2.2"}));
  cmd->footer(
      "Prints the URL as the first line of stdout and serves until SIGINT/SIGTERM (exit 0).\n"
      "Open it in a browser on this machine, or from another one over SSH:\n"
      "  ssh -L 8080:127.0.0.1:8080 robot-pc   then http://127.0.0.1:8080/ on yours");
  auto* token = cmd->get_option("--token");
  cmd->callback([&ctx, o, token] {
    const bool token_given = token->count() > 0;
    ctx.action = [&ctx, o, token_given] { return run_ui(ctx, *o, token_given); };
  });
}

}  // namespace cli
