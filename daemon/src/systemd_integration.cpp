#include "lamina/daemon/systemd_integration.hpp"

#include <systemd/sd-daemon.h>
#include <sys/socket.h>

#include <cstdint>
#include <cstdlib>

namespace lamina::daemon::systemd {
namespace {

// sd_notify is a newline-separated list of KEY=VALUE: a newline inside a status would end the
// STATUS line early and make the rest look like another (possibly meaningful) assignment.
std::string one_line(const std::string& text) {
  std::string out = text;
  for (char& c : out)
    if (c == '\n' || c == '\r') c = ' ';
  return out;
}

// sd_notify returns 0 both when NOTIFY_SOCKET is unset and, for an empty message, when nothing
// was sent; > 0 only when the datagram went out. Callers want "was it delivered".
bool send(const std::string& message) {
  if (std::getenv("NOTIFY_SOCKET") == nullptr) return false;
  return sd_notify(0, message.c_str()) > 0;
}

std::string with_status(std::string message, const std::string& status) {
  if (!status.empty()) message += "\nSTATUS=" + one_line(status);
  return message;
}

}  // namespace

bool notify_ready(const std::string& status) { return send(with_status("READY=1", status)); }

bool notify_status(const std::string& status) { return send("STATUS=" + one_line(status)); }

bool notify_stopping(const std::string& status) { return send(with_status("STOPPING=1", status)); }

bool notify_watchdog() { return send("WATCHDOG=1"); }

std::optional<std::chrono::microseconds> watchdog_period() {
  std::uint64_t usec = 0;
  // Keep the variables (unset_environment = 0): the period is asked for again after a reload,
  // and WATCHDOG_PID already keeps `lamina plan` children from taking it as theirs.
  if (sd_watchdog_enabled(0, &usec) <= 0 || usec == 0) return std::nullopt;
  return std::chrono::microseconds(usec);
}

std::vector<int> listen_fds() {
  // unset_environment = 1: the planner and other children must not think the fds are theirs.
  const int n = sd_listen_fds(1);
  std::vector<int> fds;
  for (int i = 0; i < n; ++i) fds.push_back(SD_LISTEN_FDS_START + i);
  return fds;
}

bool is_unix_stream_listener(int fd) { return sd_is_socket_unix(fd, SOCK_STREAM, 1, nullptr, 0) > 0; }

}  // namespace lamina::daemon::systemd
