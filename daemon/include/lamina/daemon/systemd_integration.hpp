#pragma once
// systemd without systemd required: sd_notify messages (READY, STATUS, WATCHDOG, STOPPING) go
// to $NOTIFY_SOCKET when set (nothing happens otherwise), and listening sockets come from
// socket activation (sd_listen_fds) when the unit has a .socket. libsystemd stays inside the .cpp.
#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace lamina::daemon::systemd {

bool notify_ready(const std::string& status = {});
bool notify_status(const std::string& status);
bool notify_stopping(const std::string& status = {});
bool notify_watchdog();
// The watchdog period the service manager expects pings within (WATCHDOG_USEC), if enabled.
std::optional<std::chrono::microseconds> watchdog_period();
// File descriptors passed by socket activation (SD_LISTEN_FDS_START…), for this process only;
// the environment variables are unset afterwards.
std::vector<int> listen_fds();
// Whether fd is a listening Unix stream socket (what laminad.socket passes).
bool is_unix_stream_listener(int fd);

}  // namespace lamina::daemon::systemd
