// HttpServer: the listener, on the daemon's io thread; each connection is a Session
// (http_session.hpp), over plain TCP or TLS.
#include "http/http_server.hpp"

#include <boost/asio/dispatch.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "http/http_server_state.hpp"
#include "http/passwords.hpp"

namespace lamina::daemon::http {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

HttpServer::Impl::Impl(asio::io_context& io_context, HttpSettings s, ArtefactLookup lookup, WebSocketHandoff ws,
                       UploadSink upload_sink)
    : io(io_context),
      settings(std::move(s)),
      artefacts(std::move(lookup)),
      websockets(std::move(ws)),
      uploads(std::move(upload_sink)),
      access(settings.access),
      acceptor(io_context) {
  if (access.users_configured()) dummy_hash = hash_password(random_token()).value_or("");
}

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
  auto session = tls ? make_tls_connection(std::move(socket), shared_from_this(), id)
                     : make_plain_connection(std::move(socket), shared_from_this(), id);
  connections[id] = session;
  ++count;
  if (count > settings.max_connections) session->refuse_busy();
  else session->start();
  accept_next();
}

void HttpServer::Impl::close_all() {
  stopped = true;
  boost::system::error_code ignored;
  acceptor.close(ignored);
  for (auto& [id, weak] : connections)
    if (auto s = weak.lock()) s->close();
}

HttpServer::HttpServer(asio::io_context& io, HttpSettings settings, ArtefactLookup artefacts,
                       WebSocketHandoff websockets, UploadSink uploads)
    : impl_(std::make_shared<Impl>(io, std::move(settings), std::move(artefacts), std::move(websockets),
                                   std::move(uploads))) {}

HttpServer::~HttpServer() { stop(); }

std::expected<void, std::string> HttpServer::listen() {
  const std::string where = fmt::format("{}:{}", impl_->settings.host, impl_->settings.port);
  if (!impl_->settings.tls_cert.empty() || !impl_->settings.tls_key.empty()) {
    auto context = make_tls_context(impl_->settings.tls_cert, impl_->settings.tls_key);
    if (!context) return std::unexpected(context.error());
    impl_->tls.emplace(std::move(*context));
  }
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

bool HttpServer::tls() const { return impl_->tls.has_value(); }

}  // namespace lamina::daemon::http
