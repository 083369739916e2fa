#pragma once
// laminad's web server (issue 19), on the daemon's io_context: the console's files, each job's
// artefacts, the login, and the WebSocket that hands a logged-in browser to the JSON-RPC server.
// Routing is http_routes and access web_access (both sans-IO); this file moves bytes.
// A connection gets the limits of an RPC client: a bounded request head, an idle timeout, a
// bounded number of connections; a file is read in chunks as the client takes it.
#include <cstddef>
#include <expected>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include <boost/asio/io_context.hpp>

#include "http/http_routes.hpp"
#include "http/web_access.hpp"
#include "rpc_transport.hpp"

namespace lamina::daemon::http {

struct HttpSettings {
  std::string host = "127.0.0.1";
  int port = 8080;                     // 0: any free port (tests); port() says which
  std::filesystem::path static_dir;    // the console's files; empty: none are served
  double idle_timeout_s = 30;          // a connection that sends nothing this long is closed
  std::size_t max_header_bytes = 8192;
  std::size_t max_connections = 64;    // beyond: 503 and close
  AccessSettings access;
  std::size_t max_request_bytes = 1 << 20;  // a WebSocket message, as [server] max_request_bytes
  // Both set: HTTPS and wss:// only (PEM files: the certificate chain, then its private key).
  // access.tls must then be true too (Secure cookies, https:// origins).
  std::filesystem::path tls_cert, tls_key;
};

// A job's artefact as a file to send, or why not (404: no such job or no such file yet).
using ArtefactLookup = std::function<std::expected<std::filesystem::path, RouteError>(const ArtefactRequest&)>;

// A browser through the WebSocket handshake, for the JSON-RPC server (RpcServer::adopt); the
// reason when it cannot be taken (the transport is then dropped, which closes it).
using WebSocketHandoff =
    std::function<std::expected<void, std::string>(std::unique_ptr<RpcTransport>, const Visitor&, std::string peer)>;

// Where POST /api/uploads puts a model (laminad: its Uploads, the same as upload.begin/chunk):
// an upload id the browser then names in job.submit. Errors carry their HTTP status.
struct UploadSink {
  std::function<std::expected<std::string, RouteError>(const std::string& name, std::uint64_t size)> begin;
  std::function<std::expected<void, RouteError>(const std::string& id, std::uint64_t offset, std::string_view bytes)> append;
  std::function<void(const std::string& id)> cancel;
  std::uint64_t max_bytes = 0;  // a larger Content-Length is refused (413) before its body is read
};

class HttpServer {
 public:
  HttpServer(boost::asio::io_context& io, HttpSettings settings, ArtefactLookup artefacts, WebSocketHandoff websockets,
             UploadSink uploads = {});
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  // Loads the TLS certificate and key when set, binds and listens; the error names the file or
  // the address.
  std::expected<void, std::string> listen();
  int port() const;
  bool tls() const;  // after listen()
  // Stop accepting; close every connection. Thread-safe.
  void stop();
  std::size_t connection_count() const;

  struct Impl;  // the listener's state, shared with its connections (http_server.cpp)

 private:
  std::shared_ptr<Impl> impl_;
};

// The static file a StaticRequest names under `root`, if it is a regular file there: the real
// path (symlinks resolved) must stay inside the real root.
std::expected<std::filesystem::path, RouteError> resolve_static(const std::filesystem::path& root,
                                                                const StaticRequest& request);

}  // namespace lamina::daemon::http
