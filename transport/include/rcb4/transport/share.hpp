// rcb4 — sharing a held serial port: the program that holds a board's port (rcb4 ui) serves it
// on a local socket, and other programs (the rcb4 tool, pyrcb4) that find the port busy reach the
// board through it. Every request goes through the holder's client, so it shares that client's
// one FIFO: the bytes of two exchanges never interleave on the wire.
// SPDX-License-Identifier: BSL-1.0
//
// Wire: the socket carries RCB-4 frames exactly as the serial line does (docs/protocol.md §2):
// a request frame in, its reply frame out (nothing out when the board did not answer, as on the
// line). The socket is a Unix stream socket, in a folder only its user can enter:
//   $XDG_RUNTIME_DIR/rcb4/share/<device>.sock, or /tmp/rcb4-<uid>/share/<device>.sock
// where <device> is the port's canonical path with '/' written as '_' (_dev_ttyUSB0).
// Only a peer of the same user is served (SO_PEERCRED).
#pragma once

#include <rcb4/rcb4.hpp>
#include <rcb4/transport/error.hpp>
#include <rcb4/transport/response.hpp>

#include <boost/asio/io_context.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/write.hpp>

#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace rcb4::transport {

/** The Unix socket on the io_context's own executor type (see tcp_socket). */
using local_socket =
    boost::asio::basic_stream_socket<boost::asio::local::stream_protocol, boost::asio::io_context::executor_type>;

/** The folder the shares of this user live in (made, mode 0700, by the holder). */
inline std::filesystem::path share_folder() {
  const char* runtime = std::getenv("XDG_RUNTIME_DIR");
  if (runtime && *runtime == '/') return std::filesystem::path(runtime) / "rcb4" / "share";
  return std::filesystem::path("/tmp") / ("rcb4-" + std::to_string(::getuid())) / "share";
}

/** Where the share of @p device is (the same file for every name of the port: symlinks resolved). */
inline std::filesystem::path share_path(const std::string& device) {
  std::error_code ec;
  auto canonical = std::filesystem::weakly_canonical(device, ec);
  std::string name = (ec ? std::filesystem::path(device) : canonical).string();
  for (char& c : name)
    if (c == '/') c = '_';
  // sockaddr_un holds 108 bytes: a longer path is cut, keeping the end (the device's own name).
  const auto folder = share_folder().string();
  const std::size_t room = 100 > folder.size() + 6 ? 100 - folder.size() - 6 : 8;
  if (name.size() > room) name = name.substr(name.size() - room);
  return share_folder() / (name + ".sock");
}

namespace detail {
/** The uid and pid of a connected Unix socket's peer, or false. */
inline bool peer_of(int fd, ::ucred& who) {
  ::socklen_t size = sizeof who;
  return ::getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &who, &size) == 0;
}
/** Makes @p folder (and its parent) for this user only; false when it is someone else's or open to others. */
inline bool private_folder(const std::filesystem::path& folder, error_code& ec) {
  for (const auto& f : {folder.parent_path(), folder}) {
    if (::mkdir(f.c_str(), 0700) != 0 && errno != EEXIST) {
      ec = error_code(errno, boost::system::system_category());
      return false;
    }
    struct ::stat st {};
    if (::lstat(f.c_str(), &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != ::getuid() || (st.st_mode & 0077) != 0) {
      ec = error_code(EPERM, boost::system::system_category());
      return false;
    }
  }
  return true;
}
}  // namespace detail

/**
 * Connects to the share of @p device. @p ec is set (and the socket closed) when nobody shares
 * it: no socket (ENOENT), a socket left by a holder that ended (ECONNREFUSED), or one served by
 * another user. @p holder_pid, when given, gets the holder's process id.
 */
inline local_socket connect_share(boost::asio::io_context& io, const std::string& device, error_code& ec,
                                  int* holder_pid = nullptr) {
  local_socket socket(io);
  boost::system::error_code bec;
  socket.connect(boost::asio::local::stream_protocol::endpoint(share_path(device).string()), bec);
  ::ucred who{};
  if (!bec && (!detail::peer_of(socket.native_handle(), who) || who.uid != ::getuid()))
    bec = boost::system::error_code(EPERM, boost::system::system_category());
  if (bec) {
    boost::system::error_code ignored;
    socket.close(ignored);
  } else if (holder_pid) {
    *holder_pid = who.pid;
  }
  ec = bec;
  return socket;
}

/**
 * Serves the board behind @p Client (a basic_client) on share_path(device). Runs on @p io's
 * thread; the client may run on another. Each complete request frame a peer sends is parsed
 * (parse_command: bytes that are no request are dropped, as the board drops noise; a partial
 * frame left unfinished for 200 ms is dropped) and queued with async_exchange; its reply frame
 * is written back, or nothing when the line failed (the peer's own deadline then runs out, as on
 * the serial line). @p observe (optional) hears every relayed exchange on the client's thread.
 * The owner calls stop() before the client goes: it closes every connection and removes the
 * socket file.
 */
template <class Client>
class share_server : public std::enable_shared_from_this<share_server<Client>> {
 public:
  /** Hears each relayed exchange: the command, the line's error (if any) and the reply. */
  using observer = std::function<void(const command&, const error_code&, const response&)>;

