// rcb4 command-line tool: what every command file shares. The options and help of each command
// are declared with CLI11 in its own file (cmd_*.cpp); JSON goes through nlohmann::json.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/board/virtual_board.hpp>
#include <rcb4/fmt.hpp>
#include <rcb4/ops.hpp>
#include <rcb4/robot/ops.hpp>
#include <rcb4/robot/profile.hpp>
#include <rcb4/robot/services/link.hpp>
#include <rcb4/transport/board_server.hpp>
#include <rcb4/transport/client.hpp>
#include <rcb4/transport/operations.hpp>

#include <fmt/core.h>
#include <CLI/CLI.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <csignal>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace cli {

// Exit codes, one per kind of failure (in `rcb4 --help` and the README).
inline constexpr int exit_ok = 0;             ///< done
inline constexpr int exit_board = 1;          ///< the board refused (NACK) or answered something malformed
inline constexpr int exit_usage = 2;          ///< bad command line
inline constexpr int exit_io = 3;             ///< device missing, busy, not permitted, unplugged
inline constexpr int exit_timeout = 4;        ///< no answer before the deadline (silent board, wrong baud)
inline constexpr int exit_interrupted = 130;  ///< stopped by SIGINT/SIGTERM where the command cleans up first

/** A failure a command reports itself: its message, exit code and a hint with the fix. */
struct failure : std::runtime_error {
  /** @p message says what went wrong; @p hint (optional) what to do about it. */
  failure(int code, std::string message, std::string fix = {}, nlohmann::ordered_json fields = {})
      : std::runtime_error(std::move(message)), exit(code), hint(std::move(fix)), extra(std::move(fields)) {}
  int exit;                      ///< one of the exit codes above
  std::string hint;              ///< the fix, or empty
  nlohmann::ordered_json extra;  ///< facts for --json (e.g. how far a transfer got), or null
};

/** The exit code of a robot service's refusal: board 1, usage and limit 2, timeout 4, a failed line 3. */
constexpr int exit_of(rcb4::robot::services::refusal_kind k) noexcept {
  using rcb4::robot::services::refusal_kind;
  switch (k) {
    case refusal_kind::board: return exit_board;
    case refusal_kind::usage:
    case refusal_kind::limit: return exit_usage;
    case refusal_kind::timeout: return exit_timeout;
    case refusal_kind::line: break;
  }
  return exit_io;
}

/** A command-line mistake found after parsing (a value out of range, a servo given twice): exit 2. */
struct usage_error : failure {
  /** @p message names the argument and what is wrong with it. */
  explicit usage_error(std::string message) : failure(exit_usage, std::move(message)) {}
};

/** The global options (before the command). */
struct globals {
  std::string device;                      ///< empty: the in-process virtual board
  std::optional<std::uint32_t> baud;       ///< empty: detect (serial) or unknown (TCP)
  std::chrono::milliseconds timeout{100};  ///< turnaround allowance per exchange
  bool trace = false;                      ///< print every frame with its meaning
  bool json = false;                       ///< machine-readable output
  std::string empty_device;                ///< why the device is empty when it was named so (checked on open)
  std::string robot = "khr-3hv";           ///< --robot: a built-in profile name or a profile file
};

/** The robot --robot names (loaded once); a bad profile is a usage error naming file and line. */
const rcb4::robot::model& robot_of(const globals& g);

/** Keys in the order they were set: output reads as it is documented. */
using json = nlohmann::ordered_json;

/** Prints @p j on one line of stdout. */
void emit(const json& j);

/** The local time for file names: "20261124-230605". */
std::string file_stamp();
/** "1 byte", "2 bytes". */
std::string plural(std::size_t n, std::string_view word);
/** A duration for people: "640 us", "501.1 ms", "12.34 s". */
std::string duration_text(std::chrono::duration<double, std::micro> d);

/**
 * A servo block's position word for people (protocol.md §7): "8389 (+30.0 deg)", "FREE", "HOLD",
 * and for 0, which is no angle, "0 (@p zero)": "no answer" for a measured position, "never
 * driven" for a target. @p compact: "8389  +30.0" for tables.
 */
