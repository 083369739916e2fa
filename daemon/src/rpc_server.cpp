// The listening half of the JSON-RPC server: sockets, accepting, the set of connections,
// broadcast and stop. Reading, dispatching and writing per client is rpc_connection.cpp.
//
// Threading: everything runs on the caller's io_context (one thread), and every completion
// handler takes ServerShared::mutex. stop() and the destructor take it too and then close sockets
// directly, so they are synchronous and safe from any thread, whether or not the io_context is
// still running (Asio allows closing a socket from another thread while operations are pending,
// as long as calls on that socket are not concurrent, which the lock guarantees). The io_context
// must outlive the RpcServer and must not be built with the "unsafe" concurrency hint. Since
// stop() waits for a handler that is running, a handler must not wait on a thread calling stop().
#include "lamina/daemon/rpc_server.hpp"

#include <grp.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <map>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "rpc_connection.hpp"
#include "rpc_protocol.hpp"
#include "rpc_transport.hpp"

namespace lamina::daemon {
namespace {

using boost::asio::ip::tcp;
using UnixProtocol = boost::asio::local::stream_protocol;
using rpc_detail::Connection;

std::shared_ptr<spdlog::logger> rpc_logger() {
  static std::mutex mutex;  // two servers created at once would make spdlog throw on the second
  std::lock_guard lock(mutex);
  if (auto existing = spdlog::get("rpc")) return existing;
  return spdlog::stdout_color_mt("rpc");
}

std::string errno_text() { return std::strerror(errno); }

// Whether a server accepts on the socket file at path (then it is not stale and not ours).
bool unix_socket_is_live(const std::string& path) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) return false;
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::memcpy(address.sun_path, path.c_str(), path.size() + 1);
  const int rc = ::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address);
  // EAGAIN: a live server with a full backlog. ECONNREFUSED: nobody listens (stale).
  const bool live = rc == 0 || errno == EAGAIN || errno == EINPROGRESS;
  ::close(fd);
  return live;
}

std::expected<gid_t, std::string> group_id(const std::string& name) {
  std::vector<char> buffer(4096);
  for (;;) {
    group entry{};
    group* found = nullptr;
    const int rc = ::getgrnam_r(name.c_str(), &entry, buffer.data(), buffer.size(), &found);
    if (rc == ERANGE && buffer.size() < (1U << 20)) {
      buffer.resize(buffer.size() * 2);
      continue;
    }
    if (rc != 0) return std::unexpected(fmt::format("cannot look up the group '{}': {}", name, std::strerror(rc)));
    if (found == nullptr) return std::unexpected(fmt::format("the Unix socket's group '{}' does not exist", name));
    return found->gr_gid;
  }
}

std::string unix_peer(int fd) {
  ucred credentials{};
  socklen_t size = sizeof credentials;
  if (::getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &credentials, &size) != 0) return "unix";
  return fmt::format("unix pid {} uid {}", credentials.pid, credentials.uid);
}

std::string tcp_peer(const tcp::socket& socket) {
  boost::system::error_code error;
  const auto endpoint = socket.remote_endpoint(error);
  if (error) return "tcp";
  return fmt::format("tcp {}:{}", endpoint.address().to_string(), endpoint.port());
}

}  // namespace

struct RpcServer::Impl : std::enable_shared_from_this<RpcServer::Impl> {
  Impl(boost::asio::io_context& context, std::shared_ptr<rpc_detail::ServerShared> state)
      : io(context), shared(std::move(state)) {}

  boost::asio::io_context& io;
  std::shared_ptr<rpc_detail::ServerShared> shared;
  // Acceptors are closed, never destroyed, while the Impl lives: accept handlers refer to them.
  std::optional<UnixProtocol::acceptor> unix_acceptor;
  std::optional<tcp::acceptor> tcp_acceptor;
  std::map<std::uint64_t, std::shared_ptr<Connection>> connections;
  std::uint64_t next_client_id = 1;
  bool stopped = false;
  // The socket file this server created, removed at stop if it is still that file (a newer
  // daemon may have replaced it). An adopted listener's file belongs to systemd.
  std::string owned_path;
  dev_t owned_device = 0;
  ino_t owned_inode = 0;
  std::atomic<int> bound_tcp_port{0};
  std::atomic<std::size_t> clients{0};
  // The worker thread of ServerShared::worker (see rpc_connection.hpp).
  std::optional<boost::asio::executor_work_guard<boost::asio::io_context::executor_type>> worker_guard;
  std::thread worker_thread;

