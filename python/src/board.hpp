// pyrcb4: the Board the Python module wraps, in C++ (no Python here: module.cpp binds it, releases
// the GIL around what reaches the wire, and turns board_error into the Python exceptions).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/board/virtual_board.hpp>
#include <rcb4/ops.hpp>
#include <rcb4/robot/ops.hpp>
#include <rcb4/robot/profile.hpp>
#include <rcb4/robot/services/buttons.hpp>
#include <rcb4/robot/services/host_play.hpp>
#include <rcb4/robot/services/motion_slots.hpp>
#include <rcb4/robot/services/record.hpp>
#include <rcb4/robot/services/rom.hpp>
#include <rcb4/robot/services/trims.hpp>
#include <rcb4/transport/board_server.hpp>
#include <rcb4/transport/client.hpp>
#include <rcb4/transport/io_thread.hpp>
#include <rcb4/transport/operations.hpp>

#include <boost/asio/posix/stream_descriptor.hpp>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <stdexcept>
#include <string>
#include <vector>

namespace pyrcb4 {

/** The kinds of failure, one Python exception each (module.cpp). */
enum class fault { refused, timeout, device, bad_reply, limit, usage, closed };

/** A failure with its kind and a message for a person. */
struct board_error : std::runtime_error {
  board_error(fault k, const std::string& what, int os_errno = 0) : std::runtime_error(what), kind(k), err(os_errno) {}
  fault kind;  ///< which exception
  int err;     ///< the OS error number of a device error, or 0
};

/**
 * A service's words for Python: its hints name the rcb4 tool's commands and options (one text for
 * every front end); here they name the Board's methods and arguments instead ("rcb4 motion show
 * 70" becomes "show_motion(70)").
 */
std::string python_words(std::string text);

/** How long a wait may go on before it checks for Ctrl-C (module.cpp passes PyErr_CheckSignals). */
using interrupt_check = std::function<void()>;

/** The client over a serial port, a TCP bridge or a pseudo-terminal. */
using stream = boost::asio::posix::stream_descriptor;
using client = rcb4::transport::basic_client<stream>;

/** The motion state, as Python sees it. */
struct motion_status {
  bool running = false, suspended = false;
  std::optional<unsigned> motion;
  std::uint32_t program_counter = 0;
  bool program_on = true;  ///< the ROM program runs (off: buttons play nothing until resume_motion)
};

/** One reading of the board's inputs. */
struct sensor_reading {
  double battery_volts = 0;
  std::vector<std::uint16_t> ad;
  std::uint16_t pio_direction = 0, pio_value = 0, buttons = 0;
  std::vector<std::string> button_names;
  std::vector<std::uint8_t> pa;
};

/** A board: opened on construction, closed by close() or destruction; every call ends by its deadline. */
class board {
 public:
  /**
   * Opens @p device ("" : an in-process virtual board wired as @p robot; "/dev/ttyUSB0";
   * "tcp:HOST:PORT") at @p baud (0: detected on a serial port), each exchange allowed @p timeout.
   */
  board(const std::string& device, std::uint32_t baud, const std::string& robot, std::chrono::milliseconds timeout);
  ~board();
  board(const board&) = delete;
  board& operator=(const board&) = delete;

  /** Lets the line go; later calls raise a closed error. Safe to call twice. */
  void close();
  /** True until close(). */
  bool is_open() const;
  /** What was opened, for messages and repr. */
  const std::string& where() const noexcept { return where_; }
  /** The line rate in use; nothing over TCP when it was not given (the bridge's rate is its own). */
  std::optional<std::uint32_t> baud() const;
  /** The robot model. */
  const rcb4::robot::model& robot() const noexcept { return model_; }

  /** One round trip; its time in seconds. */
  double ping();
  /** The VERSION field's text. */
  std::string version();
  /** The config word, decoded. */
  rcb4::config_word config();
  /** Writes the config word (RAM: until power-off). */
  void set_config(const rcb4::config_word& c);
  /** @p n bytes of "ram" or "rom" from @p address. */
  std::vector<std::uint8_t> read(const std::string& memory, std::uint32_t address, std::size_t n);
  /** Writes @p data to "ram" or "rom" at @p address. */
  void write(const std::string& memory, std::uint32_t address, const std::vector<std::uint8_t>& data);

