#pragma once
// Who may use the web console, decided from a request's head (sans-IO: time is an argument):
// the Host it names (DNS rebinding), the Origin a browser sends (another site's page), the
// session cookie (a login). The login itself (a password check on its own thread) is
// http_server's; this holds the users, the sessions and the limiter it consults.
#include <expected>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "http/http_routes.hpp"
#include "http/login_limiter.hpp"
#include "http/session_table.hpp"
#include "lamina/daemon/daemon_config.hpp"

namespace lamina::daemon::http {

struct AccessSettings {
  std::vector<WebUser> users;             // none: nobody logs in, and every visitor is a local viewer
  double session_lifetime_s = 12 * 3600;
  std::vector<std::string> server_names;  // besides IP literals, localhost and this machine's name
  std::vector<std::string> allowed_origins;
  std::string machine_name;               // gethostname(), for the Host check
  bool tls = false;                       // cookies get Secure
  std::size_t max_sessions = 256;
};

struct Visitor {
  std::string user;  // the login, or "local" without users
  Role role = Role::viewer;
  bool logged_in = false;
};

inline constexpr std::string_view kSessionCookie = "lamina_session";

class WebAccess {
 public:
  explicit WebAccess(AccessSettings settings);

  bool users_configured() const { return !settings_.users.empty(); }
  const WebUser* user(std::string_view name) const;

  // 400 unless the Host names this server: an IP literal, localhost, this machine or a server name.
  std::expected<void, RouteError> check_host(std::string_view host) const;
  // 403 for another site's page: an Origin that is neither this console ("scheme://Host") nor an
  // allowed origin. No Origin at all is not a browser's cross-site request, and passes.
  std::expected<void, RouteError> check_origin(std::string_view origin, std::string_view host) const;
  // The visitor a Cookie header makes: a live session; without users, a local viewer; else 401.
  std::expected<Visitor, RouteError> visitor(std::string_view cookie_header, double now_s);

  SessionTable& sessions() { return sessions_; }
  LoginLimiter& limiter() { return limiter_; }
  std::string session_cookie(const std::string& token) const;  // Set-Cookie value
  std::string cleared_cookie() const;

 private:
  AccessSettings settings_;
  SessionTable sessions_;
  LoginLimiter limiter_;
};

// A cookie's value from a Cookie header ("a=1; lamina_session=…"), empty when absent.
std::string_view cookie_value(std::string_view header, std::string_view name);

}  // namespace lamina::daemon::http