  const RpcServerSettings& settings() const { return shared->settings; }
  spdlog::logger& log() const { return *shared->log; }

  std::expected<void, std::string> listen() {
    if (stopped) return std::unexpected(std::string("the RPC server is stopped"));
    const auto& s = settings();
    if (s.tcp_host && s.token.empty()) return std::unexpected(std::string("TCP needs a token (the token is empty)"));
    const bool want_unix = !unix_acceptor && !s.unix_path.empty();
    const bool want_tcp = !tcp_acceptor && s.tcp_host.has_value();
    if (!unix_acceptor && !want_unix && !tcp_acceptor && !want_tcp)
      return std::unexpected(std::string("nothing to listen on: no Unix socket path and no TCP host"));
    if (want_unix)
      if (auto opened = listen_unix(); !opened) return opened;
    if (want_tcp) {
      if (auto opened = listen_tcp(); !opened) {
        if (want_unix) {  // all or nothing: no half-configured server
          remove_socket_file();
          unix_acceptor.reset();  // safe: no accept was started on it yet
        }
        return opened;
      }
    }
    if (want_unix) accept_next(*unix_acceptor, Via::unix_socket);
    if (want_tcp) accept_next(*tcp_acceptor, Via::tcp);
    return {};
  }

  std::expected<void, std::string> listen_unix() {
    const std::string& path = settings().unix_path;
    if (path.size() >= sizeof(sockaddr_un::sun_path))
      return std::unexpected(fmt::format("Unix socket path {} is too long ({} bytes, at most {})", path, path.size(),
                                         sizeof(sockaddr_un::sun_path) - 1));
    struct stat existing {};
    if (::lstat(path.c_str(), &existing) == 0) {
      if (!S_ISSOCK(existing.st_mode))
        return std::unexpected(fmt::format("{} exists and is not a socket; not replacing it", path));
      if (unix_socket_is_live(path)) return std::unexpected(fmt::format("another server is listening on {}", path));
      if (::unlink(path.c_str()) != 0 && errno != ENOENT)
        return std::unexpected(fmt::format("cannot remove the stale socket {}: {}", path, errno_text()));
      log().info("removed the stale socket file {}", path);
    }
    UnixProtocol::acceptor acceptor(io);
    boost::system::error_code error;
    acceptor.open(UnixProtocol(), error);
    if (error) return std::unexpected(fmt::format("cannot create a socket for {}: {}", path, error.message()));
    acceptor.bind(UnixProtocol::endpoint(path), error);
    if (error) return std::unexpected(fmt::format("cannot bind {}: {}", path, error.message()));
    // The file exists from here on; clients cannot connect before listen(), so setting its mode
    // and group between bind and listen leaves no window with the wrong permissions.
    const auto fail = [&](std::string message) {
      boost::system::error_code ignored;
      acceptor.close(ignored);
      ::unlink(path.c_str());
      return std::unexpected(std::move(message));
    };
    if (::chmod(path.c_str(), settings().unix_mode & 07777) != 0)
      return fail(fmt::format("cannot chmod {:o} {}: {}", settings().unix_mode, path, errno_text()));
    if (!settings().unix_group.empty()) {
      const auto gid = group_id(settings().unix_group);
      if (!gid) return fail(gid.error());
      if (::chown(path.c_str(), static_cast<uid_t>(-1), *gid) != 0)
        return fail(fmt::format("cannot chgrp {} {}: {}", settings().unix_group, path, errno_text()));
    }
    acceptor.listen(boost::asio::socket_base::max_listen_connections, error);
    if (error) return fail(fmt::format("cannot listen on {}: {}", path, error.message()));
    struct stat created {};
    if (::lstat(path.c_str(), &created) == 0) {
      owned_device = created.st_dev;
      owned_inode = created.st_ino;
    }
    owned_path = path;
    unix_acceptor.emplace(std::move(acceptor));
    log().info("listening on {}", path);
    return {};
  }

