// rcb4 command-line tool: what the commands share: parsing helpers, output, the device session,
// progress, the trace printer, and how errors become exit codes.
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <ctime>
#include <future>

#include <boost/asio/post.hpp>

#include <rcb4/transport/detect.hpp>
#include <rcb4/transport/serial.hpp>
#include <rcb4/transport/share.hpp>
#include <rcb4/transport/tcp.hpp>

#include <termios.h>
#include <unistd.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace cli {

void emit(const json& j) {
  // Names from a profile file may be any bytes: invalid UTF-8 becomes U+FFFD, never an exception.
  fmt::print("{}\n", j.dump(-1, ' ', false, json::error_handler_t::replace));
  std::fflush(stdout);
}

std::string file_stamp() { return rcb4::robot::services::file_stamp(); }

std::string plural(std::size_t n, std::string_view word) { return fmt::format("{} {}{}", n, word, n == 1 ? "" : "s"); }

std::string duration_text(std::chrono::duration<double, std::micro> d) {
  const double us = d.count();
  if (us < 10'000) return fmt::format("{:.0f} us", us);
  if (us < 10'000'000) return fmt::format("{:.1f} ms", us / 1000);
  return fmt::format("{:.2f} s", us / 1e6);
}

std::string position_text(std::uint16_t word, std::string_view zero, bool compact) {
  if (word == rcb4::servo_position::free_value) return "FREE";
  if (word == rcb4::servo_position::hold_value) return "HOLD";
  if (word == 0) return compact ? fmt::format("{:5} {:>6}", 0, zero) : fmt::format("0 ({})", zero);
  const auto d = rcb4::ops::degrees_of(word);
  if (!d) return fmt::format("0x{:04X}", word);
  return compact ? fmt::format("{:5} {:+6.1f}", word, *d) : fmt::format("{} ({:+.1f} deg)", word, *d);
}

json degrees_json(std::uint16_t word) {
  const auto d = rcb4::ops::degrees_of(word);
  if (!d) return nullptr;
  return std::round(*d * 100) / 100;
}

std::string join(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) {
    if (!out.empty()) out += ' ';
    out += w;
  }
  return out;
}

CLI::Validator int_range(long long lo, long long hi) {
  return CLI::Validator(
      [lo, hi](std::string& s) -> std::string {
        try {
          parse_int(s, "value", lo, hi);
        } catch (const usage_error& e) {
          return std::string(e.what()).substr(7);  // without "value: "
        }
        return {};
      },
      fmt::format("{}..{}", lo, hi));
}

long long parse_int(std::string_view s, std::string_view what, long long lo, long long hi) {
  const std::string_view original = s;
  bool negative = false;
  if (!s.empty() && (s[0] == '-' || s[0] == '+')) {
    negative = s[0] == '-';
    s.remove_prefix(1);
  }
  int base = 10;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    base = 16;
    s.remove_prefix(2);
  }
  unsigned long long v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v, base);
  if (s.empty() || r.ec != std::errc{} || r.ptr != s.data() + s.size())
    throw usage_error{fmt::format("{}: not a number: '{}'", what, original)};
  const long long value = negative ? -static_cast<long long>(v) : static_cast<long long>(v);
  if (value < lo || value > hi) throw usage_error{fmt::format("{}: {} is outside {}..{}", what, original, lo, hi)};
  return value;
}

std::vector<std::uint8_t> parse_hex(std::string_view s, std::string_view what) {
  std::vector<std::uint8_t> out;
  int pending = -1;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const char ch = s[i];
    if (ch == ' ' || ch == ',' || ch == ':' || ch == '\t' || ch == '\n' || ch == '\r') {
      if (pending >= 0) throw usage_error{fmt::format("{}: odd number of hex digits before position {}", what, i)};
      continue;
    }
    if (ch == '0' && i + 1 < s.size() && (s[i + 1] == 'x' || s[i + 1] == 'X') && pending < 0) {
      ++i;
      continue;
    }
    if (!std::isxdigit(static_cast<unsigned char>(ch)))
      throw usage_error{fmt::format("{}: '{}' is not a hex digit", what, ch)};
    const int d = std::isdigit(static_cast<unsigned char>(ch)) ? ch - '0' : (std::tolower(ch) - 'a' + 10);
    if (pending < 0) {
      pending = d;
    } else {
      out.push_back(static_cast<std::uint8_t>(pending * 16 + d));
      pending = -1;
    }
  }
  if (pending >= 0) throw usage_error{fmt::format("{}: odd number of hex digits", what)};
  return out;
}

