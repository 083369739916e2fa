// HttpServer: one acceptor and one Session per connection, all on the daemon's io thread.
#include "http/http_server.hpp"

#include <atomic>
#include <cmath>
#include <map>

#include <boost/asio/dispatch.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "http/password_checker.hpp"
#include "http/passwords.hpp"
#include "http/websocket_transport.hpp"

namespace lamina::daemon::http {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace bhttp = boost::beast::http;
using tcp = asio::ip::tcp;

namespace {

class Session;

constexpr std::size_t kMaxLoginBody = 4096;

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Headers every answer carries: the console is its own origin and nothing is cached stale (a
// job's drawing changes when it is planned again).
template <class Response>
void common_headers(Response& res) {
  res.set(bhttp::field::server, "laminad");
  res.set(bhttp::field::cache_control, "no-cache");
  res.set("X-Content-Type-Options", "nosniff");
  // Inline styles only (the planner's SVG drawings carry a <style>); scripts from our files only.
  res.set("Content-Security-Policy",
          "default-src 'self'; connect-src 'self'; img-src 'self' data: blob:; style-src 'self' 'unsafe-inline'");
  res.set("X-Frame-Options", "DENY");
}

}  // namespace

struct HttpServer::Impl : std::enable_shared_from_this<HttpServer::Impl> {
  Impl(asio::io_context& io_context, HttpSettings s, ArtefactLookup lookup, WebSocketHandoff ws)
      : io(io_context),
        settings(std::move(s)),
        artefacts(std::move(lookup)),
        websockets(std::move(ws)),
        access(settings.access),
        acceptor(io_context) {
    // Unknown names are checked against this, so that a wrong name costs what a wrong password
    // does (no user list by timing).
    if (access.users_configured()) dummy_hash = hash_password(random_token()).value_or("");
  }

  asio::io_context& io;
  HttpSettings settings;
  ArtefactLookup artefacts;
  WebSocketHandoff websockets;
  WebAccess access;                                        // io thread
  PasswordChecker passwords;
  std::string dummy_hash;
  tcp::acceptor acceptor;
  int bound_port = 0;
  bool stopped = false;                                    // io thread
  std::uint64_t next_id = 1;                               // io thread
  std::map<std::uint64_t, std::weak_ptr<Session>> sessions;  // io thread
  std::atomic<std::size_t> count{0};

  void accept_next();
  void on_accept(const boost::system::error_code& error, tcp::socket socket);
  void close_all();
};

namespace {

class Session : public std::enable_shared_from_this<Session> {
 public:
  Session(tcp::socket socket, std::shared_ptr<HttpServer::Impl> server, std::uint64_t id)
      : stream_(std::move(socket)), server_(std::move(server)), id_(id) {
    beast::error_code ec;
    const auto remote = stream_.socket().remote_endpoint(ec);
    address_ = ec ? "unknown" : remote.address().to_string();
    peer_ = ec ? "unknown" : fmt::format("{}:{}", address_, remote.port());
  }

  void start() { read_next(); }
  void close() {
    beast::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_both, ignored);
    stream_.close();
  }
  // A full house: one short answer, then the connection closes.
  void refuse_busy() { send_text(bhttp::status::service_unavailable, "too many connections\n", false); }

 private:
  std::chrono::steady_clock::duration idle() const {
    return std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(server_->settings.idle_timeout_s));
  }

  void read_next() {
    parser_.emplace();
    parser_->header_limit(static_cast<std::uint32_t>(server_->settings.max_header_bytes));
    parser_->body_limit(kMaxLoginBody);  // checked against Content-Length as the head ends
    stream_.expires_after(idle());
    bhttp::async_read_header(stream_, buffer_, *parser_,
                             [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_header(ec); });
  }

  // Only the login has a body (a few hundred bytes of JSON); anything else with one is refused.
  void on_header(beast::error_code ec) {
    if (ec) return on_read(ec);
    const bool post = parser_->get().method() == bhttp::verb::post;
    const auto length = parser_->content_length();
    if (!post && ((length && *length > 0) || parser_->chunked())) return on_read(bhttp::error::body_limit);
    parser_->body_limit(post ? kMaxLoginBody : 0);  // a chunked body is counted as it comes
    bhttp::async_read(stream_, buffer_, *parser_,
                      [self = shared_from_this()](beast::error_code e, std::size_t) { self->on_read(e); });
  }

