#include "api_methods.hpp"

#include "plan_settings.hpp"

#include <functional>
#include <limits>
#include <map>

#include <fmt/format.h>

namespace lamina::daemon {
namespace {

using Json = nlohmann::json;
using Method = std::function<RpcResult(const Json& params, ClientContext& client)>;

// One row per method: who may call it (roles.hpp) and what it does. Reading is a viewer's.
struct MethodRow {
  Role role = Role::viewer;
  Method call;
};
using MethodTable = std::map<std::string, MethodRow>;

Actor actor_of(const ClientContext& client) { return Actor{client.user, client.role}; }

RpcError invalid(std::string message) { return RpcError{rpc_code::invalid_params, std::move(message), nullptr}; }

// params must be an object (positional arrays are not used by this API).
std::expected<const Json*, RpcError> object_params(const Json& params) {
  if (!params.is_object()) return std::unexpected(invalid("params: expected an object"));
  return &params;
}

std::expected<std::string, RpcError> string_param(const Json& params, const char* key) {
  auto it = params.find(key);
  if (it == params.end()) return std::unexpected(invalid(fmt::format("params.{}: missing", key)));
  if (!it->is_string() || it->get<std::string>().empty())
    return std::unexpected(invalid(fmt::format("params.{}: expected a non-empty string", key)));
  return it->get<std::string>();
}

// An integer within [min, max]: read wide and checked, never narrowed (get<int>() of
// 4294967297 is 1, which confirmed sheet 1).
std::expected<int, RpcError> int_param(const Json& params, const char* key, int min, int max) {
  auto it = params.find(key);
  if (it == params.end()) return std::unexpected(invalid(fmt::format("params.{}: missing", key)));
  if (!it->is_number_integer()) return std::unexpected(invalid(fmt::format("params.{}: expected an integer", key)));
  const bool too_big = it->is_number_unsigned() && it->get<std::uint64_t>() > static_cast<std::uint64_t>(max);
  if (too_big || it->get<std::int64_t>() < min || it->get<std::int64_t>() > max)
    return std::unexpected(invalid(fmt::format("params.{}: {} is out of range {} … {}", key, it->dump(), min, max)));
  return static_cast<int>(it->get<std::int64_t>());
}

RpcResult job_result(std::expected<JobRecord, JobError> r) {
  if (!r) return std::unexpected(rpc_error(r.error()));
  return to_json(*r);
}

RpcResult machine_result(std::expected<Json, JobError> r) {
  if (!r) return std::unexpected(rpc_error(r.error()));
  return std::move(*r);
}

// upload.begin / chunk / cancel: a model sent in pieces (uploads.hpp).
void add_upload_methods(MethodTable& m, Uploads& uploads) {
  m["upload.begin"] = {Role::engineer, [&uploads](const Json& params, ClientContext&) -> RpcResult {
    auto p = object_params(params);
    if (!p) return std::unexpected(p.error());
    auto name = string_param(params, "name");
    if (!name) return std::unexpected(name.error());
    if (!params.contains("size") || !params["size"].is_number_unsigned())
      return std::unexpected(invalid("params.size: expected the file's size in bytes"));
    auto id = uploads.begin(*name, params["size"].get<std::uint64_t>());
    if (!id) return std::unexpected(rpc_error(id.error()));
    return Json{{"upload", *id}};
  }};
  m["upload.chunk"] = {Role::engineer, [&uploads](const Json& params, ClientContext&) -> RpcResult {
    auto p = object_params(params);
    if (!p) return std::unexpected(p.error());
    auto id = string_param(params, "upload");
    if (!id) return std::unexpected(id.error());
    auto data = string_param(params, "data");
    if (!data) return std::unexpected(data.error());
    if (!params.contains("offset") || !params["offset"].is_number_unsigned())
      return std::unexpected(invalid("params.offset: expected a byte offset"));
    auto received = uploads.chunk(*id, params["offset"].get<std::uint64_t>(), *data);
    if (!received) return std::unexpected(rpc_error(received.error()));
    return Json{{"received", *received}};
  }};
  m["upload.cancel"] = {Role::engineer, [&uploads](const Json& params, ClientContext&) -> RpcResult {
    auto p = object_params(params);
    if (!p) return std::unexpected(p.error());
    auto id = string_param(params, "upload");
    if (!id) return std::unexpected(id.error());
    if (auto r = uploads.cancel(*id); !r) return std::unexpected(rpc_error(r.error()));
    return Json{{"cancelled", *id}};
  }};
}

}  // namespace

RpcError rpc_error(const JobError& e) {
  int code = rpc_code::internal_error;
  switch (e.kind) {
    case JobErrorKind::bad_request: code = rpc_code::invalid_params; break;
    case JobErrorKind::not_found: code = rpc_code::job_not_found; break;
    case JobErrorKind::wrong_state: code = rpc_code::invalid_state; break;
    case JobErrorKind::machine_busy: code = rpc_code::machine_busy; break;
    case JobErrorKind::storage: code = rpc_code::storage_error; break;
    case JobErrorKind::shutting_down: code = rpc_code::shutting_down; break;
    case JobErrorKind::internal: code = rpc_code::internal_error; break;
  }
  return RpcError{code, e.message, nullptr};
}

namespace {

// job.submit: a model named on the cell PC or sent with upload.begin, with plan settings.
RpcResult submit_job(JobManager& jobs, Uploads& uploads, const Json& params, const Actor& by) {
  auto p = object_params(params);
  if (!p) return std::unexpected(p.error());
  SubmitRequest r;
  r.by = by;
  if (params.contains("upload") == params.contains("model"))
    return std::unexpected(invalid("params: give either model (a path on the cell PC) or upload (from upload.begin)"));
  for (const auto& [key, value] : params.items())
    if (key != "model" && key != "upload" && key != "name" && key != "settings")
      return std::unexpected(invalid(fmt::format("params.{}: unknown parameter", key)));
  if (auto it = params.find("name"); it != params.end()) {
    if (!it->is_string()) return std::unexpected(invalid("params.name: expected a string"));
    r.name = it->get<std::string>();
  }
  if (auto it = params.find("settings"); it != params.end()) r.settings = *it;
  // Checked before an upload is taken: a mistyped setting leaves the upload for the next try.
  if (auto args = plan_args_from_settings(r.settings); !args) return std::unexpected(invalid(args.error()));
  if (params.contains("upload")) {
    auto id = string_param(params, "upload");
    if (!id) return std::unexpected(id.error());
    auto file = uploads.take(*id);
    if (!file) return std::unexpected(rpc_error(file.error()));
    r.model_path = file->string();
    r.move_into_job = true;
  } else {
    auto model = string_param(params, "model");
    if (!model) return std::unexpected(model.error());
    r.model_path = *model;
  }
  return job_result(jobs.submit(std::move(r)));
}

// job.*: one job each, named by params.job.
void add_job_methods(MethodTable& m, JobManager& jobs, Uploads& uploads) {
  m["job.submit"] = {Role::engineer, [&jobs, &uploads](const Json& params, ClientContext& client) {
                       return submit_job(jobs, uploads, params, actor_of(client));
                     }};
  m["job.list"] = {Role::viewer, [&jobs](const Json&, ClientContext&) -> RpcResult {
                     Json list = Json::array();
                     for (const JobRecord& j : jobs.list())
                       list.push_back({{"id", j.id}, {"state", to_string(j.state)}, {"name", j.name},
                                       {"current_sheet", j.current_sheet}, {"sheets", j.sheets.size()},
                                       {"error", j.error}, {"created_unix_ms", j.created_unix_ms}});
                     return list;
                   }};
  using JobCall = std::function<std::expected<JobRecord, JobError>(const std::string&, const Json&, const Actor&)>;
  auto with_job = [](Role role, JobCall f) {
    return MethodRow{role, [f](const Json& params, ClientContext& client) -> RpcResult {
                       auto p = object_params(params);
                       if (!p) return std::unexpected(p.error());
                       auto id = string_param(params, "job");
                       if (!id) return std::unexpected(id.error());
                       return job_result(f(*id, params, actor_of(client)));
                     }};
  };
  m["job.get"] = with_job(Role::viewer, [&jobs](const std::string& id, const Json&, const Actor&) { return jobs.get(id); });
  m["job.events"] = {Role::viewer, [&jobs](const Json& params, ClientContext&) -> RpcResult {
                       auto id = string_param(params, "job");
                       if (!id) return std::unexpected(id.error());
                       auto events = jobs.events(*id);
                       if (!events) return std::unexpected(rpc_error(events.error()));
                       Json list = Json::array();
                       for (const JobEvent& e : *events)
                         list.push_back({{"t_unix_ms", e.t_unix_ms}, {"kind", e.kind}, {"data", e.data}});
                       return list;
                     }};
  m["job.cancel"] = with_job(Role::engineer, [&jobs](const std::string& id, const Json&, const Actor& by) {
    return jobs.cancel(id, by);
  });
  m["job.resume"] = with_job(Role::machine_operator, [&jobs](const std::string& id, const Json&, const Actor& by) {
    return jobs.resume(id, by);
  });
  m["job.confirm_sheet"] = with_job(
      Role::machine_operator,
      [&jobs](const std::string& id, const Json& params, const Actor& by) -> std::expected<JobRecord, JobError> {
        auto sheet = int_param(params, "sheet", 1, 100000);
        if (!sheet) return std::unexpected(job_error(JobErrorKind::bad_request, sheet.error().message));
        return jobs.confirm_sheet(id, *sheet, by);
      });
}

// server.warnings {since?}: what laminad warned about (every logger's warnings and errors, the
// last 200), those after `since` (a seq from an earlier answer). `last` is the newest seq, so a
// client that polls asks for what it has not seen.
RpcResult warnings_since(const WarningLog* log, const Json& params) {
  std::uint64_t after = 0;
  if (params.is_object() && params.contains("since")) {
    auto since = int_param(params, "since", 0, std::numeric_limits<int>::max());
    if (!since) return std::unexpected(since.error());
    after = static_cast<std::uint64_t>(*since);
  }
  Json list = Json::array();
  std::uint64_t last = after;
  for (const LoggedWarning& w : log ? log->since(after) : std::vector<LoggedWarning>{}) {
    list.push_back({{"seq", w.seq}, {"t_unix_ms", w.t_unix_ms}, {"level", w.level}, {"source", w.source}, {"message", w.message}});
    last = w.seq;
  }
  return Json{{"warnings", list}, {"last", last}};
}

// machine.*: the machine, whichever job has it.
void add_machine_methods(MethodTable& m, JobManager& jobs) {
  m["machine.status"] = {Role::viewer, [&jobs](const Json&, ClientContext&) -> RpcResult { return jobs.machine_status(); }};
  m["machine.hold"] = {Role::machine_operator, [&jobs](const Json&, ClientContext& client) -> RpcResult {
                         return machine_result(jobs.hold(actor_of(client)));
                       }};
  m["machine.resume"] = {Role::machine_operator, [&jobs](const Json&, ClientContext& client) -> RpcResult {
                           return machine_result(jobs.resume_motion(actor_of(client)));
                         }};
  m["machine.abort"] = {Role::machine_operator, [&jobs](const Json& params, ClientContext& client) -> RpcResult {
                          std::string why = "aborted by the operator";
                          if (params.is_object() && params.contains("reason") && params["reason"].is_string())
                            why = params["reason"];
                          return machine_result(jobs.abort(why, actor_of(client)));
                        }};
}

}  // namespace

RpcServer::Handler make_api_handler(JobManager& jobs, Uploads& uploads, ServerInfo info) {
  auto methods = std::make_shared<MethodTable>();
  auto& m = *methods;
  m["server.info"] = {Role::viewer, [info](const Json&, ClientContext& client) -> RpcResult {
                        return Json{{"name", "laminad"}, {"version", info.version}, {"machine", info.machine},
                                    {"state_dir", info.state_dir}, {"api", 1}, {"user", client.user},
                                    {"role", role_name(client.role)}};
                      }};
  m["server.subscribe"] = {Role::viewer, [](const Json&, ClientContext& client) -> RpcResult {
                             client.subscribed = true;
                             return Json{{"subscribed", true},
                                         {"notifications", {"notify_job_progress", "notify_machine_status"}}};
                           }};
  m["server.warnings"] = {Role::viewer, [log = info.warnings](const Json& params, ClientContext&) -> RpcResult {
                            return warnings_since(log.get(), params);
                          }};
  add_upload_methods(m, uploads);
  add_job_methods(m, jobs, uploads);
  add_machine_methods(m, jobs);
  return [methods](const RpcRequest& request, ClientContext& client) -> RpcResult {
    auto it = methods->find(request.method);
    if (it == methods->end())
      return std::unexpected(RpcError{rpc_code::method_not_found, fmt::format("no method '{}'", request.method), nullptr});
    // Refused out loud, never ignored: the console shows this message to the person who pressed.
    if (client.role < it->second.role)
      return std::unexpected(RpcError{rpc_code::forbidden,
                                      fmt::format("{} is for {} or above; {} is {}", request.method,
                                                  role_with_article(it->second.role), client.user,
                                                  role_with_article(client.role)),
                                      Json{{"needs", role_name(it->second.role)}, {"role", role_name(client.role)}}});
    return it->second.call(request.params, client);
  };
}

}  // namespace lamina::daemon
