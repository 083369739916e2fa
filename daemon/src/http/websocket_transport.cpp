#include "http/websocket_transport.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include <boost/asio/buffer.hpp>
#include <boost/beast/core/buffers_to_string.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/websocket.hpp>
#include <boost/beast/websocket/ssl.hpp>

namespace lamina::daemon::http {
namespace {

namespace websocket = boost::beast::websocket;

// Over plain TCP or over TLS: the same messages, the stream underneath differs.
template <class Stream>
class WebSocketTransport final : public RpcTransport {
 public:
  WebSocketTransport(Stream ws, std::size_t max_request_bytes) : ws_(std::move(ws)) {
    ws_.read_message_max(max_request_bytes + 1);
    ws_.text(true);
  }

  boost::asio::any_io_executor executor() override { return ws_.get_executor(); }

  void async_read(ReadHandler handler) override {
    ws_.async_read(in_, [this, handler = std::move(handler)](const boost::system::error_code& error, std::size_t) {
      if (error) return handler(error == websocket::error::closed ? boost::asio::error::eof : error, {});
      // One message is one request: its own line ends (pretty-printed JSON) become spaces.
      line_ = boost::beast::buffers_to_string(in_.data());
      in_.consume(in_.size());
      std::replace_if(line_.begin(), line_.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
      line_ += '\n';
      handler(error, line_);
    });
  }

  void async_write(std::span<const Line> lines, WriteHandler handler) override {
    pending_.assign(lines.begin(), lines.end());
    next_ = 0;
    write_next(std::move(handler));
  }

  void shutdown_send() override {
    if (closing_) return;
    closing_ = true;
    ws_.async_close(websocket::close_code::policy_error, [](const boost::system::error_code&) {});
  }

  void close() override {
    boost::system::error_code ignored;
    boost::beast::get_lowest_layer(ws_).socket().shutdown(boost::asio::ip::tcp::socket::shutdown_both, ignored);
    boost::beast::get_lowest_layer(ws_).close();
  }

 private:
  // A message per line, one after the other (a WebSocket has one write in flight at a time).
  // The handler travels in the operation, never in a member: it holds the connection, which
  // owns this transport, and an io_context destroyed with the write pending must free it.
  void write_next(WriteHandler handler) {
    if (next_ == pending_.size()) {
      pending_.clear();
      return handler(boost::system::error_code{});
    }
    const std::string& line = *pending_[next_++];
    const std::size_t size = !line.empty() && line.back() == '\n' ? line.size() - 1 : line.size();
    ws_.async_write(boost::asio::buffer(line.data(), size),
                    [this, handler = std::move(handler)](const boost::system::error_code& error, std::size_t) mutable {
                      if (error) {
                        pending_.clear();
                        return handler(error);
                      }
                      write_next(std::move(handler));
                    });
  }

  // The connection owns the transport and its handlers hold the connection, so `this` outlives
  // every operation.
  Stream ws_;
  boost::beast::flat_buffer in_;
  std::string line_;
  std::vector<Line> pending_;
  std::size_t next_ = 0;
  bool closing_ = false;
};

}  // namespace

std::unique_ptr<RpcTransport> make_websocket_transport(WebSocket ws, std::size_t max_request_bytes) {
  return std::make_unique<WebSocketTransport<WebSocket>>(std::move(ws), max_request_bytes);
}

std::unique_ptr<RpcTransport> make_websocket_transport(TlsWebSocket ws, std::size_t max_request_bytes) {
  return std::make_unique<WebSocketTransport<TlsWebSocket>>(std::move(ws), max_request_bytes);
}

namespace {
template <class Stream>
void set_timeouts(Stream& ws, double idle_timeout_s) {
  websocket::stream_base::timeout t{};
  t.handshake_timeout = std::chrono::seconds(10);
  t.idle_timeout = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(idle_timeout_s));
  t.keep_alive_pings = true;  // a ping at half the idle time; no answer by the end: closed
  ws.set_option(t);
}
}  // namespace

void set_websocket_timeouts(WebSocket& ws, double idle_timeout_s) { set_timeouts(ws, idle_timeout_s); }
void set_websocket_timeouts(TlsWebSocket& ws, double idle_timeout_s) { set_timeouts(ws, idle_timeout_s); }

}  // namespace lamina::daemon::http
