// rcb4 — robot services: the board as the workflows see it, and how they refuse.
// SPDX-License-Identifier: BSL-1.0
//
// A robot service (rcb4/robot/services/*.hpp) is a workflow a user runs: push a motion, erase it,
// press a button. Its policy is decided once, here, from what it reads of the board; the front
// ends (the rcb4 tool, rcb4 ui, pyrcb4, the ROS node) hand it a link to their board and render its
// report, or its refusal, in their own way:
//
//   struct my_link : rcb4::robot::services::link {
//     rcb4::reply exchange(const rcb4::command& c) override { return my_client.exchange(c); }
//   };
//   my_link l;
//   auto report = rcb4::robot::services::erase_motion(l, rcb4::hth4_2_2, 10, save_backup_here);
//
// A refusal is a `refused` exception (its kind maps to the tool's exit code and to pyrcb4's
// exception class); a failure of the line is whatever the link throws.
#pragma once

#include <rcb4/error_category.hpp>
#include <rcb4/ops/operation.hpp>

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>

namespace rcb4::robot::services {

/** Why a workflow refused (each front end maps it once: exit code, exception class). */
enum class refusal_kind {
  board,    ///< the board's state forbids it (a motion runs, a slot is broken): tool exit 1, pyrcb4 BoardRefused
  usage,    ///< the request or its file is wrong (a bad number, a file that does not read): exit 2, UsageError
  limit,    ///< a joint would go beyond its limit: exit 2, LimitError
  line,     ///< the line failed part way through a workflow (refused::code says how): exit 3 or 4, DeviceError
  timeout,  ///< the board did not finish in the time allowed (a called motion that runs on): exit 4, TimeoutError
};

/** A workflow that did not do what it was asked, and why; nothing was written unless the message says so. */
struct refused : std::runtime_error {
  /** @p message says what and why, @p fix what to do (optional), @p saved a backup the workflow had saved. */
  refused(refusal_kind k, std::string message, std::string fix = {}, std::string saved = {}, std::error_code why = {})
      : std::runtime_error(std::move(message)), kind(k), hint(std::move(fix)), backup(std::move(saved)), code(why) {}
  refusal_kind kind;     ///< how the front end reports it
  std::string hint;      ///< what to do about it, or empty
  std::string backup;    ///< the backup file of what the workflow had begun to replace, or empty
  std::error_code code;  ///< for refusal_kind::line: the line's error (a timeout, an unplugged device)
};

/** The board, one exchange at a time, as the front end reaches it (a client, a board in-process, a UART). */
class link {
 public:
  virtual ~link() = default;
  /** Sends @p c and returns its reply (valid until the next call); throws std::system_error when the line fails. */
  virtual reply exchange(const command& c) = 0;
  /** An operation failed (a NACK, a malformed reply): throws; the default throws std::system_error. */
  [[noreturn]] virtual void failed(errc e) { throw std::system_error(make_error_code(e)); }
  /** Long work goes on: @p done of @p total under @p label (a progress bar; the default shows nothing). */
  virtual void progress(std::string_view label, std::size_t done, std::size_t total) {
    (void)label, (void)done, (void)total;
  }
};

/** The local time for the names of files a workflow saves: "20261124-230605". */
std::string file_stamp();

/** Runs @p op (kept by the caller) to its end on @p l; its failure through link::failed. */
template <ops::Operation Op>
Op& drive(link& l, Op& op) {
  while (auto c = op.next()) op.on_reply(l.exchange(*c));
  if (op.error() != errc{}) l.failed(op.error());
  return op;
}

/** Runs @p op (by value) and returns its value. */
template <ops::Operation Op>
auto run(link& l, Op op) {
  drive(l, op);
  return op.value();
}

}  // namespace rcb4::robot::services
