// RPC latency of laminad under load: N clients, each calling job.list and machine.status in turn
// as fast as answers come, for a while; prints p50/p99/max latency in ms and the call count as
// JSON. Used by bench/daemon_latency.sh while a job streams to lamina-sim.
// Usage: daemon_rpc_load SOCKET [CLIENTS=50] [SECONDS=10]
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "lamina/daemon/rpc_client.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: daemon_rpc_load SOCKET [CLIENTS] [SECONDS]\n");
    return 2;
  }
  const std::string socket = argv[1];
  const int clients = argc > 2 ? std::stoi(argv[2]) : 50;
  const double seconds = argc > 3 ? std::stod(argv[3]) : 10;
  using Clock = std::chrono::steady_clock;
  std::mutex mutex;
  std::vector<double> latencies_ms;
  std::atomic<int> errors{0};
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  std::vector<std::thread> threads;
  for (int i = 0; i < clients; ++i)
    threads.emplace_back([&, i] {
      auto c = lamina::daemon::RpcClient::connect_unix(socket);
      if (!c) {
        ++errors;
        return;
      }
      std::vector<double> mine;
      for (int k = i; Clock::now() < end; ++k) {
        const auto t0 = Clock::now();
        auto r = c->call(k % 2 ? "job.list" : "machine.status", nlohmann::json::object(), 10);
        mine.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
        if (!r) ++errors;
      }
      std::lock_guard lock(mutex);
      latencies_ms.insert(latencies_ms.end(), mine.begin(), mine.end());
    });
  for (auto& t : threads) t.join();
  std::sort(latencies_ms.begin(), latencies_ms.end());
  auto pct = [&](double p) {
    return latencies_ms.empty() ? 0.0 : latencies_ms[std::min(latencies_ms.size() - 1, static_cast<std::size_t>(p * latencies_ms.size()))];
  };
  fmt::print("{{\"clients\": {}, \"calls\": {}, \"errors\": {}, \"p50_ms\": {:.2f}, \"p99_ms\": {:.2f}, \"max_ms\": {:.2f}}}\n",
             clients, latencies_ms.size(), errors.load(), pct(0.5), pct(0.99), latencies_ms.empty() ? 0.0 : latencies_ms.back());
  return errors.load() == 0 ? 0 : 1;
}