namespace {
/** Wraps an open descriptor (its own dup: the lock and TIOCEXCL stay with the open file). */
stream adopt(boost::asio::io_context& io, int fd) {
  const int own = ::dup(fd);
  if (own < 0) throw std::system_error(errno, std::generic_category(), "dup");
  return stream(io, own);
}
}  // namespace

session::session(const globals& g) {
  if (!g.empty_device.empty()) throw usage_error(g.empty_device);
  rcb4::transport::client_options opt;
  opt.turnaround = g.timeout;
  if (g.trace) {
    auto printer = std::make_shared<frame_printer>();
    const auto start = std::chrono::steady_clock::now();
    opt.trace = [printer, start](rcb4::transport::direction d, std::chrono::steady_clock::time_point t,
                                 std::span<const std::uint8_t> b) {
      const double ms = std::chrono::duration<double, std::milli>(t - start).count();
      if (d == rcb4::transport::direction::tx)
        fmt::print(stderr, "{:10.3f} ms  -> {}\n", ms, printer->request(b));
      else
        for (const auto& line : printer->received(b)) fmt::print(stderr, "{:10.3f} ms  <- {}\n", ms, line);
    };
  }
  std::string path = g.device;
  std::uint32_t baud = 115200;
  if (path.empty()) {
    rcb4::board::options o;
    o.servos = robot_of(g).mask();  // the virtual board is the robot --robot names
    board_ = std::make_unique<rcb4::board::virtual_board>(o);
    board_io_ = std::make_unique<rcb4::transport::io_thread>();
    server_ = rcb4::transport::board_server::serve_pty(board_io_->context(), *board_);
    path = server_->where();
    where_ = fmt::format("the in-process virtual board ({})", path);
  } else {
    where_ = path;
  }
  if (path.rfind("tcp:", 0) == 0) {
    // A malformed address is the user's mistake (exit 2), not the device's.
    const auto rest = std::string_view(path).substr(4);
    const auto colon = rest.rfind(':');
    if (colon == std::string_view::npos || colon == 0)
      throw usage_error(fmt::format("--device {}: expected tcp:HOST:PORT", path));
    parse_int(rest.substr(colon + 1), "--device port", 1, 65535);
    rate_known_ = g.baud.has_value();
    baud = g.baud.value_or(115200);  // the bridge's line rate is unknown: the slowest gives safe deadlines
    auto socket = rcb4::transport::connect(io_.context(), path.substr(4));
    opt.baud = baud;
    client_ = std::make_unique<client>(adopt(io_.context(), socket.native_handle()), opt);
    return;
  }
  // A port held by rcb4 ui is reached through it (transport/share.hpp): the studio's one FIFO
  // carries our exchanges between its own, and its page sees what we change.
  rcb4::transport::error_code shared_ec;
  int holder = 0;
  if (auto socket = rcb4::transport::connect_share(io_.context(), path, shared_ec, &holder); !board_ && !shared_ec) {
    where_ = fmt::format("{} (through rcb4 ui, pid {})", path, holder);
    if (g.trace) fmt::print(stderr, "rcb4: {} is held by rcb4 ui (pid {}): going through it\n", path, holder);
    rate_known_ = false;  // the studio's rate is not ours to know: the slowest gives safe deadlines
    opt.baud = g.baud.value_or(115200);
    client_ = std::make_unique<client>(adopt(io_.context(), socket.native_handle()), opt);
    client_->execute(rcb4::ping{rcb4::ping_form::short_});
    shared_ = true;
    return;
  }
  if (g.baud) {
    baud = *g.baud;
  } else {
    rcb4::transport::detect_options how;
    how.turnaround = std::max(g.timeout, std::chrono::milliseconds(50));
    how.trace = opt.trace;  // --trace shows the detection's frames too
    rcb4::transport::error_code ec;
    baud = rcb4::transport::detect_baud(io_.context(), path, ec, how);
    if (ec) throw rcb4::transport::system_error(ec, path);  // names the device
  }
  auto port = rcb4::transport::open_serial(io_.context(), path, baud);
  // Bytes a previous program left behind (a late reply to a request it gave up on) must not
  // answer our first request: drop what has arrived, then a ping puts the line in step (a stale
  // reply that comes later fails the ping's shape, and the client resynchronises).
  ::tcflush(port.native_handle(), TCIFLUSH);
  opt.baud = baud;
  client_ = std::make_unique<client>(adopt(io_.context(), port.native_handle()), opt);
  client_->execute(rcb4::ping{rcb4::ping_form::short_});
  holds_port_ = !board_;
}