  void on_read(beast::error_code ec) {
    if (ec == bhttp::error::header_limit) return send_text(bhttp::status::request_header_fields_too_large, "request head too large\n", false);
    if (ec == bhttp::error::body_limit) return send_text(bhttp::status::payload_too_large, "a request body is not accepted here\n", false);
    if (ec) return finish();  // end of stream, timeout, reset, garbage: nothing to answer
    const auto& req = parser_->get();
    keep_alive_ = req.keep_alive();
    head_only_ = req.method() == bhttp::verb::head;
    if (auto host = server_->access.check_host(field(bhttp::field::host)); !host) return refuse(host.error());
    if (req.method() == bhttp::verb::post) return on_post();
    if (req.method() != bhttp::verb::get && !head_only_)
      return send_text(bhttp::status::method_not_allowed, fmt::format("{} is not served here\n", std::string(req.method_string())), keep_alive_, "GET, HEAD, POST");
    auto route = route_get(std::string_view(req.target().data(), req.target().size()));
    if (!route) return refuse(route.error());
    std::visit([&](const auto& r) { serve(r); }, *route);
  }

  std::string_view field(bhttp::field name) const {
    const auto& req = parser_->get();
    const auto it = req.find(name);
    return it == req.end() ? std::string_view{} : std::string_view(it->value().data(), it->value().size());
  }

  void refuse(const RouteError& e) {
    send_text(static_cast<bhttp::status>(e.status), e.message + "\n", keep_alive_);
  }

  std::expected<Visitor, RouteError> visitor() { return server_->access.visitor(field(bhttp::field::cookie), now_s()); }

  void serve(const WebSocketRequest&) {
    if (auto origin = server_->access.check_origin(field(bhttp::field::origin), field(bhttp::field::host)); !origin)
      return refuse(origin.error());
    auto who = visitor();
    if (!who) return refuse(who.error());
    if (!beast::websocket::is_upgrade(parser_->get()))
      return send_text(bhttp::status::upgrade_required, "/ws is a WebSocket\n", keep_alive_);
    auto ws = std::make_shared<WebSocket>(std::move(stream_));
    beast::get_lowest_layer(*ws).expires_never();  // the WebSocket keeps its own time (pings)
    set_websocket_timeouts(*ws, server_->settings.idle_timeout_s);
    ws->async_accept(parser_->get(), [self = shared_from_this(), ws, who = *who](beast::error_code ec) {
      self->on_upgraded(ec, ws, who);
    });
  }

  void on_upgraded(beast::error_code ec, const std::shared_ptr<WebSocket>& ws, const Visitor& who) {
    const std::string peer = peer_;
    finish_counting();  // the WebSocket is the RPC server's client now, counted there
    if (ec) return spdlog::info("http: WebSocket handshake with {} failed: {}", peer, ec.message());
    if (!server_->websockets) return;
    auto adopted = server_->websockets(make_websocket_transport(std::move(*ws), server_->settings.max_request_bytes), who,
                                       fmt::format("websocket {} {}", peer, who.user));
    if (!adopted) spdlog::warn("http: WebSocket of {} ({}) refused: {}", who.user, peer, adopted.error());
  }

  void serve(const SessionRequest&) {
    auto who = visitor();
    if (!who) return send_json(static_cast<bhttp::status>(who.error().status), {{"error", who.error().message}});
    send_json(bhttp::status::ok, {{"user", who->user}, {"role", role_name(who->role)}, {"logged_in", who->logged_in},
                                  {"users_configured", server_->access.users_configured()}});
  }
  void serve(const StaticRequest& r) {
    if (server_->settings.static_dir.empty()) return send_text(bhttp::status::not_found, "no console files are configured\n", keep_alive_);
    auto path = resolve_static(server_->settings.static_dir, r);
    if (!path) return refuse(path.error());
    send_file(*path, content_type(r.relative));
  }
  void serve(const ArtefactRequest& r) {
    if (auto who = visitor(); !who) return refuse(who.error());
    auto path = server_->artefacts ? server_->artefacts(r) : std::unexpected(RouteError{404, "no jobs here"});
    if (!path) return refuse(path.error());
    send_file(*path, r.kind == Artefact::model ? content_type(path->filename().string()) : content_type(artefact_file_name(r)));
  }

  // --- POST: the login and the logout (their bodies and answers are JSON) ---
  void on_post() {
    const auto& req = parser_->get();
    auto route = route_post(std::string_view(req.target().data(), req.target().size()));
    if (!route) return send_json(static_cast<bhttp::status>(route.error().status), {{"error", route.error().message}});
    // A form another site's page posts (CSRF): the browser says whose page it is.
    if (auto origin = server_->access.check_origin(field(bhttp::field::origin), field(bhttp::field::host)); !origin)
      return send_json(bhttp::status::forbidden, {{"error", origin.error().message}});
    if (*route == PostRoute::logout) {
      server_->access.sessions().close(cookie_value(field(bhttp::field::cookie), kSessionCookie));
      return send_json(bhttp::status::ok, {{"logged_out", true}}, server_->access.cleared_cookie());
    }
    login(req.body());
  }

