// The web server's plain-TCP connections (http_session.hpp).
#include "http/http_session.hpp"

namespace lamina::daemon::http {

std::shared_ptr<HttpConnection> make_plain_connection(boost::asio::ip::tcp::socket socket,
                                                      std::shared_ptr<HttpServer::Impl> server, std::uint64_t id) {
  return std::make_shared<session_detail::Session<boost::beast::tcp_stream>>(std::move(server), id, std::move(socket));
}

}  // namespace lamina::daemon::http
