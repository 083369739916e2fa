// laminad: the cell daemon. Takes jobs over JSON-RPC (docs/api.md), plans them with `lamina plan`
// on worker threads, and cuts them through the machine link while it minds the cell's PLC.
// One io_context thread serves the sockets; SIGTERM stops it cleanly (the machine held, the
// cell made safe, the job interrupted and saved). systemd: Type=notify, watchdog, socket activation.
#include <termios.h>
#include <unistd.h>

#include <iostream>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include <CLI/CLI.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "api_methods.hpp"
#include "http/http_server.hpp"
#include "http/passwords.hpp"
#include "http/job_artefacts.hpp"
#include "http/upload_sink.hpp"
#include "job_manager.hpp"
#include "lamina/daemon/daemon_config.hpp"
#include "lamina/daemon/job_store.hpp"
#include "lamina/daemon/rpc_server.hpp"
#include "lamina/daemon/systemd_integration.hpp"
#include "machine_session.hpp"
#include "warning_log.hpp"

namespace fs = std::filesystem;
using namespace lamina::daemon;

namespace {

constexpr const char* kVersion = LAMINA_VERSION;  // the project's (CMakeLists.txt), as the package's

// `lamina` for planning: configured, else beside laminad (build tree), else ../bin (installed).
fs::path find_lamina(const std::string& configured) {
  if (!configured.empty()) return configured;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  for (const fs::path& candidate : {self.parent_path() / "lamina", self.parent_path().parent_path() / "bin" / "lamina"})
    if (!ec && ::access(candidate.c_str(), X_OK) == 0) return candidate;
  return "/usr/bin/lamina";
}

// Every logger of laminad (its own and the drivers') writes to stderr (the journal) and to the
// warning log the console shows; made here, before anything asks for one by name.
std::shared_ptr<WarningLog> setup_logging() {
  // Under systemd the journal stamps each line; elsewhere the time helps.
  const bool journal = std::getenv("JOURNAL_STREAM") != nullptr;
  spdlog::set_pattern(journal ? "[%n] %l: %v" : "%Y-%m-%d %H:%M:%S.%e [%n] %l: %v");
  auto warnings = std::make_shared<WarningLog>();
  auto main_logger = spdlog::stderr_color_mt("laminad");
  main_logger->sinks().push_back(warnings);
  spdlog::set_default_logger(main_logger);
  for (const char* name : {"jobs", "cut", "rpc", "store", "cell", "modbus-link"})
    if (!spdlog::get(name)) spdlog::register_logger(main_logger->clone(name));
  return warnings;
}

template <typename F>
void every(boost::asio::steady_timer& timer, std::chrono::milliseconds period, F f) {
  timer.expires_after(period);
  timer.async_wait([&timer, period, f](const boost::system::error_code& ec) {
    if (ec) return;
    f();
    every(timer, period, f);
  });
}

// The state directory's jobs/ (an error when it cannot be made) and the parts folder: the
// default one is ours to make; a configured one is the shop's (only noted when missing).
bool prepare_folders(const DaemonConfig& config) {
  std::error_code ec;
  fs::create_directories(config.state_dir / "jobs", ec);
  if (ec) {
    spdlog::error("state directory {}: {}", config.state_dir.string(), ec.message());
    return false;
  }
  for (const fs::path root : config.jobs.roots) {
    if (root == config.state_dir / "parts") fs::create_directories(root, ec);
    if (!fs::is_directory(root, ec)) spdlog::warn("[jobs] roots: {} is not a folder; no model can be named there", root.string());
  }
  return true;
}

RpcServerSettings server_settings(const ServerConfig& server) {
  RpcServerSettings rs;
  rs.unix_path = server.socket_path;
  rs.unix_mode = server.socket_mode;
  rs.unix_group = server.socket_group;
  rs.tcp_host = server.tcp_host;
  rs.tcp_port = server.tcp_port;
  rs.token = server.token;
  rs.max_request_bytes = server.max_request_bytes;
  rs.max_clients = server.max_clients;
  rs.idle_timeout_s = server.idle_timeout_s;
  rs.pre_auth_timeout_s = server.pre_auth_timeout_s;
  // The operator's stop buttons jump every queue (and server.subscribe touches its own client).
  rs.inline_methods = {"machine.hold", "machine.abort", "server.subscribe", "server.info"};
  return rs;
}

// The job store, its jobs recovered from the last stop; null once the error was said.
std::unique_ptr<JobStore> open_store(const DaemonConfig& config) {
  auto store = JobStore::open(config.state_dir / "lamina.db");
  if (!store) {
    spdlog::error("{}", store.error().message);
    return nullptr;
  }
  if (auto changed = (*store)->recover_after_restart(); !changed) {
    spdlog::error("{}", changed.error().message);
    return nullptr;
  } else if (!changed->empty()) {
    spdlog::warn("{} job(s) were cut short by the last stop: interrupted or planned again", changed->size());
  }
  return std::move(*store);
}

// Unix listeners systemd handed over (socket activation).
std::vector<int> activated_listeners() {
  std::vector<int> activated;
  for (int fd : systemd::listen_fds())
    if (systemd::is_unix_stream_listener(fd)) activated.push_back(fd);
  return activated;
}

// The activated listeners adopted, else our own socket; TCP (if any) is ours to open.
bool start_listening(RpcServer& server, const std::vector<int>& activated, const RpcServerSettings& rs) {
  for (int fd : activated)
    if (auto r = server.adopt_unix_listener(fd); !r) {
      spdlog::error("socket activation: {}", r.error());
      return false;
    }
  if (activated.empty() || rs.tcp_host) {
    if (auto r = server.listen(); !r) {
      spdlog::error("{}", r.error());
      return false;
    }
  }
  return true;
}

// [http] listen set: the web console's server, listening (nullptr and the error logged if it
// cannot; nullptr without a word when [http] is off).
std::string machine_name() {
  char name[256] = {};
  return ::gethostname(name, sizeof name - 1) == 0 ? std::string(name) : std::string();
}

// The console's HTTP server; a browser's WebSocket becomes a client of the RPC server, with
// the user and role of its login.
std::unique_ptr<http::HttpServer> start_web(boost::asio::io_context& io, const DaemonConfig& config,
                                            const JobManager& jobs, Uploads& uploads, RpcServer& rpc) {
  const HttpConfig& c = config.http;
  if (!c.host) return nullptr;
  http::HttpSettings s;
  s.host = *c.host == "localhost" ? "127.0.0.1" : *c.host;
  s.port = c.port;
  s.static_dir = c.static_dir;
  s.idle_timeout_s = c.idle_timeout_s;
  s.max_connections = c.max_connections;
  s.max_request_bytes = config.server.max_request_bytes;
  s.tls_cert = c.tls_cert;
  s.tls_key = c.tls_key;
  s.access = http::AccessSettings{c.users,           c.session_hours * 3600, c.server_names,
                                  c.allowed_origins, machine_name(),         !c.tls_cert.empty()};
  auto handoff = [&rpc](std::unique_ptr<RpcTransport> transport, const http::Visitor& who, std::string peer) {
    return rpc.adopt(std::move(transport), Via::websocket, who.user, who.role, std::move(peer));
  };
  auto web = std::make_unique<http::HttpServer>(io, s, http::job_artefacts(jobs), handoff,
                                                http::upload_sink(uploads, config.jobs.max_model_bytes));
  if (auto r = web->listen(); !r) {
    spdlog::error("{}", r.error());
    return nullptr;
  }
  spdlog::info("web console: {}://{}:{}/ (files from {}; {})", web->tls() ? "https" : "http", s.host, web->port(),
               s.static_dir.string(), c.users.empty() ? "no users: viewing only" : fmt::format("{} users", c.users.size()));
  if (!web->tls() && !c.users.empty() && *c.host != "127.0.0.1" && *c.host != "::1" && *c.host != "localhost")
    spdlog::warn("web console: passwords and session cookies cross the network in clear text; set [http] tls_cert "
                 "and tls_key, or serve it through a TLS proxy (docs/web.md)");
  return web;
}

// Runs the io_context: the machine's status to subscribers, systemd's status and watchdog; a
// SIGTERM or SIGINT winds the jobs down off the io thread, which keeps pinging the watchdog.
void serve(boost::asio::io_context& io, boost::asio::signal_set& signals, RpcServer& server, http::HttpServer* web,
           JobManager& jobs) {
  boost::asio::steady_timer status_timer(io), watchdog_timer(io), notify_timer(io);
  // 5 a second: the console's machine view moves as the head does (issue 19).
  every(status_timer, std::chrono::milliseconds(200),
        [&] { server.broadcast("notify_machine_status", jobs.machine_status()); });
  every(notify_timer, std::chrono::milliseconds(2000), [&] { systemd::notify_status(jobs.status_line()); });
  if (const auto period = systemd::watchdog_period()) {
    const auto half = std::chrono::duration_cast<std::chrono::milliseconds>(*period / 2);
    every(watchdog_timer, std::max(half, std::chrono::milliseconds(100)), [] { systemd::notify_watchdog(); });
  }
  std::thread stopper;
  signals.async_wait([&](const boost::system::error_code& ec, int signal) {
    if (ec) return;
    spdlog::info("{}: stopping (machine held, cell made safe, jobs saved)", signal == SIGTERM ? "SIGTERM" : "SIGINT");
    systemd::notify_stopping("stopping");
    server.stop();
    if (web) web->stop();
    status_timer.cancel();
    notify_timer.cancel();
    stopper = std::thread([&] {
      jobs.shutdown("the daemon was stopped (SIGTERM)");
      boost::asio::post(io, [&] {
        watchdog_timer.cancel();
        io.stop();
      });
    });
  });
  io.run();
  if (stopper.joinable()) stopper.join();
}

int run(const fs::path& config_path, bool check_only, std::shared_ptr<const WarningLog> warnings) {
  auto config = load_daemon_config(config_path);
  if (!config) {
    spdlog::error("{}", config.error().message);
    return 2;
  }
  if (check_only) {
    fmt::print("{}: ok\n", config_path.string());
    return 0;
  }
  config->planner.lamina_path = find_lamina(config->planner.lamina_path).string();
  if (!prepare_folders(*config)) return 1;
  std::unique_ptr<JobStore> store = open_store(*config);
  if (!store) return 1;
  std::unique_ptr<MachineSession> machine;
  try {
    machine = std::make_unique<MachineSession>(*config);
  } catch (const std::exception& e) {
    spdlog::error("{}: {}", config->source, e.what());
    return 2;
  }

  boost::asio::io_context io;
  // Caught from here on: a SIGTERM during start-up (systemd stopping a unit it just started) is
  // queued until the handler below is waiting, not the default action that kills us mid-write.
  boost::asio::signal_set signals(io, SIGTERM, SIGINT);
  RpcServerSettings rs = server_settings(config->server);
  const std::vector<int> activated = activated_listeners();
  if (!activated.empty()) rs.unix_path.clear();

  RpcServer* server_ptr = nullptr;
  JobManager jobs(*config, *store, *machine, [&server_ptr](const std::string& method, const nlohmann::json& params) {
    if (server_ptr) server_ptr->broadcast(method, params);
  });
  Uploads uploads(config->state_dir / "uploads", UploadLimits{config->jobs.max_model_bytes, UploadLimits{}.max_chunk_bytes,
                                                               config->jobs.max_uploads, config->jobs.upload_idle_s});
  RpcServer server(io, rs, make_api_handler(jobs, uploads, ServerInfo{kVersion, machine->describe(), config->state_dir.string(), warnings}));
  server_ptr = &server;
  // The console before the socket: a client that reaches the socket finds the console up too.
  std::unique_ptr<http::HttpServer> web = start_web(io, *config, jobs, uploads, server);
  if (config->http.host && !web) return 1;
  if (!start_listening(server, activated, rs)) return 1;
  if (auto r = jobs.start(); !r) {
    spdlog::error("{}", r.error().message);
    return 1;
  }
  spdlog::info("laminad {} ready: socket {}{}, {}, state in {}", kVersion,
               !activated.empty() ? "(from systemd)" : config->server.socket_path,
               rs.tcp_host ? fmt::format(", tcp {}:{}", *rs.tcp_host, server.tcp_port()) : std::string(),
               machine->describe(), config->state_dir.string());
  systemd::notify_ready(jobs.status_line());
  serve(io, signals, server, web.get(), jobs);
  jobs.shutdown("the daemon was stopped");
  spdlog::info("stopped");
  return 0;
}

// The password is read without echo from a terminal, or as the first line of a pipe.
int print_password_hash() {
  const bool tty = ::isatty(STDIN_FILENO) == 1;
  termios saved{};
  if (tty) {
    fmt::print(stderr, "password: ");
    ::tcgetattr(STDIN_FILENO, &saved);
    termios quiet = saved;
    quiet.c_lflag &= ~static_cast<tcflag_t>(ECHO);
    ::tcsetattr(STDIN_FILENO, TCSANOW, &quiet);
  }
  std::string password;
  std::getline(std::cin, password);
  if (tty) {
    ::tcsetattr(STDIN_FILENO, TCSANOW, &saved);
    fmt::print(stderr, "\n");
  }
  if (!password.empty() && password.back() == '\r') password.pop_back();
  auto hashed = http::hash_password(password);
  if (!hashed) {
    fmt::print(stderr, "laminad --hash-password: {}\n", hashed.error());
    return 2;
  }
  fmt::print("{}\n", *hashed);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"laminad: the Lamina cell daemon (JSON-RPC on a Unix socket; see docs/api.md)"};
  std::string config_path = "/etc/lamina/lamina.toml";
  bool check = false;
  app.add_option("--config", config_path, "configuration file (TOML)");
  app.add_flag("--check-config", check, "validate the configuration and exit");
  bool hash = false;
  app.add_flag("--hash-password", hash,
               "read a password on standard input and print its Argon2id hash for [[http.users]] password_hash");
  app.set_version_flag("--version", std::string("laminad ") + kVersion);
  CLI11_PARSE(app, argc, argv);
  if (hash) return print_password_hash();
  auto warnings = setup_logging();
  try {
    return run(config_path, check, warnings);
  } catch (const std::exception& e) {  // start-up failures only: the running daemon reports errors as data
    spdlog::critical("{}", e.what());
    return 1;
  }
}
