// The JSON-RPC server's sockets and lifetime: the socket file's mode, group, stale and live
// files at the path, systemd's listener, stop() and the destructor.
#include <fcntl.h>
#include <grp.h>
#include <sys/stat.h>

#include <fstream>
#include <future>

#include <boost/asio/post.hpp>

#include "rpc_test_support.hpp"
#include "rpc_transport.hpp"

namespace lamina::daemon::test {
namespace {

using RpcLifecycle = ServerFixture;

// A listening Unix socket at path, made as systemd's laminad.socket would.
int unix_listener(const std::string& path) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::strncpy(address.sun_path, path.c_str(), sizeof address.sun_path - 1);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0 || ::listen(fd, 16) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

TEST_F(RpcLifecycle, TheSocketFileHasTheConfiguredMode) {
  ::umask(022);  // the default would give 0755: the mode must come from the settings
  start();
  struct stat info {};
  ASSERT_EQ(::lstat(socket_path().c_str(), &info), 0);
  EXPECT_TRUE(S_ISSOCK(info.st_mode));
  EXPECT_EQ(info.st_mode & 07777, 0660U);
}

TEST_F(RpcLifecycle, ACustomModeAndAnExistingGroupAreApplied) {
  auto settings = default_settings();
  settings.unix_mode = 0600;
  // The process's own group: a socket's owner may always chgrp to it, root or not.
  const group* own = ::getgrgid(::getegid());
  ASSERT_NE(own, nullptr);
  settings.unix_group = own->gr_name;
  start(settings);
  struct stat info {};
  ASSERT_EQ(::lstat(socket_path().c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 07777, 0600U);
  EXPECT_EQ(info.st_gid, ::getegid());
}

TEST_F(RpcLifecycle, AMissingGroupIsAnErrorThatNamesIt) {
  auto settings = default_settings();
  settings.unix_group = "no-such-lamina-group";
  RpcServer server(io_, settings, [](const RpcRequest&, ClientContext&) -> RpcResult { return nullptr; });
  const auto listening = server.listen();
  ASSERT_FALSE(listening.has_value());
  EXPECT_NE(listening.error().find("no-such-lamina-group"), std::string::npos) << listening.error();
  EXPECT_FALSE(std::filesystem::exists(socket_path()));  // no half-made socket left behind
}

TEST_F(RpcLifecycle, StopRemovesTheSocketFileAndDisconnectsClients) {
  start();
  auto client = unix_client();
  ASSERT_TRUE(client.call("echo").has_value());
  ASSERT_TRUE(std::filesystem::exists(socket_path()));
  server_->stop();
  EXPECT_FALSE(std::filesystem::exists(socket_path()));
  EXPECT_EQ(server_->client_count(), 0U);
  const auto after = client.call("echo", json::object(), 3);
  ASSERT_FALSE(after.has_value());
  EXPECT_EQ(after.error().code, rpc_code::transport_error);
  EXPECT_FALSE(RpcClient::connect_unix(socket_path()).has_value());
  server_->stop();  // twice is harmless
}

TEST_F(RpcLifecycle, AStaleSocketFileIsReplaced) {
  // A socket file whose server died without removing it.
  const int dead = unix_listener(socket_path());
  ASSERT_GE(dead, 0);
  ::close(dead);
  ASSERT_TRUE(std::filesystem::exists(socket_path()));
  start();
  auto client = unix_client();
  const auto reply = client.call("add", {{"a", 1}, {"b", 2}});
  ASSERT_TRUE(reply.has_value()) << reply.error().message;
  EXPECT_EQ(*reply, 3);
}

TEST_F(RpcLifecycle, ALiveSocketOrAnotherFileAtThePathIsLeftAlone) {
  const int live = unix_listener(socket_path());
  ASSERT_GE(live, 0);
  auto handler = [](const RpcRequest&, ClientContext&) -> RpcResult { return nullptr; };
  {
    RpcServer second(io_, default_settings(), handler);
    const auto listening = second.listen();
    ASSERT_FALSE(listening.has_value());
    EXPECT_NE(listening.error().find(socket_path()), std::string::npos) << listening.error();
  }
  EXPECT_TRUE(std::filesystem::exists(socket_path()));  // not the second server's to remove
  ::close(live);
  std::filesystem::remove(socket_path());

  std::ofstream(socket_path()) << "not a socket";
  RpcServer third(io_, default_settings(), handler);
  const auto listening = third.listen();
  ASSERT_FALSE(listening.has_value());
  EXPECT_NE(listening.error().find("not a socket"), std::string::npos) << listening.error();
  EXPECT_TRUE(std::filesystem::is_regular_file(socket_path()));
}

TEST_F(RpcLifecycle, ASystemdListenerIsAdopted) {
  const std::string path = (dir_.path() / "activated.sock").string();
  const int fd = unix_listener(path);
  ASSERT_GE(fd, 0);
  RpcServerSettings settings;  // no unix_path: the socket comes from systemd
  server_ = std::make_unique<RpcServer>(io_, settings, [this](const RpcRequest& r, ClientContext& c) {
    return handle(r, c);
  });
  const int not_a_socket = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  EXPECT_FALSE(server_->adopt_unix_listener(not_a_socket).has_value());
  ::close(not_a_socket);
  const auto adopted = server_->adopt_unix_listener(fd);
  ASSERT_TRUE(adopted.has_value()) << adopted.error();
  ASSERT_TRUE(server_->listen().has_value());  // nothing more to open, and not an error
  thread_ = std::thread([this] { io_.run(); });

  auto client = RpcClient::connect_unix(path);
  ASSERT_TRUE(client.has_value()) << client.error();
  const auto reply = client->call("add", {{"a", 2}, {"b", 2}});
  ASSERT_TRUE(reply.has_value());
  EXPECT_EQ(*reply, 4);
  server_->stop();
  EXPECT_TRUE(std::filesystem::exists(path));  // systemd's file: not removed by the daemon
}

TEST_F(RpcLifecycle, NothingToListenOnOrTcpWithoutATokenIsAnError) {
  auto handler = [](const RpcRequest&, ClientContext&) -> RpcResult { return nullptr; };
  RpcServer nothing(io_, RpcServerSettings{}, handler);
  EXPECT_FALSE(nothing.listen().has_value());

  auto settings = default_settings();
  settings.tcp_host = "127.0.0.1";
  RpcServer tokenless(io_, settings, handler);
  const auto listening = tokenless.listen();
  ASSERT_FALSE(listening.has_value());
  EXPECT_NE(listening.error().find("token"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(socket_path()));
}

TEST_F(RpcLifecycle, TheDestructorClosesEverythingWhileTheIoThreadRuns) {
  auto settings = default_settings();
  settings.tcp_host = "127.0.0.1";
  settings.token = "t";
  start(settings);
  auto client = unix_client();
  auto tcp = RpcClient::connect_tcp("127.0.0.1", server_->tcp_port(), "t");
  ASSERT_TRUE(tcp.has_value());
  ASSERT_TRUE(client.call("server.subscribe").has_value());
  ASSERT_TRUE(tcp->call("echo").has_value());
  auto idle = RawConn::unix_socket(socket_path());
  ASSERT_TRUE(idle.send(R"({"jsonrpc":"2.0","id":1,"method":"ec)"));  // half a request pending

  server_.reset();
  EXPECT_FALSE(std::filesystem::exists(socket_path()));
  EXPECT_TRUE(idle.wait_closed(3s));
  EXPECT_FALSE(client.call("echo", json::object(), 3).has_value());
  EXPECT_FALSE(tcp->call("echo", json::object(), 3).has_value());
}

TEST_F(RpcLifecycle, TheDestructorWorksWhenTheIoContextNeverRanOrHasStopped) {
  {
    RpcServer never_run(io_, default_settings(), [](const RpcRequest&, ClientContext&) -> RpcResult { return 1; });
    ASSERT_TRUE(never_run.listen().has_value());
    auto connected = RawConn::unix_socket(socket_path());  // in the backlog, never accepted
    EXPECT_TRUE(connected.connected());
    never_run.broadcast("x", json::object());  // queued in an io_context nobody runs
  }
  EXPECT_FALSE(std::filesystem::exists(socket_path()));

  start();
  auto client = unix_client();
  ASSERT_TRUE(client.call("echo").has_value());
  guard_.reset();
  io_.stop();
  thread_.join();
  server_.reset();  // io_context stopped with the connection's read still pending
  EXPECT_FALSE(std::filesystem::exists(socket_path()));
  EXPECT_FALSE(client.call("echo", json::object(), 3).has_value());
}

// A client that sends one line, then waits; it tells when it is destroyed and when it is closed.
class OneLineTransport final : public RpcTransport {
 public:
  OneLineTransport(boost::asio::io_context& io, std::string line, std::atomic<bool>& destroyed,
                   std::function<void()> on_close = {})
      : io_(io), line_(std::move(line)), destroyed_(destroyed), on_close_(std::move(on_close)) {}
  ~OneLineTransport() override { destroyed_ = true; }
  boost::asio::any_io_executor executor() override { return io_.get_executor(); }
  void async_read(ReadHandler handler) override {
    ++reads;
    if (line_.empty()) {
      waiting_ = std::move(handler);
      return;
    }
    boost::asio::post(io_, [handler = std::move(handler), line = std::exchange(line_, {})] { handler({}, line); });
  }
  void async_write(std::span<const Line>, WriteHandler handler) override {
    boost::asio::post(io_, [handler = std::move(handler)] { handler({}); });
  }
  void shutdown_send() override {}
  void close() override {
    if (waiting_)
      boost::asio::post(io_, [handler = std::exchange(waiting_, {})] { handler(boost::asio::error::operation_aborted, {}); });
    if (auto callback = std::exchange(on_close_, {})) callback();
  }
  std::atomic<int> reads{0};

 private:
  boost::asio::io_context& io_;
  std::string line_;
  std::atomic<bool>& destroyed_;
  std::function<void()> on_close_;
  ReadHandler waiting_;
};

// One client's request runs on the worker while another's waits behind it when the server goes.
// The waiting one must never run (its client is gone, the server stopped) and its client must be
// released: a request left in the worker's queue held its connection, which held the queue.
TEST_F(RpcLifecycle, ARequestStillWaitingWhenTheServerGoesNeverRunsAndItsClientIsReleased) {
  std::atomic<bool> slow_gone{false};
  std::atomic<bool> waiting_gone{false};
  std::atomic<bool> slow_started{false};
  std::atomic<int> late_calls{0};
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  {
    boost::asio::io_context io;
    auto guard = boost::asio::make_work_guard(io);
    std::thread io_thread([&io] { io.run(); });
    auto server = std::make_unique<RpcServer>(io, RpcServerSettings{}, [&](const RpcRequest& request, ClientContext&) -> RpcResult {
      if (request.method == "slow") {
        slow_started = true;
        released.wait();
      } else {
        ++late_calls;
      }
      return nullptr;
    });
    auto slow = std::make_unique<OneLineTransport>(io, R"({"jsonrpc":"2.0","id":1,"method":"slow"})" "\n", slow_gone,
                                                   [&release] { release.set_value(); });
    auto waiting = std::make_unique<OneLineTransport>(io, R"({"jsonrpc":"2.0","id":2,"method":"quick"})" "\n", waiting_gone);
    OneLineTransport& waiting_view = *waiting;
    std::promise<void> adopted;
    boost::asio::post(io, [&] {
      EXPECT_TRUE(server->adopt(std::move(slow), Via::websocket, "a", Role::engineer, "a").has_value());
      adopted.set_value();
    });
    adopted.get_future().wait();
    EXPECT_TRUE(eventually([&] { return slow_started.load(); }));
    boost::asio::post(io, [&] {
      (void)server->adopt(std::move(waiting), Via::websocket, "b", Role::engineer, "b");
    });
    // Its first line taken, the waiting client reads again: its request is in the worker's queue.
    EXPECT_TRUE(eventually([&] { return waiting_view.reads.load() >= 2; }));
    server.reset();  // closing the slow client lets its request finish
    guard.reset();
    io_thread.join();
  }
  EXPECT_EQ(late_calls.load(), 0) << "a closed client's request ran after the server stopped";
  EXPECT_TRUE(slow_gone.load());
  EXPECT_TRUE(waiting_gone.load()) << "the client whose request waited for the worker was never released";
}

}  // namespace
}  // namespace lamina::daemon::test
