#pragma once
// laminad's configuration: TOML (/etc/lamina/lamina.toml; config/lamina.toml holds the defaults,
// config/demo.toml points at the simulator). Validated at start: a wrong type, a value out of
// range or an unknown key is an error naming the file, the key and (when known) the line.
#include <cstdint>
#include <expected>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "lamina/daemon/roles.hpp"

#include "lamina/drivers/link_factory.hpp"

namespace lamina::daemon {

struct ServerConfig {
  std::string socket_path = "/run/lamina/lamina.sock";
  unsigned socket_mode = 0660;
  std::string socket_group = "lamina";     // empty: leave the group as created
  std::optional<std::string> tcp_host;     // [server] tcp = "127.0.0.1:7400"; unset: no TCP
  int tcp_port = 0;
  std::string token;                       // required when TCP is on (or token_file)
  std::size_t max_request_bytes = 1 << 20;
  std::size_t max_clients = 64;            // per kind (Unix, TCP); the longest idle makes room
  double idle_timeout_s = 600;             // a client silent this long (not subscribed) is closed; 0: never
  double pre_auth_timeout_s = 10;          // TCP: a valid token within this, or closed
};

// [link]: the drivers' one link struct (lamina/drivers/link_factory.hpp); its `plc` is [cell]'s.
using MachineLinkConfig = drivers::LinkSettings;

struct CellConfig {
  bool enabled = true;                     // a PLC minds pump and interlocks
  std::string modbus = "127.0.0.1:502";    // HOST:PORT
  int modbus_unit = 1;                     // Modbus unit (slave) id; a gateway routes by it
  double modbus_timeout_s = 0.5;           // per request
  int modbus_reconnects = 3;               // per failed request, then the PLC is lost (the cut stops)
  double heartbeat_period_s = 0.2;
  double idle_poll_s = 1.0;     // between cuts the PLC's inputs are read this often (machine.status)
  double pump_ready_timeout_s = 10;
  double pressure_setpoint_mpa = 380;
  double abrasive_g_per_min = 350;
  double hold_limit_s = 600;    // a feed hold (jet off) longer than this becomes a stop
  double jet_restart_s = 1.0;   // resume from a hold: jet on, this long, then the motion
};

struct PlannerConfig {
  std::string lamina_path;                 // empty: `lamina` beside laminad
  int workers = 1;                         // planning jobs at once
  std::string machine_file;                // --machine for lamina plan (empty: its default)
  std::string materials_file;
  double timeout_s = 3600;
  // The child's limits: a hostile or huge model must not starve a cut on the cell PC.
  std::uint64_t memory_limit_mb = 4096;    // address space (RLIMIT_AS); 0: none
  double cpu_limit_s = 0;                  // CPU time of all its threads (RLIMIT_CPU); 0: none (timeout_s still holds)
  int nice = 10;                           // 0 … 19: below the cut's threads
};

// Files a client may name (job.submit's model, settings.stock_file) and its uploads.
struct JobsConfig {
  std::vector<std::string> roots;          // folders; empty: <state_dir>/parts
  std::uint64_t max_model_bytes = 512ull << 20;
  std::uint64_t max_stock_file_bytes = 1 << 20;
  double upload_idle_s = 600;              // an upload with no chunk this long is dropped
  std::size_t max_uploads = 16;            // unfinished at once
};

// [[http.users]]: who may log in to the web console.
struct WebUser {
  std::string name;
  Role role = Role::viewer;
  std::string password_hash;  // Argon2id PHC string (laminad --hash-password)
};

// [http]: the web console (issue 19).
struct HttpConfig {
  std::optional<std::string> host = "127.0.0.1";  // [http] listen = "HOST:PORT"; "" (nullopt): no web server
  int port = 8080;
  std::string static_dir = "/usr/share/lamina/web";  // the console's built files
  double idle_timeout_s = 30;              // a connection silent this long is closed
  std::size_t max_connections = 64;
  // Without users the console only watches, and only from this machine (loopback); with users
  // every request but the console's own files needs a login, and any address may be listened on.
  std::vector<WebUser> users;
  double session_hours = 12;               // a login lasts a shift
  // Host names the console is reached by, besides IP addresses, localhost and this machine's
  // name: a request naming another host is refused (DNS rebinding).
  std::vector<std::string> server_names;
  // Origins allowed besides the console's own (a reverse proxy's "https://cell.example").
  std::vector<std::string> allowed_origins;
  // HTTPS: a PEM certificate (chain) and its private key, both or neither. Relative paths are
  // from the configuration file's folder.
  std::string tls_cert, tls_key;
};

struct DaemonConfig {
  std::filesystem::path state_dir = "/var/lib/lamina";
  ServerConfig server;
  HttpConfig http;
  MachineLinkConfig link;
  CellConfig cell;
  PlannerConfig planner;
  JobsConfig jobs;
  std::string source;                      // the file read, for messages
};

struct ConfigError {
  std::string message;  // "<file>:<line>: [section] key: what is wrong"
};

std::expected<DaemonConfig, ConfigError> load_daemon_config(const std::filesystem::path& file);
std::expected<DaemonConfig, ConfigError> parse_daemon_config(const std::string& toml_text, const std::string& source_name);

}  // namespace lamina::daemon
