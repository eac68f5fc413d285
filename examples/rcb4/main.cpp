// rcb4 — the command-line tool: talk to an RCB-4 (or the virtual one), or be one.
// SPDX-License-Identifier: BSL-1.0
#include "cli.hpp"

#include <rcb4/transport/error.hpp>

#include <cstdio>

namespace cli {
std::string_view device_help();
}

namespace {

constexpr std::string_view usage_top = R"(rcb4 — talk to KONDO RCB-4 boards (KHR-3HV, KXR), or be one.

usage: rcb4 [global options] COMMAND [ARGS]      (`rcb4 COMMAND --help` for each command)

global options:
  --device D      /dev/ttyUSB0 (serial), tcp:HOST:PORT (ser2net); default: an in-process
                  virtual board, so every command works without a robot
  --baud B        115200, 625000 or 1250000 (default: detected by ping)
  --timeout MS    turnaround allowance per exchange (default 100)
  --trace         print every frame on stderr: time, hex, meaning
  --json          machine-readable output where the output is data

)";

constexpr std::string_view usage_bottom = R"(
  list            serial ports, recognising KONDO's adapter and FTDI
  doctor          check permissions, dialout, udev rule, latency timer, baud: each with the fix
  decode HEX      frames (arguments or stdin) to descriptions
  encode CMD      a command's frame
  serve           serve a virtual RCB-4 on a pseudo-terminal or TCP port

exit codes: 0 ok, 1 the board refused or answered wrongly, 2 usage, 3 device/I/O problem,
            4 no answer before the deadline
)";

/** Exit code and hint for an error from the device. */
int report(std::string_view cmd, const std::error_code& ec, std::string_view what) {
  namespace t = rcb4::transport;
  int code = cli::exit_io;
  std::string_view hint;
  if (ec.category() == rcb4::codec_category()) {
    code = cli::exit_board;
    if (ec == rcb4::errc::nack) hint = "the board refused the command (range, unallocated servo, or a busy program)";
  } else if (ec == t::transport_errc::echo) {
    code = cli::exit_board;
    hint = "the line returns what is sent: a loopback plug or an echoing adapter, not an RCB-4";
  } else if (ec == t::transport_errc::timeout || ec == t::transport_errc::no_board) {
    code = cli::exit_timeout;
    hint = "is the board powered, the cable in, the adapter in RCB-4 mode? try --baud, or `rcb4 doctor`";
  } else if (ec == t::transport_errc::port_busy) {
    hint = "another program has the port open (`fuser -v` on the device shows which)";
  } else if (ec == std::errc::permission_denied) {
    hint = "no permission: join the dialout group or install the udev rule (`rcb4 doctor` says how)";
  } else if (ec == std::errc::no_such_file_or_directory) {
    hint = "no such device: `rcb4 list` shows the serial ports";
  } else if (t::is_link_lost(ec)) {
    hint = "the device went away (unplugged?)";
  }
  fmt::print(stderr, "rcb4 {}: {}\n", cmd, what);
  if (!hint.empty()) fmt::print(stderr, "  {}\n", hint);
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string_view> all(argv + 1, argv + argc);
  cli::globals g;
  cli::args a;
  try {
    // Global options may come before or after the command (not for `serve`, which has its own).
    std::vector<std::string_view> rest;
    bool is_serve = false;
    for (std::size_t i = 0; i < all.size(); ++i) {
      const auto s = all[i];
      auto value = [&]() -> std::string_view {
        if (i + 1 >= all.size()) throw cli::usage_error{fmt::format("{} needs a value", s)};
        return all[++i];
      };
      if (is_serve)
        rest.push_back(s);
      else if (s == "--device") {
        g.device = std::string(value());
        // An empty device is a mistake (an unset variable in a script), never the virtual board.
        if (g.device.empty()) throw cli::usage_error{"--device is empty (leave it out for the virtual board)"};
      } else if (s == "--baud") {
        const auto b = static_cast<std::uint32_t>(cli::parse_int(value(), "--baud", 1200, 4000000));
        if (b != 115200 && b != 625000 && b != 1250000)  // the board's COM rates (protocol.md §9)
          throw cli::usage_error{fmt::format("--baud {}: the RCB-4 speaks 115200, 625000 or 1250000", b)};
        g.baud = b;
      } else if (s == "--timeout")
        g.timeout = std::chrono::milliseconds(cli::parse_int(value(), "--timeout", 1, 600000));
      else if (s == "--trace")
        g.trace = true;
      else if (s == "--json")
        g.json = true;
      else {
        if (rest.empty() && s == "serve") is_serve = true;
        rest.push_back(s);
      }
    }
    if (rest.empty() || rest[0] == "help" || rest[0] == "--help" || rest[0] == "-h") {
      fmt::print("{}commands:{}", usage_top, cli::device_help().substr(cli::device_help().find("device commands")));
      fmt::print("{}", usage_bottom);
      return rest.empty() ? cli::exit_usage : cli::exit_ok;
    }
    a.command = rest[0];
    a.list.assign(rest.begin() + 1, rest.end());
    if (a.command == "serve") return cli::serve(a);
    if (a.command == "list") return cli::list(a, g);
    if (a.command == "doctor") return cli::doctor(a, g);
    if (a.command == "decode") return cli::decode(a, g);
    if (a.command == "encode") return cli::encode(a, g);
    return cli::device_command(a, g);
  } catch (const cli::usage_error& e) {
    fmt::print(stderr, "rcb4{}{}: {}\n(see rcb4 {}--help)\n", a.command.empty() ? "" : " ", a.command, e.message,
               a.command.empty() ? "" : fmt::format("{} ", a.command));
    return cli::exit_usage;
  } catch (const std::system_error& e) {
    return report(a.command, e.code(), e.what());
  } catch (const boost::system::system_error& e) {
    // Boost's what() ends with the code's location, " [category:value]": a person needs the words.
    std::string_view what = e.what();
    if (const auto at = what.rfind(" ["); at != std::string_view::npos && what.back() == ']') what = what.substr(0, at);
    return report(a.command, std::error_code(e.code()), what);
  }
}
