#pragma once
// One browser's connection to laminad's web server: requests read with bounded heads and bodies,
// the console's files and a job's artefacts sent, the login checked, and a WebSocket upgrade
// handed to the JSON-RPC server. A template over the stream, so that TLS (beast::ssl_stream)
// and plain TCP share every line of it; http_session_tcp.cpp and http_session_tls.cpp each
// build one (the two take a while to compile, in parallel).
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

#include <boost/asio/ssl.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/ssl.hpp>
#include <boost/beast/websocket.hpp>
#include <boost/beast/websocket/ssl.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "http/http_server_state.hpp"
#include "http/passwords.hpp"
#include "http/websocket_transport.hpp"

namespace lamina::daemon::http::session_detail {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace bhttp = boost::beast::http;
using tcp = asio::ip::tcp;

constexpr std::size_t kMaxLoginBody = 4096;

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

// Stream: beast::tcp_stream, or TlsStream (TLS over it) when [http] tls_cert is set.
template <class Stream>
class Session final : public HttpConnection, public std::enable_shared_from_this<Session<Stream>> {
  static constexpr bool kTls = !std::is_same_v<Stream, beast::tcp_stream>;

 public:
  // StreamArgs: the socket, and for TLS the server's context.
  template <class... StreamArgs>
  Session(std::shared_ptr<HttpServer::Impl> server, std::uint64_t id, StreamArgs&&... stream_args)
      : stream_(std::forward<StreamArgs>(stream_args)...), server_(std::move(server)), id_(id) {
    beast::error_code ec;
    const auto remote = lowest().socket().remote_endpoint(ec);
    address_ = ec ? "unknown" : remote.address().to_string();
    peer_ = ec ? "unknown" : fmt::format("{}:{}", address_, remote.port());
  }

  void start() override {
    if constexpr (!kTls) {
      read_next();
    } else {
      lowest().expires_after(idle());  // a client that never says hello is dropped
      stream_.async_handshake(boost::asio::ssl::stream_base::server, [self = this->shared_from_this()](beast::error_code ec) {
        if (!ec) return self->read_next();
        // Plain HTTP to the TLS port, an old protocol, a scanner: nothing can be answered.
        spdlog::debug("http: TLS handshake with {} failed: {}", self->peer_, ec.message());
        self->finish();
      });
    }
  }
  void close() override {
    beast::error_code ignored;
    lowest().socket().shutdown(tcp::socket::shutdown_both, ignored);
    lowest().close();
  }
  void refuse_busy() override {
    if constexpr (kTls) return finish();  // an answer would need a handshake first: not for a full house
    else send_text(bhttp::status::service_unavailable, "too many connections\n", false);
  }

 private:
  beast::tcp_stream& lowest() { return beast::get_lowest_layer(stream_); }

  std::chrono::steady_clock::duration idle() const {
    return std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(server_->settings.idle_timeout_s));
  }

  void read_next() {
    parser_.emplace();
    parser_->header_limit(static_cast<std::uint32_t>(server_->settings.max_header_bytes));
    // Checked against Content-Length as the head ends: the largest body any route takes (an
    // upload); on_header narrows it to the route's own.
    parser_->body_limit(std::max<std::uint64_t>(kMaxLoginBody, server_->uploads.max_bytes));
    lowest().expires_after(idle());
    bhttp::async_read_header(stream_, buffer_, *parser_,
                             [self = this->shared_from_this()](beast::error_code ec, std::size_t) { self->on_header(ec); });
  }

  // Only the login (a few hundred bytes of JSON) and an upload (streamed to disk) have a body;
  // anything else with one is refused.
  void on_header(beast::error_code ec) {
    if (ec) return on_read(ec);
    const bool post = parser_->get().method() == bhttp::verb::post;
    if (post && parser_->get().target().starts_with("/api/uploads")) return start_upload();
    const auto length = parser_->content_length();
    if (!post && ((length && *length > 0) || parser_->chunked())) return on_read(bhttp::error::body_limit);
    // Beast checked Content-Length against the upload's limit as the head ended: the login's
    // is checked here, and a chunked body is counted against it as it comes.
    if (length && *length > kMaxLoginBody) return on_read(bhttp::error::body_limit);
    parser_->body_limit(post ? kMaxLoginBody : 0);
    bhttp::async_read(stream_, buffer_, *parser_,
                      [self = this->shared_from_this()](beast::error_code e, std::size_t) { self->on_read(e); });
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
    auto ws = std::make_shared<beast::websocket::stream<Stream>>(std::move(stream_));
    beast::get_lowest_layer(*ws).expires_never();  // the WebSocket keeps its own time (pings)
    set_websocket_timeouts(*ws, server_->settings.idle_timeout_s);
    ws->async_accept(parser_->get(), [self = this->shared_from_this(), ws, who = *who](beast::error_code ec) {
      self->on_upgraded(ec, ws, who);
    });
  }

  void on_upgraded(beast::error_code ec, const std::shared_ptr<beast::websocket::stream<Stream>>& ws, const Visitor& who) {
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
    auto route = checked_post();
    if (!route) return;
    if (route->route == PostRoute::logout) {
      server_->access.sessions().close(cookie_value(field(bhttp::field::cookie), kSessionCookie));
      return send_json(bhttp::status::ok, {{"logged_out", true}}, server_->access.cleared_cookie());
    }
    login(req.body());
  }

