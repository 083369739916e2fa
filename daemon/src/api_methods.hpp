#pragma once
// The JSON-RPC methods of laminad (docs/api.md): parameter checking, the call into the
// JobManager, and its errors mapped to JSON-RPC codes. Runs on the RPC worker thread (the four
// inline methods on the io thread: rpc_server.hpp); every method returns quickly.
#include <memory>
#include <string>

#include "job_manager.hpp"
#include "uploads.hpp"
#include "warning_log.hpp"
#include "lamina/daemon/rpc_server.hpp"

namespace lamina::daemon {

struct ServerInfo {
  std::string version;
  std::string machine;     // MachineSession::describe()
  std::string state_dir;
  std::shared_ptr<const WarningLog> warnings;  // server.warnings; none: an empty list
};

RpcServer::Handler make_api_handler(JobManager& jobs, Uploads& uploads, ServerInfo info);

// The one place the job domain's errors become JSON-RPC codes (docs/api.md's table).
RpcError rpc_error(const JobError& e);

}  // namespace lamina::daemon