  std::expected<void, std::string> listen_tcp() {
    const std::string host = settings().tcp_host->empty() ? "127.0.0.1" : *settings().tcp_host;
    const int port = settings().tcp_port;
    if (port < 0 || port > 65535) return std::unexpected(fmt::format("TCP port {} is out of range", port));
    boost::system::error_code error;
    tcp::resolver resolver(io);
    const auto found = resolver.resolve(host, std::to_string(port),
                                        tcp::resolver::passive | tcp::resolver::numeric_service, error);
    if (error || found.empty())
      return std::unexpected(fmt::format("cannot resolve the TCP host {}: {}", host, error.message()));
    const tcp::endpoint endpoint = found.begin()->endpoint();
    tcp::acceptor acceptor(io);
    acceptor.open(endpoint.protocol(), error);
    if (!error) acceptor.set_option(tcp::acceptor::reuse_address(true), error);  // restart during TIME_WAIT
    if (!error) acceptor.bind(endpoint, error);
    if (!error) acceptor.listen(boost::asio::socket_base::max_listen_connections, error);
    if (error) return std::unexpected(fmt::format("cannot listen on TCP {}:{}: {}", host, port, error.message()));
    bound_tcp_port = acceptor.local_endpoint(error).port();
    tcp_acceptor.emplace(std::move(acceptor));
    log().info("listening on TCP {}:{}", endpoint.address().to_string(), bound_tcp_port.load());
    if (!endpoint.address().is_loopback())
      log().warn("TCP on {}, not loopback: the token travels in clear text", endpoint.address().to_string());
    return {};
  }

  template <typename Acceptor>
  void accept_next(Acceptor& acceptor, Via via) {
    acceptor.async_accept(
        [self = shared_from_this(), &acceptor, via](const boost::system::error_code& error, auto socket) {
          std::lock_guard lock(self->shared->mutex);
          self->on_accept(acceptor, via, error, std::move(socket));
        });
  }

  template <typename Acceptor, typename Socket>
  void on_accept(Acceptor& acceptor, Via via, const boost::system::error_code& error, Socket socket) {
    if (stopped || error == boost::asio::error::operation_aborted) return;
    if (error) {
      // EMFILE and the like: accepting again at once would spin while nothing frees descriptors.
      log().warn("accepting a {} client failed: {}; retrying", via_name(via), error.message());
      auto timer = std::make_shared<boost::asio::steady_timer>(io, std::chrono::milliseconds(100));
      timer->async_wait([self = shared_from_this(), timer, &acceptor, via](const boost::system::error_code& e) {
        std::lock_guard lock(self->shared->mutex);
        if (!e && !self->stopped) self->accept_next(acceptor, via);
      });
      return;
    }
    accept_next(acceptor, via);
    std::string peer;
    std::string user = "tcp";
    if constexpr (std::is_same_v<typename Socket::protocol_type, tcp>) {
      boost::system::error_code ignored;
      socket.set_option(tcp::no_delay(true), ignored);  // replies are small and awaited
      peer = tcp_peer(socket);
    } else {
      peer = unix_peer(socket.native_handle());
      user = peer;
    }
    if (count(via) >= settings().max_clients && !evict_one(via)) {
      refuse(socket, peer, via);
      return;
    }
    admit(std::move(socket), via, std::move(peer), std::move(user));
  }

  std::size_t count(Via via) const {
    std::size_t n = 0;
    for (const auto& [id, connection] : connections) n += connection->context().via == via;
    return n;
  }

  // 128 idle connections used to lock every new client out until a restart: the longest-idle
  // one of the same kind makes room (never a subscriber, nor one with a request in flight).
  bool evict_one(Via via) {
    const auto now = std::chrono::steady_clock::now();
    std::shared_ptr<Connection> oldest;
    for (const auto& [id, connection] : connections)
      if (connection->context().via == via && connection->evictable(now) &&
          (!oldest || connection->last_active() < oldest->last_active()))
        oldest = connection;
    if (!oldest) return false;
    oldest->close(fmt::format("the longest idle of {} {} clients, dropped to make room", settings().max_clients,
                              via_name(via)));
    return true;
  }