  // Every POST's route and Origin (a form another site's page posts, CSRF: the browser says
  // whose page it is); nullopt when refused, the answer sent.
  std::optional<PostRequest> checked_post() {
    const auto& req = parser_->get();
    auto route = route_post(std::string_view(req.target().data(), req.target().size()));
    if (!route) {
      send_json(static_cast<bhttp::status>(route.error().status), {{"error", route.error().message}});
      return std::nullopt;
    }
    if (auto origin = server_->access.check_origin(field(bhttp::field::origin), field(bhttp::field::host)); !origin) {
      send_json(bhttp::status::forbidden, {{"error", origin.error().message}});
      return std::nullopt;
    }
    return *route;
  }

  // --- POST /api/uploads?name=…: a model, its bytes the body (Content-Length required) ---
  // Checked before a byte of the body is read: the Host, the Origin, an engineer's session, the
  // size. Then read in 256 KiB pieces, each appended to the upload's file as it comes.
  void start_upload() {
    keep_alive_ = false;  // an upload's connection closes after its answer (a refused body is never read)
    if (auto host = server_->access.check_host(field(bhttp::field::host)); !host) return refuse(host.error());
    auto route = checked_post();
    if (!route) return;
    auto who = visitor();
    if (!who) return send_json(static_cast<bhttp::status>(who.error().status), {{"error", who.error().message}});
    if (who->role < Role::engineer)
      return send_json(bhttp::status::forbidden, {{"error", fmt::format("uploading a model is for an engineer; {} is {}",
                                                                         who->user, role_with_article(who->role))}});
    const UploadSink& sink = server_->uploads;
    if (!sink.begin) return send_json(bhttp::status::not_found, {{"error", "uploads are not taken here"}});
    const auto length = parser_->content_length();
    if (!length || parser_->chunked())
      return send_json(bhttp::status::length_required, {{"error", "an upload needs its Content-Length"}});
    if (*length == 0 || *length > sink.max_bytes)
      return send_json(bhttp::status::payload_too_large, {{"error", fmt::format("a model is 1 … {} bytes; this is {}", sink.max_bytes, *length)}});
    auto id = sink.begin(route->upload_name, *length);
    if (!id) return send_json(static_cast<bhttp::status>(id.error().status), {{"error", id.error().message}});
    upload_id_ = *id;
    upload_parser_.emplace(std::move(*parser_));
    upload_parser_->body_limit(*length);
    spdlog::info("http: {} uploads {} ({} bytes) from {}", who->user, route->upload_name, *length, address_);
    read_upload();
  }

  void read_upload() {
    upload_chunk_.resize(256 * 1024);
    auto& body = upload_parser_->get().body();
    body.data = upload_chunk_.data();
    body.size = upload_chunk_.size();
    lowest().expires_after(idle());  // a sender that stalls is dropped, and its upload with it
    bhttp::async_read(stream_, buffer_, *upload_parser_,
                      [self = this->shared_from_this()](beast::error_code ec, std::size_t) { self->on_upload_read(ec); });
  }

  void on_upload_read(beast::error_code ec) {
    if (ec == bhttp::error::need_buffer) ec = {};
    const std::size_t got = upload_chunk_.size() - upload_parser_->get().body().size;
    if (!ec && got > 0) {
      auto ok = server_->uploads.append(upload_id_, upload_received_, std::string_view(upload_chunk_.data(), got));
      if (!ok) {
        server_->uploads.cancel(upload_id_);
        return send_json(static_cast<bhttp::status>(ok.error().status), {{"error", ok.error().message}});
      }
      upload_received_ += got;
    }
    if (ec) {  // the sender went away or stalled: what came is dropped, not left as a half model
      spdlog::warn("http: upload from {} ended after {} bytes: {}", peer_, upload_received_, ec.message());
      server_->uploads.cancel(upload_id_);
      return finish();
    }
    if (!upload_parser_->is_done()) return read_upload();
    send_json(bhttp::status::ok, {{"upload", upload_id_}, {"size", upload_received_}});
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
        hash, json["password"], stream_.get_executor(), [self = this->shared_from_this(), name, known = user != nullptr](bool ok) {
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
    lowest().expires_after(idle());
    bhttp::async_write(stream_, *res, [self = this->shared_from_this(), res](beast::error_code ec, std::size_t) {
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
      server_->connections.erase(id_);
      --server_->count;
    }
  }

  Stream stream_;
  beast::flat_buffer buffer_;
  std::optional<bhttp::request_parser<bhttp::string_body>> parser_;
  std::optional<bhttp::request_parser<bhttp::buffer_body>> upload_parser_;
  std::vector<char> upload_chunk_;
  std::string upload_id_;
  std::uint64_t upload_received_ = 0;
  std::shared_ptr<HttpServer::Impl> server_;
  std::uint64_t id_;
  std::string address_, peer_;  // the client's IP (the login limiter's key), and with its port
  bool keep_alive_ = false, head_only_ = false;
  bool counted_ = true;  // in server_->connections and count (until closed or handed over)
};

}  // namespace lamina::daemon::http::session_detail