session::~session() {
  client_.reset();
  rcb4::transport::board_server::shutdown(server_);  // before board_io_'s context goes
  board_io_.reset();                                 // joins the board's thread
}

std::optional<std::uint16_t> session::by_hand(rcb4::ics_number n, std::uint16_t position) {
  if (!board_) return std::nullopt;
  // The board lives on its own io thread: the hand turns it there, and this waits (1 s at most).
  auto done = std::make_shared<std::promise<std::optional<std::uint16_t>>>();
  auto answer = done->get_future();
  boost::asio::post(board_io_->context(), [done, n, position, b = board_.get()] {
    const auto block = b->block_of(n);
    if (!block) return done->set_value(std::nullopt);
    const auto target = b->ram16(*block + rcb4::servo_block::target.offset);
    if (target == 0x8000) b->turn_by_hand(n, position);
    done->set_value(target);
  });
  if (answer.wait_for(std::chrono::seconds(1)) != std::future_status::ready) return std::nullopt;
  return answer.get();
}

// ---------------------------------------------------------------------------------------------

std::string frame_printer::request(std::span<const std::uint8_t> frame) {
  const auto r = rcb4::parse_command(frame);
  if (r.status != rcb4::parse_status::complete) {
    expected_.reset();
    return fmt::format("{:<30}  (not a request: {})", rcb4::hex(frame),
                       r.status == rcb4::parse_status::error ? rcb4::message(r.error) : "incomplete");
  }
  expected_ = rcb4::expected_reply(r.value());
  return fmt::format("{:<30}  {}", rcb4::hex(frame), r.value());
}

std::vector<std::string> frame_printer::received(std::span<const std::uint8_t> bytes) {
  rx_.insert(rx_.end(), bytes.begin(), bytes.end());
  std::vector<std::string> lines;
  while (!rx_.empty()) {
    const auto r = expected_ ? rcb4::parse_reply(rx_, *expected_) : rcb4::parse_reply_frame(rx_);
    if (r.status == rcb4::parse_status::need_more) break;
    const std::size_t n = r.status == rcb4::parse_status::complete ? r.consumed : std::max<std::size_t>(r.consumed, 1);
    const auto frame = std::span<const std::uint8_t>(rx_).first(std::min(n, rx_.size()));
    if (r.status == rcb4::parse_status::complete)
      lines.push_back(fmt::format("{:<30}  {}", rcb4::hex(frame), r.value()));
    else
      lines.push_back(fmt::format("{:<30}  (bad reply: {})", rcb4::hex(frame), rcb4::message(r.error)));
    rx_.erase(rx_.begin(), rx_.begin() + static_cast<std::ptrdiff_t>(frame.size()));
    expected_.reset();
  }
  return lines;
}

// ---------------------------------------------------------------------------------------------

progress::progress(std::string label, std::size_t total, bool json_output)
    : label_(std::move(label)), total_(total), on_(!json_output && ::isatty(STDERR_FILENO)) {}

progress::~progress() { finish(); }

