#pragma once
// The byte pipe under one JSON-RPC client (rpc_connection.cpp): a Unix or TCP socket carrying
// newline-delimited requests, or a WebSocket carrying one request per message. The connection's
// pipeline (framing, limits, authorisation, the worker queue, replies in order) is the same for
// every transport, so a browser gets exactly the limits of any other client.
//
// Every call is made on the transport's executor holding the server's mutex; handlers run on
// that executor (the connection takes the mutex in them). One read and one write at a time.
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/generic/stream_protocol.hpp>
#include <boost/system/error_code.hpp>

namespace lamina::daemon {

class RpcTransport {
 public:
  // `bytes` is valid during the call only: newline-delimited text. A message transport hands
  // each message as one line (its own line ends turned into spaces, which JSON allows).
  using ReadHandler = std::function<void(const boost::system::error_code&, std::string_view bytes)>;
  using WriteHandler = std::function<void(const boost::system::error_code&)>;
  using Line = std::shared_ptr<const std::string>;  // ends with '\n'

  virtual ~RpcTransport() = default;
  virtual boost::asio::any_io_executor executor() = 0;
  virtual void async_read(ReadHandler handler) = 0;
  // The lines stay alive (the caller holds them) until the handler has run.
  virtual void async_write(std::span<const Line> lines, WriteHandler handler) = 0;
  // After a refusal: tell the peer nothing more comes (a half close; a WebSocket's close frame).
  virtual void shutdown_send() = 0;
  // Pending operations complete with operation_aborted. Idempotent.
  virtual void close() = 0;
};

// A connected Unix or TCP stream socket: the lines as they are, many in one gathered write.
std::unique_ptr<RpcTransport> make_stream_transport(boost::asio::generic::stream_protocol::socket socket);

}  // namespace lamina::daemon
