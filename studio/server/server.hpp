// rcb4 ui: the web server (Boost.Beast): the embedded page over HTTP, the pages' WebSockets.
// SPDX-License-Identifier: BSL-1.0
//
// What it refuses, and how:
//  - a path that is not one of the embedded files or of the vendor files read at start: 404
//    (nothing is read from disk while serving);
//  - without the token, when one is set: 401 (the URL printed at start carries it; the page's
//    first load turns it into a SameSite=Strict cookie);
//  - a Host that is not a loopback name, on a loopback listener (DNS rebinding): 421;
//  - a WebSocket upgrade whose Origin is not this server's own: 403, not upgraded;
//  - more than max_connections at once: closed at accept;
//  - a request header over 8 KiB, a body, a message over 16 KiB, a peer silent for 30 s (HTTP)
//    or not answering pings for 10 s (WebSocket): closed.
#pragma once

#include "hub.hpp"

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace cli::ui {

/** A file of the page, embedded at build time (page_files.cpp, generated). */
struct embedded_file {
  std::string_view path;  ///< "/", "/app.js"
  std::string_view type;  ///< its Content-Type
  std::string_view body;  ///< its bytes
};
/** Every file the server serves. */
std::span<const embedded_file> page_files();

/** A file the server reads once at start (three.js from Debian's libjs-three): path, type, bytes. */
struct served_file {
  std::string path;  ///< "/vendor/three/build/three.module.js"
  std::string type;  ///< its Content-Type
  std::string body;  ///< its bytes
};

/** How the server listens. */
struct server_options {
  boost::asio::ip::tcp::endpoint listen;  ///< where
  std::string token;                      ///< empty: no token needed (a loopback listener)
  std::size_t max_connections = 64;       ///< HTTP and WebSocket together
  std::vector<served_file> vendor;        ///< served besides the page (read at start: nothing from disk later)
};

class ws_session;

/** Serves the page and the WebSockets on one io_context (one thread). */
class web_server {
 public:
  /** Binds @p o.listen on @p io (throws boost::system::system_error when it cannot). */
  web_server(boost::asio::io_context& io, server_options o);
  ~web_server();
  web_server(const web_server&) = delete;
  web_server& operator=(const web_server&) = delete;

  /** Starts accepting; pages' events go to @p h. */
  void start(hub& h);
  /** Stops accepting and closes every connection; io.run() then returns. Call on the io thread. */
  void stop();
  /** The bound endpoint (the real port when 0 was asked). */
  boost::asio::ip::tcp::endpoint local() const;
  /** Sends @p text to page @p to (0: every page). Thread-safe: posts to the io thread. */
  void send(client_id to, std::string text);

  // For the sessions (io thread only).
  /** The options in force. */
  const server_options& options() const noexcept { return options_; }
  /** The hub, once started. */
  hub* events() const noexcept { return hub_; }
  /** A new WebSocket page; its id. */
  client_id add(std::weak_ptr<ws_session> s);
  /** Page @p id is gone. */
  void remove(client_id id);
  /** A connection opened (false: too many, refuse it) / closed. */
  bool open_connection();
  /** A connection closed. */
  void close_connection() noexcept;
  /** Remembers how to close an HTTP connection when the server stops. */
  void track(std::weak_ptr<void> owner, std::function<void()> closer);
  /** True once stop() ran. */
  bool stopping() const noexcept { return stopping_; }

 private:
  void accept();
  void deliver(client_id to, const std::string& text);

  boost::asio::io_context& io_;
  server_options options_;
  boost::asio::ip::tcp::acceptor acceptor_;
  hub* hub_ = nullptr;
  std::map<client_id, std::weak_ptr<ws_session>> pages_;
  std::vector<std::pair<std::weak_ptr<void>, std::function<void()>>> closers_;  ///< HTTP connections
  client_id next_id_ = 1;
  std::size_t connections_ = 0;
  bool stopping_ = false;
};

/** True when @p host (a Host header's name, without the port) names this machine's loopback. */
bool loopback_host(std::string_view host) noexcept;
/** True when @p origin ("http://host:port") is the same origin as a request to @p host ("host:port"). */
bool same_origin(std::string_view origin, std::string_view host) noexcept;
/** Equal strings, compared in time that does not depend on where they differ. */
bool same_secret(std::string_view a, std::string_view b) noexcept;
/** The value of @p key in the query of @p target ("/x?token=abc&y=1"), or empty. */
std::string query_value(std::string_view target, std::string_view key);

}  // namespace cli::ui