void progress::finish() {
  if (on_ && last_ != std::chrono::steady_clock::time_point{}) fmt::print(stderr, "\r{:70}\r", "");
  last_ = {};
}

void progress::update(std::size_t done) {
  if (!on_) return;
  const auto now = std::chrono::steady_clock::now();
  if (done < total_ && now - last_ < std::chrono::milliseconds(100)) return;
  last_ = now;
  fmt::print(stderr, "\r  {}  {}/{}  {:3.0f} %", label_, done, total_,
             total_ ? 100.0 * static_cast<double>(done) / static_cast<double>(total_) : 100.0);
  std::fflush(stderr);
}

const rcb4::robot::model& robot_of(const globals& g) {
  static std::optional<rcb4::robot::model> loaded;
  if (!loaded) {
    try {
      loaded = rcb4::robot::open_profile(g.robot);
    } catch (const rcb4::robot::profile_error& e) {
      throw failure(exit_usage, fmt::format("--robot {}", e.what()),
                    "profiles/khr-3hv.yaml shows the format, with comments");
    }
  }
  return *loaded;
}

void on_device(CLI::App* cmd, context& ctx, std::function<int(session&)> f) {
  cmd->callback([&ctx, f = std::move(f)] {
    ctx.action = [&ctx, f] {
      session s(ctx.g);
      return f(s);
    };
  });
}

void on_run(CLI::App* cmd, context& ctx, std::function<int()> f) {
  cmd->callback([&ctx, f = std::move(f)] { ctx.action = f; });
}

std::string_view plain_message(std::string_view what) {
  if (const auto at = what.rfind(" ["); at != std::string_view::npos && what.back() == ']') what = what.substr(0, at);
  for (std::string_view prefix : {"rcb4 operation: ", "rcb4: "})
    if (what.substr(0, prefix.size()) == prefix) what.remove_prefix(prefix.size());
  return what;
}

session_link::~session_link() = default;

rcb4::reply session_link::exchange(const rcb4::command& c) {
  rcb4::transport::error_code ec;
  last_.emplace(s_.c().exchange(c, ec));
  if (ec) {  // the services take std::system_error (Boost 1.81 carries the category across)
    throw std::system_error(std::error_code(ec));
  }
  return last_->view();
}

void session_link::failed(rcb4::errc e) { throw std::system_error(make_error_code(e), std::string(rcb4::message(e))); }

void session_link::progress(std::string_view label, std::size_t done, std::size_t total) {
  if (!bar_ || label != label_) {
    bar_.reset();  // the last line cleared first
    label_ = label;
    bar_ = std::make_unique<cli::progress>(label_, total, json_);
  }
  bar_->update(done);
  if (done >= total) bar_.reset();
}