  /** Every joint's measured angle in degrees, in the profile's order; nothing for a servo that never answered. */
  std::vector<std::optional<double>> angles();
  /** Moves joints (name → degrees) over @p seconds, limits checked before anything is sent; returns the seconds it
   * takes. */
  double move(const std::vector<std::pair<std::string, double>>& targets, double seconds);
  /** Frees (no torque) or holds the joints, groups or "all" that @p words name (none: all). */
  std::vector<std::string> power(bool free, const std::vector<std::string>& words);

  /** Plays ROM motion @p n (the layout told from the ROM). */
  void play_motion(unsigned n);
  /** Suspends the ROM program. */
  void stop_motion();
  /** Whether a motion runs. */
  motion_status motion();
  /** Waits until no motion runs, or @p seconds; @p check runs between polls (Ctrl-C). */
  motion_status wait_motion(double seconds, const interrupt_check& check);
  /** The used motion slots: number, name, size. */
  std::vector<rcb4::ops::motion_slot> motions();
  /** AD, battery, PIO, buttons. */
  sensor_reading sensors();

  /** Every joint's block (trim, measured position, target), in the profile's order; unallocated ones marked. */
  std::vector<rcb4::robot::joint_reading> states();
  /** Writes trims (joint → degrees, within ±30) to RAM, and with @p persistent to HTH4's ROM image; read back. */
  rcb4::robot::services::trims_report set_trims(const std::vector<std::pair<std::string, double>>& trims,
                                                bool persistent);
  /** Every joint's trim, RAM and ROM (joints without a servo block marked). */
  std::vector<rcb4::robot::services::trim_entry> trims();
  /** Sets the ICS speed (@p speed) or stretch parameter to @p value (1..127) on the joints @p words name (none: all).
   */
  std::vector<std::string> set_param(bool speed, long long value, const std::vector<std::string>& words);
  /** Lets the ROM program run again where stop_motion() left it. */
  void resume_motion();
  /** The allocated servo slots, with their measured positions. */
  std::vector<rcb4::ops::slot_probe> scan();
  /** Sends servos by ICS number to positions (FREE, HOLD or 0..16383) over @p frames, in one CONST. */
  void move_servos(const rcb4::servo_set<rcb4::servo_position>& targets, unsigned frames);

  // The robot services (rcb4/robot/services/), as the tool runs them (board_services.cpp).
  /** Motion @p n's slot: its bytes and its code as the board runs it. */
  std::pair<std::vector<std::uint8_t>, rcb4::motion::listing> show_motion(unsigned n);
  /** Motion @p n as a motion file's document. */
  rcb4::robot::services::pull_report pull_motion(unsigned n);
  /** Writes @p src into motion @p n (the old bytes to @p backup, or motion-N-DATE.bin here). */
  rcb4::robot::services::push_report push_motion(const rcb4::robot::services::push_source& src, unsigned n,
                                                 const std::string& backup, bool dry_run);
  /** Empties motion @p n, its old bytes saved first. */
  rcb4::robot::services::erase_report erase_motion(unsigned n, const std::string& backup);
  /** Both copies of the button table. */
  rcb4::robot::services::button_tables buttons();
  /** @p word plays motion @p n. */
  rcb4::robot::services::table_report set_button(std::uint16_t word, unsigned n);
  /** @p word plays nothing. */
  rcb4::robot::services::table_report clear_button(std::uint16_t word);
  /** Presses @p word as a receiver would. */
  rcb4::robot::services::press_report press(std::uint16_t word, bool hold);
  /** Releases every button. */
  void release();
  /** The whole ROM. */
  std::vector<std::uint8_t> rom_backup();
  /** Writes @p image where it differs; the replaced ROM saved by @p save. */
  rcb4::robot::services::restore_report rom_restore(std::span<const std::uint8_t> image,
                                                    const rcb4::robot::services::rom_sink& save, bool force);
  /** The board's VERSION text and output period (for files the services write). */
  rcb4::output_period period();
  /** What a play from the host did. */
  struct file_play {
    std::size_t poses = 0, calls = 0;
    double seconds = 0;
    bool interrupted = false;
    std::vector<std::string> notes;
  };
  /**
   * Plays @p d from the host at the board's timing (rcb4/robot/services/host_play.hpp); @p stop
   * is asked between waits (true: the play stops, a called ROM motion too), as is close().
   */
  file_play play_file(const rcb4::robot::motion_document& d, const std::string& name, bool rescale, double timeout_s,
                      const std::function<bool()>& stop);
  /**
   * Records the joints @p words name (none: all) every @p every_s until @p seconds pass (0: until
   * @p stop says so, or close()); freed first with @p free and held again at the end.
   */
  rcb4::robot::services::record_report record(const std::vector<std::string>& words, double every_s, double seconds,
                                              double threshold, bool free, const std::function<bool()>& stop);
  /** The layout told from the ROM (cached). */
  const rcb4::rom_layout& rom_layout() { return layout(); }

