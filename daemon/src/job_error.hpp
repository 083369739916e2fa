#pragma once
// What the job domain (JobManager, client files) says when it refuses or fails, in its own
// words (issue 18): a kind and a message. The transport maps kinds to its codes in one place —
// JSON-RPC's in api_methods.cpp — so the web console's HTTP statuses can map them too, and the
// domain never includes the RPC server.
#include <string>
#include <utility>

namespace lamina::daemon {

enum class JobErrorKind {
  bad_request,    // a parameter or file the client gave is wrong
  not_found,      // no such job
  wrong_state,    // the job or machine is not in a state that allows it
  machine_busy,   // the machine is with another job, or still stopping
  storage,        // the job store or the disk failed
  shutting_down,  // the daemon is stopping
  internal,       // a bug: a state the daemon should never reach
};

struct JobError {
  JobErrorKind kind = JobErrorKind::internal;
  std::string message;
};

inline JobError job_error(JobErrorKind kind, std::string message) { return JobError{kind, std::move(message)}; }
inline JobError bad_request(std::string message) { return job_error(JobErrorKind::bad_request, std::move(message)); }

}  // namespace lamina::daemon