std::string position_text(std::uint16_t word, std::string_view zero, bool compact = false);
/** The angle of a position word in hundredths of a degree, or null (see position_text). */
json degrees_json(std::uint16_t word);

/** Integer from decimal, 0x hex or negative decimal, checked against [lo, hi]. */
long long parse_int(std::string_view s, std::string_view what, long long lo, long long hi);
/** Hex bytes: "07 0F 00", "070F00", "0x07,0x0F" (separators: space, comma, colon). */
std::vector<std::uint8_t> parse_hex(std::string_view s, std::string_view what);
/** Joins command-line words with spaces (hex bytes given as several words). */
std::string join(const std::vector<std::string>& words);
/** A run-time value as a checked codec value; a bad one is a usage error naming @p what. */
template <class T>
T checked(long long v, std::string_view what) {
  auto r = T::make(v);
  if (!r) throw usage_error(fmt::format("{}: {} ({})", what, v, rcb4::message(r.error())));
  return *r;
}

/** Validator for a CLI11 option holding an integer in [lo, hi] (decimal or 0x hex). */
CLI::Validator int_range(long long lo, long long hi);

using stream = boost::asio::posix::stream_descriptor;
using client = rcb4::transport::basic_client<stream>;

/**
 * An open device: a serial port, a TCP bridge, or (no --device) an in-process virtual board on
 * a pseudo-terminal. Owns the io thread, the client, and the board when there is one.
 */
class session {
 public:
  /** Opens what @p g names (detecting the baud on a serial port without --baud); throws on failure. */
  explicit session(const globals& g);
  ~session();
  session(const session&) = delete;
  session& operator=(const session&) = delete;

  /** The client. */
  client& c() { return *client_; }
  /** The baud in use for deadlines (the wire rate on a serial port). */
  std::uint32_t baud() const noexcept { return client_->options().baud; }
  /** True when the line rate is known (serial, or TCP with --baud): wire limits mean something. */
  bool rate_known() const noexcept { return rate_known_; }
  /** What was opened, for messages. */
  const std::string& where() const noexcept { return where_; }
  /** True when no --device was given. */
  bool is_virtual() const noexcept { return board_ != nullptr; }
  /** True when this session opened --device's serial port itself (what rcb4 ui shares). */
  bool holds_port() const noexcept { return holds_port_; }
  /** True when --device is held by rcb4 ui and this session goes through it (transport/share.hpp). */
  bool shared() const noexcept { return shared_; }
  /**
   * The virtual board's hand: turns ICS @p n to @p position when its servo is free (on the
   * board's own thread). Returns the servo's output word (+6: 0x8000 when it was free and turned),
   * or nothing without a virtual board or a block for @p n, or when the board did not answer in 1 s.
   */
  std::optional<std::uint16_t> by_hand(rcb4::ics_number n, std::uint16_t position);
  /** Runs @p op; throws rcb4::transport::system_error on failure. */
  template <rcb4::ops::Operation Op>
  auto run(Op op) {
    return rcb4::transport::run(*client_, std::move(op));
  }
  /**
   * Runs @p op exchange by exchange, calling @p step after each reply (progress); sets @p ec
   * and returns on the first failure, with what the operation did so far left in @p op.
   */
  template <rcb4::ops::Operation Op, class Step>
  void run_steps(Op& op, rcb4::transport::error_code& ec, Step&& step) {
    ec.clear();
    while (auto cmd = op.next()) {
      const auto r = client_->exchange(*cmd, ec);
      if (ec) return;
      op.on_reply(r.view());
      step();
    }
    if (op.error() != rcb4::errc{}) ec = op.error();
  }

 private:
  std::unique_ptr<rcb4::board::virtual_board> board_;
  std::unique_ptr<rcb4::transport::io_thread> board_io_;
  std::shared_ptr<rcb4::transport::board_server> server_;
  rcb4::transport::io_thread io_;
  std::unique_ptr<client> client_;
  std::string where_;
  bool rate_known_ = true;
  bool holds_port_ = false;
  bool shared_ = false;
};

/** A progress line on stderr for long work: only on a terminal, never under --json. */
class progress;

