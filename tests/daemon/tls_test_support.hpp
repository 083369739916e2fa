#pragma once
// TLS for the web server's tests: a self-signed certificate for localhost made by Debian's
// openssl at test time (nothing secret is checked in), and an HTTPS client that verifies it.
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/read.hpp>
#include <boost/asio/ssl.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/ssl/ssl_stream.hpp>

namespace lamina::daemon::testing {

struct TestCertificate {
  std::filesystem::path cert, key;
};

// An EC P-256 certificate for localhost and 127.0.0.1, valid two days, in `dir`.
inline TestCertificate make_test_certificate(const std::filesystem::path& dir, const std::string& name = "console") {
  TestCertificate c{dir / (name + ".crt"), dir / (name + ".key")};
  const std::string command = "openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -days 2 "
                              "-subj /CN=localhost -addext subjectAltName=DNS:localhost,IP:127.0.0.1 -keyout '" +
                              c.key.string() + "' -out '" + c.cert.string() + "' 2>/dev/null";
  if (std::system(command.c_str()) != 0) throw std::runtime_error("openssl could not make a test certificate");
  return c;
}

// A client context that trusts only `cert` and checks the peer's name.
inline boost::asio::ssl::context client_context(const TestCertificate& trusted) {
  boost::asio::ssl::context context(boost::asio::ssl::context::tls_client);
  context.load_verify_file(trusted.cert.string());
  context.set_verify_mode(boost::asio::ssl::verify_peer);
  return context;
}

// One request over TLS, everything the server says until it closes (10 s at most). An error
// (no handshake, a certificate that does not verify) comes back as "TLS: <why>".
inline std::string https_exchange(int port, const std::string& request, boost::asio::ssl::context& context) {
  boost::asio::io_context io;
  boost::beast::ssl_stream<boost::beast::tcp_stream> stream(io, context);
  boost::beast::get_lowest_layer(stream).expires_after(std::chrono::seconds(10));
  boost::beast::get_lowest_layer(stream).connect(
      boost::asio::ip::tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  SSL_set_tlsext_host_name(stream.native_handle(), "localhost");
  stream.set_verify_callback(boost::asio::ssl::host_name_verification("localhost"));
  boost::system::error_code ec;
  stream.handshake(boost::asio::ssl::stream_base::client, ec);
  if (ec) return "TLS: " + ec.message();
  boost::asio::write(stream, boost::asio::buffer(request), ec);
  std::string out;
  char buf[16384];
  for (;;) {
    const std::size_t n = stream.read_some(boost::asio::buffer(buf), ec);
    out.append(buf, n);
    if (ec) break;  // the server's close (with or without a TLS close_notify)
  }
  return out;
}

}  // namespace lamina::daemon::testing
