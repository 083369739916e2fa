// The operator's hold under the client attacks of issue 16, item 8: while STRANGERS TCP peers
// without a token each send a MiB of '[' (and reconnect when hung up on) and IDLE Unix
// connections sit open, an operator connects on the Unix socket and calls machine.hold then
// machine.resume, HOLDS times; prints the hold's latency percentiles (ms) as JSON. Used by
// bench/hold_under_attack.sh while a job cuts on lamina-sim.
// Usage: daemon_attack SOCKET TCP_PORT [HOLDS=100] [STRANGERS=100] [IDLE=128]
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "lamina/daemon/rpc_client.hpp"

namespace {

using Clock = std::chrono::steady_clock;

int connect_tcp(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

int connect_unix(const std::string& path) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_un a{};
  a.sun_family = AF_UNIX;
  std::snprintf(a.sun_path, sizeof a.sun_path, "%s", path.c_str());
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// A MiB of '[', half-close, read until hung up; again, until told to stop.
void stranger(int port, const std::atomic<bool>& stop) {
  const std::string brackets(1 << 20, '[');
  char sink[65536];
  while (!stop) {
    const int fd = connect_tcp(port);
    if (fd < 0) continue;
    for (std::size_t sent = 0; sent < brackets.size();) {
      const ssize_t n = ::send(fd, brackets.data() + sent, brackets.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) break;
      sent += static_cast<std::size_t>(n);
    }
    ::shutdown(fd, SHUT_WR);
    while (::recv(fd, sink, sizeof sink, 0) > 0) {
    }
    ::close(fd);
  }
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: daemon_attack SOCKET TCP_PORT [HOLDS] [STRANGERS] [IDLE]\n");
    return 2;
  }
  const std::string socket = argv[1];
  const int port = std::stoi(argv[2]);
  const int holds = argc > 3 ? std::stoi(argv[3]) : 100;
  const int strangers = argc > 4 ? std::stoi(argv[4]) : 100;
  const int idle = argc > 5 ? std::stoi(argv[5]) : 128;
  std::atomic<bool> stop{false};
  std::vector<int> idle_fds;
  for (int i = 0; i < idle; ++i) idle_fds.push_back(connect_unix(socket));
  std::vector<std::thread> attack;
  for (int i = 0; i < strangers; ++i) attack.emplace_back(stranger, port, std::cref(stop));
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // the attack is on; the idle are idle

  std::vector<double> hold_ms;
  int errors = 0;
  auto op = lamina::daemon::RpcClient::connect_unix(socket);
  for (int k = 0; op && k < holds; ++k) {
    const auto t0 = Clock::now();
    auto held = op->call("machine.hold", nlohmann::json::object(), 30);
    hold_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    if (!held) ++errors;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the machine stops
    if (!op->call("machine.resume", nlohmann::json::object(), 30)) ++errors;
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the jet restarts, motion goes on
  }
  stop = true;
  for (auto& t : attack) t.join();
  for (int fd : idle_fds)
    if (fd >= 0) ::close(fd);
  fmt::print("{{\"holds\": {}, \"errors\": {}, \"connected\": {}, \"p50_ms\": {:.2f}, \"p99_ms\": {:.2f}, \"max_ms\": {:.2f}}}\n",
             hold_ms.size(), errors, op.has_value(), percentile(hold_ms, 0.5), percentile(hold_ms, 0.99),
             hold_ms.empty() ? 0.0 : *std::max_element(hold_ms.begin(), hold_ms.end()));
  return errors == 0 && op ? 0 : 1;
}
