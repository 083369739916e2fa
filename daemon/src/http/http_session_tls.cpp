// The web server's TLS connections (http_session.hpp), and the TLS context they share.
#include <openssl/err.h>

#include "http/http_session.hpp"

namespace lamina::daemon::http {

std::shared_ptr<HttpConnection> make_tls_connection(boost::asio::ip::tcp::socket socket,
                                                    std::shared_ptr<HttpServer::Impl> server, std::uint64_t id) {
  boost::asio::ssl::context& context = *server->tls;
  return std::make_shared<session_detail::Session<TlsStream>>(std::move(server), id, std::move(socket), context);
}

std::expected<boost::asio::ssl::context, std::string> make_tls_context(const std::filesystem::path& cert,
                                                                       const std::filesystem::path& key) {
  namespace ssl = boost::asio::ssl;
  // TLS 1.2 and 1.3 only: every browser a cell PC runs speaks them, and the older ones are broken.
  ssl::context context(ssl::context::tls_server);
  context.set_options(ssl::context::default_workarounds | ssl::context::no_sslv2 | ssl::context::no_sslv3 |
                      ssl::context::no_tlsv1 | ssl::context::no_tlsv1_1 | ssl::context::single_dh_use);
  // The key first: a certificate that does not match it then leaves the context without a key,
  // which the check below names in words a person can act on.
  boost::system::error_code ec;
  context.use_private_key_file(key.string(), ssl::context::pem, ec);
  if (ec) return std::unexpected(fmt::format("[http] tls_key {}: {}", key.string(), ec.message()));
  context.use_certificate_chain_file(cert.string(), ec);
  if (ec) return std::unexpected(fmt::format("[http] tls_cert {}: {}", cert.string(), ec.message()));
  if (SSL_CTX_check_private_key(context.native_handle()) != 1) {
    ERR_clear_error();
    return std::unexpected(fmt::format("[http] tls_key {} is not the key of the certificate in {}", key.string(), cert.string()));
  }
  return context;
}

}  // namespace lamina::daemon::http
