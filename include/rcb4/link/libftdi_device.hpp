// rcb4 — an FTDI adapter (KONDO's USB adapters are FTDI chips, ics.md §6) through libftdi and
// libusb: no tty, no ftdi_sio driver, no file descriptor. A byte_device for device_link.hpp, which
// brings the link's whole policy (deadlines, resync, retries, a write sent once, reopening an
// adapter that was unplugged). Needs <ftdi.h> and -lftdi1 (Debian: libftdi1-dev; pkg-config
// libftdi1, version 1.5 or later for ftdi_tciflush); everything else in rcb4/link/ is std only.
//
//   rcb4::link::libftdi_device ftdi({0x165C, 0x0008}, 115200);   // KONDO's DUAL USB ADAPTER HS
//   if (!ftdi.ok()) fail(ftdi.error());
//   rcb4::link::device_link<rcb4::link::libftdi_device, std::chrono::steady_clock> link(ftdi, opts);
//
// The line is 8E1 (protocol.md §1) at the rate asked; the adapter's latency timer is set to 1 ms
// (the FTDI default of 16 ms would add 16 ms to every reply) and a read returns within 2 ms when
// nothing came, so the link polls it against its deadline.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/link/device_link.hpp>

#include <ftdi.h>

#include <chrono>
#include <cstdint>
#include <span>
#include <string>
#include <thread>
#include <utility>

namespace rcb4::link {

/** An FTDI adapter opened through libftdi, as a byte_device (see device_link.hpp). */
class libftdi_device {
 public:
  /** Which adapter: USB vendor and product, optionally its serial number and index among equals. */
  struct which {
    int vendor = 0x165C;   ///< KONDO (ics.md §6)
    int product = 0x0008;  ///< DUAL USB ADAPTER HS; 0x0002, 0x0005, 0x0007: the COM adapters
    std::string serial{};  ///< empty: any
    unsigned index = 0;    ///< the n-th of the matching adapters
  };

  /** Opens @p w at @p baud, 8E1; ok() says whether that worked, error() why not. */
  libftdi_device(which w, std::uint32_t baud) : which_(std::move(w)), baud_(baud) { open(); }
  ~libftdi_device() { close(); }
  libftdi_device(const libftdi_device&) = delete;
  libftdi_device& operator=(const libftdi_device&) = delete;

  /** True while the adapter is open. */
  bool ok() const noexcept { return open_; }
  /** Why opening (or the last operation) failed: libftdi's words, with the step. */
  const std::string& error() const noexcept { return error_; }

  /** Bytes of @p out the adapter took (libftdi writes them all or fails); negative: it failed. */
  long write(std::span<const std::uint8_t> out) {
    if (!open_) return -1;
    const int n = ftdi_write_data(ctx_, out.data(), static_cast<int>(out.size()));
    if (n < 0) failed("write");
    return n;
  }
  /** Bytes that came, into @p in (0: none within the 2 ms read timeout); negative: it failed. */
  long read(std::span<std::uint8_t> in) {
    if (!open_) return -1;
    const int n = ftdi_read_data(ctx_, in.data(), static_cast<int>(in.size()));
    if (n < 0) failed("read");
    return n;
  }
  /**
   * Waits while the link waits: only for a reopen's backoff does it sleep (until @p until); for
   * input or room to write, a read or write already waits up to libftdi's 2 ms USB timeout.
   */
  template <class TimePoint>
  void idle(TimePoint until, waiting w) {
    if (w == waiting::time) std::this_thread::sleep_until(until);
  }
  /** Closes and opens the same adapter again (after an unplug): true when it is back. */
  bool reopen() {
    close();
    return open();
  }

 private:
  bool open() {
    ctx_ = ftdi_new();
    if (!ctx_) return fail_open("ftdi_new: out of memory");
    const char* serial = which_.serial.empty() ? nullptr : which_.serial.c_str();
    if (ftdi_usb_open_desc_index(ctx_, which_.vendor, which_.product, nullptr, serial, which_.index) < 0)
      return fail_open("no FTDI adapter " + hex4(which_.vendor) + ":" + hex4(which_.product) + " (" +
                       ftdi_get_error_string(ctx_) + ")");
    if (ftdi_set_baudrate(ctx_, static_cast<int>(baud_)) < 0) return fail_open("the rate", true);
    if (ftdi_set_line_property(ctx_, BITS_8, STOP_BIT_1, EVEN) < 0) return fail_open("8E1", true);
    if (ftdi_set_latency_timer(ctx_, 1) < 0) return fail_open("the latency timer", true);
    if (ftdi_tciflush(ctx_) < 0) return fail_open("flushing its input", true);
    ctx_->usb_read_timeout = 2;     // ms: a read returns soon when nothing came (the link keeps the deadline)
    ctx_->usb_write_timeout = 100;  // ms: a 128-byte frame takes 12 ms at 115200
    open_ = true;
    error_.clear();
    return true;
  }
  bool fail_open(std::string what, bool set_failed = false) {
    error_ = set_failed ? "cannot set " + what + ": " + ftdi_get_error_string(ctx_) : std::move(what);
    close();
    return false;
  }
  void failed(const char* what) { error_ = std::string(what) + ": " + ftdi_get_error_string(ctx_); }
  void close() noexcept {
    if (!ctx_) return;
    if (open_) ftdi_usb_close(ctx_);
    ftdi_free(ctx_);
    ctx_ = nullptr;
    open_ = false;
  }
  static std::string hex4(int v) {
    static constexpr char digits[] = "0123456789abcdef";
    std::string s(4, '0');
    for (int i = 3; i >= 0; --i, v >>= 4) s[static_cast<std::size_t>(i)] = digits[v & 0xF];
    return s;
  }

  which which_;
  std::uint32_t baud_;
  ftdi_context* ctx_ = nullptr;
  bool open_ = false;
  std::string error_;
};

}  // namespace rcb4::link