 private:
  template <class Op>
  auto run(Op op, const char* what);
  /** Refuses (BoardRefused) a play of motion @p n when its slot is empty or broken. */
  void check_playable(unsigned n, const char* what);
  /** Runs @p f(link) on the line: the services' refusals become board_error, a failed line its fault. */
  template <class F>
  auto service(const char* what, F&& f);
  client& c(const char* what);
  rcb4::ops::link_cost link(const char* what);
  void refuse_if_motion_runs(const char* what);
  /** A failure of @p what: when another program changed the serial line's settings, set again and said so. */
  [[noreturn]] void fail(const std::error_code& ec, const std::string& what);
  /** The servos of the joints @p words name that the board has blocks for, and their names; refused when none. */
  std::pair<rcb4::servo_mask, std::vector<std::string>> servos_of(const std::vector<std::string>& words);
  /** The joints @p words name (joints, groups, "all"; none: all), each once. */
  std::vector<const rcb4::robot::joint*> joints_named(const std::vector<std::string>& words) const;
  const rcb4::rom_layout& layout();
  const rcb4::robot::joint_map& joints_located();

  friend class control_loop;
  rcb4::robot::model model_;
  std::unique_ptr<rcb4::board::virtual_board> board_;
  std::unique_ptr<rcb4::transport::io_thread> board_io_;
  std::shared_ptr<rcb4::transport::board_server> server_;
  std::unique_ptr<rcb4::transport::io_thread> io_;
  std::unique_ptr<client> client_;
  std::string where_;
  int line_fd_ = -1;  // the serial port's descriptor (owned by client_), or -1
  std::uint32_t line_baud_ = 0;
  bool baud_known_ = true;            // false over TCP without a baud: the bridge's rate is its own
  std::atomic<bool> closing_{false};  // close() has begun: long waits end at their next look
  mutable std::shared_mutex life_;    // calls hold it shared while they use the line; close() waits for them
  mutable std::mutex state_;          // guards the caches
  std::optional<rcb4::robot::joint_map> map_;
  const rcb4::rom_layout* layout_ = nullptr;
};

/**
 * The read and write halves of a control loop over every located joint: the reads the planner
 * chose (planned once), one CONST of every target per write; nothing allocated per cycle here.
 */
class control_loop {
 public:
  /** Plans the reads of @p b's located joints. */
  explicit control_loop(board& b);
  /** The joints, in the order read() and set() use (the profile's). */
  std::size_t size() const noexcept { return index_.size(); }
  /** Reads every joint's angle into @p out (size() values; NaN: no servo, or it never answered). */
  void read(double* out);
  /**
   * Takes the targets (size() degrees; NaN: the joint is left out of the next send()). A target
   * beyond a limit: the problem, and none of the new targets is kept.
   */
  std::optional<std::string> set(const double* degrees);
  /** Sends the joints the last set() named as one CONST reached in @p frames output periods (none: nothing). */
  void send(unsigned frames);
  /** The reads the planner chose: (address, size) of each. */
  const std::vector<rcb4::ops::byte_range>& plan() const noexcept { return reads_.plan(); }
  /** The ICS numbers a write sends, ascending. */
  std::vector<unsigned> slots() const {
    std::vector<unsigned> out;
    for (const auto ics : targets_.targets().mask()) out.push_back(ics.value());
    return out;
  }

 private:
  board& b_;
  rcb4::robot::joint_map map_;
  rcb4::robot::read_joints reads_;
  rcb4::robot::joint_targets targets_;
  std::vector<std::ptrdiff_t> index_;  // profile joint → its place in targets_.joints(), or -1
  rcb4::servo_mask send_;              // the joints the last set() named: what send() sends
};

/** Raises the board_error that @p ec is, with @p what (the operation) in its message. */
[[noreturn]] void raise(const std::error_code& ec, const std::string& what);

/** The exception class (fault) a service's refusal is in Python (board_services.cpp): one mapping for every binding. */
fault fault_of(rcb4::robot::services::refusal_kind k);
/**
 * Raises the board_error that the refusal @p e is, its message "@p what: why (hint)" in Python's
 * words (python_words); a refusal of kind line with an error code goes through raise().
 */
[[noreturn]] void raise_refusal(const rcb4::robot::services::refused& e, const std::string& what);

}  // namespace pyrcb4
