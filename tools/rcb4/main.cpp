// rcb4 — the command-line tool: talk to an RCB-4 (or the virtual one), or be one.
// The commands live one group per file (cmd_*.cpp); this file holds the global options, the
// parse, and how every failure becomes a message (text or JSON) and an exit code.
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/transport/error.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#ifndef RCB4_VERSION
#define RCB4_VERSION "unknown"
#endif

namespace {

constexpr std::string_view footer = R"(
Without --device (and without $RCB4_DEVICE) every device command talks to an in-process virtual
RCB-4 wired as the --robot (a KHR-3HV by default), so all of them work without a robot.
`rcb4 COMMAND --help` explains each command; `rcb4 joint list` shows the robot's joints.

exit codes: 0 ok, 1 the board refused or answered wrongly, 2 usage, 3 device/I/O problem,
            4 no answer before the deadline (with --json, failures are {"error", "exit", "hint"})
)";

/** Prints a failure as text on stderr, or as one JSON object on stdout; returns its exit code. */
int fail(const cli::globals& g, std::string_view command, const cli::failure& f) {
  const std::string_view what = cli::plain_message(f.what());
  if (g.json) {
    cli::json j;
    j["error"] = what;
    j["exit"] = f.exit;
    if (!f.hint.empty()) j["hint"] = f.hint;
    if (!command.empty()) j["command"] = command;
    if (f.extra.is_object())
      for (const auto& [k, v] : f.extra.items()) j[k] = v;
    cli::emit(j);
  } else {
    fmt::print(stderr, "rcb4{}{}: {}\n", command.empty() ? "" : " ", command, what);
    if (!f.hint.empty()) fmt::print(stderr, "  {}\n", f.hint);
  }
  return f.exit;
}

/** Help whose usage line names the whole command ("rcb4 motion play"), not its last word. */
class formatter : public CLI::Formatter {
 public:
  std::string make_usage(const CLI::App* app, std::string name) const override {
    for (const CLI::App* p = app->get_parent(); p; p = p->get_parent()) name = p->get_name() + " " + name;
    return CLI::Formatter::make_usage(app, name);
  }
};

/** The deepest command chosen (`servo move`), or the app. */
const CLI::App* deepest(const CLI::App& app) {
  const CLI::App* a = &app;
  while (!a->get_subcommands().empty()) a = a->get_subcommands().front();
  return a;
}

/** The command words chosen ("servo move"), for messages. */
std::string chosen(const CLI::App& app) {
  std::string out;
  for (const CLI::App* a = &app; !a->get_subcommands().empty();) {
    a = a->get_subcommands().front();
    out += out.empty() ? "" : " ";
    out += a->get_name();
  }
  return out;
}

/** --json before the command, found before parsing so that a usage error can be JSON too. */
bool json_requested(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "--json") return true;
    if (a == "--device" || a == "--baud" || a == "--timeout" || a == "--robot")
      ++i;
    else if (a.empty() || a[0] != '-')
      return false;  // the command: what follows is its own
  }
  return false;
}

}  // namespace

namespace {
/**
 * For a command line with a global option after the command ("rcb4 doctor --device /dev/ttyUSB0"),
 * the hint with the option and its value moved before it; nothing when there is none. Only the
 * options CLI11 left over (@p unexpected) move: a command's own --timeout (seconds, in motion
 * wait) is not the global one.
 */
std::optional<std::string> globals_first(int argc, char** argv, const std::vector<std::string>& unexpected) {
  static constexpr std::string_view with_value[] = {"--device", "--baud", "--timeout", "--robot"};
  static constexpr std::string_view flags[] = {"--trace", "--json"};
  const auto left_over = [&](std::string_view a) {
    return std::find(unexpected.begin(), unexpected.end(), a) != unexpected.end();
  };
  std::vector<std::string> front, rest;
  std::string moved;
  bool in_command = false;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    const auto name = a.substr(0, a.find('='));
    const bool takes_value = std::find(std::begin(with_value), std::end(with_value), name) != std::end(with_value);
    const bool is_flag = std::find(std::begin(flags), std::end(flags), a) != std::end(flags);
    if ((takes_value || is_flag) && (!in_command || left_over(a))) {
      if (in_command && moved.empty()) moved = std::string(name);
      front.emplace_back(a);
      if (takes_value && name == a && i + 1 < argc) front.emplace_back(argv[++i]);
      continue;
    }
    if (!a.empty() && a[0] != '-') in_command = true;
    rest.emplace_back(a);
  }
  if (moved.empty()) return std::nullopt;
  std::string line = "rcb4";
  for (const auto& w : front) line += " " + w;
  for (const auto& w : rest) line += " " + w;
  return fmt::format("{} is a global option: put it before the command: {}", moved, line);
}
}  // namespace

