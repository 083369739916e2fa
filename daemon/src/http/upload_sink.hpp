#pragma once
// The web server's POST /api/uploads into the daemon's Uploads (the same as upload.begin and
// upload.chunk over the socket): the upload id it answers is what job.submit takes.
#include "http/http_server.hpp"

namespace lamina::daemon {
class Uploads;
}

namespace lamina::daemon::http {

UploadSink upload_sink(Uploads& uploads, std::uint64_t max_bytes);

}  // namespace lamina::daemon::http
