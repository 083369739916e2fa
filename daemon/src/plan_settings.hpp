#pragma once
// job.submit's "settings" object → the flags of `lamina plan` that the daemon runs. Only known
// keys with the right types pass; the error names the key. Units as in the API: mm and degrees.
#include <expected>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace lamina::daemon {

struct PlanArgs {
  std::vector<std::string> flags;  // e.g. {"--strategy", "curved", "--tolerance", "0.2"}
};

std::expected<PlanArgs, std::string> plan_args_from_settings(const nlohmann::json& settings);

// The keys accepted, for docs/api.md and error messages.
std::vector<std::string> plan_setting_keys();

}  // namespace lamina::daemon
