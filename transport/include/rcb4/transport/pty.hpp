// rcb4 — pseudo-terminals for serving the virtual board: a master side for us, a /dev/pts/N for clients.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>
#include <cerrno>
#include <cstdlib>
#include <string>
#include <system_error>

namespace rcb4::transport {

/** An open pseudo-terminal pair. The slave stays open here so the master never sees EIO. */
class pty_pair {
 public:
  /** Opens a pair, puts the slave in raw 8E1 mode; throws std::system_error on failure. */
  pty_pair() {
    master_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (master_ < 0) fail("posix_openpt");
    if (::grantpt(master_) != 0 || ::unlockpt(master_) != 0) fail("grantpt/unlockpt");
    char name[128];
    if (::ptsname_r(master_, name, sizeof name) != 0) fail("ptsname_r");
    path_ = name;
    slave_ = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (slave_ < 0) fail("open pty slave");
    termios t{};
    if (::tcgetattr(slave_, &t) != 0) fail("tcgetattr");
    ::cfmakeraw(&t);
    t.c_cflag |= CS8 | PARENB | CLOCAL | CREAD;  // what the board speaks (pty ignores parity)
    t.c_cflag &= ~static_cast<tcflag_t>(PARODD | CSTOPB);
    ::cfsetspeed(&t, B115200);
    if (::tcsetattr(slave_, TCSANOW, &t) != 0) fail("tcsetattr");
  }
  pty_pair(const pty_pair&) = delete;
  pty_pair& operator=(const pty_pair&) = delete;
  ~pty_pair() {
    if (slave_ >= 0) ::close(slave_);
    if (master_ >= 0) ::close(master_);
  }
  /** The path clients open, e.g. /dev/pts/3. */
  const std::string& path() const noexcept { return path_; }
  /** Hands the master descriptor over (the caller closes it). */
  int release_master() noexcept {
    const int fd = master_;
    master_ = -1;
    return fd;
  }

 private:
  [[noreturn]] void fail(const char* what) {
    const int e = errno;
    if (slave_ >= 0) ::close(slave_);
    if (master_ >= 0) ::close(master_);
    throw std::system_error(e, std::generic_category(), what);
  }
  int master_ = -1;
  int slave_ = -1;
  std::string path_;
};

}  // namespace rcb4::transport
