#pragma once
// What a browser may GET from laminad's web server, decided from the request target alone
// (sans-IO, tested string by string): a job's artefact, the WebSocket, or a file of the web
// console (and POST: the login). No part of a target reaches the filesystem unchecked: a path is a list of plain
// segments ([A-Za-z0-9._-], no "." or "..", none hidden), percent-encoding is refused rather
// than decoded, and an artefact is a name from a fixed list, never a path.
#include <cstdint>
#include <expected>
#include <string>
#include <string_view>
#include <variant>

namespace lamina::daemon::http {

enum class Artefact : std::uint8_t { report, stack, sheet_drawing, sheet_program, model };

struct ArtefactRequest {  // GET /api/jobs/<job id>/<name>
  std::string job_id;
  Artefact kind = Artefact::report;
  int sheet = 0;  // 1-based, for the sheet's drawing and program
};
struct WebSocketRequest {};  // GET /ws (an upgrade)
struct SessionRequest {};    // GET /api/session: who the cookie says is here
struct StaticRequest {       // anything else: a file of the console ("/" is index.html)
  std::string relative;      // segments joined by '/', safe to append to the static folder
};
using Route = std::variant<ArtefactRequest, WebSocketRequest, SessionRequest, StaticRequest>;

// POST /api/login, /api/logout, /api/uploads?name=<file name> (a model, the body its bytes).
enum class PostRoute : std::uint8_t { login, logout, upload };
struct PostRequest {
  PostRoute route = PostRoute::login;
  std::string upload_name;  // plain characters ([A-Za-z0-9._-]), not starting with '.'
};

struct RouteError {
  int status = 400;  // HTTP status: 400 (malformed), 404 (no such thing)
  std::string message;
};

std::expected<Route, RouteError> route_get(std::string_view target);
std::expected<PostRequest, RouteError> route_post(std::string_view target);

// The artefact's file name in the job's folder ("sheet-2.svg"); the model is the job's own path.
std::string artefact_file_name(const ArtefactRequest& request);

// Content type from a file name's extension (application/octet-stream when unknown).
std::string_view content_type(std::string_view file_name);

}  // namespace lamina::daemon::http
