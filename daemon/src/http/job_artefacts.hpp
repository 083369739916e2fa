#pragma once
// Where a job's artefacts are on disk, for the web server: the job's folder and its file name
// from the fixed list (http_routes), or the job's model. Nothing from the request is a path.
#include "http/http_server.hpp"

namespace lamina::daemon {
class JobManager;
}

namespace lamina::daemon::http {

ArtefactLookup job_artefacts(const JobManager& jobs);

}  // namespace lamina::daemon::http