int main(int argc, char** argv) {
  cli::context ctx;
  CLI::App app{"rcb4 — talk to KONDO RCB-4 boards (KHR-3HV, KXR), or be one.", "rcb4"};
  app.formatter(std::make_shared<formatter>());
  app.set_version_flag("--version", std::string("rcb4 ") + RCB4_VERSION);
  app.require_subcommand(1);
  app.fallthrough(false);  // global options go before the command
  auto* device = app.add_option("--device", ctx.g.device,
                                "serial port (/dev/ttyUSB0, /dev/rcb4-0) or tcp:HOST:PORT (ser2net); "
                                "default $RCB4_DEVICE, else an in-process virtual board");
  device->type_name("D");
  // "--device --baud 115200" would take "--baud" as the device: a value is not an option.
  const CLI::Validator not_an_option(
      [](std::string& v) -> std::string {
        if (v.size() > 1 && v[0] == '-')
          return fmt::format("needs a value, and '{}' is an option (for a path that starts with -, write ./{})", v, v);
        return {};
      },
      "");
  device->check(not_an_option);
  std::uint32_t baud = 0;
  app.add_option("--baud", baud, "115200, 625000 or 1250000 (default: detected: a ping, or an ICS servo's answer)")
      ->type_name("B")
      ->check(CLI::Validator(
          [](std::string& v) -> std::string {
            // The board's COM rates (protocol.md §9); anything else cannot reach it.
            if (v == "115200" || v == "625000" || v == "1250000") return {};
            return fmt::format("{}: the RCB-4 and ICS servos speak 115200, 625000 or 1250000", v);
          },
          "{115200,625000,1250000}"));
  long long timeout_ms = 100;
  app.add_option("--timeout", timeout_ms, "turnaround allowance per exchange in ms (default 100)")
      ->type_name("MS")
      ->check(cli::int_range(1, 600000));
  app.add_flag("--trace", ctx.g.trace, "print every frame on stderr: time, hex, meaning");
  app.add_flag("--json", ctx.g.json, "machine-readable output: one JSON object (per line for monitor)");
  app.add_option("--robot", ctx.g.robot,
                 "the robot: a profile file (YAML, see profiles/) or a built-in name: khr-3hv (default), kxr-l2")
      ->type_name("FILE")
      ->check(not_an_option);

  cli::add_board_commands(app, ctx);
  cli::add_memory_commands(app, ctx);
  cli::add_servo_commands(app, ctx);
  cli::add_sensor_commands(app, ctx);
  cli::add_motion_commands(app, ctx);
  cli::add_rom_commands(app, ctx);
  cli::add_bench_command(app, ctx);
  cli::add_host_commands(app, ctx);
  cli::add_frame_commands(app, ctx);
  cli::add_serve_command(app, ctx);
  cli::add_robot_commands(app, ctx);
  cli::add_urdf_command(app, ctx);
  cli::add_ics_commands(app, ctx);
  cli::add_project_commands(app, ctx);
  cli::add_ui_command(app, ctx);
  app.footer(std::string(footer));  // after the commands: they would inherit it

  ctx.g.json = json_requested(argc, argv);
  if (argc == 1) {
    fmt::print("{}", app.help());
    return cli::exit_usage;
  }
  try {
    try {
      app.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
      fmt::print("{}", deepest(app)->help());
      return cli::exit_ok;
    } catch (const CLI::CallForAllHelp&) {
      fmt::print("{}", app.help("", CLI::AppFormatMode::All));
      return cli::exit_ok;
    } catch (const CLI::CallForVersion&) {
      if (ctx.g.json)
        cli::emit(cli::json{{"version", RCB4_VERSION}});
      else
        fmt::print("rcb4 {}\n", RCB4_VERSION);
      return cli::exit_ok;
    } catch (const CLI::ParseError& e) {
      std::string message = e.what();
      const std::string words = chosen(app);
      std::string hint = fmt::format("see rcb4 {}--help", words.empty() ? "" : words + " ");
      if (dynamic_cast<const CLI::ExtrasError*>(&e) || dynamic_cast<const CLI::RequiredError*>(&e)) {
        const auto remaining = app.remaining();
        if (words.empty() && !remaining.empty() && !remaining.front().empty() && remaining.front()[0] != '-') {
          message = fmt::format("unknown command '{}'", remaining.front());
          hint = "see rcb4 --help for the commands";
        }
        // A global option after the command: the hint is the command line with it moved first.
        if (!words.empty())
          if (const auto fixed = globals_first(argc, argv, app.remaining(true))) hint = *fixed;
      }
      throw cli::failure(cli::exit_usage, message, hint);
    }
    // What CLI11 cannot check alone.
    if (device->count() == 0)
      if (const char* env = std::getenv("RCB4_DEVICE")) {
        if (!*env) ctx.g.empty_device = "RCB4_DEVICE is set but empty (unset it for the virtual board)";
        ctx.g.device = env;
      }
    if (device->count() > 0 && ctx.g.device.empty())
      ctx.g.empty_device = "--device is empty (leave it out for the virtual board)";  // refused where a device opens
    if (baud != 0) ctx.g.baud = baud;
    ctx.g.timeout = std::chrono::milliseconds(timeout_ms);
    if (!ctx.action) throw cli::usage_error("no command given");
    return ctx.action();
  } catch (const cli::failure& f) {
    return fail(ctx.g, chosen(app), f);
  } catch (const rcb4::robot::services::refused& r) {
    // A line that failed part way: its exit code and, when the service has no better one, its hint.
    auto f = r.code ? cli::explain(r.code, r.what()) : cli::failure(cli::exit_of(r.kind), r.what());
    if (!r.hint.empty()) f.hint = r.hint;
    if (!r.backup.empty()) f.extra = cli::json{{"backup", r.backup}};
    return fail(ctx.g, chosen(app), f);
  } catch (const std::system_error& e) {
    return fail(ctx.g, chosen(app), cli::explain(e.code(), e.what()));
  } catch (const boost::system::system_error& e) {
    return fail(ctx.g, chosen(app), cli::explain(std::error_code(e.code()), e.what()));
  }
}
