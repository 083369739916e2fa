// HttpServer: one acceptor and one Session per connection, all on the daemon's io thread.
#include "http/http_server.hpp"

#include <atomic>
#include <map>

#include <boost/asio/dispatch.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

namespace lamina::daemon::http {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace bhttp = boost::beast::http;
using tcp = asio::ip::tcp;

namespace {

class Session;

// Headers every answer carries: the console is its own origin and nothing is cached stale (a
// job's drawing changes when it is planned again).
template <class Response>
void common_headers(Response& res) {
  res.set(bhttp::field::server, "laminad");
  res.set(bhttp::field::cache_control, "no-cache");
  res.set("X-Content-Type-Options", "nosniff");
  res.set("Content-Security-Policy", "default-src 'self'; connect-src 'self'; img-src 'self' data: blob:");
  res.set("X-Frame-Options", "DENY");
}

}  // namespace

struct HttpServer::Impl : std::enable_shared_from_this<HttpServer::Impl> {
  Impl(asio::io_context& io_context, HttpSettings s, ArtefactLookup lookup)
      : io(io_context), settings(std::move(s)), artefacts(std::move(lookup)), acceptor(io_context) {}

  asio::io_context& io;
  HttpSettings settings;
  ArtefactLookup artefacts;
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
      : stream_(std::move(socket)), server_(std::move(server)), id_(id) {}

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
    parser_->body_limit(0);  // GET and HEAD only (uploads go over the RPC methods)
    stream_.expires_after(idle());
    bhttp::async_read(stream_, buffer_, *parser_,
                      [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
  }

  void on_read(beast::error_code ec) {
    if (ec == bhttp::error::header_limit) return send_text(bhttp::status::request_header_fields_too_large, "request head too large\n", false);
    if (ec == bhttp::error::body_limit) return send_text(bhttp::status::payload_too_large, "a request body is not accepted here\n", false);
    if (ec) return finish();  // end of stream, timeout, reset, garbage: nothing to answer
    const auto& req = parser_->get();
    keep_alive_ = req.keep_alive();
    head_only_ = req.method() == bhttp::verb::head;
    if (req.method() != bhttp::verb::get && !head_only_)
      return send_text(bhttp::status::method_not_allowed, fmt::format("{} is not served here\n", std::string(req.method_string())), keep_alive_, "GET, HEAD");
    auto route = route_get(std::string_view(req.target().data(), req.target().size()));
    if (!route) return send_text(static_cast<bhttp::status>(route.error().status), route.error().message + "\n", keep_alive_);
    std::visit([&](const auto& r) { serve(r); }, *route);
  }

  void serve(const WebSocketRequest&) {
    send_text(bhttp::status::not_implemented, "the WebSocket is not served yet\n", keep_alive_);
  }
  void serve(const StaticRequest& r) {
    if (server_->settings.static_dir.empty()) return send_text(bhttp::status::not_found, "no console files are configured\n", keep_alive_);
    auto path = resolve_static(server_->settings.static_dir, r);
    if (!path) return send_text(static_cast<bhttp::status>(path.error().status), path.error().message + "\n", keep_alive_);
    send_file(*path, content_type(r.relative));
  }
  void serve(const ArtefactRequest& r) {
    auto path = server_->artefacts ? server_->artefacts(r) : std::unexpected(RouteError{404, "no jobs here"});
    if (!path) return send_text(static_cast<bhttp::status>(path.error().status), path.error().message + "\n", keep_alive_);
    send_file(*path, r.kind == Artefact::model ? content_type(path->filename().string()) : content_type(artefact_file_name(r)));
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
    server_->sessions.erase(id_);
    --server_->count;
  }

  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<bhttp::request_parser<bhttp::empty_body>> parser_;
  std::shared_ptr<HttpServer::Impl> server_;
  std::uint64_t id_;
  bool keep_alive_ = false, head_only_ = false;
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

HttpServer::HttpServer(asio::io_context& io, HttpSettings settings, ArtefactLookup artefacts)
    : impl_(std::make_shared<Impl>(io, std::move(settings), std::move(artefacts))) {}

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
