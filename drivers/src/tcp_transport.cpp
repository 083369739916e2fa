// open_tcp(): a controller's network stream (grblHAL and others take G-code over TCP).
//
// The connect runs on a private io_context on the caller's thread, so opening does not need the
// shared io_context to be running, nor disturb the thread that runs it; the connected socket is
// then handed over (release/assign) to the shared io_context, where its handlers will run.
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <unistd.h>

#include <chrono>
#include <optional>

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <fmt/core.h>

#include "asio_stream_transport.hpp"

namespace lamina::drivers {

namespace {

using boost::asio::ip::tcp;

LinkError connect_error(const std::string& where, const boost::system::error_code& ec) {
  // The kernel's own connect timeout is a timeout too, not a refusal.
  const LinkErrorCode code = ec == boost::asio::error::timed_out ? LinkErrorCode::timeout : LinkErrorCode::open_failed;
  return LinkError{code, fmt::format("cannot connect to {}: {}", where, ec.message())};
}

}  // namespace

std::expected<std::unique_ptr<Transport>, LinkError> open_tcp(boost::asio::io_context& io, const std::string& host,
                                                              int port, double connect_timeout_s) {
  const std::string where = fmt::format("{}:{}", host, port);
  if (port <= 0 || port > 65535)
    return std::unexpected(LinkError{LinkErrorCode::bad_request, fmt::format("tcp {}: port out of range", where)});
  if (!(connect_timeout_s > 0))
    return std::unexpected(
        LinkError{LinkErrorCode::bad_request, fmt::format("tcp {}: connect timeout {} s", where, connect_timeout_s)});

  boost::asio::io_context local;
  boost::system::error_code ec;
  tcp::resolver resolver(local);
  // A numeric address resolves at once; a name asks the system resolver (blocking, this thread).
  const auto endpoints = resolver.resolve(host, std::to_string(port), tcp::resolver::numeric_service, ec);
  if (ec)
    return std::unexpected(
        LinkError{LinkErrorCode::open_failed, fmt::format("cannot resolve {}: {}", where, ec.message())});

  tcp::socket socket(local);
  boost::asio::steady_timer timer(local);
  std::optional<boost::system::error_code> connected;
  bool timed_out = false;
  boost::asio::async_connect(socket, endpoints, [&](const boost::system::error_code& e, const tcp::endpoint&) {
    connected = e;
    timer.cancel();
  });
  timer.expires_after(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(connect_timeout_s)));
  timer.async_wait([&](const boost::system::error_code& e) {
    if (e || connected) return;  // cancelled: the connect finished first
    timed_out = true;
    boost::system::error_code ignored;
    socket.close(ignored);  // the pending connect completes with operation_aborted
  });
  local.run();

  if (timed_out)
    return std::unexpected(LinkError{LinkErrorCode::timeout, fmt::format("cannot connect to {}: no answer within {} s",
                                                                         where, connect_timeout_s)});
  if (!connected || *connected) return std::unexpected(connect_error(where, connected.value_or(boost::asio::error::fault)));

  // Lines are small and latency matters (a feed hold must leave at once): no Nagle.
  socket.set_option(tcp::no_delay(true), ec);
  if (ec)
    return std::unexpected(
        LinkError{LinkErrorCode::configure_failed, fmt::format("tcp {}: TCP_NODELAY refused: {}", where, ec.message())});
  const auto protocol = socket.remote_endpoint(ec).protocol();
  if (ec) return std::unexpected(connect_error(where, ec));
  const int fd = socket.release(ec);
  if (ec) return std::unexpected(connect_error(where, ec));
  tcp::socket shared(io);
  shared.assign(protocol, fd, ec);
  if (ec) {
    ::close(fd);
    return std::unexpected(connect_error(where, ec));
  }
  return std::make_unique<detail::AsioStreamTransport<tcp::socket>>(std::move(shared), fmt::format("tcp {}", where));
}

}  // namespace lamina::drivers
