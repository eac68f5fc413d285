// rcb4 — an io_context with a thread of its own, for programs that use the blocking API.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>

#include <thread>

namespace rcb4::transport {

/** An io_context run by its own thread until destruction (then stopped and joined). */
class io_thread {
 public:
  /** Starts the thread. */
  io_thread() : work_(io_.get_executor()), thread_([this] { io_.run(); }) {}
  io_thread(const io_thread&) = delete;
  io_thread& operator=(const io_thread&) = delete;
  /** Stops the context and joins the thread. */
  ~io_thread() {
    work_.reset();
    io_.stop();
    thread_.join();
  }
  /** The context the thread runs. */
  boost::asio::io_context& context() noexcept { return io_; }

 private:
  boost::asio::io_context io_;
  boost::asio::executor_work_guard<boost::asio::io_context::executor_type> work_;
  std::thread thread_;
};

}  // namespace rcb4::transport
