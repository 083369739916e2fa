#include "lamina/daemon/daemon_config.hpp"

#include "lamina/drivers/modbus_endpoint.hpp"
#include "http/passwords.hpp"

#include <fmt/format.h>
#include <sys/un.h>
#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <span>
#include <sstream>
#include <string_view>
#include <utility>

namespace lamina::daemon {
namespace {

namespace fs = std::filesystem;
using namespace std::string_view_literals;

// Bounds of a number; `open_min`: the minimum itself is not allowed (a period or a timeout of 0).
struct Bounds {
  double min, max;
  bool open_min = false;
};

std::string describe(const Bounds& b) { return fmt::format("{}{}, {}]", b.open_min ? '(' : '[', b.min, b.max); }

std::string join(std::span<const std::string_view> names) {
  std::string out;
  for (const auto n : names) out += (out.empty() ? "" : ", ") + std::string(n);
  return out;
}

// The whole file, or why not (the message is completed by the caller, who knows which key).
std::expected<std::string, std::string> read_file(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::unexpected(fmt::format("cannot read {} ({})", file.string(), std::strerror(errno)));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return std::unexpected(fmt::format("cannot read {}", file.string()));
  return text.str();
}

std::string trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  return std::string(s.substr(first, s.find_last_not_of(" \t\r\n") - first + 1));
}

// Reading one file: where messages point, the folder relative paths start from, and the error
// reported. One precise message beats a cascade; of several, the one nearest the top of the file
// (toml++ walks a table in key order, not in line order, and a person reads top down).
class Reader {
 public:
  Reader(std::string source, fs::path base) : source_(std::move(source)), base_(std::move(base)) {}

  void fail(const toml::source_region& where, std::string_view section, std::string_view key, std::string_view what) {
    const auto line = where.begin.line;
    if (error_ && (line == 0 || (error_line_ != 0 && error_line_ <= line))) return;
    const std::string name = section.empty() ? std::string(key) : fmt::format("[{}] {}", section, key);
    const std::string at = line == 0 ? source_ : fmt::format("{}:{}", source_, line);  // 0: no line known
    error_ = ConfigError{fmt::format("{}: {}: {}", at, name, what)};
    error_line_ = line;
  }
  bool failed() const { return error_.has_value(); }
  const ConfigError& error() const { return *error_; }

  // Relative to the configuration file's folder, as a user reading the file would expect
  // (laminad's working directory under systemd is /, which nobody means).
  std::string resolve(const std::string& path) const {
    const fs::path p(path);
    if (p.empty() || p.is_absolute()) return path;
    return (base_ / p).lexically_normal().string();
  }

 private:
  std::string source_;
  fs::path base_;
  std::optional<ConfigError> error_;
  toml::source_index error_line_ = 0;
};

// One table of the file: the keys it may hold (anything else is an error, so that a typo never
// silently leaves a default in force) and typed getters that keep the default when a key is absent.
class Section {
 public:
  Section(Reader& r, std::string_view name, const toml::table* table, std::span<const std::string_view> known,
          bool check_keys = true)
      : r_(r), name_(name), table_(table) {
    if (!table_ || !check_keys) return;
    for (const auto& [key, node] : *table_) {
      bool ok = false;
      for (const auto k : known) ok = ok || key.str() == k;
      if (!ok) r_.fail(key.source(), name_, key.str(), fmt::format("unknown key (known: {})", join(known)));
    }
  }

  const toml::node* node(std::string_view key) const { return table_ ? table_->get(key) : nullptr; }

  // The key's line when it is in the file, else the section header's (a key that is missing).
  void fail(std::string_view key, std::string_view what) {
    const toml::node* n = node(key);
    r_.fail(n ? n->source() : table_ ? table_->source() : toml::source_region{}, name_, key, what);
  }

