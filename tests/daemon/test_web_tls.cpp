// The web console over HTTPS ([http] tls_cert and tls_key): the login, its cookie and the
// WebSocket (wss://) through OpenSSL as a browser would use them, against a certificate made at
// test time; what a plain-HTTP client or a broken certificate gets.
#include <gtest/gtest.h>

#include "rpc_test_support.hpp"
#include "tls_test_support.hpp"
#include "web_test_console.hpp"
#include "ws_test_client.hpp"

namespace lamina::daemon::http {
namespace {

using testing::body_of;
using testing::status_of;
using testing_console::Console;

class WebTls : public ::testing::Test {
 protected:
  test::TempDir dir_;
  testing::TestCertificate cert_ = testing::make_test_certificate(dir_.path());
  boost::asio::ssl::context client_ = testing::client_context(cert_);

  std::string login(const Console& console, const std::string& origin) {
    const std::string body = R"({"user":"ana","password":"ana's password"})";
    return testing::https_exchange(console.port(),
                                   "POST /api/login HTTP/1.1\r\nHost: localhost:" + std::to_string(console.port()) + "\r\nOrigin: " + origin +
                                       "\r\nContent-Type: application/json\r\nContent-Length: " +
                                       std::to_string(body.size()) + "\r\nConnection: close\r\n\r\n" + body,
                                   client_);
  }
};

TEST_F(WebTls, TheLoginGetsASecureCookieAndTheWebSocketIsWss) {
  Console console(1 << 20, cert_.cert, cert_.key);
  const std::string https = "https://localhost:" + std::to_string(console.port());
  const std::string r = login(console, https);
  ASSERT_EQ(status_of(r), 200) << r;
  EXPECT_NE(r.find("; Secure"), std::string::npos) << "a session cookie over HTTPS must never go out over HTTP: " << r;
  const std::string cookie = testing::session_cookie(r);

  testing::WssClient ws(console.port(), cookie, https, client_);
  ASSERT_TRUE(ws.open()) << ws.status() << " " << ws.refusal();
  const auto reply = ws.call("server.info");
  EXPECT_EQ(reply["result"]["user"], "ana") << reply.dump();
  EXPECT_EQ(reply["result"]["via"], "WebSocket");

  // The console's own origin is https:// now: a page served over http:// is another site.
  testing::WssClient plain_page(console.port(), cookie, "http://localhost:" + std::to_string(console.port()), client_);
  EXPECT_FALSE(plain_page.open());
  EXPECT_EQ(plain_page.status(), 403U) << plain_page.refusal();
}

TEST_F(WebTls, PlainHttpToTheTlsPortGetsNoAnswerAndTheConsoleKeepsServing) {
  Console console(1 << 20, cert_.cert, cert_.key);
  const std::string plain = testing::http_get(console.port(), "/api/session");
  EXPECT_FALSE(plain.starts_with("HTTP/")) << "a plain answer would carry the console in clear text: " << plain;
  const std::string r = testing::https_exchange(
      console.port(), "GET /api/session HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n", client_);
  EXPECT_EQ(status_of(r), 401) << r;  // through TLS, and users are configured: no session yet
  // The refused connection is let go, not left holding one of the console's slots.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (console.web->connection_count() != 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(console.web->connection_count(), 0U);
}

TEST_F(WebTls, AClientThatDoesNotTrustTheCertificateGetsNothing) {
  Console console(1 << 20, cert_.cert, cert_.key);
  const auto other = testing::make_test_certificate(dir_.path(), "other");
  auto stranger = testing::client_context(other);
  const std::string r = testing::https_exchange(
      console.port(), "GET /api/session HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n", stranger);
  EXPECT_TRUE(r.starts_with("TLS: ")) << r;
}

TEST_F(WebTls, AMissingCertificateOrAKeyThatIsNotItsIsAnErrorNamingTheFile) {
  const auto other = testing::make_test_certificate(dir_.path(), "other");
  const auto missing = dir_.path() / "missing.crt";
  try {
    Console console(1 << 20, missing, cert_.key);
    ADD_FAILURE() << "listened without its certificate";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("[http] tls_cert " + missing.string()), std::string::npos) << e.what();
  }
  try {
    Console console(1 << 20, cert_.cert, other.key);
    ADD_FAILURE() << "listened with another certificate's key";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("is not the key of the certificate in " + cert_.cert.string()), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace lamina::daemon::http
