// laminad's configuration: the shipped files parse to what they say, and every mistake a person
// can make in the file is an error naming the key and its line.
#include "lamina/daemon/daemon_config.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;
using lamina::daemon::DaemonConfig;
using lamina::daemon::load_daemon_config;
using lamina::daemon::parse_daemon_config;
using lamina::daemon::Role;

const fs::path kSource = LAMINA_SOURCE_DIR;

// A fresh folder per test (removed with its files at the end).
class ScratchDir {
 public:
  ScratchDir() {
    std::string pattern = (fs::temp_directory_path() / "lamina-config-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }
  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path file = path_ / name;
    fs::create_directories(file.parent_path());
    std::ofstream(file) << text;
    return file;
  }

 private:
  fs::path path_;
};

// The message of a configuration that must be refused.
std::string error_of(const std::string& text) {
  auto c = parse_daemon_config(text, "test.toml");
  EXPECT_FALSE(c.has_value()) << "accepted:\n" << text;
  return c ? std::string{} : c.error().message;
}

// Every field, so that a default changed in the header but not in config/lamina.toml is caught.
void expect_same(const DaemonConfig& a, const DaemonConfig& b) {
  EXPECT_EQ(a.state_dir, b.state_dir);
  EXPECT_EQ(a.server.socket_path, b.server.socket_path);
  EXPECT_EQ(a.server.socket_mode, b.server.socket_mode);
  EXPECT_EQ(a.server.socket_group, b.server.socket_group);
  EXPECT_EQ(a.server.tcp_host, b.server.tcp_host);
  EXPECT_EQ(a.server.tcp_port, b.server.tcp_port);
  EXPECT_EQ(a.server.token, b.server.token);
  EXPECT_EQ(a.server.max_request_bytes, b.server.max_request_bytes);
  EXPECT_EQ(a.server.max_clients, b.server.max_clients);
  EXPECT_EQ(a.server.idle_timeout_s, b.server.idle_timeout_s);
  EXPECT_EQ(a.server.pre_auth_timeout_s, b.server.pre_auth_timeout_s);
  EXPECT_EQ(a.http.host, b.http.host);
  EXPECT_EQ(a.http.port, b.http.port);
  EXPECT_EQ(a.http.static_dir, b.http.static_dir);
  EXPECT_EQ(a.http.idle_timeout_s, b.http.idle_timeout_s);
  EXPECT_EQ(a.http.max_connections, b.http.max_connections);
  EXPECT_EQ(a.http.users.size(), b.http.users.size());
  EXPECT_EQ(a.http.session_hours, b.http.session_hours);
  EXPECT_EQ(a.http.server_names, b.http.server_names);
  EXPECT_EQ(a.http.allowed_origins, b.http.allowed_origins);
  EXPECT_EQ(a.link.protocol, b.link.protocol);
  EXPECT_EQ(a.link.port, b.link.port);
  EXPECT_EQ(a.link.tcp, b.link.tcp);
  EXPECT_EQ(a.link.baud, b.link.baud);
  EXPECT_EQ(a.link.rx_buffer, b.link.rx_buffer);
  EXPECT_EQ(a.link.status_hz, b.link.status_hz);
  EXPECT_EQ(a.cell.enabled, b.cell.enabled);
  EXPECT_EQ(a.cell.modbus, b.cell.modbus);
  EXPECT_EQ(a.cell.modbus_unit, b.cell.modbus_unit);
  EXPECT_EQ(a.cell.modbus_timeout_s, b.cell.modbus_timeout_s);
  EXPECT_EQ(a.cell.modbus_reconnects, b.cell.modbus_reconnects);
  EXPECT_EQ(a.cell.heartbeat_period_s, b.cell.heartbeat_period_s);
  EXPECT_EQ(a.cell.hold_limit_s, b.cell.hold_limit_s);
  EXPECT_EQ(a.cell.jet_restart_s, b.cell.jet_restart_s);
  EXPECT_EQ(a.cell.pump_ready_timeout_s, b.cell.pump_ready_timeout_s);
  EXPECT_EQ(a.cell.pressure_setpoint_mpa, b.cell.pressure_setpoint_mpa);
  EXPECT_EQ(a.cell.abrasive_g_per_min, b.cell.abrasive_g_per_min);
  EXPECT_EQ(a.planner.lamina_path, b.planner.lamina_path);
  EXPECT_EQ(a.planner.workers, b.planner.workers);
  EXPECT_EQ(a.planner.machine_file, b.planner.machine_file);
  EXPECT_EQ(a.planner.materials_file, b.planner.materials_file);
  EXPECT_EQ(a.planner.timeout_s, b.planner.timeout_s);
  EXPECT_EQ(a.planner.memory_limit_mb, b.planner.memory_limit_mb);
  EXPECT_EQ(a.planner.cpu_limit_s, b.planner.cpu_limit_s);
  EXPECT_EQ(a.planner.nice, b.planner.nice);
  // jobs.roots: [] means <state_dir>/parts, which the parser fills in (JobsRoots below).
  EXPECT_EQ(a.jobs.max_model_bytes, b.jobs.max_model_bytes);
  EXPECT_EQ(a.jobs.max_stock_file_bytes, b.jobs.max_stock_file_bytes);
  EXPECT_EQ(a.jobs.upload_idle_s, b.jobs.upload_idle_s);
  EXPECT_EQ(a.jobs.max_uploads, b.jobs.max_uploads);
}

TEST(DaemonConfig, TheDefaultsFileHoldsTheStructDefaults) {
  const fs::path file = kSource / "config/lamina.toml";
  auto c = load_daemon_config(file);
  ASSERT_TRUE(c.has_value()) << c.error().message;
  expect_same(*c, DaemonConfig{});
  EXPECT_EQ(c->source, file.string());
}

TEST(DaemonConfig, TheDefaultsFileShowsEveryKey) {
  // "Every key is shown": a key added to the parser must be added to the shipped file too.
  std::ifstream in(kSource / "config/lamina.toml");
  std::string text((std::istreambuf_iterator<char>(in)), {});
  for (const char* key : {"state_dir", "socket", "socket_mode", "socket_group", "tcp", "token", "token_file",
                          "max_request_bytes", "max_clients", "idle_timeout_s", "pre_auth_timeout_s", "protocol", "port", "baud", "rx_buffer", "status_hz", "enabled",
                          "modbus", "heartbeat_period_s", "pump_ready_timeout_s", "pressure_setpoint_mpa",
                          "abrasive_g_per_min", "hold_limit_s", "jet_restart_s", "lamina", "workers", "machine",
                          "materials", "timeout_s", "memory_limit_mb", "cpu_limit_s", "nice", "roots",
                          "max_model_bytes", "max_stock_file_bytes", "upload_idle_s", "max_uploads", "listen",
                          "static_dir", "max_connections", "session_hours", "server_names", "allowed_origins",
                          "tls_cert", "tls_key"})
    EXPECT_NE(text.find(std::string("\n") + key + " = "), std::string::npos) << key;
}

TEST(DaemonConfig, TheDemoFilePointsAtTheSimulator) {
  auto c = load_daemon_config(kSource / "config/demo.toml");
  ASSERT_TRUE(c.has_value()) << c.error().message;
  EXPECT_EQ(c->state_dir, "/tmp/lamina-demo/state");
  EXPECT_EQ(c->server.socket_path, "/tmp/lamina-demo/lamina.sock");
  EXPECT_EQ(c->server.socket_group, "");
  EXPECT_FALSE(c->server.tcp_host);
  EXPECT_EQ(c->link.protocol, "grbl");
  EXPECT_EQ(c->link.port, "/tmp/lamina-demo/cnc");
  EXPECT_EQ(c->link.tcp, "");
  EXPECT_TRUE(c->cell.enabled);
  EXPECT_EQ(c->cell.modbus, "127.0.0.1:1502");
}

// The folders a client may name files in: by default the state directory's parts/, never the
// state directory itself (the database, other jobs' files).
TEST(DaemonConfig, JobsRoots) {
  auto d = parse_daemon_config("state_dir = \"/srv/cell\"\n", "/etc/lamina/x.toml");
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_EQ(d->jobs.roots, std::vector<std::string>{"/srv/cell/parts"});
  auto two = parse_daemon_config("[jobs]\nroots = [\"/srv/parts\", \"shared\"]\n", "/etc/lamina/x.toml");
  ASSERT_TRUE(two) << two.error().message;
  EXPECT_EQ(two->jobs.roots, (std::vector<std::string>{"/srv/parts", "/etc/lamina/shared"}));
  for (const char* bad : {"\"/var/lib/lamina\"", "\"/var/lib\"", "\"/\"", "\"/var/lib/lamina/jobs\"",
                          "\"/var/lib/lamina/uploads/x\""}) {
    const std::string e = error_of(fmt::format("[jobs]\nroots = [{}]\n", bad));
    EXPECT_NE(e.find("test.toml:2: [jobs] roots:"), std::string::npos) << e;
    EXPECT_NE(e.find("state directory"), std::string::npos) << e;
  }
  EXPECT_NE(error_of("[jobs]\nroots = \"/srv/parts\"\n").find("expected a list of folders"), std::string::npos);
  EXPECT_NE(error_of("[jobs]\nroots = [\"\"]\n").find("non-empty"), std::string::npos);
  EXPECT_NE(error_of("[planner]\nmemory_limit_mb = 100\n").find("at least 256"), std::string::npos);
  EXPECT_NE(error_of("[planner]\nnice = 20\n").find("[planner] nice: 20 is out of range [0, 19]"), std::string::npos);
}

// The web console (issue 19): on at 127.0.0.1:8080 unless turned off; another machine may reach
// it only once it has users and logins, which it has not yet.
TEST(DaemonConfig, TheWebConsoleListensOnLoopbackOnlyWithoutUsers) {
  auto on = parse_daemon_config("[http]\nlisten = \"127.0.0.1:9090\"\nstatic_dir = \"web\"\n", "/etc/lamina/x.toml");
  ASSERT_TRUE(on.has_value()) << on.error().message;
  EXPECT_EQ(on->http.host, "127.0.0.1");
  EXPECT_EQ(on->http.port, 9090);
  EXPECT_EQ(on->http.static_dir, "/etc/lamina/web");
  auto off = parse_daemon_config("[http]\nlisten = \"\"\n", "x.toml");
  ASSERT_TRUE(off.has_value()) << off.error().message;
  EXPECT_FALSE(off->http.host);
  const std::string wide = error_of("[http]\nlisten = \"0.0.0.0:8080\"\n");
  EXPECT_NE(wide.find("test.toml:2: [http] listen: 0.0.0.0 is not a loopback address; without [[http.users]]"),
            std::string::npos)
      << wide;
  EXPECT_NE(error_of("[http]\nlisten = \"8080\"\n").find("[http] listen: expected \"HOST:PORT\""), std::string::npos);
  EXPECT_NE(error_of("[http]\nmax_connections = 0\n").find("[http] max_connections"), std::string::npos);
}

const std::string kHash = "$argon2id$v=19$m=65536,t=2,p=1$Bcj9sax4waBzCIk+PcmmHg$O43CmjaxoLxIl9IsDJlYts+dL6q/p/tqaSwAspBVZ5c";

std::string user_entry(const std::string& name, const std::string& role, const std::string& hash = kHash) {
  return "[[http.users]]\nname = \"" + name + "\"\nrole = \"" + role + "\"\npassword_hash = \"" + hash + "\"\n";
}

TEST(DaemonConfig, WebUsersLetTheConsoleListenOnAnyAddress) {
  auto c = parse_daemon_config("[http]\nlisten = \"0.0.0.0:8080\"\nsession_hours = 8\nserver_names = [\"cell-7\"]\n" +
                                   user_entry("ana", "operator") + user_entry("eng", "engineer") +
                                   user_entry("vic", "viewer"),
                               "x.toml");
  ASSERT_TRUE(c.has_value()) << c.error().message;
  EXPECT_EQ(c->http.host, "0.0.0.0");
  ASSERT_EQ(c->http.users.size(), 3U);
  EXPECT_EQ(c->http.users[0].name, "ana");
  EXPECT_EQ(c->http.users[0].role, Role::machine_operator);
  EXPECT_EQ(c->http.users[1].role, Role::engineer);
  EXPECT_EQ(c->http.users[2].role, Role::viewer);
  EXPECT_EQ(c->http.users[0].password_hash, kHash);
  EXPECT_EQ(c->http.session_hours, 8);
  EXPECT_EQ(c->http.server_names, std::vector<std::string>{"cell-7"});
}

TEST(DaemonConfig, HttpsTakesACertificateAndItsKeyTogether) {
  auto c = parse_daemon_config("[http]\ntls_cert = \"tls/cell.crt\"\ntls_key = \"/etc/ssl/private/cell.key\"\n",
                               "/etc/lamina/lamina.toml");
  ASSERT_TRUE(c.has_value()) << c.error().message;
  EXPECT_EQ(c->http.tls_cert, "/etc/lamina/tls/cell.crt");  // from the file's folder, as every path
  EXPECT_EQ(c->http.tls_key, "/etc/ssl/private/cell.key");
  const std::string alone = error_of("[http]\ntls_cert = \"cell.crt\"\n");
  EXPECT_NE(alone.find("test.toml:2: [http] tls_cert: tls_cert and tls_key go together"), std::string::npos) << alone;
  const std::string key_only = error_of("[http]\nlisten = \"127.0.0.1:8443\"\ntls_key = \"cell.key\"\n");
  EXPECT_NE(key_only.find("test.toml:3: [http] tls_key: tls_cert and tls_key go together"), std::string::npos)
      << key_only;
}

TEST(DaemonConfig, AWebUserWithAWrongRoleHashOrNameIsAnErrorAtItsLine) {
  const std::string role = error_of("[http]\n" + user_entry("ana", "admin"));
  EXPECT_NE(role.find("test.toml:4: [http.users] role: \"admin\" is not one of viewer, operator, engineer"),
            std::string::npos)
      << role;
  const std::string plain = error_of("[http]\n" + user_entry("ana", "operator", "hunter2"));
  EXPECT_NE(plain.find("[http.users] password_hash: expected an Argon2id hash"), std::string::npos) << plain;
  const std::string twice = error_of("[http]\n" + user_entry("ana", "operator") + user_entry("ana", "viewer"));
  EXPECT_NE(twice.find("test.toml:7: [http.users] name: 'ana' is named twice"), std::string::npos) << twice;
  const std::string blank = error_of("[http]\n" + user_entry("a b", "viewer"));
  EXPECT_NE(blank.find("[http.users] name: expected a name"), std::string::npos) << blank;
  const std::string key = error_of("[http]\n[[http.users]]\nname = \"x\"\nrole = \"viewer\"\npassword = \"p\"\n");
  EXPECT_NE(key.find("[http.users] password: unknown key (known: name, role, password_hash)"), std::string::npos) << key;
}

TEST(DaemonConfig, AnEmptyFileKeepsTheDefaults) {
  auto c = parse_daemon_config("", "empty.toml");
  ASSERT_TRUE(c.has_value()) << c.error().message;
  expect_same(*c, DaemonConfig{});
}

TEST(DaemonConfig, UnknownKeysAndSectionsAreErrorsAtTheirLine) {
  const std::string key = error_of("[server]\nsocket = \"/run/x.sock\"\nsockt_mode = \"0660\"\n");
  EXPECT_NE(key.find("test.toml:3: [server] sockt_mode: unknown key (known: socket, socket_mode,"), std::string::npos)
      << key;
  const std::string section = error_of("state_dir = \"/x\"\n\n[srever]\nsocket = \"/y\"\n");
  EXPECT_NE(section.find("test.toml:3: [srever]: unknown section"), std::string::npos) << section;
  const std::string top = error_of("# a comment\nstatedir = \"/x\"\n");
  EXPECT_NE(top.find("test.toml:2: statedir: unknown key"), std::string::npos) << top;
  const std::string cell = error_of("[cell]\nenabled = true\npressure_mpa = 380\n");
  EXPECT_NE(cell.find("test.toml:3: [cell] pressure_mpa: unknown key (known: enabled, modbus,"), std::string::npos) << cell;
}

TEST(DaemonConfig, WrongTypesAreErrorsAtTheirLine) {
  const std::string baud = error_of("[link]\nport = \"/dev/ttyUSB0\"\nbaud = \"fast\"\n");
  EXPECT_NE(baud.find("test.toml:3: [link] baud: expected a whole number"), std::string::npos) << baud;
  const std::string enabled = error_of("[cell]\nenabled = \"yes\"\n");
  EXPECT_NE(enabled.find("test.toml:2: [cell] enabled: expected true or false"), std::string::npos) << enabled;
  const std::string workers = error_of("[planner]\n\nworkers = 1.5\n");
  EXPECT_NE(workers.find("test.toml:3: [planner] workers:"), std::string::npos) << workers;
  const std::string server = error_of("server = 1\n");
  EXPECT_NE(server.find("test.toml:1: server: expected a table"), std::string::npos) << server;
  const std::string socket = error_of("[server]\nsocket = 7\n");
  EXPECT_NE(socket.find("test.toml:2: [server] socket: expected a string"), std::string::npos) << socket;
}

TEST(DaemonConfig, ValuesOutOfRangeAreErrors) {
  EXPECT_NE(error_of("[link]\nstatus_hz = 0\n").find("test.toml:2: [link] status_hz: 0 is out of range [0.5, 50]"),
            std::string::npos);
  EXPECT_NE(error_of("[link]\nbaud = 100\n").find("[link] baud: 100 is out of range"), std::string::npos);
  EXPECT_NE(error_of("[cell]\npump_ready_timeout_s = 0\n").find("[cell] pump_ready_timeout_s: 0 is out of range (0,"),
            std::string::npos);
  EXPECT_NE(error_of("[cell]\npressure_setpoint_mpa = 6200\n").find("[cell] pressure_setpoint_mpa"), std::string::npos);
  EXPECT_NE(error_of("[planner]\nworkers = 0\n").find("[planner] workers: 0 is out of range [1, 64]"), std::string::npos);
  EXPECT_NE(error_of("[server]\nmax_request_bytes = -1\n").find("[server] max_request_bytes"), std::string::npos);
  EXPECT_NE(error_of("state_dir = \"\"\n").find("test.toml:1: state_dir: must not be empty"), std::string::npos);
  EXPECT_NE(error_of("[server]\nsocket = \"/" + std::string(120, 's') + "\"\n").find("[server] socket:"),
            std::string::npos);
  // Edges that are allowed.
  auto c = parse_daemon_config("[link]\nstatus_hz = 50\nbaud = 4000000\n[cell]\nabrasive_g_per_min = 0\n", "t.toml");
  ASSERT_TRUE(c.has_value()) << c.error().message;
  EXPECT_EQ(c->link.status_hz, 50);
  EXPECT_EQ(c->cell.abrasive_g_per_min, 0);
}

TEST(DaemonConfig, SocketModeIsAnOctalString) {
  const std::string expected = "test.toml:3: [server] socket_mode: expected an octal string like \"0660\"";
  EXPECT_EQ(error_of("[server]\nsocket = \"/run/x.sock\"\nsocket_mode = 660\n"), expected);
  EXPECT_EQ(error_of("[server]\nsocket = \"/run/x.sock\"\nsocket_mode = \"0968\"\n"), expected);
  EXPECT_EQ(error_of("[server]\nsocket = \"/run/x.sock\"\nsocket_mode = \"4660\"\n"), expected);
  EXPECT_EQ(error_of("[server]\nsocket = \"/run/x.sock\"\nsocket_mode = \"rw-rw----\"\n"), expected);
  for (const auto& [text, mode] : {std::pair{"0600", 0600u}, std::pair{"660", 0660u}, std::pair{"0777", 0777u}}) {
    auto c = parse_daemon_config(std::string("[server]\nsocket_mode = \"") + text + "\"\n", "t.toml");
    ASSERT_TRUE(c.has_value()) << c.error().message;
    EXPECT_EQ(c->server.socket_mode, mode) << text;
  }
}

TEST(DaemonConfig, TcpNeedsAToken) {
  const std::string e = error_of("[server]\ntcp = \"127.0.0.1:7400\"\n");
  EXPECT_NE(e.find("test.toml:2: [server] tcp: TCP needs a token"), std::string::npos) << e;
  EXPECT_NE(error_of("[server]\ntcp = \"7400\"\ntoken = \"s3cret\"\n").find("test.toml:2: [server] tcp: expected \"HOST:PORT\""),
            std::string::npos);
  EXPECT_NE(error_of("[server]\ntcp = \"host:70000\"\ntoken = \"s3cret\"\n").find("[server] tcp:"), std::string::npos);

  auto c = parse_daemon_config("[server]\ntcp = \"0.0.0.0:7400\"\ntoken = \"s3cret\"\n", "t.toml");
  ASSERT_TRUE(c.has_value()) << c.error().message;
  EXPECT_EQ(c->server.tcp_host, "0.0.0.0");
  EXPECT_EQ(c->server.tcp_port, 7400);
  EXPECT_EQ(c->server.token, "s3cret");
  auto v6 = parse_daemon_config("[server]\ntcp = \"[::1]:7401\"\ntoken = \"s3cret\"\n", "t.toml");
  ASSERT_TRUE(v6.has_value()) << v6.error().message;
  EXPECT_EQ(v6->server.tcp_host, "::1");
  EXPECT_EQ(v6->server.tcp_port, 7401);
}

TEST(DaemonConfig, TheTokenComesFromTheTokenFile) {
  ScratchDir dir;
  dir.write("etc/token", "  t0ken-from-file\n");
  dir.write("etc/empty-token", "\n\n");
  const auto file = dir.write("etc/lamina.toml", "[server]\ntcp = \"127.0.0.1:7400\"\ntoken_file = \"token\"\n");
  auto c = load_daemon_config(file);
  ASSERT_TRUE(c.has_value()) << c.error().message;
  EXPECT_EQ(c->server.token, "t0ken-from-file");

  const auto missing = dir.write("etc/missing.toml", "[server]\n\ntoken_file = \"no-such-token\"\n");
  auto m = load_daemon_config(missing);
  ASSERT_FALSE(m.has_value());
  EXPECT_NE(m.error().message.find(missing.string() + ":3: [server] token_file: cannot read " +
                                   (dir.path() / "etc/no-such-token").string()),
            std::string::npos)
      << m.error().message;

  auto empty = load_daemon_config(dir.write("etc/e.toml", "[server]\ntoken_file = \"empty-token\"\n"));
  ASSERT_FALSE(empty.has_value());
  EXPECT_NE(empty.error().message.find(":2: [server] token_file:"), std::string::npos) << empty.error().message;
  EXPECT_NE(empty.error().message.find("is empty"), std::string::npos) << empty.error().message;

  auto both = load_daemon_config(dir.write("etc/b.toml", "[server]\ntoken = \"x\"\ntoken_file = \"token\"\n"));
  ASSERT_FALSE(both.has_value());
  EXPECT_NE(both.error().message.find("token or token_file, not both"), std::string::npos) << both.error().message;
}

TEST(DaemonConfig, ProtocolMustBeKnown) {
  const std::string e = error_of("[link]\nprotocol = \"marlin\"\n");
  EXPECT_NE(e.find("test.toml:2: [link] protocol: \"marlin\" is not one of grbl, send-response, xonxoff, modbus"),
            std::string::npos)
      << e;
  for (const char* p : {"grbl", "send-response", "xonxoff"}) {
    auto c = parse_daemon_config(std::string("[link]\nprotocol = \"") + p + "\"\n", "t.toml");
    ASSERT_TRUE(c.has_value()) << p << ": " << c.error().message;
    EXPECT_EQ(c->link.protocol, p);
  }
}

TEST(DaemonConfig, TheLinkIsReachedOneWay) {
  const std::string both = error_of("[link]\nport = \"/dev/ttyUSB0\"\ntcp = \"10.0.0.5:23\"\n");
  EXPECT_NE(both.find("test.toml:3: [link] tcp: give port (serial) or tcp"), std::string::npos) << both;
  // The Modbus mailbox goes through the PLC at [cell] modbus: port/tcp would be ignored.
  const std::string mailbox_port = error_of("[link]\nprotocol = \"modbus\"\nport = \"/dev/ttyUSB0\"\n");
  EXPECT_NE(mailbox_port.find("test.toml:3: [link] port: protocol \"modbus\""), std::string::npos) << mailbox_port;
  const std::string no_cell = error_of("[link]\nprotocol = \"modbus\"\n[cell]\nenabled = false\n");
  EXPECT_NE(no_cell.find("test.toml:2: [link] protocol:"), std::string::npos) << no_cell;
  auto ok = parse_daemon_config("[link]\nprotocol = \"modbus\"\n[cell]\nmodbus = \"10.0.0.9:502\"\n", "t.toml");
  ASSERT_TRUE(ok.has_value()) << ok.error().message;
  EXPECT_EQ(ok->cell.modbus, "10.0.0.9:502");
  auto tcp = parse_daemon_config("[link]\ntcp = \"10.0.0.5:23\"\n", "t.toml");
  ASSERT_TRUE(tcp.has_value()) << tcp.error().message;
  EXPECT_EQ(tcp->link.tcp, "10.0.0.5:23");
}

TEST(DaemonConfig, TheCellNeedsItsPlcAddressWhenEnabled) {
  EXPECT_NE(error_of("[cell]\nmodbus = \"\"\n").find("test.toml:2: [cell] modbus:"), std::string::npos);
  EXPECT_NE(error_of("[cell]\nmodbus = \"plc\"\n").find("test.toml:2: [cell] modbus: expected \"HOST:PORT\""),
            std::string::npos);
  EXPECT_NE(error_of("[cell]\nmodbus = \"plc:0\"\n").find("[cell] modbus: expected"), std::string::npos);
  EXPECT_NE(error_of("[cell]\nmodbus = \"::1:502\"\n").find("[cell] modbus: expected"), std::string::npos)
      << "an IPv6 host needs its brackets";
  EXPECT_NE(error_of("[cell]\nmodbus_unit = 256\n").find("test.toml:2: [cell] modbus_unit: 256 is out of range"),
            std::string::npos);
  EXPECT_NE(error_of("[cell]\nmodbus_timeout_s = 0\n").find("[cell] modbus_timeout_s"), std::string::npos);
  EXPECT_NE(error_of("[cell]\nmodbus_reconnects = -1\n").find("[cell] modbus_reconnects"), std::string::npos);
  // A PLC behind a gateway: its address, unit id and patience.
  auto gw = parse_daemon_config("[cell]\nmodbus = \"[fd00::7]:1502\"\nmodbus_unit = 17\nmodbus_timeout_s = 1.5\n"
                                "modbus_reconnects = 0\n", "t.toml");
  ASSERT_TRUE(gw.has_value()) << gw.error().message;
  EXPECT_EQ(gw->cell.modbus, "[fd00::7]:1502");
  EXPECT_EQ(gw->cell.modbus_unit, 17);
  EXPECT_EQ(gw->cell.modbus_timeout_s, 1.5);
  EXPECT_EQ(gw->cell.modbus_reconnects, 0);
  auto off = parse_daemon_config("[cell]\nenabled = false\nmodbus = \"\"\n", "t.toml");
  ASSERT_TRUE(off.has_value()) << off.error().message;
  EXPECT_FALSE(off->cell.enabled);
}

TEST(DaemonConfig, RelativePathsStartAtTheFilesFolder) {
  ScratchDir dir;
  dir.write("cfg/token", "abc\n");
  const auto file = dir.write("cfg/lamina.toml",
                              "state_dir = \"state\"\n[server]\nsocket = \"run/l.sock\"\ntoken_file = \"token\"\n"
                              "[planner]\nlamina = \"../bin/lamina\"\nmachine = \"machine.toml\"\n"
                              "materials = \"/abs/materials.toml\"\n");
  auto c = load_daemon_config(file);
  ASSERT_TRUE(c.has_value()) << c.error().message;
  EXPECT_EQ(c->state_dir, dir.path() / "cfg/state");
  EXPECT_EQ(c->server.socket_path, (dir.path() / "cfg/run/l.sock").string());
  EXPECT_EQ(c->server.token, "abc");
  EXPECT_EQ(c->planner.lamina_path, (dir.path() / "bin/lamina").string());
  EXPECT_EQ(c->planner.machine_file, (dir.path() / "cfg/machine.toml").string());
  EXPECT_EQ(c->planner.materials_file, "/abs/materials.toml");
  // Parsed from text: relative to the folder of the name given.
  auto t = parse_daemon_config("state_dir = \"state\"\n", "/etc/lamina/lamina.toml");
  ASSERT_TRUE(t.has_value()) << t.error().message;
  EXPECT_EQ(t->state_dir, "/etc/lamina/state");
}

TEST(DaemonConfig, OfSeveralMistakesTheFirstInTheFileIsReported) {
  // toml++ walks keys alphabetically; a person reads top down.
  EXPECT_EQ(error_of("x = 1\n[foo]\n").rfind("test.toml:1: x: unknown key", 0), 0u);
  EXPECT_EQ(error_of("[link]\nbaud = 1\n[cell]\nmodbus = \"x\"\n[server]\nsockt = 1\n").rfind("test.toml:2: [link] baud", 0), 0u);
  EXPECT_EQ(error_of("[server]\nsockt = 1\n[link]\nbaud = 1\n").rfind("test.toml:2: [server] sockt", 0), 0u);
  // A token file that cannot be read is the mistake, not the TCP listener left without a token.
  const std::string token = error_of("[server]\ntcp = \"127.0.0.1:7400\"\ntoken_file = \"/nonexistent/token\"\n");
  EXPECT_EQ(token.rfind("test.toml:3: [server] token_file: cannot read /nonexistent/token", 0), 0u) << token;
}

TEST(DaemonConfig, SyntaxErrorsAndMissingFilesAreErrors) {
  const std::string e = error_of("[server]\nsocket = \"/run/x.sock\n");
  EXPECT_EQ(e.rfind("test.toml:2: ", 0), 0u) << e;
  const std::string mode = error_of("[server]\nsocket_mode = 0660\n");
  EXPECT_EQ(mode.rfind("test.toml:2: ", 0), 0u) << mode;
  EXPECT_NE(mode.find("\"0660\""), std::string::npos) << mode;
  auto missing = load_daemon_config("/nonexistent/lamina.toml");
  ASSERT_FALSE(missing.has_value());
  EXPECT_NE(missing.error().message.find("/nonexistent/lamina.toml"), std::string::npos) << missing.error().message;
}

}  // namespace
