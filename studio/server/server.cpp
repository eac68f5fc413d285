// rcb4 ui: the web server (see server.hpp).
// SPDX-License-Identifier: BSL-1.0
#include "server.hpp"

#include <boost/asio/dispatch.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include <algorithm>
#include <cctype>
#include <deque>
#include <utility>

namespace cli::ui {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using namespace std::chrono_literals;

// --- checks ------------------------------------------------------------------------------------

namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  for (auto& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

/** "host:port" → "host"; "[::1]:8080" → "::1". */
std::string_view host_name(std::string_view host) {
  if (!host.empty() && host.front() == '[') {
    const auto end = host.find(']');
    return end == std::string_view::npos ? host : host.substr(1, end - 1);
  }
  const auto colon = host.rfind(':');
  return colon == std::string_view::npos ? host : host.substr(0, colon);
}

}  // namespace

bool loopback_host(std::string_view host) noexcept {
  const auto h = lower(host);
  if (h == "localhost" || h == "::1") return true;
  // 127.0.0.0/8
  unsigned parts[4];
  char tail = 0;
  return std::sscanf(h.c_str(), "%u.%u.%u.%u%c", &parts[0], &parts[1], &parts[2], &parts[3], &tail) == 4 &&
         parts[0] == 127 && parts[1] < 256 && parts[2] < 256 && parts[3] < 256;
}

bool same_origin(std::string_view origin, std::string_view host) noexcept {
  constexpr std::string_view scheme = "http://";
  if (lower(origin.substr(0, scheme.size())) != scheme) return false;
  return !host.empty() && lower(origin.substr(scheme.size())) == lower(host);
}

bool same_secret(std::string_view a, std::string_view b) noexcept {
  unsigned char diff = a.size() == b.size() ? 0 : 1;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ (i < b.size() ? b[i] : 0));
  return diff == 0;
}

std::string query_value(std::string_view target, std::string_view key) {
  const auto q = target.find('?');
  if (q == std::string_view::npos) return {};
  auto rest = target.substr(q + 1);
  while (!rest.empty()) {
    const auto amp = rest.find('&');
    const auto item = rest.substr(0, amp);
    const auto eq = item.find('=');
    if (eq != std::string_view::npos && item.substr(0, eq) == key) return std::string(item.substr(eq + 1));
    if (amp == std::string_view::npos) break;
    rest = rest.substr(amp + 1);
  }
  return {};
}

namespace {

/** The value of cookie @p name in a Cookie header, or empty. */
std::string cookie_value(std::string_view header, std::string_view name) {
  while (!header.empty()) {
    const auto semi = header.find(';');
    auto item = header.substr(0, semi);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    const auto eq = item.find('=');
    if (eq != std::string_view::npos && item.substr(0, eq) == name) return std::string(item.substr(eq + 1));
    if (semi == std::string_view::npos) break;
    header = header.substr(semi + 1);
  }
  return {};
}

const embedded_file* file_for(std::string_view target) {
  const auto path = target.substr(0, target.find('?'));
  for (const auto& f : page_files())
    if (f.path == path) return &f;
  return nullptr;
}

using http_request = http::request<http::string_body>;

/** What a request may do: nothing (an answer saying why) or go on. */
struct verdict {
  http::status status = http::status::ok;
  std::string why;
  bool token_from_query = false;
};

verdict check(const http_request& req, const server_options& o, bool upgrade) {
  verdict v;
  const auto host = std::string_view(req[http::field::host]);
  if (o.token.empty() && !loopback_host(host_name(host)))
    return {http::status::misdirected_request,
            "this rcb4 ui listens on loopback only: open it as http://127.0.0.1:PORT/ (over SSH: ssh -L)", false};
  if (!o.token.empty()) {
    const auto q = query_value(req.target(), "token");
    const auto c = cookie_value(req[http::field::cookie], "rcb4_token");
    v.token_from_query = !q.empty() && same_secret(q, o.token);
    if (!v.token_from_query && !(!c.empty() && same_secret(c, o.token)))
      return {http::status::unauthorized, "this rcb4 ui needs its token: open the URL rcb4 ui printed (?token=...)",
              false};
  }
  if (upgrade) {
    const auto origin = std::string_view(req[http::field::origin]);
    // No Origin: not a browser (a browser always sends one on a WebSocket upgrade).
    if (req.find(http::field::origin) != req.end() && !same_origin(origin, host))
      return {http::status::forbidden,
              "WebSocket refused: Origin '" + std::string(origin.substr(0, 200)) + "' is not this server's", false};
  }
  return v;
}

template <class Body>
void common_headers(http::response<Body>& res) {
  res.set(http::field::server, "rcb4 ui");
  res.set(http::field::cache_control, "no-store");
  res.set("X-Content-Type-Options", "nosniff");
  res.set("X-Frame-Options", "DENY");
  res.set("Referrer-Policy", "no-referrer");
  res.set("Content-Security-Policy",
          "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' data:; connect-src 'self'; "
          "frame-ancestors 'none'; base-uri 'none'; form-action 'none'");
}

}  // namespace