/** The session as the robot services see it: exchanges, failures as the tool reports them, progress lines. */
class session_link final : public rcb4::robot::services::link {
 public:
  /** Over @p s; progress lines unless @p json_output. */
  session_link(session& s, bool json_output) : s_(s), json_(json_output) {}
  ~session_link() override;
  session_link(const session_link&) = delete;
  session_link& operator=(const session_link&) = delete;
  /** One exchange through the session's client; a failed line throws std::system_error. */
  rcb4::reply exchange(const rcb4::command& c) override;
  /** Throws std::system_error(@p e). */
  [[noreturn]] void failed(rcb4::errc e) override;
  /** A progress line per label, cleared when the label changes. */
  void progress(std::string_view label, std::size_t done, std::size_t total) override;

 private:
  session& s_;
  bool json_;
  std::optional<rcb4::transport::response> last_;
  std::unique_ptr<cli::progress> bar_;
  std::string label_;
};

/** A progress line on stderr for long work: only on a terminal, never under --json. */
class progress {
 public:
  /** Shows "@p label  done/total" while work goes on, when stderr is a terminal and not @p json. */
  progress(std::string label, std::size_t total, bool json_output);
  ~progress();
  progress(const progress&) = delete;
  progress& operator=(const progress&) = delete;
  /** @p done of the total are finished (redrawn at most 10 times a second). */
  void update(std::size_t done);
  /** Clears the line (before the result is printed). */
  void finish();

 private:
  std::string label_;
  std::size_t total_;
  bool on_;
  std::chrono::steady_clock::time_point last_{};
};

/** Prints a frame for --trace and `decode`: direction, hex, meaning. */
class frame_printer {
 public:
  /** A request the host sent; remembers its reply shape for the next reply. */
  std::string request(std::span<const std::uint8_t> frame);
  /** Bytes the host received; returns one line per complete frame. */
  std::vector<std::string> received(std::span<const std::uint8_t> bytes);

 private:
  std::vector<std::uint8_t> rx_;
  std::optional<rcb4::reply_shape> expected_;
};

/** Where the parsed command leaves its work: run once parsing is done (errors of use come first). */
struct context {
  globals g;                    ///< the global options
  std::function<int()> action;  ///< the chosen command
};

/** Makes @p cmd, when chosen, open a session and run @p f on it. */
void on_device(CLI::App* cmd, context& ctx, std::function<int(session&)> f);
/** Makes @p cmd, when chosen, run @p f (no device opened). */
void on_run(CLI::App* cmd, context& ctx, std::function<int()> f);

// The command groups, one file each.
void add_board_commands(CLI::App& app, context& ctx);      ///< ping, version, config (cmd_board.cpp)
void add_memory_commands(CLI::App& app, context& ctx);     ///< read, write (cmd_memory.cpp)
void add_servo_commands(CLI::App& app, context& ctx);      ///< servo … (cmd_servo.cpp)
void add_sensor_commands(CLI::App& app, context& ctx);     ///< sensors, monitor (cmd_sensors.cpp)
void add_motion_commands(CLI::App& app, context& ctx);     ///< motion … (cmd_motion.cpp)
void add_button_commands(CLI::App* motion, context& ctx);  ///< motion buttons … (cmd_buttons.cpp)

void add_motion_file_commands(CLI::App* motion, context& ctx);  ///< motion pull|push|erase (cmd_motion_files.cpp)
/** The buttons (or other vector entries) of ROM's and RAM's table that go to @p address (cmd_buttons.cpp). */
std::vector<std::string> entries_playing(session& s, std::uint32_t address);
/** Options the motion commands share (cmd_motion.cpp). */
struct motion_options {
  std::string layout = "auto";  ///< the HTH4 version that wrote the board's program, or auto
  double timeout_s = 60;        ///< how long --wait / wait waits
};
/** Adds --layout (auto, 2.2, 2.0, 2.1, 1.3) to @p cmd. */
void add_layout(CLI::App* cmd, motion_options& o);
/** The layout --layout names (nothing for auto), before any board is asked. */
const rcb4::rom_layout* named_layout(const motion_options& o);
/**
 * The layout --layout names, refused when the ROM plainly has another; auto: told from the ROM
 * (ops::detect_layout), else a failure naming why.
 */