  template <typename Socket>
  void refuse(Socket& socket, const std::string& peer, Via via) {
    const char* kind = via_name(via);
    log().warn("refusing {}: {} {} clients connected, none idle (max_clients)", peer, count(via), kind);
    const std::string line = rpc_detail::error_line(
        nullptr, RpcError{rpc_detail::too_many_clients,
                          fmt::format("too many {} clients (limit {}, none idle)", kind, settings().max_clients), {}});
    boost::system::error_code ignored;
    // A fresh socket's send buffer is empty, so this short write does not block; it is best effort.
    socket.non_blocking(true, ignored);
    socket.write_some(boost::asio::buffer(line), ignored);
    socket.close(ignored);
  }

  template <typename Socket>
  void admit(Socket socket, Via via, std::string peer, std::string user) {
    // One socket type for both kinds of client: the transport does not care which it is.
    boost::system::error_code error;
    const boost::asio::generic::stream_protocol protocol(socket.local_endpoint(error).protocol());
    const int fd = socket.release(error);
    if (error) {
      log().warn("cannot take over the socket of {}: {}", peer, error.message());
      return;
    }
    boost::asio::generic::stream_protocol::socket generic(io);
    generic.assign(protocol, fd, error);
    if (error) {
      ::close(fd);
      log().warn("cannot take over the socket of {}: {}", peer, error.message());
      return;
    }
    start_connection(make_stream_transport(std::move(generic)),
                     ClientContext{next_client_id++, via, false, std::move(user), Role::engineer}, std::move(peer));
  }

  void start_connection(std::unique_ptr<RpcTransport> transport, ClientContext context, std::string peer) {
    auto connection = std::make_shared<Connection>(
        std::move(transport), context, std::move(peer), shared, [weak = weak_from_this()](std::uint64_t id) {
          // Runs inside Connection::close, under the lock.
          if (auto self = weak.lock()) {
            self->connections.erase(id);
            self->clients = self->connections.size();
          }
        });
    connections.emplace(context.id, connection);
    clients = connections.size();
    connection->start();
  }

  void remove_socket_file() {
    if (owned_path.empty()) return;
    struct stat current {};
    if (::lstat(owned_path.c_str(), &current) == 0 && current.st_dev == owned_device && current.st_ino == owned_inode)
      ::unlink(owned_path.c_str());
    owned_path.clear();
  }

  void stop(std::string_view reason) {
    if (stopped) return;
    stopped = true;
    boost::system::error_code ignored;
    if (unix_acceptor) unix_acceptor->close(ignored);
    if (tcp_acceptor) tcp_acceptor->close(ignored);
    remove_socket_file();
    // Connection::close erases from the map: close from a copy.
    const auto open = std::exchange(connections, {});
    clients = 0;
    for (const auto& [id, connection] : open) connection->close(reason);
    log().info("stopped ({} clients disconnected)", open.size());
  }
};

RpcServer::RpcServer(boost::asio::io_context& io, RpcServerSettings settings, Handler handler) {
  auto shared = std::make_shared<rpc_detail::ServerShared>();
  shared->settings = std::move(settings);
  shared->handler = std::move(handler);
  shared->log = rpc_logger();
  impl_ = std::make_shared<Impl>(io, std::move(shared));
  impl_->worker_guard.emplace(impl_->shared->worker.get_executor());
  impl_->worker_thread = std::thread([shared = impl_->shared] { shared->worker.run(); });
}

RpcServer::~RpcServer() {
  {
    std::lock_guard lock(impl_->shared->mutex);
    impl_->stop("server destroyed");
  }
  // A handler still running on the worker finishes (its reply finds the connection closed).
  // The requests queued behind it are drained, not dropped: each finds its connection closed
  // and releases it. A stopped io_context would keep them, and with them their connections,
  // which keep the shared state that owns the queue (a cycle). Not under the lock: the
  // handler's reply takes it.
  impl_->worker_guard.reset();
  if (impl_->worker_thread.joinable()) impl_->worker_thread.join();
  std::lock_guard lock(impl_->shared->mutex);
  // Completion handlers still queued keep the shared state alive; they find every connection
  // closed, and with the handler gone nothing it captured can be reached any more.
  impl_->shared->handler = nullptr;
}

