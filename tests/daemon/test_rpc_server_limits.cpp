// What no client may do to the others (issue 16, item 8): a TCP stranger gets a few KiB per line
// and a deadline before its token; idle clients make room instead of locking new ones out; Unix
// and TCP clients have their own slots; a slow handler runs on the worker, and the operator's
// inline methods answer while it does.
#include "rpc_test_support.hpp"

#include <future>

namespace lamina::daemon::test {
namespace {

class RpcLimits : public ServerFixture {};

RpcServerSettings with_tcp(RpcServerSettings s) {
  s.tcp_host = "127.0.0.1";
  s.token = "s3cret-token";
  return s;
}

TEST_F(RpcLimits, AStrangersLineIsAFewKilobytes) {
  start(with_tcp(default_settings()));
  auto stranger = RawConn::tcp_loopback(server_->tcp_port());
  ASSERT_TRUE(stranger.send(std::string(8192, '[')));  // no token, no newline: 100 of these held the daemon 40 s
  const auto refusal = stranger.read_json();
  ASSERT_TRUE(refusal.has_value());
  EXPECT_EQ(refusal->at("error").at("code"), rpc_code::invalid_request);
  EXPECT_NE(refusal->at("error").at("message").get<std::string>().find("before a valid token"), std::string::npos)
      << *refusal;
  EXPECT_TRUE(stranger.wait_closed(3s));
  // With the token, the MiB limit applies.
  auto client = RpcClient::connect_tcp("127.0.0.1", server_->tcp_port(), "s3cret-token");
  ASSERT_TRUE(client.has_value());
  const auto echoed = client->call("echo", {{"pad", std::string(100000, 'x')}});
  ASSERT_TRUE(echoed.has_value()) << echoed.error().message;
  EXPECT_EQ(echoed->at("pad").get<std::string>().size(), 100000u);
}

TEST_F(RpcLimits, AStrangerWithoutATokenIsClosedAtItsDeadline) {
  auto settings = with_tcp(default_settings());
  settings.pre_auth_timeout_s = 0.3;
  start(settings);
  auto silent = RawConn::tcp_loopback(server_->tcp_port());
  ASSERT_TRUE(silent.connected());
  EXPECT_TRUE(silent.wait_closed(10s)) << "a peer that never shows its token does not keep its slot";
  auto client = RpcClient::connect_tcp("127.0.0.1", server_->tcp_port(), "s3cret-token");
  ASSERT_TRUE(client.has_value());
  ASSERT_TRUE(client->call("echo").has_value());
  std::this_thread::sleep_for(600ms);  // past the pre-auth deadline: an authenticated client stays
  EXPECT_TRUE(client->call("echo").has_value());
}

TEST_F(RpcLimits, AnIdleClientIsClosedButASubscriberStays) {
  auto settings = default_settings();
  settings.idle_timeout_s = 0.3;
  start(settings);
  auto subscriber = unix_client();
  ASSERT_TRUE(subscriber.call("server.subscribe").has_value());
  auto idle = RawConn::unix_socket(socket_path());
  ASSERT_TRUE(idle.send(request_line(1, "echo")));
  ASSERT_TRUE(idle.read_json().has_value());
  EXPECT_TRUE(idle.wait_closed(10s));
  server_->broadcast("tick", {{"n", 1}});
  EXPECT_TRUE(subscriber.next_notification(5).has_value()) << "the subscriber was not dropped";
}

// 128 idle connections used to lock every new client out until a restart.
TEST_F(RpcLimits, WhenFullTheLongestIdleMakesRoomButNeverASubscriber) {
  auto settings = default_settings();
  settings.max_clients = 2;
  start(settings);
  auto first = RawConn::unix_socket(socket_path());
  auto second = unix_client();
  ASSERT_TRUE(second.call("echo").has_value());
  ASSERT_TRUE(eventually([&] { return server_->client_count() == 2; }));
  std::this_thread::sleep_for(1100ms);  // both idle for longer than the 1 s that makes one evictable
  auto third = unix_client();
  const auto served = third.call("echo", {{"n", 3}});
  ASSERT_TRUE(served.has_value()) << served.error().message;
  EXPECT_TRUE(first.wait_closed(5s)) << "the first (longest idle) made room";
  EXPECT_TRUE(second.call("echo").has_value());

  // Subscribers are not dropped: with both slots subscribed, a new client is refused.
  ASSERT_TRUE(second.call("server.subscribe").has_value());
  ASSERT_TRUE(third.call("server.subscribe").has_value());
  std::this_thread::sleep_for(1100ms);
  auto fourth = RawConn::unix_socket(socket_path());
  const auto refusal = fourth.read_json(3s);
  ASSERT_TRUE(refusal.has_value());
  EXPECT_NE(refusal->at("error").at("message").get<std::string>().find("too many Unix clients"), std::string::npos);
}

TEST_F(RpcLimits, TcpClientsCannotTakeTheUnixSlots) {
  auto settings = with_tcp(default_settings());
  settings.max_clients = 2;
  start(settings);
  std::vector<RawConn> strangers;
  for (int i = 0; i < 4; ++i) strangers.push_back(RawConn::tcp_loopback(server_->tcp_port()));
  auto local = unix_client();
  const auto who = local.call("whoami");
  ASSERT_TRUE(who.has_value()) << who.error().message;
  EXPECT_EQ(who->at("tcp"), false);
}

// A handler that blocks (a file copied, a thread joined) holds only the worker: an inline method
// is answered meanwhile, from any client, even ahead of the blocked client's own queue.
TEST_F(RpcLimits, InlineMethodsAnswerWhileTheWorkerIsBusy) {
  auto settings = default_settings();
  settings.inline_methods = {"hold"};
  start(settings);
  auto slow = RawConn::unix_socket(socket_path());
  ASSERT_TRUE(slow.send(request_line(1, "block") + request_line(2, "echo", {{"after", "block"}}) + request_line(3, "hold")));
  ASSERT_TRUE(eventually([&] { return blocked_ == 1; }));
  const auto first_reply = slow.read_json();  // the hold, ahead of the two queued before it
  ASSERT_TRUE(first_reply.has_value());
  EXPECT_EQ(first_reply->at("id"), 3);
  EXPECT_EQ(first_reply->at("result"), "held");
  auto other = unix_client();
  const auto held = other.call("hold");
  ASSERT_TRUE(held.has_value()) << "answered while the worker is blocked: " << held.error().message;
  EXPECT_EQ(blocked_, 1) << "the worker is still in block";
  release_ = true;
  const auto second_reply = slow.read_json(), third_reply = slow.read_json();
  ASSERT_TRUE(second_reply && third_reply);
  EXPECT_EQ(second_reply->at("id"), 1) << "the worker's replies keep their order";
  EXPECT_EQ(third_reply->at("id"), 2);
}

TEST_F(RpcLimits, AMegabyteOfBracketsIsRefusedWithoutBuildingIt) {
  start();
  auto raw = RawConn::unix_socket(socket_path());
  ASSERT_TRUE(raw.send(std::string((1 << 20) - 16, '[') + "\n"));
  const auto reply = raw.read_json(10s);
  ASSERT_TRUE(reply.has_value());
  EXPECT_NE(reply->at("error").at("message").get<std::string>().find("nested deeper"), std::string::npos) << *reply;
  auto other = unix_client();
  EXPECT_TRUE(other.call("echo").has_value());
}

}  // namespace
}  // namespace lamina::daemon::test