  void login(const std::string& body) {
    if (!server_->access.users_configured())
      return send_json(bhttp::status::not_found, {{"error", "no users are configured ([[http.users]] in lamina.toml)"}});
    const auto json = nlohmann::json::parse(body, nullptr, false);
    if (json.is_discarded() || !json.is_object() || !json.contains("user") || !json["user"].is_string() ||
        !json.contains("password") || !json["password"].is_string())
      return send_json(bhttp::status::bad_request, {{"error", "expected {\"user\": \"…\", \"password\": \"…\"}"}});
    const std::string name = json["user"];
    if (auto wait = server_->access.limiter().refused_for(address_, name, now_s())) {
      auto res = json_response(bhttp::status::too_many_requests,
                               {{"error", fmt::format("too many failed logins; try again in {:.0f} s", std::ceil(*wait))}});
      res->set(bhttp::field::retry_after, std::to_string(static_cast<long>(std::ceil(*wait))));
      return write(res);
    }
    const WebUser* user = server_->access.user(name);
    const std::string hash = user ? user->password_hash : server_->dummy_hash;
    const bool queued = server_->passwords.check(
        hash, json["password"], stream_.get_executor(), [self = shared_from_this(), name, known = user != nullptr](bool ok) {
          self->on_password_checked(name, known && ok);
        });
    if (!queued) send_json(bhttp::status::service_unavailable, {{"error", "too many logins at once; try again"}});
  }

  void on_password_checked(const std::string& name, bool ok) {
    auto& access = server_->access;
    const WebUser* user = access.user(name);
    if (!ok || !user) {
      access.limiter().failed(address_, name, now_s());
      spdlog::warn("http: failed login as '{}' from {}", name, address_);
      return send_json(bhttp::status::unauthorized, {{"error", "wrong user name or password"}});
    }
    access.limiter().succeeded(address_);
    const std::string token = access.sessions().open(user->name, user->role, now_s());
    spdlog::info("http: {} logged in as {} from {}", user->name, role_name(user->role), address_);
    send_json(bhttp::status::ok,
              {{"user", user->name}, {"role", role_name(user->role)}, {"expires_in_s", access.sessions().lifetime_s()}},
              access.session_cookie(token));
  }

  std::shared_ptr<bhttp::response<bhttp::string_body>> json_response(bhttp::status status, const nlohmann::json& body) {
    auto res = std::make_shared<bhttp::response<bhttp::string_body>>(status, 11);
    common_headers(*res);
    res->set(bhttp::field::content_type, "application/json");
    res->keep_alive(keep_alive_);
    if (!head_only_) res->body() = body.dump() + "\n";
    res->prepare_payload();
    return res;
  }

  void send_json(bhttp::status status, const nlohmann::json& body, const std::string& set_cookie = {}) {
    auto res = json_response(status, body);
    if (!set_cookie.empty()) res->set(bhttp::field::set_cookie, set_cookie);
    write(res);
  }

  void send_file(const std::filesystem::path& path, std::string_view type) {
    beast::error_code ec;
    bhttp::file_body::value_type body;
    body.open(path.c_str(), beast::file_mode::scan, ec);
    if (ec) return send_text(bhttp::status::not_found, "the file cannot be read\n", keep_alive_);
    const std::uint64_t size = body.size();
    if (head_only_) {
      auto res = std::make_shared<bhttp::response<bhttp::empty_body>>(bhttp::status::ok, 11);
      common_headers(*res);
      res->set(bhttp::field::content_type, type);
      res->content_length(size);
      res->keep_alive(keep_alive_);
      return write(res);
    }
    auto res = std::make_shared<bhttp::response<bhttp::file_body>>(std::piecewise_construct, std::make_tuple(std::move(body)),
                                                                   std::make_tuple(bhttp::status::ok, 11));
    common_headers(*res);
    res->set(bhttp::field::content_type, type);
    res->content_length(size);
    res->keep_alive(keep_alive_);
    write(res);
  }

