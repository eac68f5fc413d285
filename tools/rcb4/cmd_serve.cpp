// rcb4 command-line tool: `rcb4 serve`, a virtual RCB-4 board on a pty or TCP.
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <boost/asio.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

namespace cli {
namespace {

struct serve_options {
  bool pty = false;
  std::string tcp;
  std::string rom_path;
  long long latency_us = 0;
  std::string series = "reboot", shift = "measured";
  long long servos = -1;
  std::vector<int> silent;
  int period_ms = 0;
  std::string turn;   // ICS:MS, a hand turning a servo on a schedule
  bool hand = false;  // a hand that turns freed joints as lines on stdin say (JOINT DEGREES)
  rcb4::transport::serve_options serve;
  rcb4::board::options board;
};

/** Fails now (not at exit, after a session's work) when the ROM image could not be saved. */
void check_rom_writable(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path p(path);
  const bool exists = fs::exists(p, ec);
  const auto dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  if (exists ? ::access(path.c_str(), W_OK) != 0 : ::access(dir.c_str(), W_OK) != 0)
    throw failure(exit_io,
                  fmt::format("--rom {}: cannot be written ({}), so the ROM could not be saved at exit", path,
                              std::strerror(errno)),
                  "name a file in a directory you may write");
}

int serve(serve_options& o, const globals& g) {
  using namespace rcb4;
  o.serve.latency = std::chrono::microseconds(o.latency_us);
  o.board.series = o.series == "execute" ? board::series_behaviour::execute : board::series_behaviour::reboot;
  o.board.shift = o.shift == "manual" ? shift_encoding::kondo_manual : shift_encoding::measured_2015;
  // The robot --robot names (default: a KHR-3HV), unless --servos asks for anonymous slots.
  o.board.servos = o.servos >= 0 ? rcb4::board::first_slots(static_cast<unsigned>(o.servos)) : robot_of(g).mask();
  if (o.period_ms != 0) o.board.period = static_cast<rcb4::output_period>((o.period_ms - 10) / 5);
  for (const int k : o.silent) {
    const auto n = rcb4::ics_number::make(k).value();
    if (!o.board.servos.contains(n))
      throw usage_error(fmt::format("--silent {}: the board has no servo slot ICS {} to silence", k, k));
    o.board.unanswered.insert(n);
  }

  std::optional<boost::asio::ip::tcp::endpoint> endpoint;
  if (!o.tcp.empty()) {
    const auto colon = o.tcp.rfind(':');
    if (colon == std::string::npos) throw usage_error(fmt::format("--tcp: expected HOST:PORT, not '{}'", o.tcp));
    const auto port = parse_int(std::string_view(o.tcp).substr(colon + 1), "--tcp port", 0, 65535);
    boost::system::error_code ec;
    const auto address = boost::asio::ip::make_address(o.tcp.substr(0, colon), ec);
    if (ec) throw usage_error(fmt::format("--tcp: '{}' is not an IP address", o.tcp.substr(0, colon)));
    endpoint.emplace(address, static_cast<std::uint16_t>(port));
  }

  std::optional<std::pair<rcb4::ics_number, std::chrono::milliseconds>> turn;
  if (!o.turn.empty()) {
    const auto colon = o.turn.find(':');
    if (colon == std::string::npos) throw usage_error(fmt::format("--turn: expected ICS:MS, not '{}'", o.turn));
    const auto n =
        rcb4::ics_number::make(parse_int(std::string_view(o.turn).substr(0, colon), "--turn ICS", 0, 34)).value();
    if (!o.board.servos.contains(n) || o.board.unanswered.contains(n))
      throw usage_error(fmt::format("--turn {}: the board has no answering servo at ICS {}", o.turn, n.value()));
    turn.emplace(
        n, std::chrono::milliseconds(parse_int(std::string_view(o.turn).substr(colon + 1), "--turn MS", 1, 3'600'000)));
  }

  board::virtual_board board(o.board);
  if (!o.rom_path.empty()) {
    check_rom_writable(o.rom_path);
    std::ifstream f(o.rom_path, std::ios::binary);
    if (f) {
      std::vector<std::uint8_t> image{std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
      if (!board.load_rom(image))
        throw failure(exit_io, fmt::format("{}: a ROM image is exactly {} bytes, this file has {}", o.rom_path,
                                           rom_size, image.size()));
    }
  }

  boost::asio::io_context io;
  std::shared_ptr<transport::board_server> server;
  try {
    if (o.pty)
      server = transport::board_server::serve_pty(io, board, o.serve);
    else
      server = transport::board_server::serve_tcp(io, board, *endpoint, o.serve);
  } catch (const boost::system::system_error& e) {
    throw failure(exit_io, fmt::format("cannot serve on {}: {}", o.pty ? "a pty" : o.tcp, e.code().message()));
  } catch (const std::system_error& e) {
    throw failure(exit_io, fmt::format("cannot serve on {}: {}", o.pty ? "a pty" : o.tcp, e.code().message()));
  }
  if (g.json)
    emit(json{{"where", server->where()}});
  else
    fmt::print("{}\n", server->where());
  std::fflush(stdout);

  // The ROM is saved whenever it changed (checked every second, on the board's own thread), and at
  // the end: a closed terminal (SIGHUP) or a kill loses at most the last second.
  std::vector<std::uint8_t> saved(board.rom().begin(), board.rom().end());
  const auto save = [&] {
    if (o.rom_path.empty() || std::equal(saved.begin(), saved.end(), board.rom().begin(), board.rom().end())) return;
    const std::string tmp = o.rom_path + ".tmp";
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(board.rom().data()), static_cast<std::streamsize>(board.rom().size()));
    f.close();
    std::error_code ec;
    if (!f || (std::filesystem::rename(tmp, o.rom_path, ec), ec))
      throw failure(exit_io, fmt::format("could not save the ROM to {}", o.rom_path));
    saved.assign(board.rom().begin(), board.rom().end());
  };
  boost::asio::steady_timer saver(io);
  std::function<void()> arm = [&] {
    saver.expires_after(std::chrono::seconds(1));
    saver.async_wait([&](const boost::system::error_code& ec) {
      if (ec) return;
      save();
      arm();
    });
  };
  if (!o.rom_path.empty()) arm();

  // --turn: a hand turns the servo 500 counts one way, then back, every MS; each turn is printed
  // with its CLOCK_MONOTONIC time (steady_clock here, time.monotonic() in Python) for latency
  // measurements: from the measured position changing to a program seeing it.
  boost::asio::steady_timer hand(io);
  auto next_turn = std::chrono::steady_clock::now();  // on a fixed grid: late wake-ups do not add up
  bool turned = false;
  std::uint16_t rest = 0;
  std::function<void()> turn_next = [&] {
    next_turn += turn->second;
    hand.expires_at(next_turn);
    hand.async_wait([&](const boost::system::error_code& ec) {
      if (ec) return;
      if (!turned) rest = board.ram16(*board.block_of(turn->first) + servo_block::position.offset);
      const auto to = static_cast<std::uint16_t>(turned ? rest : rest + 500);
      board.turn_by_hand(turn->first, to);
      const double at = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
      turned = !turned;
      if (g.json)
        emit(json{{"turned", turn->first.value()}, {"to", to}, {"at", at}});
      else
        fmt::print("turned ICS {} to {} at {:.6f}\n", turn->first.value(), to, at);
      std::fflush(stdout);
      turn_next();
    });
  };
  if (turn) turn_next();

  // --hand: "JOINT DEGREES" per line on stdin turns that joint by hand when its servo is free (a
  // person posing the robot, for capture, record and teaching tests); each line is answered.
  boost::asio::posix::stream_descriptor input(io);
  boost::asio::streambuf lines;
  std::function<void()> read_line = [&] {
    boost::asio::async_read_until(input, lines, '\n', [&](const boost::system::error_code& ec, std::size_t n) {
      if (ec) return;  // end of input: the board goes on being served
      std::string line(boost::asio::buffers_begin(lines.data()),
                       boost::asio::buffers_begin(lines.data()) + static_cast<std::ptrdiff_t>(n));
      lines.consume(n);
      std::istringstream words(line);
      std::string name;
      double deg = 0;
      const auto& m = robot_of(g);
      const auto* j = (words >> name >> deg) ? m.find(name) : nullptr;
      if (!j) {
        fmt::print(stderr, "hand: '{}': expected JOINT DEGREES with a joint of {}\n", line.substr(0, line.find('\n')),
                   m.name());
      } else if (const auto block = board.block_of(j->ics); !block) {
        fmt::print(stderr, "hand: {}: the board has no servo for it\n", name);
      } else if (board.ram16(*block + servo_block::target.offset) != 0x8000) {
        fmt::print(stderr, "hand: {}: its servo holds its position: free it first\n", name);
      } else {
        const double d = std::clamp(deg, j->lower, j->upper);
        board.turn_by_hand(j->ics, std::get<rcb4::servo_position>(rcb4::robot::to_position(*j, d)).value());
        if (g.json)
          emit(json{{"hand", name}, {"degrees", d}});
        else
          fmt::print("hand turned {} to {:g}\n", name, d);
        std::fflush(stdout);
      }
      read_line();
    });
  };
  if (o.hand) {
    // A named pipe is held open for writing too, so each `echo ... > hand` is read: without a
    // writer of our own, the first writer's close would end the input.
    struct stat st {};
    const int fd =
        ::fstat(STDIN_FILENO, &st) == 0 && S_ISFIFO(st.st_mode) ? ::open("/proc/self/fd/0", O_RDWR | O_CLOEXEC) : -1;
    input.assign(fd >= 0 ? fd : ::dup(STDIN_FILENO));
    read_line();
  }
  boost::asio::signal_set signals(io, SIGINT, SIGTERM, SIGHUP);
  signals.async_wait([&](const boost::system::error_code&, int) {
    saver.cancel();
    hand.cancel();
    boost::system::error_code ignored;
    if (input.is_open()) input.close(ignored);
    server->stop();
  });
  io.run();
  save();
  return exit_ok;
}

}  // namespace

void add_serve_command(CLI::App& app, context& ctx) {
  auto* cmd = app.add_subcommand("serve", "serve a virtual RCB-4 on a pseudo-terminal or a TCP port");
  auto o = std::make_shared<serve_options>();
  auto* pty = cmd->add_flag("--pty", o->pty, "serve on a new pseudo-terminal");
  auto* tcp =
      cmd->add_option("--tcp", o->tcp, "serve on TCP, one client at a time (e.g. 127.0.0.1:0)")->type_name("HOST:PORT");
  pty->excludes(tcp);
  cmd->add_flag("--pace", o->serve.pace, "deliver replies at the board's line rate (11 bits per byte, 8E1)");
  cmd->add_option("--latency", o->latency_us, "extra microseconds before each reply (USB adapter, turnaround)")
      ->type_name("US")
      ->check(int_range(0, 10'000'000));
  cmd->add_option(
         "--rom", o->rom_path,
         "load the 256 KiB ROM image from FILE if it exists; save it there when it changes (each second) and on exit")
      ->type_name("FILE");
  cmd->add_option("--series", o->series, "SERIES (0x11): reboot (default, as measured in 2015) or execute")
      ->check(CLI::IsMember({"reboot", "execute"}));
  cmd->add_option("--shift", o->shift, "SHIFT counts: measured (default, 2015 report) or manual (KONDO's manual)")
      ->check(CLI::IsMember({"measured", "manual"}));
  cmd->add_option("--period", o->period_ms,
                  "boot with this servo output period in ms (default: the ROM's, 10; HTH4's sample projects use 15)")
      ->type_name("MS")
      ->check(CLI::IsMember({10, 15, 20, 25}));
  auto* strict = cmd->add_flag("--strict-baud", o->serve.strict_baud,
                               "on a pty: ignore frames sent at another rate than the board's (as a real line)");
  strict->needs(pty);
  cmd->add_flag("--arith-to-com", o->board.allow_arith_to_com,
                "answer arithmetic with COM as destination (refused by default)");
  cmd->add_flag("--strict-timing", o->board.strict_timing, "drop frames whose bytes arrive more than 150 us apart");
  cmd->add_option("--servos", o->servos,
                  "N anonymous servo slots, ICS 0..N-1, instead of the robot's (ICS 35 is the receiver)")
      ->check(int_range(0, 35));
  cmd->add_option("--silent", o->silent, "allocated slots whose servo never answers (its measured position stays 0)")
      ->type_name("ICS,...")
      ->delimiter(',')
      ->check(int_range(0, 34));
  cmd->add_option("--turn", o->turn,
                  "turn servo ICS by hand every MS ms, 500 counts one way then back (a free servo stays where it is "
                  "turned), each turn printed with its CLOCK_MONOTONIC time: for latency measurements")
      ->type_name("ICS:MS");
  cmd->add_flag("--hand", o->hand,
                "a hand for scripts: each line \"JOINT DEGREES\" on stdin turns that joint (of --robot) when its "
                "servo is free, as a person posing the robot; each line is answered on stdout (or why not on stderr)");
  cmd->footer(
      "Serves an emulated RCB-4HV wired as the robot --robot names (default: a KHR-3HV, 20 servos,\n"
      "three demo motions) until SIGINT/SIGTERM. The first line on stdout is where to connect:\n"
      "the /dev/pts/N path for --pty (open it with the usual serial settings), or HOST:PORT for --tcp\n"
      "(port 0 picks a free one; loopback unless you name another address).");
  cmd->callback([&ctx, o] {
    if (!o->pty && o->tcp.empty()) throw usage_error("serve: give --pty or --tcp HOST:PORT");
    ctx.action = [&ctx, o] { return serve(*o, ctx.g); };
  });
}

}  // namespace cli