const rcb4::rom_layout& layout_for(session& s, const motion_options& o);
/** `motion play FILE`: a motion file played from the host, pose by pose with the board's timing (cmd_motion_files.cpp).
 */
int play_file(session& s, const std::string& file, bool rescale, const motion_options& o, const globals& g);
void add_bench_command(CLI::App& app, context& ctx);            ///< bench (cmd_bench.cpp)
void add_host_commands(CLI::App& app, context& ctx);            ///< list, doctor (cmd_host.cpp)
void add_frame_commands(CLI::App& app, context& ctx);           ///< decode, encode (cmd_frames.cpp)
void add_serve_command(CLI::App& app, context& ctx);            ///< serve (cmd_serve.cpp)
void add_robot_commands(CLI::App& app, context& ctx);           ///< joint, pose, trim, scan (cmd_robot.cpp)
void add_ui_command(CLI::App& app, context& ctx);               ///< ui (cmd_ui.cpp, ui/)
void add_rom_commands(CLI::App& app, context& ctx);             ///< rom backup|restore (cmd_rom.cpp)
void add_urdf_command(CLI::App& app, context& ctx);             ///< urdf (cmd_urdf.cpp)
void add_ics_commands(CLI::App& app, context& ctx);             ///< ics … (cmd_ics.cpp, cmd_ics_serve.cpp)
void add_project_commands(CLI::App& app, context& ctx);         ///< project import|export (cmd_project.cpp)
void add_trim_import(CLI::App* trim, context& ctx);             ///< trim import (cmd_project.cpp)
void add_startup_command(CLI::App* motion, context& ctx);       ///< motion startup (cmd_startup.cpp)
void add_flowchart_import(CLI::App* motion, context& ctx);      ///< motion import (cmd_project.cpp)
void add_motion_check_command(CLI::App* motion, context& ctx);  ///< motion check (cmd_motion_check.cpp)
// Shared by the robot commands (cmd_robot.cpp) and motion record (cmd_record.cpp).
/** Reads stdin up to a newline: true when Enter came; false at its end or on a caught signal. */
bool wait_for_enter();
/** The joints the words name (joints, groups, "all"; none: all), each once, in the model's order. */
std::vector<const rcb4::robot::joint*> joints_of(const rcb4::robot::model& m, const std::vector<std::string>& words);
/** Refuses (exit 1) naming @p missing, the joints of @p m the board has no servo block for; nothing when none. */
void refuse_missing(const rcb4::robot::model& m, const std::vector<const rcb4::robot::joint*>& missing);
/** Where the joints are on this board; joints without a block are an error naming them. */
rcb4::robot::joint_map locate(session& s, const rcb4::robot::model& m,
                              const std::vector<const rcb4::robot::joint*>& need);
/** Every located joint's block fields @p f, in the reads the planner chooses for this link. */
std::vector<rcb4::robot::joint_reading> read_all(session& s, const rcb4::robot::joint_map& map, rcb4::robot::fields f);
void add_record_command(CLI::App* motion, context& ctx);  ///< motion record (cmd_record.cpp)

/** An exception's words for a person: without Boost's " [category:value]" tail or the library's "rcb4: " prefix. */
std::string_view plain_message(std::string_view what);

/** Exit code and hint for an error from the device or the board. */
failure explain(const std::error_code& ec, std::string_view what);

/**
 * Catches SIGINT, SIGTERM and SIGHUP while it lives (without SA_RESTART, so a blocking read returns), so
 * that a command can stop cleanly or undo what it did (hold the joints it freed) before it exits.
 * The previous handlers come back when it goes.
 */
class signal_catcher {
 public:
  signal_catcher();
  ~signal_catcher();
  signal_catcher(const signal_catcher&) = delete;
  signal_catcher& operator=(const signal_catcher&) = delete;
  /** True once a signal arrived while a catcher lived. */
  static bool caught() noexcept;

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
  struct sigaction old_hup_ {};
};

}  // namespace cli
