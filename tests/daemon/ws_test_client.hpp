#pragma once
// A WebSocket client for the web console's tests (Boost.Beast, as a browser would speak it):
// the handshake with the headers a test chooses (Cookie, Origin), JSON-RPC calls as text
// messages; over TCP (ws://) or TLS (wss://, the server's certificate verified for localhost).
// Every wait is bounded (10 s) so a hung server fails a test instead of hanging it.
#include <chrono>
#include <optional>
#include <stdexcept>
#include <string>

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ssl.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/ssl.hpp>
#include <boost/beast/websocket.hpp>
#include <boost/beast/websocket/ssl.hpp>
#include <nlohmann/json.hpp>

namespace lamina::daemon::testing {

using TlsTcpStream = boost::beast::ssl_stream<boost::beast::tcp_stream>;

// NextLayer: boost::beast::tcp_stream, or TlsTcpStream (give the constructor a client context).
template <class NextLayer>
class BasicWsClient {
 public:
  // Connects and shakes hands; `refusal` gets the server's HTTP answer when it does not upgrade.
  template <class... TlsContext>
  BasicWsClient(int port, const std::string& cookie, const std::string& origin, TlsContext&... tls)
      : ws_(io_, tls...) {
    namespace bhttp = boost::beast::http;
    boost::asio::ip::tcp::endpoint at(boost::asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port));
    boost::beast::get_lowest_layer(ws_).expires_after(std::chrono::seconds(10));
    boost::beast::get_lowest_layer(ws_).connect(at);
    boost::system::error_code ec;
    if constexpr (sizeof...(TlsContext) > 0) {
      auto& tls_stream = ws_.next_layer();
      SSL_set_tlsext_host_name(tls_stream.native_handle(), "localhost");
      tls_stream.set_verify_callback(boost::asio::ssl::host_name_verification("localhost"));
      tls_stream.handshake(boost::asio::ssl::stream_base::client, ec);
      if (ec) {
        refusal_ = "TLS: " + ec.message();
        return;
      }
    }
    ws_.set_option(boost::beast::websocket::stream_base::decorator([&](boost::beast::websocket::request_type& req) {
      if (!cookie.empty()) req.set(bhttp::field::cookie, cookie);
      if (!origin.empty()) req.set(bhttp::field::origin, origin);
    }));
    boost::beast::websocket::response_type res;
    ws_.handshake(res, "localhost:" + std::to_string(port), "/ws", ec);
    if (ec) {
      status_ = res.result_int();
      refusal_ = res.body();
      return;
    }
    status_ = 101;
    boost::beast::get_lowest_layer(ws_).expires_never();
  }

  bool open() const { return status_ == 101; }
  unsigned status() const { return status_; }  // 101, or the refusal's HTTP status
  const std::string& refusal() const { return refusal_; }

  // False when the server has closed (a write into a refused message can meet a reset).
  bool send(const std::string& text) {
    boost::system::error_code ec;
    ws_.write(boost::asio::buffer(text), ec);
    return !ec;
  }

  // The next message, or nullopt when the server closed (or nothing came within 10 s).
  std::optional<std::string> receive(std::chrono::seconds limit = std::chrono::seconds(10)) {
    boost::beast::flat_buffer buffer;
    std::optional<boost::system::error_code> done;
    ws_.async_read(buffer, [&](boost::system::error_code ec, std::size_t) { done = ec; });
    io_.restart();
    io_.run_for(limit);
    if (!done) {
      boost::beast::get_lowest_layer(ws_).close();  // the read completes aborted
      io_.restart();
      io_.run();
      return std::nullopt;
    }
    if (*done) return std::nullopt;
    return boost::beast::buffers_to_string(buffer.data());
  }

  // A call and its reply (notifications that come first are skipped).
  nlohmann::json call(const std::string& method, const nlohmann::json& params = nlohmann::json::object()) {
    const int id = ++next_id_;
    if (!send(nlohmann::json{{"jsonrpc", "2.0"}, {"id", id}, {"method", method}, {"params", params}}.dump()))
      throw std::runtime_error("the server closed the WebSocket before " + method);
    for (int skipped = 0; skipped < 1000; ++skipped) {
      auto text = receive();
      if (!text) throw std::runtime_error("the server closed the WebSocket before answering " + method);
      auto reply = nlohmann::json::parse(*text);
      if (reply.contains("id") && reply["id"] == id) return reply;
    }
    throw std::runtime_error("no reply to " + method);
  }

 private:
  boost::asio::io_context io_;
  boost::beast::websocket::stream<NextLayer> ws_;
  unsigned status_ = 0;
  std::string refusal_;
  int next_id_ = 0;
};

using WsClient = BasicWsClient<boost::beast::tcp_stream>;
using WssClient = BasicWsClient<TlsTcpStream>;

}  // namespace lamina::daemon::testing
