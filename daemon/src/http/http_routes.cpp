#include "http/http_routes.hpp"

#include <algorithm>

#include <array>
#include <charconv>
#include <vector>

#include <fmt/format.h>

namespace lamina::daemon::http {
namespace {

constexpr std::size_t kMaxTarget = 1024;
constexpr std::size_t kMaxSegments = 16;

bool plain_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '_' || c == '-';
}

// The path's segments, or why the path is refused. A trailing '/' names the folder's index.html.
std::expected<std::vector<std::string_view>, RouteError> segments_of(std::string_view path) {
  if (path.empty() || path.front() != '/') return std::unexpected(RouteError{400, "the path must start with '/'"});
  std::vector<std::string_view> out;
  std::size_t at = 1;
  while (at <= path.size()) {
    const std::size_t end = std::min(path.find('/', at), path.size());
    const std::string_view segment = path.substr(at, end - at);
    if (segment.empty()) {
      if (end != path.size()) return std::unexpected(RouteError{400, "empty path segment ('//')"});
      break;  // the trailing '/'
    }
    for (char c : segment) {
      if (c == '%') return std::unexpected(RouteError{400, "percent-encoded paths are not served"});
      if (!plain_char(c))
        return std::unexpected(RouteError{400, fmt::format("character {:?} is not allowed in a path", c)});
    }
    if (segment.front() == '.')
      return std::unexpected(RouteError{400, fmt::format("path segment '{}' ('.', '..' and hidden names are refused)", segment)});
    out.push_back(segment);
    if (out.size() > kMaxSegments) return std::unexpected(RouteError{400, "too many path segments"});
    at = end + 1;
  }
  return out;
}

// "j-<unix ms>-<4 hex>", as new_job_id() makes them.
bool is_job_id(std::string_view id) {
  if (id.size() < 8 || !id.starts_with("j-")) return false;
  const std::size_t dash = id.rfind('-');
  if (dash <= 2 || id.size() - dash - 1 != 4) return false;
  for (std::size_t i = 2; i < dash; ++i)
    if (id[i] < '0' || id[i] > '9') return false;
  for (std::size_t i = dash + 1; i < id.size(); ++i) {
    const char c = id[i];
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

std::expected<ArtefactRequest, RouteError> artefact(std::string_view job_id, std::string_view name) {
  if (!is_job_id(job_id)) return std::unexpected(RouteError{404, fmt::format("'{}' is not a job id", job_id)});
  ArtefactRequest r{std::string(job_id), Artefact::report, 0};
  if (name == "report.json") return r;
  if (name == "stack.stl") return r.kind = Artefact::stack, r;
  if (name == "model") return r.kind = Artefact::model, r;
  for (const auto& [ext, kind] : std::array<std::pair<std::string_view, Artefact>, 2>{
           {{".svg", Artefact::sheet_drawing}, {".nc", Artefact::sheet_program}}}) {
    if (!name.starts_with("sheet-") || !name.ends_with(ext)) continue;
    const std::string_view digits = name.substr(6, name.size() - 6 - ext.size());
    int n = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), n);
    if (ec != std::errc{} || end != digits.data() + digits.size() || n < 1 || digits.front() == '0') break;
    r.kind = kind;
    r.sheet = n;
    return r;
  }
  return std::unexpected(RouteError{
      404, fmt::format("'{}' is not an artefact (report.json, stack.stl, model, sheet-<n>.svg, sheet-<n>.nc)", name)});
}

}  // namespace

std::expected<Route, RouteError> route_get(std::string_view target) {
  if (target.size() > kMaxTarget) return std::unexpected(RouteError{400, "the request target is too long"});
  const std::string_view path = target.substr(0, target.find('?'));  // a query is ignored
  auto segments = segments_of(path);
  if (!segments) return std::unexpected(segments.error());
  const auto& s = *segments;
  if (s.size() == 1 && s[0] == "ws") return WebSocketRequest{};
  if (!s.empty() && s[0] == "api") {
    if (s.size() == 2 && s[1] == "session") return SessionRequest{};
    if (s.size() == 4 && s[1] == "jobs") {
      auto a = artefact(s[2], s[3]);
      if (!a) return std::unexpected(a.error());
      return *a;
    }
    return std::unexpected(RouteError{404, fmt::format("no such API path {}", path)});
  }
  std::string relative;
  for (const auto& segment : s) relative += (relative.empty() ? "" : "/") + std::string(segment);
  if (s.empty() || path.back() == '/') relative += relative.empty() ? "index.html" : "/index.html";
  return StaticRequest{relative};
}

std::expected<PostRequest, RouteError> route_post(std::string_view target) {
  if (target == "/api/login") return PostRequest{PostRoute::login, {}};
  if (target == "/api/logout") return PostRequest{PostRoute::logout, {}};
  constexpr std::string_view upload = "/api/uploads?name=";
  if (target.starts_with(upload)) {
    // Only the extension matters (the model's format); the job's own name goes with job.submit.
    const std::string_view name = target.substr(upload.size());
    if (name.empty() || name.size() > 200 || name.front() == '.' || !std::all_of(name.begin(), name.end(), plain_char))
      return std::unexpected(RouteError{400, "name: a plain file name of [A-Za-z0-9._-], e.g. part.stl"});
    return PostRequest{PostRoute::upload, std::string(name)};
  }
  return std::unexpected(RouteError{404, "POST is served at /api/login, /api/logout and /api/uploads?name=… only"});
}

std::string artefact_file_name(const ArtefactRequest& request) {
  switch (request.kind) {
    case Artefact::report: return "report.json";
    case Artefact::stack: return "stack.stl";
    case Artefact::sheet_drawing: return fmt::format("sheet-{}.svg", request.sheet);
    case Artefact::sheet_program: return fmt::format("sheet-{}.nc", request.sheet);
    case Artefact::model: return "model";
  }
  return "";
}

std::string_view content_type(std::string_view name) {
  static constexpr std::array<std::pair<std::string_view, std::string_view>, 12> kTypes{{
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".svg", "image/svg+xml"},
      {".png", "image/png"},
      {".ico", "image/x-icon"},
      {".woff2", "font/woff2"},
      {".map", "application/json"},
      {".nc", "text/plain; charset=utf-8"},
      {".stl", "model/stl"},
      {".txt", "text/plain; charset=utf-8"},
  }};
  for (const auto& [ext, type] : kTypes)
    if (name.ends_with(ext)) return type;
  return "application/octet-stream";
}

}  // namespace lamina::daemon::http