  void send_text(bhttp::status status, std::string text, bool keep_alive, std::string_view allow = {}) {
    auto res = std::make_shared<bhttp::response<bhttp::string_body>>(status, 11);
    common_headers(*res);
    res->set(bhttp::field::content_type, "text/plain; charset=utf-8");
    if (!allow.empty()) res->set(bhttp::field::allow, allow);
    res->keep_alive(keep_alive);
    if (!head_only_) res->body() = std::move(text);
    res->prepare_payload();
    write(res);
  }

  template <class Response>
  void write(std::shared_ptr<Response> res) {
    stream_.expires_after(idle());
    bhttp::async_write(stream_, *res, [self = shared_from_this(), res](beast::error_code ec, std::size_t) {
      if (ec || !res->keep_alive()) return self->finish();
      self->read_next();
    });
  }

  void finish() {
    close();
    finish_counting();
  }

  void finish_counting() {
    if (std::exchange(counted_, false)) {
      server_->sessions.erase(id_);
      --server_->count;
    }
  }

  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<bhttp::request_parser<bhttp::string_body>> parser_;
  std::shared_ptr<HttpServer::Impl> server_;
  std::uint64_t id_;
  std::string address_, peer_;  // the client's IP (the login limiter's key), and with its port
  bool keep_alive_ = false, head_only_ = false;
  bool counted_ = true;  // in server_->sessions and count (until closed or handed over)
};

}  // namespace

void HttpServer::Impl::accept_next() {
  acceptor.async_accept([self = shared_from_this()](const boost::system::error_code& e, tcp::socket s) {
    self->on_accept(e, std::move(s));
  });
}

void HttpServer::Impl::on_accept(const boost::system::error_code& error, tcp::socket socket) {
  if (stopped) return;
  if (error) {
    if (error == asio::error::operation_aborted) return;
    spdlog::warn("http: accept failed: {}", error.message());
    return accept_next();
  }
  const std::uint64_t id = next_id++;
  auto session = std::make_shared<Session>(std::move(socket), shared_from_this(), id);
  sessions[id] = session;
  ++count;
  if (count > settings.max_connections) session->refuse_busy();
  else session->start();
  accept_next();
}

void HttpServer::Impl::close_all() {
  stopped = true;
  boost::system::error_code ignored;
  acceptor.close(ignored);
  for (auto& [id, weak] : sessions)
    if (auto s = weak.lock()) s->close();
}

HttpServer::HttpServer(asio::io_context& io, HttpSettings settings, ArtefactLookup artefacts,
                       WebSocketHandoff websockets)
    : impl_(std::make_shared<Impl>(io, std::move(settings), std::move(artefacts), std::move(websockets))) {}

HttpServer::~HttpServer() { stop(); }

std::expected<void, std::string> HttpServer::listen() {
  const std::string where = fmt::format("{}:{}", impl_->settings.host, impl_->settings.port);
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(impl_->settings.host, ec);
  if (ec) return std::unexpected(fmt::format("[http] listen {}: not an IP address", where));
  const tcp::endpoint endpoint(address, static_cast<unsigned short>(impl_->settings.port));
  impl_->acceptor.open(endpoint.protocol(), ec);
  if (!ec) impl_->acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) impl_->acceptor.bind(endpoint, ec);
  if (!ec) impl_->acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) return std::unexpected(fmt::format("[http] listen {}: {}", where, ec.message()));
  impl_->bound_port = impl_->acceptor.local_endpoint().port();
  impl_->accept_next();
  return {};
}

int HttpServer::port() const { return impl_->bound_port; }
std::size_t HttpServer::connection_count() const { return impl_->count.load(); }

void HttpServer::stop() {
  if (impl_->io.stopped()) return impl_->close_all();  // nobody else runs handlers now
  asio::dispatch(impl_->io, [impl = impl_] { impl->close_all(); });
}

std::expected<std::filesystem::path, RouteError> resolve_static(const std::filesystem::path& root,
                                                                const StaticRequest& request) {
  std::error_code ec;
  const auto real_root = std::filesystem::canonical(root, ec);
  if (ec) return std::unexpected(RouteError{404, "the console's folder is missing"});
  const auto real = std::filesystem::canonical(real_root / request.relative, ec);
  if (ec) return std::unexpected(RouteError{404, fmt::format("no such file: /{}", request.relative)});
  const auto inside = real.lexically_relative(real_root);
  if (inside.empty() || *inside.begin() == "..")
    return std::unexpected(RouteError{404, fmt::format("no such file: /{}", request.relative)});
  if (!std::filesystem::is_regular_file(real, ec)) return std::unexpected(RouteError{404, fmt::format("no such file: /{}", request.relative)});
  return real;
}

}  // namespace lamina::daemon::http
