#include "http/web_access.hpp"

#include <algorithm>
#include <cctype>

#include <boost/asio/ip/address.hpp>
#include <fmt/format.h>

namespace lamina::daemon::http {
namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

// "name:port" → "name"; "[::1]:port" → "::1"; a bare IPv6 literal stays whole.
std::string host_name_of(std::string_view host) {
  if (host.starts_with('[')) {
    const auto close = host.find(']');
    return close == std::string_view::npos ? std::string(host) : std::string(host.substr(1, close - 1));
  }
  const auto colon = host.find(':');
  if (colon != std::string_view::npos && host.find(':', colon + 1) == std::string_view::npos) host = host.substr(0, colon);
  return lower(host);
}

bool is_ip_literal(const std::string& name) {
  boost::system::error_code ec;
  (void)boost::asio::ip::make_address(name, ec);
  return !ec;
}

}  // namespace

WebAccess::WebAccess(AccessSettings settings)
    : settings_(std::move(settings)), sessions_(settings_.session_lifetime_s, settings_.max_sessions) {}

const WebUser* WebAccess::user(std::string_view name) const {
  for (const WebUser& u : settings_.users)
    if (u.name == name) return &u;
  return nullptr;
}

std::expected<void, RouteError> WebAccess::check_host(std::string_view host) const {
  if (host.empty()) return std::unexpected(RouteError{400, "the request names no Host"});
  const std::string name = host_name_of(host);
  if (is_ip_literal(name) || name == "localhost" || name == lower(settings_.machine_name)) return {};
  for (const auto& allowed : settings_.server_names)
    if (name == lower(allowed)) return {};
  return std::unexpected(RouteError{
      400, fmt::format("host '{}' is not this console's name (add it to [http] server_names)", name)});
}

std::expected<void, RouteError> WebAccess::check_origin(std::string_view origin, std::string_view host) const {
  if (origin.empty()) return {};
  const std::string own = fmt::format("{}://{}", settings_.tls ? "https" : "http", lower(host));
  if (lower(origin) == own) return {};
  for (const auto& allowed : settings_.allowed_origins)
    if (lower(origin) == lower(allowed)) return {};
  return std::unexpected(RouteError{403, fmt::format("origin '{}' is not this console's", origin)});
}

std::expected<Visitor, RouteError> WebAccess::visitor(std::string_view cookie_header, double now_s) {
  if (!users_configured()) return Visitor{"local", Role::viewer, false};
  const std::string_view token = cookie_value(cookie_header, kSessionCookie);
  if (token.empty()) return std::unexpected(RouteError{401, "log in first"});
  const auto session = sessions_.find(token, now_s);
  if (!session) return std::unexpected(RouteError{401, "the session has ended; log in again"});
  return Visitor{session->user, session->role, true};
}

std::string WebAccess::session_cookie(const std::string& token) const {
  return fmt::format("{}={}; Path=/; Max-Age={}; HttpOnly; SameSite=Strict{}", kSessionCookie, token,
                     static_cast<long long>(settings_.session_lifetime_s), settings_.tls ? "; Secure" : "");
}

std::string WebAccess::cleared_cookie() const {
  return fmt::format("{}=; Path=/; Max-Age=0; HttpOnly; SameSite=Strict{}", kSessionCookie,
                     settings_.tls ? "; Secure" : "");
}

std::string_view cookie_value(std::string_view header, std::string_view name) {
  while (!header.empty()) {
    const auto end = std::min(header.find(';'), header.size());
    std::string_view pair = header.substr(0, end);
    header.remove_prefix(std::min(end + 1, header.size()));
    while (!pair.empty() && pair.front() == ' ') pair.remove_prefix(1);
    const auto eq = pair.find('=');
    if (eq != std::string_view::npos && pair.substr(0, eq) == name) return pair.substr(eq + 1);
  }
  return {};
}

}  // namespace lamina::daemon::http
