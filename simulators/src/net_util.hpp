#pragma once
// Loopback TCP helpers shared by the CNC's TCP port and the control socket.
#include <string>
#include <utility>

namespace lamina::sim {

// "127.0.0.1:PORT" → host, port. Throws std::runtime_error naming the text when malformed
// or when the host is not a loopback address (the simulator never listens outside).
std::pair<std::string, int> parse_loopback_address(const std::string& text, const char* what);
// Non-blocking, close-on-exec listening socket; port 0 picks one. Throws on failure.
int listen_loopback(const std::string& host, int port);
int bound_port(int fd);
// Accept one pending connection, non-blocking and close-on-exec; -1 if none.
int accept_nonblocking(int listen_fd);

}  // namespace lamina::sim
