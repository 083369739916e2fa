#pragma once
// The JSON-RPC methods of laminad (docs/api.md): parameter checking and the call into the
// JobManager. Runs on the io thread; every method returns quickly.
#include <string>

#include "job_manager.hpp"
#include "uploads.hpp"
#include "lamina/daemon/rpc_server.hpp"

namespace lamina::daemon {

struct ServerInfo {
  std::string version;
  std::string machine;     // MachineSession::describe()
  std::string state_dir;
};

RpcServer::Handler make_api_handler(JobManager& jobs, Uploads& uploads, ServerInfo info);

}  // namespace lamina::daemon
