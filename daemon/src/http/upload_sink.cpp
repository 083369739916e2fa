#include "http/upload_sink.hpp"

#include "uploads.hpp"

namespace lamina::daemon::http {
namespace {

// The job domain's refusal as an HTTP status: the client's mistake, a full house, the disk.
RouteError http_error(const JobError& e) {
  switch (e.kind) {
    case JobErrorKind::bad_request: return RouteError{400, e.message};
    case JobErrorKind::wrong_state:
    case JobErrorKind::machine_busy:
    case JobErrorKind::shutting_down: return RouteError{503, e.message};
    default: return RouteError{500, e.message};
  }
}

}  // namespace

UploadSink upload_sink(Uploads& uploads, std::uint64_t max_bytes) {
  UploadSink sink;
  sink.max_bytes = max_bytes;
  sink.begin = [&uploads](const std::string& name, std::uint64_t size) -> std::expected<std::string, RouteError> {
    auto id = uploads.begin(name, size);
    if (!id) return std::unexpected(http_error(id.error()));
    return *id;
  };
  sink.append = [&uploads](const std::string& id, std::uint64_t offset,
                           std::string_view bytes) -> std::expected<void, RouteError> {
    auto received = uploads.append(id, offset, bytes);
    if (!received) return std::unexpected(http_error(received.error()));
    return {};
  };
  sink.cancel = [&uploads](const std::string& id) { (void)uploads.cancel(id); };
  return sink;
}

}  // namespace lamina::daemon::http
