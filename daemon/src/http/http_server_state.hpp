#pragma once
// What the web server's listener and its connections share (http_server.cpp, http_session*.cpp).
// Everything here is touched on the daemon's io thread only, but for `count`.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ssl/context.hpp>

#include "http/http_server.hpp"
#include "http/password_checker.hpp"

namespace lamina::daemon::http {

// One browser connection, plain or TLS (http_session.hpp).
class HttpConnection {
 public:
  virtual ~HttpConnection() = default;
  virtual void start() = 0;
  virtual void close() = 0;
  // A full house: one short answer where the protocol allows it, then the connection closes.
  virtual void refuse_busy() = 0;
};

struct HttpServer::Impl : std::enable_shared_from_this<HttpServer::Impl> {
  Impl(boost::asio::io_context& io_context, HttpSettings s, ArtefactLookup lookup, WebSocketHandoff ws,
       UploadSink upload_sink);

  boost::asio::io_context& io;
  HttpSettings settings;
  ArtefactLookup artefacts;
  WebSocketHandoff websockets;
  UploadSink uploads;
  WebAccess access;
  PasswordChecker passwords;
  std::string dummy_hash;  // unknown names are checked against this: a wrong name costs a wrong password's time
  std::optional<boost::asio::ssl::context> tls;  // set by listen() when [http] tls_cert is
  boost::asio::ip::tcp::acceptor acceptor;
  int bound_port = 0;
  bool stopped = false;
  std::uint64_t next_id = 1;
  std::map<std::uint64_t, std::weak_ptr<HttpConnection>> connections;
  std::atomic<std::size_t> count{0};

  void accept_next();
  void on_accept(const boost::system::error_code& error, boost::asio::ip::tcp::socket socket);
  void close_all();
};

std::shared_ptr<HttpConnection> make_plain_connection(boost::asio::ip::tcp::socket socket,
                                                      std::shared_ptr<HttpServer::Impl> server, std::uint64_t id);
std::shared_ptr<HttpConnection> make_tls_connection(boost::asio::ip::tcp::socket socket,
                                                    std::shared_ptr<HttpServer::Impl> server, std::uint64_t id);

// The server's TLS context from a PEM certificate chain and its key; the error names the file.
std::expected<boost::asio::ssl::context, std::string> make_tls_context(const std::filesystem::path& cert,
                                                                       const std::filesystem::path& key);

inline double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace lamina::daemon::http
