// rcb4 command-line tool: ui, the front of the studio (studio/): the options read and checked,
// the device opened; studio/server/studio.hpp serves the robot in a browser.
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"
#include "studio.hpp"  // studio/server: the studio this command fronts

#include <filesystem>
#include <random>

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

  so.vendor = ui::three_js_files(o.three);
  ui::studio studio(std::move(so));  // listening before the board is opened: a port in use fails first

  session s(ctx.g);  // the device (or the in-process virtual robot): its failures exit 1/3/4 as everywhere
  if (s.shared())
    throw failure(exit_io, fmt::format("{} is held by another rcb4 ui: {}", ctx.g.device, s.where()),
                  "open that studio's page (one studio per board), or stop it first");

  ui::settings limits;
  limits.max_speed = o.speed;
  ui::loop_options lo;
  lo.poses = o.poses;
  try {
    lo.layout = &layout_for(s, motion_options{o.layout});
  } catch (const failure& f) {  // a board without motion 1: the page still works; say what motions will assume
    if (f.exit != exit_board) throw;
    fmt::print(stderr, "rcb4 ui: {}; motions are played as HTH4 2.2+ (--layout names another)\n", f.what());
    lo.layout = &rcb4::hth4_2_2;
  }
  return studio.run(s, m, limits, std::move(lo), ctx.g.device);
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
