// rcb4 command-line tool: what the subcommands share (options, parsing, the device session).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/board/virtual_board.hpp>
#include <rcb4/fmt.hpp>
#include <rcb4/ops.hpp>
#include <rcb4/transport/board_server.hpp>
#include <rcb4/transport/client.hpp>
#include <rcb4/transport/operations.hpp>

#include <fmt/core.h>
#include <boost/asio/posix/stream_descriptor.hpp>

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cli {

// Exit codes, one per kind of failure (documented in `rcb4 --help`).
inline constexpr int exit_ok = 0;       ///< done
inline constexpr int exit_board = 1;    ///< the board refused (NACK) or answered something malformed
inline constexpr int exit_usage = 2;    ///< bad command line
inline constexpr int exit_io = 3;       ///< device missing, busy, not permitted, unplugged
inline constexpr int exit_timeout = 4;  ///< no answer before the deadline (silent board, wrong baud)

/** A command-line mistake: printed with a pointer to --help, exit code 2. */
struct usage_error {
  std::string message;
};

/** Options every device subcommand takes. */
struct globals {
  std::string device;                      ///< empty: the in-process virtual board
  std::optional<std::uint32_t> baud;       ///< empty: detect (serial) or 1250000 (TCP)
  std::chrono::milliseconds timeout{100};  ///< turnaround allowance per exchange
  bool trace = false;                      ///< print every frame with its meaning
  bool json = false;                       ///< machine-readable output
};

/** The arguments of one subcommand, with its name for messages. */
struct args {
  std::string_view command;
  std::vector<std::string_view> list;
};

/** Integer from decimal, 0x hex or negative decimal, checked against [lo, hi]. */
long long parse_int(std::string_view s, std::string_view what, long long lo, long long hi);
/** Hex bytes: "07 0F 00", "070F00", "0x07,0x0F" (separators: space, comma, colon). */
std::vector<std::uint8_t> parse_hex(std::string_view s, std::string_view what);
/** A run-time value as a checked codec value; a bad one is a usage error naming @p what. */
template <class T>
T checked(long long v, std::string_view what) {
  auto r = T::make(v);
  if (!r) throw usage_error{fmt::format("{}: {} ({})", what, v, rcb4::message(r.error()))};
  return *r;
}

using stream = boost::asio::posix::stream_descriptor;
using client = rcb4::transport::basic_client<stream>;

/**
 * An open device: a serial port, a TCP bridge, or (no --device) an in-process virtual board on
 * a pseudo-terminal. Owns the io thread, the client, and the board when there is one.
 */
class session {
 public:
  explicit session(const globals& g);
  ~session();
  session(const session&) = delete;
  session& operator=(const session&) = delete;

  /** The client. */
  client& c() { return *client_; }
  /** The baud in use (deadlines; the wire rate on a serial port). */
  std::uint32_t baud() const noexcept { return client_->options().baud; }
  /** What was opened, for messages. */
  const std::string& where() const noexcept { return where_; }
  /** True when this is a serial device (not TCP). */
  bool is_serial() const noexcept { return serial_; }
  /** True when no --device was given. */
  bool is_virtual() const noexcept { return board_ != nullptr; }
  /** Runs @p op, throwing rcb4::transport::system_error on failure. */
  template <rcb4::ops::Operation Op>
  auto run(Op op) {
    return rcb4::transport::run(*client_, std::move(op));
  }

 private:
  std::unique_ptr<rcb4::board::virtual_board> board_;
  std::unique_ptr<rcb4::transport::io_thread> board_io_;
  std::shared_ptr<rcb4::transport::board_server> server_;
  rcb4::transport::io_thread io_;
  std::unique_ptr<client> client_;
  std::string where_;
  bool serial_ = true;
};

/** Prints a frame for --trace and `decode`: direction, hex, meaning. */
class frame_printer {
 public:
  /** A request the host sent; remembers its reply shape for the next reply. */
  std::string request(std::span<const std::uint8_t> frame);
  /** Bytes the host received; returns one line per complete frame. */
  std::vector<std::string> received(std::span<const std::uint8_t> bytes);
  /** Decodes a capture: frames back to back, requests and replies in any mix. */
  std::vector<std::string> decode(std::span<const std::uint8_t> bytes);

 private:
  std::vector<std::uint8_t> rx_;
  std::optional<rcb4::reply_shape> expected_;
};

// Subcommands; each returns an exit code.
int serve(const args& a);
int list(const args& a, const globals& g);
int doctor(const args& a, const globals& g);
int decode(const args& a, const globals& g);
int encode(const args& a, const globals& g);
int device_command(const args& a, const globals& g);

/** True when @p a asks for help. */
inline bool wants_help(const args& a) {
  for (auto s : a.list)
    if (s == "--help" || s == "-h") return true;
  return false;
}

}  // namespace cli