  // False when the key is there but not a string.
  bool string(std::string_view key, std::string& out) {
    const toml::node* n = node(key);
    if (!n) return true;
    const auto* s = n->as_string();
    if (!s) fail(key, "expected a string");
    else out = s->get();
    return s != nullptr;
  }

  void resolve(std::string& path) const { path = r_.resolve(path); }

  void path(std::string_view key, std::string& out) {
    std::string text = out;
    if (string(key, text) && node(key)) out = r_.resolve(text);
  }

  void boolean(std::string_view key, bool& out) {
    const toml::node* n = node(key);
    if (!n) return;
    if (const auto* b = n->as_boolean()) out = b->get();
    else fail(key, "expected true or false");
  }

  template <typename T>
  void integer(std::string_view key, T& out, std::int64_t min, std::int64_t max) {
    const toml::node* n = node(key);
    if (!n) return;
    const auto* i = n->as_integer();
    if (!i) return fail(key, fmt::format("expected a whole number in [{}, {}]", min, max));
    if (i->get() < min || i->get() > max)
      return fail(key, fmt::format("{} is out of range [{}, {}]", i->get(), min, max));
    out = static_cast<T>(i->get());
  }

  void number(std::string_view key, double& out, const Bounds& b) {
    const toml::node* n = node(key);
    if (!n) return;
    std::optional<double> v;
    if (const auto* i = n->as_integer()) v = static_cast<double>(i->get());
    if (const auto* f = n->as_floating_point()) v = f->get();
    if (!v) return fail(key, fmt::format("expected a number in {}", describe(b)));
    if (!std::isfinite(*v) || *v < b.min || *v > b.max || (b.open_min && *v == b.min))
      return fail(key, fmt::format("{} is out of range {}", *v, describe(b)));
    out = *v;
  }

  // "" (not set) or HOST:PORT.
  void host_port(std::string_view key, std::string& out) {
    std::string text = out;
    if (!string(key, text) || !node(key)) return;
    if (!text.empty() && !drivers::parse_host_port(text)) return fail(key, "expected \"HOST:PORT\" (\"[::1]:PORT\" for IPv6)");
    out = text;
  }

