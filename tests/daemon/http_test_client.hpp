#pragma once
// A bare HTTP/1.1 client for the web server's tests: requests go out byte for byte as written
// (a browser or curl would normalise a "../" away before sending it), answers are read to the
// server's close. Every read is bounded (10 s) so a hung server fails a test instead of hanging it.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <stdexcept>
#include <string>

namespace lamina::daemon::testing {

inline int connect_loopback(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  timeval tv{10, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    throw std::runtime_error("nobody listens on 127.0.0.1:" + std::to_string(port));
  }
  return fd;
}

// Everything the server says until it closes (or the 10 s read timeout).
inline std::string read_until_close(int fd) {
  std::string out;
  char buf[65536];
  for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) > 0;) out.append(buf, static_cast<std::size_t>(n));
  return out;
}

inline std::string http_exchange(int port, const std::string& request) {
  const int fd = connect_loopback(port);
  (void)::write(fd, request.data(), request.size());
  std::string out = read_until_close(fd);
  ::close(fd);
  return out;
}

inline std::string http_get(int port, const std::string& target) {
  return http_exchange(port, "GET " + target + " HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n");
}

inline int status_of(const std::string& response) {
  return response.size() > 12 && response.starts_with("HTTP/1.1 ") ? std::stoi(response.substr(9, 3)) : -1;
}

inline std::string body_of(const std::string& response) {
  const auto at = response.find("\r\n\r\n");
  return at == std::string::npos ? "" : response.substr(at + 4);
}

inline std::string http_post(int port, const std::string& target, const std::string& body, const std::string& extra = "") {
  return http_exchange(port, "POST " + target + " HTTP/1.1\r\nHost: localhost:" + std::to_string(port) +
                                 "\r\nContent-Type: application/json\r\nContent-Length: " + std::to_string(body.size()) +
                                 "\r\n" + extra + "Connection: close\r\n\r\n" + body);
}

// "lamina_session=…" from a login's Set-Cookie header (empty when there is none).
inline std::string session_cookie(const std::string& response) {
  const auto at = response.find("Set-Cookie: ");
  if (at == std::string::npos) return {};
  const auto end = response.find(';', at);
  return response.substr(at + 12, end - at - 12);
}

// Logs in; the cookie, or empty when refused. (The password is plain text: no JSON escaping.)
inline std::string http_login(int port, const std::string& user, const std::string& password) {
  return session_cookie(
      http_post(port, "/api/login", "{\"user\": \"" + user + "\", \"password\": \"" + password + "\"}"));
}

// A port nobody listens on right now (the kernel's pick, released again).
inline int free_loopback_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(fd);
  return ntohs(a.sin_port);
}

}  // namespace lamina::daemon::testing