  /** Starts serving; on failure @p ec says why and nothing is served. */
  static std::shared_ptr<share_server> start(boost::asio::io_context& io, Client& client, const std::string& device,
                                             observer observe, error_code& ec) {
    std::shared_ptr<share_server> s(new share_server(io, client, share_path(device), std::move(observe)));
    if (!detail::private_folder(s->path_.parent_path(), ec)) return nullptr;
    std::error_code fec;
    std::filesystem::remove(s->path_, fec);  // a socket left by a holder that ended (the port's lock is ours now)
    boost::system::error_code bec;
    const boost::asio::local::stream_protocol::endpoint where(s->path_.string());
    s->acceptor_.open(where.protocol(), bec);
    if (!bec) s->acceptor_.bind(where, bec);
    if (!bec) s->acceptor_.listen(8, bec);
    if (bec) {
      ec = bec;
      return nullptr;
    }
    ec.clear();
    s->accept();
    return s;
  }

  share_server(const share_server&) = delete;
  share_server& operator=(const share_server&) = delete;
  ~share_server() = default;

  /** Where it serves. */
  const std::filesystem::path& where() const noexcept { return path_; }

  /**
   * Ends serving: the acceptor and every connection close, the file goes. Call it on the
   * io_context's thread, or once that context runs no more, and before the client goes.
   */
  void stop() {
    stop_here();
    std::error_code ec;
    std::filesystem::remove(path_, ec);
  }

 private:
  struct connection {
    explicit connection(local_socket s) : socket(std::move(s)) {}
    local_socket socket;
    std::array<std::uint8_t, 512> in{};
    std::vector<std::uint8_t> pending;
    std::chrono::steady_clock::time_point last_byte{};
    std::vector<std::uint8_t> out;  ///< replies waiting for the write under way
    bool writing = false;
  };

  share_server(boost::asio::io_context& io, Client& client, std::filesystem::path path, observer observe)
      : acceptor_(io), client_(client), path_(std::move(path)), observe_(std::move(observe)) {}

  void accept() {
    acceptor_.async_accept([self = this->shared_from_this()](boost::system::error_code ec, local_socket socket) {
      if (ec || self->stopped_) return;
      ::ucred who{};
      if (detail::peer_of(socket.native_handle(), who) && who.uid == ::getuid()) {
        auto c = std::make_shared<connection>(std::move(socket));
        self->connections_.insert(c);
        self->read(c);
      }
      self->accept();
    });
  }

  void read(const std::shared_ptr<connection>& c) {
    c->socket.async_read_some(boost::asio::buffer(c->in),
                              [self = this->shared_from_this(), c](boost::system::error_code ec, std::size_t n) {
                                if (ec || self->stopped_) return self->drop(c);
                                self->received(c, n);
                                self->read(c);
                              });
  }

  void received(const std::shared_ptr<connection>& c, std::size_t n) {
    const auto now = std::chrono::steady_clock::now();
    if (!c->pending.empty() && now - c->last_byte > std::chrono::milliseconds(200)) c->pending.clear();
    c->last_byte = now;
    c->pending.insert(c->pending.end(), c->in.begin(), c->in.begin() + static_cast<std::ptrdiff_t>(n));
    while (!c->pending.empty()) {
      const auto r = parse_command(c->pending);
      if (r.status == parse_status::need_more) break;
      const std::size_t used = r.status == parse_status::complete ? r.consumed : std::max<std::size_t>(r.consumed, 1);
      c->pending.erase(c->pending.begin(),
                       c->pending.begin() + static_cast<std::ptrdiff_t>(std::min(used, c->pending.size())));
      if (r.status == parse_status::complete) relay(c, r.value());
    }
  }

  void relay(const std::shared_ptr<connection>& c, const command& cmd) {
    client_.async_exchange(cmd, [self = this->shared_from_this(), c, cmd](error_code ec, response r) {
      if (self->stopped_) return;
      if (self->observe_) self->observe_(cmd, ec, r);
      if (ec) return;  // silence, as the line gave
      const auto frame = encode(r.view());
      std::vector<std::uint8_t> bytes(frame.bytes().begin(), frame.bytes().end());
      boost::asio::post(self->acceptor_.get_executor(), [self, c, bytes = std::move(bytes)]() mutable {
        if (self->stopped_ || !c->socket.is_open()) return;
        c->out.insert(c->out.end(), bytes.begin(), bytes.end());
        if (!c->writing) self->write(c);
      });
    });
  }

  void write(const std::shared_ptr<connection>& c) {
    auto chunk = std::make_shared<std::vector<std::uint8_t>>(std::move(c->out));
    c->out.clear();
    c->writing = true;
    boost::asio::async_write(c->socket, boost::asio::buffer(*chunk),
                             [self = this->shared_from_this(), c, chunk](boost::system::error_code ec, std::size_t) {
                               c->writing = false;
                               if (ec) return self->drop(c);
                               if (!c->out.empty()) self->write(c);
                             });
  }

  void drop(const std::shared_ptr<connection>& c) {
    boost::system::error_code ignored;
    c->socket.close(ignored);
    connections_.erase(c);
  }

  void stop_here() {
    stopped_ = true;
    boost::system::error_code ignored;
    acceptor_.close(ignored);
    for (const auto& c : connections_) c->socket.close(ignored);
    connections_.clear();
  }

  boost::asio::basic_socket_acceptor<boost::asio::local::stream_protocol, boost::asio::io_context::executor_type>
      acceptor_;
  Client& client_;
  std::filesystem::path path_;
  observer observe_;
  std::set<std::shared_ptr<connection>> connections_;
  std::atomic<bool> stopped_{false};  ///< read on the client's thread too
};

}  // namespace rcb4::transport
