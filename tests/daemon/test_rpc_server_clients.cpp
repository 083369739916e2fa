// The JSON-RPC server with many clients: one that never reads, fifty at once, broadcasts to the
// subscribed ones, max_clients; and RpcClient's own behaviour (queued notifications, timeouts).
#include <algorithm>
#include <vector>

#include "rpc_test_support.hpp"

namespace lamina::daemon::test {
namespace {

using RpcClients = ServerFixture;

TEST_F(RpcClients, AClientThatNeverReadsIsDroppedWithoutDelayingOthers) {
  auto settings = default_settings();
  settings.max_queued_bytes = 256 * 1024;
  start(settings);
  auto reader = unix_client();
  ASSERT_TRUE(reader.call("echo").has_value());

  // 400 pipelined requests for 64 KiB each (25 MiB of replies), and never a read.
  auto hog = RawConn::unix_socket(socket_path());
  std::string requests;
  for (int i = 0; i < 400; ++i) requests += request_line(i, "big", {{"bytes", 64 * 1024}});
  ASSERT_TRUE(hog.send(requests));

  std::vector<double> latencies_ms;
  for (int i = 0; i < 200; ++i) {
    const auto begin = std::chrono::steady_clock::now();
    const auto reply = reader.call("add", {{"a", i}, {"b", 1}}, 5);
    latencies_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - begin).count());
    ASSERT_TRUE(reply.has_value()) << reply.error().message;
    ASSERT_EQ(*reply, i + 1);
  }
  std::sort(latencies_ms.begin(), latencies_ms.end());
  const double p99 = latencies_ms[latencies_ms.size() * 99 / 100];
  EXPECT_LT(p99, 200.0) << "the reader waited on the hog";

  EXPECT_TRUE(eventually([&] { return server_->client_count() == 1; })) << "the hog was not dropped";
  std::size_t received = 0;
  ASSERT_TRUE(hog.wait_closed(5s, &received));
  // What reached the hog is what the socket buffers held plus at most the queue limit.
  EXPECT_LT(received, std::size_t{400} * 64 * 1024 / 4);
}

TEST_F(RpcClients, FiftyClientsAtOnceAreAllAnswered) {
  start();
  constexpr int clients = 50;
  constexpr int calls = 20;
  std::atomic<int> correct{0};
  std::vector<std::string> failures(clients);
  std::vector<std::thread> threads;
  for (int c = 0; c < clients; ++c) {
    threads.emplace_back([&, c] {
      auto client = RpcClient::connect_unix(socket_path());
      if (!client) {
        failures[c] = client.error();
        return;
      }
      for (int i = 0; i < calls; ++i) {
        const auto reply = client->call("add", {{"a", c * 1000}, {"b", i}});
        if (reply && *reply == c * 1000 + i) {
          ++correct;
        } else {
          failures[c] = reply ? reply->dump() : reply.error().message;
        }
      }
    });
  }
  for (auto& thread : threads) thread.join();
  EXPECT_EQ(correct, clients * calls);
  for (int c = 0; c < clients; ++c) EXPECT_TRUE(failures[c].empty()) << "client " << c << ": " << failures[c];
}

TEST_F(RpcClients, BroadcastsReachOnlySubscribedClients) {
  start();
  auto first = unix_client();
  auto unsubscribed = unix_client();
  auto second = unix_client();
  ASSERT_TRUE(first.call("server.subscribe").has_value());
  ASSERT_TRUE(second.call("server.subscribe").has_value());
  ASSERT_TRUE(unsubscribed.call("echo").has_value());

  server_->broadcast("job.changed", {{"job", 42}, {"state", "cutting"}});
  const json expected{{"jsonrpc", "2.0"}, {"method", "job.changed"}, {"params", {{"job", 42}, {"state", "cutting"}}}};
  for (auto* client : {&first, &second}) {
    const auto note = client->next_notification(3);
    ASSERT_TRUE(note.has_value());
    EXPECT_EQ(*note, expected);
  }
  EXPECT_FALSE(unsubscribed.next_notification(0.3).has_value());

  // A notification that arrives while call() waits is kept for next_notification().
  server_->broadcast("job.changed", {{"job", 43}});
  std::this_thread::sleep_for(100ms);  // let it reach the socket before the call's reply
  const auto reply = first.call("add", {{"a", 1}, {"b", 1}});
  ASSERT_TRUE(reply.has_value());
  EXPECT_EQ(*reply, 2);
  const auto queued = first.next_notification(0);
  ASSERT_TRUE(queued.has_value());
  EXPECT_EQ(queued->at("params").at("job"), 43);
}

TEST_F(RpcClients, BroadcastFromAnotherThreadWhileClientsCall) {
  start();
  auto subscriber = unix_client();
  ASSERT_TRUE(subscriber.call("server.subscribe").has_value());
  std::thread broadcaster([&] {
    for (int i = 0; i < 100; ++i) server_->broadcast("tick", {{"n", i}});
  });
  for (int i = 0; i < 50; ++i) ASSERT_TRUE(subscriber.call("echo").has_value());
  broadcaster.join();
  for (int i = 0; i < 100; ++i) {
    const auto note = subscriber.next_notification(3);
    ASSERT_TRUE(note.has_value()) << "notification " << i;
    EXPECT_EQ(note->at("params").at("n"), i);  // in the order they were broadcast
  }
}