std::expected<void, std::string> RpcServer::listen() {
  std::lock_guard lock(impl_->shared->mutex);
  return impl_->listen();
}

std::expected<void, std::string> RpcServer::adopt_unix_listener(int fd) {
  std::lock_guard lock(impl_->shared->mutex);
  if (impl_->stopped) return std::unexpected(std::string("the RPC server is stopped"));
  if (impl_->unix_acceptor) return std::unexpected(std::string("a Unix socket is already listening"));
  int domain = 0;
  int type = 0;
  int listening = 0;
  socklen_t size = sizeof(int);
  const bool ok = ::getsockopt(fd, SOL_SOCKET, SO_DOMAIN, &domain, &size) == 0 && domain == AF_UNIX &&
                  ::getsockopt(fd, SOL_SOCKET, SO_TYPE, &type, &size) == 0 && type == SOCK_STREAM &&
                  ::getsockopt(fd, SOL_SOCKET, SO_ACCEPTCONN, &listening, &size) == 0 && listening == 1;
  if (!ok) return std::unexpected(fmt::format("fd {} is not a listening Unix stream socket", fd));
  UnixProtocol::acceptor acceptor(impl_->io);
  boost::system::error_code error;
  acceptor.assign(UnixProtocol(), fd, error);
  if (error) return std::unexpected(fmt::format("cannot adopt fd {}: {}", fd, error.message()));
  impl_->unix_acceptor.emplace(std::move(acceptor));
  impl_->accept_next(*impl_->unix_acceptor, Via::unix_socket);
  impl_->log().info("listening on the Unix socket passed by systemd (fd {})", fd);
  return {};
}

int RpcServer::tcp_port() const { return impl_->bound_tcp_port.load(); }

void RpcServer::broadcast(const std::string& method, const nlohmann::json& params) {
  auto line = std::make_shared<const std::string>(rpc_detail::notification_line(method, params));
  // Posted rather than sent here: a handler that broadcasts gets its own reply out first.
  boost::asio::post(impl_->io, [weak = std::weak_ptr<Impl>(impl_), line = std::move(line)] {
    const auto impl = weak.lock();
    if (!impl) return;
    std::lock_guard lock(impl->shared->mutex);
    if (impl->stopped) return;
    std::vector<std::shared_ptr<Connection>> subscribers;  // send() may drop one: not while iterating
    for (const auto& [id, connection] : impl->connections)
      if (connection->context().subscribed) subscribers.push_back(connection);
    for (const auto& connection : subscribers) connection->send(line);
  });
}

void RpcServer::stop() {
  std::lock_guard lock(impl_->shared->mutex);
  impl_->stop("server stopping");
}

std::expected<void, std::string> RpcServer::adopt(std::unique_ptr<RpcTransport> transport, Via via, std::string user,
                                                  Role role, std::string peer) {
  std::lock_guard lock(impl_->shared->mutex);
  if (impl_->stopped) return std::unexpected(std::string("the server is stopping"));
  if (impl_->count(via) >= impl_->settings().max_clients && !impl_->evict_one(via)) {
    impl_->log().warn("refusing {}: {} {} clients connected, none idle (max_clients)", peer, impl_->count(via),
                      via_name(via));
    return std::unexpected(fmt::format("too many {} clients (limit {}, none idle)", via_name(via),
                                       impl_->settings().max_clients));
  }
  impl_->start_connection(std::move(transport), ClientContext{impl_->next_client_id++, via, false, std::move(user), role},
                          std::move(peer));
  return {};
}

const char* via_name(Via via) {
  switch (via) {
    case Via::tcp: return "TCP";
    case Via::websocket: return "WebSocket";
    case Via::unix_socket: break;
  }
  return "Unix";
}


std::size_t RpcServer::client_count() const { return impl_->clients.load(); }

}  // namespace lamina::daemon
