#include "http/job_artefacts.hpp"

#include <fmt/format.h>

#include "job_manager.hpp"

namespace lamina::daemon::http {

ArtefactLookup job_artefacts(const JobManager& jobs) {
  return [&jobs](const ArtefactRequest& r) -> std::expected<std::filesystem::path, RouteError> {
    auto job = jobs.get(r.job_id);
    if (!job) return std::unexpected(RouteError{404, fmt::format("no job {}", r.job_id)});
    const std::filesystem::path path = r.kind == Artefact::model
                                           ? std::filesystem::path(job->model_path)
                                           : std::filesystem::path(job->artefact_dir) / artefact_file_name(r);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
      return std::unexpected(RouteError{404, fmt::format("job {} has no {} (yet)", r.job_id, artefact_file_name(r))});
    return path;
  };
}

}  // namespace lamina::daemon::http
