// pyrcb4: the Board in C++ (see board.hpp).
// SPDX-License-Identifier: BSL-1.0
#include "board.hpp"

#include <rcb4/motion/buttons.hpp>
#include <rcb4/ops/layout.hpp>
#include <rcb4/robot/services/moves.hpp>
#include <rcb4/transport/detect.hpp>
#include <rcb4/transport/serial.hpp>
#include <rcb4/transport/share.hpp>
#include <rcb4/transport/tcp.hpp>

#include <fmt/format.h>
#include <termios.h>
#include <unistd.h>

#include <cmath>
#include <limits>
#include <optional>
#include <thread>

namespace pyrcb4 {

namespace t = rcb4::transport;

void raise(const std::error_code& ec, const std::string& what) {
  const std::string text = what.empty() ? ec.message() : what + ": " + ec.message();
  if (ec.category() == rcb4::codec_category()) {
    using rcb4::errc;
    if (ec == errc::nack) throw board_error(fault::refused, text + " (the board answered NACK)");
    if (ec == errc::frames_out_of_range)
      throw board_error(fault::limit, what +
                                          ": longer than a move can take: 255 output periods of the board (2.55 s "
                                          "at 10 ms, 6.375 s at 25 ms)");
    // Malformed answers are BadReply; what the codec or an operation refused before or instead of
    // sending (an empty motion slot, an allocation table with nothing in it) is the board lacking it.
    static constexpr errc malformed[] = {errc::bad_checksum, errc::bad_reply_length, errc::echo_mismatch,
                                         errc::bad_ack_code, errc::unexpected_ack};
    for (const auto e : malformed)
      if (ec == e) throw board_error(fault::bad_reply, text);
    throw board_error(fault::refused, text);
  }
  if (ec == t::transport_errc::timeout || ec == t::transport_errc::no_board)
    throw board_error(
        fault::timeout,
        text + " (is the board powered, the cable in, the baud right? a slow link needs a longer timeout)");
  if (ec == t::transport_errc::truncated || ec == t::transport_errc::echo || ec == t::transport_errc::line_error)
    throw board_error(fault::bad_reply, text);
  if (ec == std::errc::inappropriate_io_control_operation)
    throw board_error(fault::device, what + ": not a serial port", ENOTTY);
  // An OS error keeps its number (DeviceError.errno); others (a busy port, a lost link) have none.
  const bool os = ec.category() == std::generic_category() || ec.category() == std::system_category() ||
                  ec.category() == boost::system::generic_category() ||
                  ec.category() == boost::system::system_category();
  throw board_error(fault::device, text, os ? ec.value() : 0);
}

namespace {
/** The share of @p path when rcb4 ui holds it and serves it, with its process id in @p holder. */
std::optional<t::local_socket> connect_shared(boost::asio::io_context& io, const std::string& path, int& holder) {
  t::error_code ec;
  auto socket = t::connect_share(io, path, ec, &holder);
  if (ec) return std::nullopt;
  return socket;
}

stream adopt(boost::asio::io_context& io, int fd) {
  const int own = ::dup(fd);
  if (own < 0) throw board_error(fault::device, std::string("dup: ") + std::strerror(errno));
  return stream(io, own);
}

rcb4::robot::model open_robot(const std::string& robot) {
  try {
    return rcb4::robot::open_profile(robot);
  } catch (const rcb4::robot::profile_error& e) {
    throw board_error(fault::usage, std::string("robot: ") + e.what());
  }
}
}  // namespace

board::board(const std::string& device, std::uint32_t baud, const std::string& robot, std::chrono::milliseconds timeout)
    : model_(open_robot(robot)) {
  if (baud != 0 && baud != 115200 && baud != 625000 && baud != 1250000)
    throw board_error(fault::usage, "baud: the RCB-4 speaks 115200, 625000 or 1250000, not " + std::to_string(baud));
  if (timeout.count() <= 0) throw board_error(fault::usage, "timeout: must be more than 0 seconds");
  t::client_options opt;
  opt.turnaround = timeout;
  std::string path = device;
  if (path.empty()) {
    rcb4::board::options o;
    o.servos = model_.mask();  // the virtual board is the robot the profile describes
    board_ = std::make_unique<rcb4::board::virtual_board>(o);
    board_io_ = std::make_unique<t::io_thread>();
    server_ = t::board_server::serve_pty(board_io_->context(), *board_);
    path = server_->where();
    where_ = "the in-process virtual board, a simulation (" + path + ")";
  } else {
    where_ = path;
  }
  io_ = std::make_unique<t::io_thread>();
  t::error_code ec;
  if (path.rfind("tcp:", 0) == 0) {
    auto socket = t::connect(io_->context(), path.substr(4), ec);
    if (ec) raise(ec, path);
    opt.baud = baud ? baud : 115200;  // the bridge's rate is unknown: the slowest gives safe deadlines
    baud_known_ = baud != 0;
    client_ = std::make_unique<client>(adopt(io_->context(), socket.native_handle()), opt);
  } else if (int holder = 0; auto shared = board_ ? std::nullopt : connect_shared(io_->context(), path, holder)) {
    // A port rcb4 ui holds is reached through it (transport/share.hpp), sharing its one FIFO.
    auto& socket = *shared;
    where_ = path + " (through rcb4 ui, pid " + std::to_string(holder) + ")";
    opt.baud = baud ? baud : 115200;  // the studio's rate is not ours to know: the slowest gives safe deadlines
    baud_known_ = false;
    client_ = std::make_unique<client>(adopt(io_->context(), socket.native_handle()), opt);
  } else {
    if (baud == 0) {
      t::detect_options how;
      how.turnaround = std::max(timeout, std::chrono::milliseconds(50));
      baud = t::detect_baud(io_->context(), path, ec, how);
      if (ec) raise(ec, path);
    }
    auto port = t::open_serial(io_->context(), path, baud, ec);
    if (ec) raise(ec, path);
    ::tcflush(port.native_handle(), TCIFLUSH);  // what a previous program left must not answer us
    opt.baud = baud;
    auto own = adopt(io_->context(), port.native_handle());
    line_fd_ = own.native_handle();
    line_baud_ = baud;
    client_ = std::make_unique<client>(std::move(own), opt);
  }
  client_->execute(rcb4::ping{rcb4::ping_form::short_}, ec);
  if (ec) {
    close();
    raise(ec, where_);
  }
}

board::~board() { close(); }

void board::close() {
  closing_ = true;               // a long wait (a motion, a play, a recording) ends at its next look
  std::unique_lock life(life_);  // waits for calls under way: each ends by its deadline
  client_.reset();
  line_fd_ = -1;
  t::board_server::shutdown(server_);
  board_io_.reset();
  io_.reset();
  board_.reset();
}

bool board::is_open() const {
  std::shared_lock life(life_);
  return client_ != nullptr;
}

std::optional<std::uint32_t> board::baud() const {
  std::shared_lock life(life_);
  if (!client_ || !baud_known_) return std::nullopt;
  return client_->options().baud;
}

void board::fail(const std::error_code& ec, const std::string& what) {
  // Another program (stty, a terminal, pyserial opening the port) may have changed the line under
  // us: a wrong rate or a cooked line answers nothing, and looks like an unplugged cable for ever.
  // (A cooked line even reads as closed: its end-of-file character, ^D, may be a byte of a reply.)
  const bool line_fault = ec == t::transport_errc::timeout || ec == t::transport_errc::no_board ||
                          ec == t::transport_errc::truncated || ec == t::transport_errc::closed ||
                          ec == t::transport_errc::settings_not_kept || ec == t::transport_errc::echo ||
                          ec == t::transport_errc::line_error || ec.category() == rcb4::codec_category();
  if (line_fault && line_fd_ >= 0) {
    t::detail::kernel_termios2 now{};
    if (::ioctl(line_fd_, t::detail::tcgets2, &now) == 0) {
      const bool rate = t::detail::rate_close(now.c_ospeed, line_baud_);
      // (PARMRK too: without it an intact 0xFF arrives single, and the marked line's decoding fails)
      const bool raw = (now.c_lflag & (ICANON | ECHO | ISIG)) == 0 && (now.c_cflag & CSIZE) == CS8 &&
                       (now.c_iflag & (IXON | ICRNL)) == 0 && t::detail::iflag_marks(now.c_iflag);
      if (!rate || !raw) {
        std::uint32_t got = 0;
        bool parity = false;
        const auto again = t::detail::set_rcb4_line(line_fd_, line_baud_, got, parity);
        ::tcflush(line_fd_, TCIOFLUSH);  // what the cooked line echoed or kept is no reply
        const std::string changed = "another program changed " + where_ + "'s settings (" +
                                    (rate ? std::string() : "rate " + std::to_string(now.c_ospeed) + " baud") +
                                    (!rate && !raw ? ", " : "") + (raw ? "" : "no longer a raw 8-bit line") + ")";
        throw board_error(fault::device, what + ": " + ec.message() + ": " + changed +
                                             (again ? ", and they could not be set again: " + again.message()
                                                    : "; they are set again: try the call again"));
      }
    }
  }
  raise(ec, what);
}

client& board::c(const char* what) {
  if (!client_) throw board_error(fault::closed, std::string(what) + ": the board is closed");
  return *client_;
}

rcb4::ops::link_cost board::link(const char* what) {
  std::shared_lock life(life_);
  return rcb4::ops::link_cost::at(c(what).options().baud, std::chrono::milliseconds(1));
}

void board::refuse_if_motion_runs(const char* what) {
  // As the tool does: a ROM motion would overwrite the move a moment later.
  std::shared_lock life(life_);
  t::error_code ec;
  rcb4::ops::read_motion_state op;
  t::run(c(what), op, ec);
  if (ec) fail(ec, what);
  // The one rule (rcb4/robot/services/moves.hpp).
  if (const auto why = rcb4::robot::services::move_refusal(op.value()))
    throw board_error(fault::refused, std::string(what) + ": " + *why + " (stop_motion() or wait_motion() first)");
}

template <class Op>
auto board::run(Op op, const char* what) {
  std::shared_lock life(life_);
  t::error_code ec;
  t::run(c(what), op, ec);
  if (ec) fail(ec, what);
  return op.value();
}

double board::ping() {
  std::shared_lock life(life_);
  t::error_code ec;
  const auto start = std::chrono::steady_clock::now();
  c("ping").execute(rcb4::ping{rcb4::ping_form::short_}, ec);
  if (ec) fail(ec, "ping");
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string board::version() { return run(rcb4::ops::read_version{}, "version"); }

rcb4::config_word board::config() { return run(rcb4::ops::read_config{}, "config"); }

void board::set_config(const rcb4::config_word& cw) {
  run(rcb4::ops::detail::ack_sequence({rcb4::ops::detail::write_u16(rcb4::ram::config, cw.encode())}), "set config");
}

namespace {
rcb4::ops::memory memory_of(const std::string& m) {
  if (m == "ram") return rcb4::ops::memory::ram;
  if (m == "rom") return rcb4::ops::memory::rom;
  throw board_error(fault::usage, "memory: 'ram' or 'rom', not '" + m + "'");
}
}  // namespace

std::vector<std::uint8_t> board::read(const std::string& memory, std::uint32_t address, std::size_t n) {
  rcb4::ops::read_memory op(memory_of(memory), address, n);
  if (op.error() != rcb4::errc{})
    throw board_error(fault::usage, "read " + memory + ": " + std::string(rcb4::message(op.error())));
  return run(std::move(op), "read");
}

void board::write(const std::string& memory, std::uint32_t address, const std::vector<std::uint8_t>& data) {
  rcb4::ops::write_memory op(memory_of(memory), address, data);
  if (op.error() != rcb4::errc{})
    throw board_error(fault::usage, "write " + memory + ": " + std::string(rcb4::message(op.error())));
  run(std::move(op), "write");
}

const rcb4::robot::joint_map& board::joints_located() {
  {
    std::lock_guard lk(state_);
    if (map_) return *map_;
  }
  auto m = run(rcb4::robot::locate_joints(model_), "locate the joints");
  std::lock_guard lk(state_);
  if (!map_) map_ = std::move(m);
  return *map_;
}

std::vector<std::optional<double>> board::angles() {
  const auto& map = joints_located();
  const auto rs =
      run(rcb4::robot::read_joints(map, rcb4::robot::fields::positions, link("read the joints")), "read the joints");
  std::vector<std::optional<double>> out(model_.joints().size());
  for (const auto& r : rs)
    for (std::size_t i = 0; i < model_.joints().size(); ++i)
      if (r.j == &model_.joints()[i]) out[i] = r.degrees();
  return out;
}

double board::move(const std::vector<std::pair<std::string, double>>& targets, double seconds) {
  if (!(seconds >= 0) || seconds > 6.375)
    throw board_error(fault::limit,
                      "time: a move takes 0 to 255 output periods of the board (2.55 s at 10 ms, "
                      "6.375 s at 25 ms)");
  const auto time = std::chrono::milliseconds(static_cast<long long>(std::llround(seconds * 1000)));
  std::vector<rcb4::robot::joint_target> ts;
  for (const auto& [name, deg] : targets) {
    if (!model_.find(name))
      throw board_error(fault::usage, "no joint of " + model_.name() + " is called '" + name + "'");
    ts.push_back({name, deg, std::nullopt});
  }
  auto checked = rcb4::robot::check_targets(model_, ts, time);
  if (!rcb4::robot::ok(checked)) throw board_error(fault::limit, std::get<rcb4::robot::problem>(checked).message);
  refuse_if_motion_runs("move");
  const auto moves = run(rcb4::robot::move_joints(std::get<std::vector<rcb4::robot::joint_move>>(checked)), "move");
  const auto period = config().period;
  unsigned longest = 0;
  for (const auto& mv : moves) longest = std::max(longest, mv.frames);
  return longest * rcb4::milliseconds(period) / 1000.0;
}

std::vector<const rcb4::robot::joint*> board::joints_named(const std::vector<std::string>& words) const {
  std::vector<const rcb4::robot::joint*> js;
  for (const auto& w : words.empty() ? std::vector<std::string>{"all"} : words) {
    const auto sel = model_.select(w);
    if (!rcb4::robot::ok(sel)) throw board_error(fault::usage, std::get<rcb4::robot::problem>(sel).message);
    for (const auto* j : std::get<std::vector<const rcb4::robot::joint*>>(sel))
      if (std::find(js.begin(), js.end(), j) == js.end()) js.push_back(j);
  }
  return js;
}

std::pair<rcb4::servo_mask, std::vector<std::string>> board::servos_of(const std::vector<std::string>& words) {
  const auto js = joints_named(words);
  const auto& map = joints_located();
  std::pair<rcb4::servo_mask, std::vector<std::string>> out;
  for (const auto* j : js)
    if (map.block_of(*j)) {
      out.first.insert(j->ics);
      out.second.push_back(j->name);
    }
  if (out.first.empty()) throw board_error(fault::refused, "none of these joints has a servo on the board");
  return out;
}

std::vector<std::string> board::power(bool free, const std::vector<std::string>& words) {
  const auto [mask, done] = servos_of(words);
  run(rcb4::ops::set_servo_power(free ? rcb4::ops::power_state::free : rcb4::ops::power_state::hold, mask),
      free ? "free" : "hold");
  return done;
}

const rcb4::rom_layout& board::layout() {
  {
    std::lock_guard lk(state_);
    if (layout_) return *layout_;
  }
  const auto guess = run(rcb4::ops::detect_layout{}, "tell the ROM's layout");
  if (!guess.layout)
    throw board_error(fault::refused, "cannot tell which HeartToHeart4 layout the ROM has: " + guess.reason);
  std::lock_guard lk(state_);
  layout_ = guess.layout;
  return *layout_;
}

void board::play_motion(unsigned n) {
  const auto& l = layout();
  if (n < 1 || n > l.motion_count)
    throw board_error(fault::usage, "motion " + std::to_string(n) + " is outside 1.." + std::to_string(l.motion_count));
  check_playable(n, "play_motion");  // an empty or broken slot would stop the board's program
  run(rcb4::ops::play_motion(n, l, rcb4::ops::servo_power::keep), "play the motion");
}

rcb4::output_period board::period() { return run(rcb4::ops::read_config{}, "read the config word").period; }

void board::stop_motion() { run(rcb4::ops::stop_motion{}, "stop the motion"); }

void board::resume_motion() { run(rcb4::ops::resume_motion(), "resume the motion"); }

std::vector<std::string> board::set_param(bool speed, long long value, const std::vector<std::string>& words) {
  const char* what = speed ? "speed" : "stretch";
  if (value < 1 || value > 127)
    throw board_error(fault::usage, std::string(what) + ": 1..127 (the ICS parameter), not " + std::to_string(value));
  const auto v = rcb4::servo_param::make(static_cast<int>(value));
  const auto [mask, done] = servos_of(words);
  run(rcb4::ops::set_servo_param(speed ? rcb4::param_kind::speed : rcb4::param_kind::stretch, *v, mask), what);
  return done;
}

motion_status board::motion() {
  const auto st = run(rcb4::ops::read_motion_state(layout()), "motion state");
  return {st.running, st.suspended, st.motion, st.program_counter, st.program_on};
}

motion_status board::wait_motion(double seconds, const interrupt_check& check) {
  const auto deadline =
      std::chrono::steady_clock::now() +
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
  for (;;) {
    const auto st = motion();
    if (!st.running) return st;
    if (closing_) throw board_error(fault::closed, "wait_motion: the board was closed");
    if (std::chrono::steady_clock::now() >= deadline)
      throw board_error(fault::timeout, fmt::format("wait_motion: the motion still runs after {:g} s", seconds));
    std::this_thread::sleep_for(std::chrono::milliseconds(50));  // the board refreshes the state every 50 ms
    if (check) check();
  }
}

std::vector<rcb4::ops::motion_slot> board::motions() {
  return run(rcb4::ops::list_motions(layout()), "list the motions");
}

sensor_reading board::sensors() {
  const auto a = run(rcb4::ops::read_analog{}, "read AD");
  const auto p = run(rcb4::ops::read_pio{}, "read PIO");
  const auto r = run(rcb4::ops::read_receiver{}, "read the receiver");
  sensor_reading s;
  s.battery_volts = a.battery_volts;
  s.ad.assign(a.values.begin(), a.values.end());
  s.pio_direction = p.direction;
  s.pio_value = p.value;
  s.buttons = r.buttons;
  for (const auto& n : rcb4::motion::button_names)
    if (r.buttons & n.bit) s.button_names.emplace_back(n.name);
  s.pa.assign(r.analog.begin(), r.analog.end());
  return s;
}

std::vector<rcb4::robot::joint_reading> board::states() {
  const auto& map = joints_located();
  return run(rcb4::robot::read_joints(map, rcb4::robot::fields::state, link("read the joints")), "read the joints");
}

std::vector<rcb4::ops::slot_probe> board::scan() { return run(rcb4::ops::scan_slots(link("read the joints")), "scan"); }

void board::move_servos(const rcb4::servo_set<rcb4::servo_position>& targets, unsigned frames) {
  const auto f = rcb4::frames::make(frames);
  if (!f) throw board_error(fault::usage, "frames: 0..255");
  const auto frame = rcb4::const_servo::make(targets, *f);
  if (!frame) throw board_error(fault::usage, "move_servos: " + std::string(rcb4::message(frame.error())));
  refuse_if_motion_runs("move_servos");
  // The board ignores a servo it has no block for: said, not silently dropped.
  const auto slots = run(rcb4::ops::scan_slots(link("read the joints")), "scan");
  for (const auto ics : targets.mask())
    if (std::none_of(slots.begin(), slots.end(), [&](const auto& p) { return p.ics == ics; }))
      throw board_error(fault::refused, "ICS " + std::to_string(ics.value()) + " has no servo block on the board");
  std::shared_lock life(life_);
  t::error_code ec;
  c("move_servos").execute(rcb4::command{*frame}, ec);
  if (ec) raise(ec, "move_servos");
}

// --- control loop ------------------------------------------------------------------------------

control_loop::control_loop(board& b)
    : b_(b),
      map_(b.joints_located()),
      reads_(map_, rcb4::robot::fields::positions, b.link("control loop")),
      targets_(map_) {
  const auto js = targets_.joints();
  for (const auto& j : b.model_.joints()) {
    const auto it = std::find(js.begin(), js.end(), &j);
    index_.push_back(it == js.end() ? -1 : it - js.begin());
  }
}

void control_loop::read(double* out) {
  std::shared_lock life(b_.life_);
  reads_.restart();
  t::error_code ec;
  t::run(b_.c("read"), reads_, ec);
  if (ec) raise(ec, "read the joints");
  const auto& rs = reads_.value();  // one per profile joint, in its order
  for (std::size_t i = 0; i < index_.size(); ++i) {
    const auto d = i < rs.size() ? rs[i].degrees() : std::nullopt;
    out[i] = d ? *d : std::numeric_limits<double>::quiet_NaN();
  }
}

std::optional<std::string> control_loop::set(const double* degrees) {
  // Every target checked before any is kept: a refused set changes nothing.
  for (std::size_t i = 0; i < index_.size(); ++i) {
    if (std::isnan(degrees[i])) continue;
    const auto& j = b_.model_.joints()[i];
    if (index_[i] < 0) return j.name + " has no servo on the board";
    if (const auto p = rcb4::robot::to_position(j, degrees[i]); !rcb4::robot::ok(p))
      return std::get<rcb4::robot::problem>(p).message;
  }
  send_ = rcb4::servo_mask{};
  for (std::size_t i = 0; i < index_.size(); ++i)
    if (!std::isnan(degrees[i])) {
      targets_.set(static_cast<std::size_t>(index_[i]), degrees[i]);
      send_.insert(b_.model_.joints()[i].ics);
    }
  return std::nullopt;
}

void control_loop::send(unsigned frames) {
  const auto f = rcb4::frames::make(frames);
  if (!f) throw board_error(fault::usage, "frames: 0..255");
  // Only the joints this write names: another joint still on its way to an earlier target must
  // not be sent there again over these (fewer) frames, which would make it jump.
  if (send_.empty()) return;
  rcb4::servo_set<rcb4::servo_position> subset;
  for (const auto ics : send_) subset.insert(ics, *targets_.targets().find(ics));
  const auto c = rcb4::const_servo::make(subset, *f);
  if (!c) raise(c.error(), "write the targets");
  std::shared_lock life(b_.life_);
  t::error_code ec;
  b_.c("write").execute(rcb4::command{*c}, ec);
  if (ec) raise(ec, "write the targets");
}

}  // namespace pyrcb4
