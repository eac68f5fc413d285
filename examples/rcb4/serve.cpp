// rcb4 command-line tool: `rcb4 serve`, a virtual RCB-4 board on a pty or TCP.
// SPDX-License-Identifier: BSL-1.0
#include "cli.hpp"

#include <boost/asio.hpp>

#include <cstdio>
#include <fstream>
#include <iterator>

namespace cli {
namespace {

constexpr std::string_view usage_serve = R"(usage: rcb4 serve (--pty | --tcp HOST:PORT) [options]

Serves an emulated RCB-4HV until SIGINT/SIGTERM. The first line on stdout is where to connect:
the /dev/pts/N path for --pty (open it with the usual serial settings), or HOST:PORT for --tcp
(port 0 picks a free one; loopback unless you name another address).

options:
  --pty               serve on a new pseudo-terminal
  --tcp HOST:PORT     serve on TCP, one client at a time (e.g. 127.0.0.1:0)
  --pace              deliver replies at the board's line rate (11 bits per byte, 8E1)
  --latency US        extra microseconds before each reply (USB adapter, turnaround)
  --rom FILE          load the 256 KiB ROM image from FILE if it exists; save it there on exit
  --series MODE       SERIES (0x11): reboot (default, as measured in 2015) or execute
  --shift ENCODING    SHIFT counts: measured (default, 2015 report) or manual (KONDO's manual)
  --arith-to-com      answer arithmetic with COM as destination (refused by default)
  --strict-timing     drop frames whose bytes arrive more than 150 us apart
  --servos N          allocated servo slots ICS 0..N-1 (default 22)
)";

std::uint32_t parse_number(std::string_view s, std::string_view what) {
  return static_cast<std::uint32_t>(parse_int(s, what, 0, 0xFFFFFFFFLL));
}

}  // namespace

int serve(const args& a_) {
  const auto& args = a_.list;
  using namespace rcb4;
  bool pty = false;
  std::string tcp;
  std::string rom_path;
  transport::serve_options serve_opt;
  board::options board_opt;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const auto a = args[i];
    auto value = [&]() -> std::string_view {
      if (i + 1 >= args.size()) throw usage_error{fmt::format("{} needs a value", a)};
      return args[++i];
    };
    if (a == "--help" || a == "-h") {
      fmt::print("{}", usage_serve);
      return exit_ok;
    } else if (a == "--pty")
      pty = true;
    else if (a == "--tcp")
      tcp = value();
    else if (a == "--pace")
      serve_opt.pace = true;
    else if (a == "--latency")
      serve_opt.latency = std::chrono::microseconds(parse_number(value(), "--latency"));
    else if (a == "--rom")
      rom_path = value();
    else if (a == "--series") {
      const auto v = value();
      if (v == "reboot")
        board_opt.series = board::series_behaviour::reboot;
      else if (v == "execute")
        board_opt.series = board::series_behaviour::execute;
      else
        throw usage_error{fmt::format("--series: expected reboot or execute, not '{}'", v)};
    } else if (a == "--shift") {
      const auto v = value();
      if (v == "measured")
        board_opt.shift = shift_encoding::measured_2015;
      else if (v == "manual")
        board_opt.shift = shift_encoding::kondo_manual;
      else
        throw usage_error{fmt::format("--shift: expected measured or manual, not '{}'", v)};
    } else if (a == "--arith-to-com")
      board_opt.allow_arith_to_com = true;
    else if (a == "--strict-timing")
      board_opt.strict_timing = true;
    else if (a == "--servos") {
      const auto n = parse_number(value(), "--servos");
      if (n > 35) throw usage_error{"--servos: at most 35 (ICS 35 is the receiver)"};
      board_opt.servo_count = static_cast<std::uint8_t>(n);
    } else
      throw usage_error{fmt::format("unknown option '{}'", a)};
  }
  if (pty == !tcp.empty()) throw usage_error{"give exactly one of --pty or --tcp HOST:PORT"};

  board::virtual_board board(board_opt);
  if (!rom_path.empty()) {
    std::ifstream f(rom_path, std::ios::binary);
    if (f) {
      std::vector<std::uint8_t> image{std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
      if (!board.load_rom(image)) {
        fmt::print(stderr, "rcb4 serve: {}: a ROM image is exactly {} bytes, this file has {}\n", rom_path, rom_size,
                   image.size());
        return exit_io;
      }
    }
  }

  boost::asio::io_context io;
  std::shared_ptr<transport::board_server> server;
  try {
    if (pty) {
      server = transport::board_server::serve_pty(io, board, serve_opt);
    } else {
      const auto colon = tcp.rfind(':');
      if (colon == std::string::npos) throw usage_error{fmt::format("--tcp: expected HOST:PORT, not '{}'", tcp)};
      const auto port = parse_number(std::string_view(tcp).substr(colon + 1), "--tcp port");
      if (port > 65535) throw usage_error{fmt::format("--tcp: port {} out of range", port)};
      boost::system::error_code ec;
      const auto address = boost::asio::ip::make_address(tcp.substr(0, colon), ec);
      if (ec) throw usage_error{fmt::format("--tcp: '{}' is not an IP address", tcp.substr(0, colon))};
      server = transport::board_server::serve_tcp(io, board, {address, static_cast<std::uint16_t>(port)}, serve_opt);
    }
  } catch (const std::system_error& e) {
    fmt::print(stderr, "rcb4 serve: cannot serve: {}\n", e.what());
    return exit_io;
  }
  fmt::print("{}\n", server->where());
  std::fflush(stdout);

  boost::asio::signal_set signals(io, SIGINT, SIGTERM);
  signals.async_wait([&](const boost::system::error_code&, int) { server->stop(); });
  io.run();

  if (!rom_path.empty()) {
    std::ofstream f(rom_path, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(board.rom().data()), static_cast<std::streamsize>(board.rom().size()));
    if (!f) {
      fmt::print(stderr, "rcb4 serve: could not save the ROM to {}\n", rom_path);
      return exit_io;
    }
  }
  return exit_ok;
}

}  // namespace cli