TEST_F(RpcClients, ClientsPastMaxClientsAreTurnedAway) {
  auto settings = default_settings();
  settings.max_clients = 2;
  start(settings);
  auto first = unix_client();
  auto second = unix_client();
  ASSERT_TRUE(first.call("echo").has_value());
  ASSERT_TRUE(second.call("echo").has_value());

  auto third = RawConn::unix_socket(socket_path());
  const auto refusal = third.read_json(3s);
  ASSERT_TRUE(refusal.has_value());
  EXPECT_EQ(refusal->at("error").at("message"), "too many Unix clients (limit 2, none idle)");
  EXPECT_TRUE(third.wait_closed(3s));
  EXPECT_EQ(server_->client_count(), 2U);

  first.close();
  ASSERT_TRUE(eventually([&] { return server_->client_count() == 1; }));
  auto fourth = unix_client();
  EXPECT_TRUE(fourth.call("echo").has_value());
}

TEST_F(RpcClients, RpcClientTimesOutAndReportsTransportErrors) {
  // A "server" that accepts (the kernel does, into the backlog) and never answers.
  const std::string path = (dir_.path() / "silent.sock").string();
  const int listener = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::strncpy(address.sun_path, path.c_str(), sizeof address.sun_path - 1);
  ASSERT_EQ(::bind(listener, reinterpret_cast<const sockaddr*>(&address), sizeof address), 0);
  ASSERT_EQ(::listen(listener, 4), 0);
  auto client = RpcClient::connect_unix(path);
  ASSERT_TRUE(client.has_value()) << client.error();
  const auto begin = std::chrono::steady_clock::now();
  const auto reply = client->call("echo", json::object(), 0.2);
  const auto waited = std::chrono::steady_clock::now() - begin;
  ASSERT_FALSE(reply.has_value());
  EXPECT_EQ(reply.error().code, rpc_code::transport_error);
  EXPECT_GE(waited, 190ms);
  EXPECT_LT(waited, 2s);
  ::close(listener);

  const auto missing = RpcClient::connect_unix((dir_.path() / "absent.sock").string());
  ASSERT_FALSE(missing.has_value());
  EXPECT_NE(missing.error().find("absent.sock"), std::string::npos) << missing.error();
  EXPECT_FALSE(RpcClient::connect_tcp("127.0.0.1", 1, "").has_value());  // a token is required
}

TEST_F(RpcClients, RpcClientIdsIncreaseAndItMoves) {
  start();
  auto client = unix_client();
  ASSERT_TRUE(client.call("echo").has_value());
  RpcClient moved = std::move(client);
  EXPECT_FALSE(client.is_open());  // NOLINT(bugprone-use-after-move): the moved-from state is the point
  EXPECT_EQ(client.call("echo").error().code, rpc_code::transport_error);
  ASSERT_TRUE(moved.call("echo").has_value());

  // What RpcClient puts on the wire, as a server sees it: ids 1, 2, 3…
  const std::string path = (dir_.path() / "spy.sock").string();
  const int listener = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::strncpy(address.sun_path, path.c_str(), sizeof address.sun_path - 1);
  ASSERT_EQ(::bind(listener, reinterpret_cast<const sockaddr*>(&address), sizeof address), 0);
  ASSERT_EQ(::listen(listener, 4), 0);
  auto spied = RpcClient::connect_unix(path);
  ASSERT_TRUE(spied.has_value());
  const int server_side = ::accept(listener, nullptr, nullptr);
  ASSERT_GE(server_side, 0);
  std::thread answer([&] {
    std::string buffer;
    char chunk[4096];
    int answered = 0;
    while (answered < 3) {
      const ssize_t n = ::recv(server_side, chunk, sizeof chunk, 0);
      if (n <= 0) return;
      buffer.append(chunk, static_cast<std::size_t>(n));
      for (auto nl = buffer.find('\n'); nl != std::string::npos; nl = buffer.find('\n')) {
        const json request = json::parse(buffer.substr(0, nl));
        buffer.erase(0, nl + 1);
        const std::string reply = json{{"jsonrpc", "2.0"}, {"id", request["id"]}, {"result", request}}.dump() + "\n";
        ::send(server_side, reply.data(), reply.size(), MSG_NOSIGNAL);
        ++answered;
      }
    }
  });
  for (int expected_id = 1; expected_id <= 3; ++expected_id) {
    const auto seen = spied->call("probe", {{"k", expected_id}});
    ASSERT_TRUE(seen.has_value());
    EXPECT_EQ(seen->at("id"), expected_id);
    EXPECT_EQ(seen->at("jsonrpc"), "2.0");
    EXPECT_EQ(seen->at("method"), "probe");
    EXPECT_EQ(seen->at("params"), (json{{"k", expected_id}}));
  }
  answer.join();
  ::close(server_side);
  ::close(listener);
}

}  // namespace
}  // namespace lamina::daemon::test