 private:
  Reader& r_;
  std::string_view name_;
  const toml::table* table_;
};

constexpr std::array kRootKeys{"state_dir"sv};
constexpr std::array kSections{"server"sv, "http"sv, "link"sv, "cell"sv, "planner"sv, "jobs"sv};
constexpr std::array kServerKeys{"socket"sv,        "socket_mode"sv,       "socket_group"sv,
                                 "tcp"sv,           "token"sv,             "token_file"sv,
                                 "max_request_bytes"sv, "max_clients"sv,   "idle_timeout_s"sv,
                                 "pre_auth_timeout_s"sv};
constexpr std::array kHttpKeys{"listen"sv,        "static_dir"sv,      "idle_timeout_s"sv, "max_connections"sv,
                               "users"sv,         "session_hours"sv,   "server_names"sv,   "allowed_origins"sv,
                               "tls_cert"sv,      "tls_key"sv};
constexpr std::array kWebUserKeys{"name"sv, "role"sv, "password_hash"sv};
constexpr std::array kLinkKeys{"protocol"sv, "port"sv, "tcp"sv, "baud"sv, "rx_buffer"sv, "status_hz"sv, "stall_margin_s"sv};
constexpr std::array kCellKeys{"enabled"sv, "modbus"sv, "modbus_unit"sv, "modbus_timeout_s"sv,
                               "modbus_reconnects"sv, "heartbeat_period_s"sv, "pump_ready_timeout_s"sv,
                               "pressure_setpoint_mpa"sv, "abrasive_g_per_min"sv, "hold_limit_s"sv,
                               "jet_restart_s"sv, "idle_poll_s"sv};
constexpr std::array kPlannerKeys{"lamina"sv,    "workers"sv,          "machine"sv,     "materials"sv,
                                  "timeout_s"sv, "memory_limit_mb"sv, "cpu_limit_s"sv, "nice"sv};
constexpr std::array kJobsKeys{"roots"sv, "max_model_bytes"sv, "max_stock_file_bytes"sv, "upload_idle_s"sv,
                               "max_uploads"sv};

// token, or token_file's contents; false when token_file was given and could not be used.
bool read_token(Section& s, ServerConfig& c) {
  s.string("token", c.token);
  std::string token_file;
  s.path("token_file", token_file);
  if (token_file.empty()) return true;
  // A file keeps the secret out of lamina.toml, which everyone may read (the token: root:lamina 0640).
  if (!c.token.empty()) {
    s.fail("token_file", "give token or token_file, not both");
    return false;
  }
  auto text = read_file(token_file);
  if (!text) {
    s.fail("token_file", text.error());
    return false;
  }
  c.token = trim(*text);
  if (c.token.empty()) s.fail("token_file", fmt::format("{} is empty", token_file));
  return !c.token.empty();
}

void read_server(Section s, ServerConfig& c) {
  s.path("socket", c.socket_path);
  if (s.node("socket")) {
    if (c.socket_path.empty()) s.fail("socket", "must not be empty");
    // The kernel's limit for a Unix socket's path (sun_path, with its terminating NUL).
    else if (c.socket_path.size() >= sizeof(sockaddr_un::sun_path))
      s.fail("socket", fmt::format("{} is {} bytes long, a Unix socket's path can have at most {}", c.socket_path,
                                   c.socket_path.size(), sizeof(sockaddr_un::sun_path) - 1));
  }

  // A string: TOML refuses 0660 (no leading zeros), 660 would be decimal and 0o660 is easily forgotten.
  if (const auto* n = s.node("socket_mode")) {
    const auto* text = n->as_string();
    const std::string_view m = text ? std::string_view(text->get()) : std::string_view{};
    const bool octal = (m.size() == 3 || (m.size() == 4 && m.front() == '0')) &&
                       m.find_first_not_of("01234567") == std::string_view::npos;
    if (!octal) s.fail("socket_mode", "expected an octal string like \"0660\"");
    else c.socket_mode = static_cast<unsigned>(std::stoul(std::string(m), nullptr, 8));
  }
  s.string("socket_group", c.socket_group);

  std::string tcp;
  s.host_port("tcp", tcp);
  if (const auto hp = drivers::parse_host_port(tcp)) {
    c.tcp_host = hp->first;
    c.tcp_port = hp->second;
  }

  // TCP reaches beyond this host's users and groups: only a token tells clients apart there.
  // (Not said when the token file failed: that message is the one that helps.)
  if (read_token(s, c) && c.tcp_host && c.token.empty()) s.fail("tcp", "TCP needs a token (set token or token_file)");
  s.integer("max_request_bytes", c.max_request_bytes, 1024, std::int64_t{1} << 30);
  s.integer("max_clients", c.max_clients, 1, 4096);
  s.number("idle_timeout_s", c.idle_timeout_s, {0, 7 * 24 * 3600});
  s.number("pre_auth_timeout_s", c.pre_auth_timeout_s, {0.1, 600});
}

// [[http.users]]: each a name, a role and an Argon2id hash; names are unique.
void read_web_users(Reader& r, Section& s, std::vector<WebUser>& users) {
  const toml::node* n = s.node("users");
  if (!n) return;
  const auto* list = n->as_array();
  if (!list) return s.fail("users", "expected [[http.users]] tables (name, role, password_hash)");
  for (const toml::node& entry : *list) {
    const auto* table = entry.as_table();
    if (!table) return s.fail("users", "expected [[http.users]] tables (name, role, password_hash)");
    Section u(r, "http.users", table, kWebUserKeys);
    // A misspelt key is the message that helps, not the key then found missing.
    const bool misspelt = std::any_of(table->begin(), table->end(), [](const auto& kv) {
      return std::find(kWebUserKeys.begin(), kWebUserKeys.end(), kv.first.str()) == kWebUserKeys.end();
    });
    if (misspelt) continue;
    WebUser user;
    std::string role;
    u.string("name", user.name);
    u.string("role", role);
    u.string("password_hash", user.password_hash);
    if (user.name.empty() || user.name.size() > 64 || user.name.find_first_of(" \t\r\n:") != std::string::npos)
      u.fail("name", "expected a name of 1-64 characters without spaces or ':'");
    for (const WebUser& other : users)
      if (other.name == user.name) u.fail("name", fmt::format("'{}' is named twice", user.name));
    if (const auto parsed = role_from_name(role)) user.role = *parsed;
    else u.fail("role", fmt::format("\"{}\" is not one of viewer, operator, engineer", role));
    if (auto ok = http::check_password_hash(user.password_hash); !ok) u.fail("password_hash", ok.error());
    users.push_back(std::move(user));
  }
}

void read_strings(Section& s, std::string_view key, std::vector<std::string>& out) {
  const toml::node* n = s.node(key);
  if (!n) return;
  const auto* list = n->as_array();
  if (!list) return s.fail(key, "expected an array of strings");
  out.clear();
  for (const toml::node& item : *list) {
    if (!item.is_string()) return s.fail(key, "expected an array of strings");
    out.push_back(item.as_string()->get());
  }
}

bool is_loopback_host(const std::string& host) { return host == "127.0.0.1" || host == "::1" || host == "localhost"; }

void read_http(Reader& r, Section s, HttpConfig& c) {
  std::string listen = fmt::format("{}:{}", c.host.value_or(""), c.port);
  s.host_port("listen", listen);
  if (listen.empty()) c.host.reset();
  read_web_users(r, s, c.users);
  if (const auto hp = drivers::parse_host_port(listen)) {
    c.host = hp->first;
    c.port = hp->second;
    if (!is_loopback_host(*c.host) && c.users.empty())
      s.fail("listen", fmt::format("{} is not a loopback address; without [[http.users]] the console is served to this "
                                   "machine only (add users, each with a role and a password hash)",
                                   *c.host));
  }
  s.path("static_dir", c.static_dir);
  s.number("idle_timeout_s", c.idle_timeout_s, {0.1, 3600});
  s.integer("max_connections", c.max_connections, 1, 4096);
  s.number("session_hours", c.session_hours, {0.01, 24 * 31});
  read_strings(s, "server_names", c.server_names);
  read_strings(s, "allowed_origins", c.allowed_origins);
  s.path("tls_cert", c.tls_cert);
  s.path("tls_key", c.tls_key);
  if (c.tls_cert.empty() != c.tls_key.empty())
    s.fail(c.tls_cert.empty() ? "tls_key" : "tls_cert", "tls_cert and tls_key go together (the certificate and its key)");
}

void read_link(Section s, MachineLinkConfig& c) {
  s.string("protocol", c.protocol);
  if (!drivers::find_link_protocol(c.protocol))
    s.fail("protocol", fmt::format("\"{}\" is not one of {}", c.protocol, drivers::link_protocol_names_text()));
  s.string("port", c.port);
  s.host_port("tcp", c.tcp);
  s.integer("baud", c.baud, 300, 4'000'000);
  s.integer("rx_buffer", c.rx_buffer, 0, 65536);
  s.number("status_hz", c.status_hz, {0.5, 50});
  s.number("stall_margin_s", c.stall_margin_s, {0.5, 600});
}

void read_cell(Section s, CellConfig& c) {
  s.boolean("enabled", c.enabled);
  s.host_port("modbus", c.modbus);
  if (c.enabled && c.modbus.empty()) s.fail("modbus", "the PLC's address \"HOST:PORT\" is needed when enabled = true");
  s.integer("modbus_unit", c.modbus_unit, 0, 255);  // Modbus TCP: 1…247, 0 and 255 for a PLC that ignores it
  s.number("modbus_timeout_s", c.modbus_timeout_s, {0.01, 10});
  s.integer("modbus_reconnects", c.modbus_reconnects, 0, 100);
  s.number("heartbeat_period_s", c.heartbeat_period_s, {0.01, 10});
  s.number("idle_poll_s", c.idle_poll_s, {0, 60});  // 0: the PLC is read between cuts only on request
  s.number("pump_ready_timeout_s", c.pump_ready_timeout_s, {0, 600, true});
  // The PLC takes the set point in 0.1 MPa in a 16-bit register; real pumps stop well below.
  s.number("pressure_setpoint_mpa", c.pressure_setpoint_mpa, {0, 1000, true});
  s.number("abrasive_g_per_min", c.abrasive_g_per_min, {0, 10000});  // 0: pure water jet
  s.number("hold_limit_s", c.hold_limit_s, {1, 86400});
  s.number("jet_restart_s", c.jet_restart_s, {0, 60});
}

void read_planner(Section s, PlannerConfig& c) {
  s.path("lamina", c.lamina_path);
  s.integer("workers", c.workers, 1, 64);
  s.path("machine", c.machine_file);
  s.path("materials", c.materials_file);
  s.number("timeout_s", c.timeout_s, {0, 7 * 24 * 3600, true});
  s.integer("memory_limit_mb", c.memory_limit_mb, 0, std::int64_t{1} << 30);
  if (c.memory_limit_mb != 0 && c.memory_limit_mb < 256) s.fail("memory_limit_mb", "0 (none) or at least 256");
  s.number("cpu_limit_s", c.cpu_limit_s, {0, 7 * 24 * 3600});
  s.integer("nice", c.nice, 0, 19);
}

// A root at or above the state directory, or inside its jobs/ or uploads/, would let a client
// plan the job database or another job's files.
bool holds_state(const fs::path& root, const fs::path& state_dir) {
  const fs::path r = (root / "").lexically_normal(), st = (state_dir / "").lexically_normal();
  const fs::path below = st.lexically_relative(r);  // state_dir seen from the root
  if (!below.empty() && *below.begin() != "..") return true;
  const fs::path inside = r.lexically_relative(st);
  if (inside.empty() || *inside.begin() == "..") return false;
  return *inside.begin() == "jobs" || *inside.begin() == "uploads";
}

// The folders a client may name files in. Absolute and distinct from the state directory's
// own files: a root there would let a client plan another job's artefacts or the database.
void read_jobs(Section s, JobsConfig& c, const fs::path& state_dir) {
  if (const auto* n = s.node("roots")) {
    const auto* list = n->as_array();
    if (!list) return s.fail("roots", "expected a list of folders, e.g. [\"/srv/lamina/parts\"]");
    for (const auto& item : *list) {
      const auto* text = item.as_string();
      if (!text || text->get().empty()) return s.fail("roots", "expected folder paths (non-empty strings)");
      std::string folder = text->get();
      s.resolve(folder);
      if (!fs::path(folder).is_absolute()) return s.fail("roots", fmt::format("{}: expected an absolute folder", folder));
      if (holds_state(folder, state_dir))
        return s.fail("roots", fmt::format("{} holds the state directory's jobs or database; name a folder of parts",
                                           folder));
      c.roots.push_back(folder);
    }
  }
  if (c.roots.empty()) c.roots.push_back((state_dir / "parts").string());
  s.integer("max_model_bytes", c.max_model_bytes, 1024, std::int64_t{1} << 40);
  s.integer("max_stock_file_bytes", c.max_stock_file_bytes, 64, std::int64_t{1} << 30);
  s.number("upload_idle_s", c.upload_idle_s, {1, 7 * 24 * 3600});
  s.integer("max_uploads", c.max_uploads, 1, 4096);
}

// How the machine is reached depends on the protocol: a line protocol goes over one serial port
// or one TCP stream; the Modbus mailbox goes through the cell's PLC, so the cell must be on.
void check_link(Section& link, const DaemonConfig& c) {
  const auto& l = c.link;
  if (l.protocol == "modbus") {
    if (!l.port.empty() || !l.tcp.empty())
      return link.fail(l.port.empty() ? "tcp" : "port",
                       "protocol \"modbus\" streams through the PLC at [cell] modbus; leave port and tcp empty");
    if (!c.cell.enabled) link.fail("protocol", "protocol \"modbus\" streams through the cell PLC: [cell] enabled must be true");
  } else if (!l.port.empty() && !l.tcp.empty()) {
    link.fail("tcp", "give port (serial) or tcp (HOST:PORT), not both");
  }
}

const toml::table* section_table(Reader& r, const toml::table& doc, std::string_view name) {
  const toml::node* n = doc.get(name);
  if (!n) return nullptr;
  if (const auto* t = n->as_table()) return t;
  r.fail(n->source(), "", name, fmt::format("expected a table ([{}])", name));
  return nullptr;
}

std::expected<DaemonConfig, ConfigError> parse(const std::string& text, const std::string& source, const fs::path& base) {
  toml::table doc;
  try {
    doc = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    // The mistake a person most likely made there: a Unix mode written as in chmod.
    const bool leading_zero = e.description().find("leading zero") != std::string_view::npos;
    return std::unexpected(ConfigError{fmt::format("{}:{}: {}{}", source, e.source().begin.line, e.description(),
                                                   leading_zero ? " (a mode is written as a string: \"0660\")" : "")});
  }
  Reader r(source, base);
  std::string sections;
  for (const auto name : kSections) sections += fmt::format("{}[{}]", sections.empty() ? "" : ", ", name);
  for (const auto& [key, node] : doc) {
    const std::string_view k = key.str();
    bool ok = k == kRootKeys[0];
    for (const auto s : kSections) ok = ok || k == s;
    if (ok) continue;
    if (node.is_table()) r.fail(key.source(), "", fmt::format("[{}]", k), fmt::format("unknown section (known: {})", sections));
    else r.fail(key.source(), "", k, fmt::format("unknown key (known: {} and the sections {})", join(kRootKeys), sections));
  }

  DaemonConfig c;
  c.source = source;
  Section root(r, "", &doc, kRootKeys, false);  // its keys were checked above, sections included
  std::string state_dir = c.state_dir.string();
  root.path("state_dir", state_dir);
  if (state_dir.empty()) root.fail("state_dir", "must not be empty");
  c.state_dir = state_dir;

  read_server(Section(r, "server", section_table(r, doc, "server"), kServerKeys), c.server);
  read_http(r, Section(r, "http", section_table(r, doc, "http"), kHttpKeys), c.http);
  Section link(r, "link", section_table(r, doc, "link"), kLinkKeys);
  read_link(link, c.link);
  read_cell(Section(r, "cell", section_table(r, doc, "cell"), kCellKeys), c.cell);
  read_planner(Section(r, "planner", section_table(r, doc, "planner"), kPlannerKeys), c.planner);
  read_jobs(Section(r, "jobs", section_table(r, doc, "jobs"), kJobsKeys), c.jobs, c.state_dir);
  check_link(link, c);
  if (r.failed()) return std::unexpected(r.error());
  return c;
}

}  // namespace

std::expected<DaemonConfig, ConfigError> load_daemon_config(const std::filesystem::path& file) {
  auto text = read_file(file);
  if (!text) return std::unexpected(ConfigError{text.error()});
  // Absolute, so that paths resolved against it still hold after laminad changes directory.
  std::error_code ec;
  const fs::path absolute = fs::absolute(file, ec);
  return parse(*text, file.string(), (ec ? file : absolute).parent_path());
}

std::expected<DaemonConfig, ConfigError> parse_daemon_config(const std::string& toml_text, const std::string& source_name) {
  return parse(toml_text, source_name, fs::path(source_name).parent_path());
}

}  // namespace lamina::daemon