// --- WebSocket sessions -------------------------------------------------------------------------

/** One page's WebSocket: reads its messages into the hub, writes what the hub sends it. */
class ws_session : public std::enable_shared_from_this<ws_session> {
 public:
  ws_session(tcp::socket&& socket, web_server& server)
      : ws_(std::move(socket)), cutoff_(ws_.get_executor()), server_(server) {}
  ~ws_session() {
    gone();
    server_.close_connection();
  }

  void accept(http_request req) {
    websocket::stream_base::timeout t{};
    t.handshake_timeout = 10s;
    t.idle_timeout = 10s;  // pinged at half: a page that vanished is gone within 10 s
    t.keep_alive_pings = true;
    ws_.set_option(t);
    ws_.set_option(websocket::stream_base::decorator(
        [](websocket::response_type& res) { res.set(http::field::server, "rcb4 ui"); }));
    ws_.read_message_max(ws_frame_max);
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) { self->on_accept(ec); });
  }

  /** Queues @p text; a state not yet being written is replaced by a newer one (a slow page skips states). */
  void queue(std::string text) {
    if (closing_) return;
    const bool is_state = text.rfind("{\"type\":\"state\"", 0) == 0;
    if (is_state && out_.size() > 1 && out_.back().rfind("{\"type\":\"state\"", 0) == 0) {
      out_.back() = std::move(text);
      return;
    }
    if (out_.size() >= 256) {  // a page that reads nothing: let it go
      close();
      gone();
      return;
    }
    out_.push_back(std::move(text));
    if (out_.size() == 1) write();
  }

  /** Starts the close handshake; a peer that does not answer it within a second is cut off. */
  void close() {
    if (closing_) return;
    closing_ = true;  // the read that fails next makes it gone()
    cutoff_.expires_after(1s);
    cutoff_.async_wait([self = shared_from_this()](beast::error_code ec) {
      if (!ec) beast::get_lowest_layer(self->ws_).close();
    });
    ws_.async_close(websocket::close_code::going_away,
                    [self = shared_from_this()](beast::error_code) { self->cutoff_.cancel(); });
  }

 private:
  void on_accept(beast::error_code ec) {
    if (ec || server_.stopping()) return;
    id_ = server_.add(weak_from_this());
    read();
    if (auto* h = server_.events()) h->join(id_);
  }

  void read() {
    ws_.async_read(in_, [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
  }

  /** The page is gone (closed, lost, too slow, refused): it hears nothing more, the hub learns it once. */
  void gone() {
    closing_ = true;
    if (!id_) return;
    const auto id = std::exchange(id_, 0);
    server_.remove(id);
    if (auto* h = server_.events()) h->leave(id);
  }

  void on_read(beast::error_code ec) {
    if (ec) return gone();  // closed, timed out, too long, or the server stops: the session ends
    auto* h = server_.events();
    if (!ws_.got_text()) {
      queue(error_text(std::nullopt, {}, "messages are JSON text, not binary"));
    } else if (h) {
      h->receive(id_, beast::buffers_to_string(in_.data()));
    }
    in_.consume(in_.size());
    read();
  }

  void write() {
    ws_.text(true);
    ws_.async_write(net::buffer(out_.front()),
                    [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_write(ec); });
  }

  void on_write(beast::error_code ec) {
    if (ec) {
      out_.clear();
      return gone();
    }
    out_.pop_front();
    if (!out_.empty() && !closing_) write();
  }

  websocket::stream<beast::tcp_stream> ws_;
  net::steady_timer cutoff_;
  web_server& server_;
  beast::flat_buffer in_;
  std::deque<std::string> out_;
  client_id id_ = 0;
  bool closing_ = false;
};

// --- HTTP sessions ------------------------------------------------------------------------------

namespace {

class http_session : public std::enable_shared_from_this<http_session> {
 public:
  http_session(tcp::socket&& socket, web_server& server) : stream_(std::move(socket)), server_(server) {}
  ~http_session() {
    if (!handed_over_) server_.close_connection();
  }

  void run() {
    server_.track(weak_from_this(), [weak = weak_from_this()] {
      if (auto self = weak.lock()) self->stream_.close();  // the server stops: a kept-alive read ends now
    });
    net::dispatch(stream_.get_executor(), [self = shared_from_this()] { self->read(); });
  }

 private:
  void read() {
    parser_.emplace();
    parser_->header_limit(8 * 1024);
    parser_->body_limit(1024);
    stream_.expires_after(10s);  // a request's headers within 10 s, or the connection goes
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
  }

  void on_read(beast::error_code ec) {
    if (ec || server_.stopping()) {
      stream_.socket().shutdown(tcp::socket::shutdown_both, ec);
      return;
    }
    http_request req = parser_->release();
    const bool upgrade = websocket::is_upgrade(req);
    const auto v = check(req, server_.options(), upgrade);
    if (v.status != http::status::ok) return answer(req, v.status, v.why, "text/plain; charset=utf-8", false);
    if (upgrade) {
      if (req.target().substr(0, req.target().find('?')) != "/ws")
        return answer(req, http::status::not_found, "no WebSocket here: /ws", "text/plain; charset=utf-8", false);
      handed_over_ = true;  // the WebSocket session counts the connection from here
      stream_.expires_never();
      std::make_shared<ws_session>(stream_.release_socket(), server_)->accept(std::move(req));
      return;
    }
    if (req.method() != http::verb::get && req.method() != http::verb::head)
      return answer(req, http::status::method_not_allowed, "GET only", "text/plain; charset=utf-8", false);
    if (const auto* f = file_for(req.target()))
      return answer(req, http::status::ok, std::string(f->body), f->type, v.token_from_query);
    const auto path = req.target().substr(0, req.target().find('?'));
    for (const auto& f : server_.options().vendor)
      if (f.path == path) return answer(req, http::status::ok, f.body, f.type, v.token_from_query);
    answer(req, http::status::not_found, "not found", "text/plain; charset=utf-8", false);
  }

  void answer(const http_request& req, http::status status, std::string body, std::string_view type, bool set_cookie) {
    auto res = std::make_shared<http::response<http::string_body>>(status, req.version());
    common_headers(*res);
    res->set(http::field::content_type, type);
    if (set_cookie)
      res->set(http::field::set_cookie,
               "rcb4_token=" + server_.options().token + "; Path=/; HttpOnly; SameSite=Strict");
    if (status == http::status::method_not_allowed) res->set(http::field::allow, "GET, HEAD");
    const bool head = req.method() == http::verb::head;
    res->body() = std::move(body);
    res->keep_alive(req.keep_alive() && status == http::status::ok);
    res->prepare_payload();
    if (head) res->body().clear();
    const bool close = !res->keep_alive();
    http::async_write(stream_, *res, [self = shared_from_this(), res, close](beast::error_code ec, std::size_t) {
      if (ec || close) {
        self->stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
        return;
      }
      self->read();
    });
  }

  beast::tcp_stream stream_;
  web_server& server_;
  beast::flat_buffer buffer_{8 * 1024};
  std::optional<http::request_parser<http::string_body>> parser_;
  bool handed_over_ = false;
};

}  // namespace

// --- the server ---------------------------------------------------------------------------------

web_server::web_server(net::io_context& io, server_options o) : io_(io), options_(std::move(o)), acceptor_(io) {
  acceptor_.open(options_.listen.protocol());
  acceptor_.set_option(net::socket_base::reuse_address(true));
  acceptor_.bind(options_.listen);
  acceptor_.listen(net::socket_base::max_listen_connections);
}

web_server::~web_server() = default;

void web_server::start(hub& h) {
  hub_ = &h;
  accept();
}

void web_server::stop() {
  stopping_ = true;
  beast::error_code ec;
  acceptor_.close(ec);
  std::vector<std::shared_ptr<ws_session>> all;
  for (auto& [id, w] : pages_)
    if (auto s = w.lock()) all.push_back(std::move(s));
  for (auto& s : all) s->close();
  for (auto& [owner, closer] : closers_)
    if (!owner.expired()) closer();
  closers_.clear();
}

void web_server::track(std::weak_ptr<void> owner, std::function<void()> closer) {
  std::erase_if(closers_, [](const auto& c) { return c.first.expired(); });
  closers_.emplace_back(std::move(owner), std::move(closer));
}

net::ip::tcp::endpoint web_server::local() const { return acceptor_.local_endpoint(); }

void web_server::send(client_id to, std::string text) {
  net::post(io_, [this, to, t = std::move(text)] { deliver(to, t); });
}

void web_server::deliver(client_id to, const std::string& text) {
  if (stopping_) return;
  if (to != 0) {
    const auto it = pages_.find(to);
    if (it != pages_.end())
      if (auto s = it->second.lock()) s->queue(text);
    return;
  }
  // queue() may drop a page (too slow), which erases it from pages_: take them out first.
  std::vector<std::shared_ptr<ws_session>> all;
  for (auto& [id, w] : pages_)
    if (auto s = w.lock()) all.push_back(std::move(s));
  for (auto& s : all) s->queue(text);
}

client_id web_server::add(std::weak_ptr<ws_session> s) {
  const auto id = next_id_++;
  pages_[id] = std::move(s);
  return id;
}

void web_server::remove(client_id id) { pages_.erase(id); }

bool web_server::open_connection() {
  if (connections_ >= options_.max_connections) return false;
  ++connections_;
  return true;
}

void web_server::close_connection() noexcept {
  if (connections_ > 0) --connections_;
}

void web_server::accept() {
  acceptor_.async_accept(io_, [this](beast::error_code ec, tcp::socket socket) {
    if (ec == net::error::operation_aborted || stopping_) return;
    if (!ec) {
      if (open_connection()) {
        std::make_shared<http_session>(std::move(socket), *this)->run();
      } else {
        beast::error_code ignored;
        socket.close(ignored);
      }
    }
    accept();
  });
}

}  // namespace cli::ui
