#include "lamina/drivers/modbus_endpoint.hpp"

namespace lamina::drivers {

std::optional<std::pair<std::string, int>> parse_host_port(std::string_view text) {
  const auto colon = text.rfind(':');
  if (colon == std::string_view::npos) return std::nullopt;
  std::string_view host = text.substr(0, colon);
  const std::string_view port = text.substr(colon + 1);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  else if (host.find(':') != std::string_view::npos) return std::nullopt;  // IPv6 needs its brackets
  if (host.empty() || port.empty() || port.size() > 5) return std::nullopt;
  for (const char c : host)
    if (c == ' ' || c == '\t' || c == '[' || c == ']' || c == '/') return std::nullopt;
  int value = 0;
  for (const char c : port) {
    if (c < '0' || c > '9') return std::nullopt;
    value = value * 10 + (c - '0');
  }
  if (value < 1 || value > 65535) return std::nullopt;
  return std::pair{std::string(host), value};
}

}  // namespace lamina::drivers
