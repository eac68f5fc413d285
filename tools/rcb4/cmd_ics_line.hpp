// rcb4 command-line tool, private to the ics commands: the ICS line they open (a port, or an
// in-process virtual servo; --trace), and how a command runs on it (Ctrl-C, a line that closes).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include "app.hpp"

#include <rcb4/robot/services/ics.hpp>
#include <rcb4/transport/ics_port.hpp>

#include <functional>
#include <memory>

namespace cli::ics_line {

namespace sv = rcb4::robot::services;
namespace ics = rcb4::ics;

/** The line: the port --device names, or an in-process virtual servo. */
class line {
 public:
  explicit line(const globals& g) : trace_(g.trace) {
    if (!g.empty_device.empty()) {
      auto why = g.empty_device;
      if (const auto at = why.find("virtual board"); at != std::string::npos) why.replace(at, 13, "virtual servo");
      throw failure(exit_usage, why, "name the adapter's port: rcb4 list shows them");
    }
    const auto baud = g.baud.value_or(115200);
    if (g.device.empty()) {
      virtual_ = std::make_unique<sv::ics_virtual_link>(ics::virtual_line({ics::virtual_servo{}}));
      virtual_->set_baud(baud);
      fmt::print(stderr, "(no --device: an in-process virtual servo; no real servo is read or changed)\n");
      return;
    }
    if (g.device.rfind("tcp:", 0) == 0)
      throw failure(exit_usage, fmt::format("{}: ICS servos are reached through a serial port (an adapter in ICS "
                                            "mode) or rcb4 ics serve's pty, not TCP",
                                            g.device));
    try {
      port_ = std::make_unique<rcb4::transport::ics_port>(g.device, baud);
    } catch (const boost::system::system_error& e) {
      throw explain(std::error_code(e.code()), fmt::format("cannot open {}: {}", g.device, e.code().message()));
    }
    link_ = std::make_unique<sv::ics_port_link<rcb4::transport::ics_port>>(*port_);
  }
  sv::ics_link& get() {
    sv::ics_link& inner = virtual_ ? static_cast<sv::ics_link&>(*virtual_) : *link_;
    if (!trace_) return inner;
    if (!traced_) traced_ = std::make_unique<tracer>(inner);
    return *traced_;
  }

 private:
  /** --trace: every exchange on stderr, time, rate, bytes out and in. */
  class tracer final : public sv::ics_link {
   public:
    explicit tracer(sv::ics_link& inner) : in_(inner), start_(std::chrono::steady_clock::now()) {}
    std::vector<std::uint8_t> transact(std::span<const std::uint8_t> request, std::size_t expect,
                                       std::chrono::milliseconds wait) override {
      print("->", request);
      auto rx = in_.transact(request, expect, wait);
      print(rx.size() < expect ? "<- (short)" : "<-", rx);
      return rx;
    }
    std::vector<std::uint8_t> linger(std::chrono::milliseconds wait) override {
      auto rx = in_.linger(wait);
      if (!rx.empty()) print("<- (late)", rx);
      return rx;
    }
    void set_baud(std::uint32_t baud) override { in_.set_baud(baud); }
    std::uint32_t baud() const override { return in_.baud(); }

   private:
    void print(std::string_view dir, std::span<const std::uint8_t> b) const {
      std::string hex;
      for (auto x : b) hex += fmt::format(" {:02X}", x);
      fmt::print(stderr, "{:10.3f} ms  {:>7}  {:<10}{}\n",
                 std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count(),
                 in_.baud(), dir, hex);
    }
    sv::ics_link& in_;
    std::chrono::steady_clock::time_point start_;
  };
  bool trace_ = false;
  std::unique_ptr<tracer> traced_;
  std::unique_ptr<sv::ics_virtual_link> virtual_;
  std::unique_ptr<rcb4::transport::ics_port> port_;
  std::unique_ptr<sv::ics_link> link_;
};

/** The service's patience from the global options (--timeout). */
sv::ics_options options_of(const globals& g);

/**
 * Runs @p f: Ctrl-C does not cut an exchange in two (an EEPROM write is finished and reported; a
 * wait or a scan stops at the next step, exit 130), and a line that closes is told in ICS words.
 */
int guarded(const std::function<int()>& f);

}  // namespace cli::ics_line