failure explain(const std::error_code& ec, std::string_view what) {
  namespace t = rcb4::transport;
  if (ec.category() == rcb4::codec_category()) {
    // The codec's and the operations' errors: all exit 1, each with what to do about it.
    static constexpr std::pair<rcb4::errc, std::string_view> hints[] = {
        {rcb4::errc::nack, "the board refused the command (range, unallocated servo, or a busy program)"},
        {rcb4::errc::bad_allocation_table,
         "`rcb4 read ram 0x0044 70` shows the table (ICS k's block address at +2k, little-endian); writing the "
         "project again from HeartToHeart4 rewrites it"},
        {rcb4::errc::bad_checksum, "replies fail their checksum: a wrong baud or parity, or a noisy line"},
        {rcb4::errc::bad_reply_length,
         "the reply is not as long as this command's answer: a wrong baud or parity, another device on the line, "
         "or a reply cut short; `rcb4 --trace ...` shows the bytes"},
        {rcb4::errc::echo_mismatch,
         "the reply is for another command: a late answer to an earlier exchange (a slow link needs a longer "
         "--timeout MS) or another program writing to the line; `rcb4 --trace ...` shows the bytes"},
        {rcb4::errc::bad_ack_code,
         "a 4-byte reply whose status is neither ACK nor NACK: a wrong baud or parity, or not an RCB-4; `rcb4 "
         "--trace ...` shows the bytes"},
        {rcb4::errc::unexpected_ack,
         "the board acknowledged a read instead of answering it: another firmware or device on the line"},
    };
    for (const auto& [e, hint] : hints)
      if (ec == e) return {exit_board, std::string(what), std::string(hint)};
    return {exit_board, std::string(what)};
  }
  if (ec == t::transport_errc::echo)
    return {exit_board, std::string(what),
            "the line returns what is sent: a loopback plug or an echoing adapter, not an RCB-4"};
  if (ec == t::transport_errc::timeout || ec == t::transport_errc::no_board)
    return {exit_timeout, std::string(what),
            "is the board powered, the cable in, the adapter in RCB-4 mode? try --baud; a slow link (a bridge, "
            "a busy adapter) needs a longer --timeout MS; `rcb4 doctor` checks the rest"};
  if (ec == t::transport_errc::truncated)
    return {exit_board, std::string(what),
            "a board answered but its reply stopped short: a noisy or failing line, a wrong baud, or a board "
            "busy with something else"};
  if (ec == t::transport_errc::line_error)
    return {exit_board, std::string(what),
            "a byte of the board's reply failed its parity check, every try: a noisy or too long cable, a loose "
            "connector, a wrong baud, or a second device on the line; damaged bytes are never used"};
  if (ec == t::transport_errc::port_busy)
    return {exit_io, std::string(what),
            "another program has the port open (`fuser -v` on the device shows which); a port rcb4 ui holds is "
            "reached through it, by the same user"};
  if (ec == std::errc::permission_denied)
    return {exit_io, std::string(what),
            "no permission: join the dialout group or install the udev rule (`rcb4 doctor` says how)"};
  if (ec == std::errc::inappropriate_io_control_operation) {  // ENOTTY: /dev/null, a file, a pipe
    std::string message(what);
    if (const auto at = message.find(ec.message()); at != std::string::npos)
      message.replace(at, ec.message().size(), "not a serial port");
    return {exit_io, message, "give the serial port the board is on (`rcb4 list`), or tcp:HOST:PORT for a bridge"};
  }
  if (ec == std::errc::no_such_file_or_directory) {
    // "127.0.0.1:4000" (what `rcb4 serve --tcp` prints) is a bridge's address, not a path.
    const auto w = std::string(what);
    const auto colon = w.find(':');
    const auto host = w.substr(0, colon);
    const bool address = colon != std::string::npos && colon > 0 && host.find('/') == std::string::npos &&
                         w.find_first_not_of("0123456789", colon + 1) > colon + 1 &&
                         std::isdigit(static_cast<unsigned char>(w[colon + 1]));
    return {exit_io, w,
            address ? fmt::format("no such device; for a TCP bridge write tcp:{}", w.substr(0, w.find(": ")))
                    : "no such device: `rcb4 list` shows the serial ports"};
  }
  if (t::is_link_lost(ec))
    return {exit_io, std::string(what),
            "the device went away (unplugged?), or the rcb4 ui this went through stopped; over TCP at the first "
            "exchange: the server has another client (rcb4 serve --tcp and ser2net serve one at a time)"};
  return {exit_io, std::string(what)};
}

namespace {
volatile std::sig_atomic_t signal_seen = 0;
extern "C" void on_caught_signal(int) { signal_seen = 1; }
}  // namespace

signal_catcher::signal_catcher() {
  struct sigaction act {};
  act.sa_handler = on_caught_signal;
  sigemptyset(&act.sa_mask);
  act.sa_flags = 0;
  ::sigaction(SIGINT, &act, &old_int_);
  ::sigaction(SIGTERM, &act, &old_term_);
  ::sigaction(SIGHUP, &act, &old_hup_);  // the terminal closed: clean up as for Ctrl-C
}

signal_catcher::~signal_catcher() {
  ::sigaction(SIGINT, &old_int_, nullptr);
  ::sigaction(SIGTERM, &old_term_, nullptr);
  ::sigaction(SIGHUP, &old_hup_, nullptr);
}

bool signal_catcher::caught() noexcept { return signal_seen != 0; }

}  // namespace cli
