#pragma once
// The JSON-RPC pipeline over a WebSocket (RFC 6455): one request or reply per text message.
// The handshake is done by the web server before this takes the stream over.
#include <cstddef>
#include <memory>

#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/ssl/ssl_stream.hpp>
#include <boost/beast/websocket/stream.hpp>

#include "rpc_transport.hpp"

namespace lamina::daemon::http {

using WebSocket = boost::beast::websocket::stream<boost::beast::tcp_stream>;
using TlsStream = boost::beast::ssl_stream<boost::beast::tcp_stream>;
using TlsWebSocket = boost::beast::websocket::stream<TlsStream>;  // wss:// ([http] tls_cert)

// Messages longer than max_request_bytes + 1 are refused by Beast (close code 1009) before
// they are buffered; one byte over still reaches the connection, which answers "request too
// large" as it does on every other transport.
std::unique_ptr<RpcTransport> make_websocket_transport(WebSocket ws, std::size_t max_request_bytes);
std::unique_ptr<RpcTransport> make_websocket_transport(TlsWebSocket ws, std::size_t max_request_bytes);

// Keep-alive pings, so a browser that vanished without a close is dropped (its subscription
// would keep it open forever otherwise), and a bound on the closing handshake.
void set_websocket_timeouts(WebSocket& ws, double idle_timeout_s);
void set_websocket_timeouts(TlsWebSocket& ws, double idle_timeout_s);

}  // namespace lamina::daemon::http
