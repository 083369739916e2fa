#pragma once
// What `lamina plan` hands back: report.json (built here from the plan, keys in reading order),
// the tables a person reads (printed from that same JSON, so both always agree). The files of DIR
// are written by plan_output.hpp.
#include "lamina/core/bevel.hpp"
#include "lamina/core/deviation.hpp"
#include "lamina/core/layering.hpp"
#include "model_loading.hpp"
#include "plan_options.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <expected>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace lamina::cli {

struct PlanTimings {  // seconds
  double read = 0.0, topology = 0.0, layering = 0.0, bevel = 0.0, deviation = 0.0, write = 0.0, total = 0.0;
};

struct StrategyDeviation {
  BevelStrategy strategy = BevelStrategy::curved;
  Deviation deviation;
};

struct PlanResult {
  Layering layering;
  BevelPlan plan;                             // the chosen --strategy
  std::vector<StrategyDeviation> deviations;  // the same layering cut vertical, sloped, curved
  std::vector<std::string> warnings;
  PlanTimings timing;
};

nlohmann::ordered_json plan_report_json(const PlanOptions& options, const PlanSettings& settings, const LoadedModel& model,
                                const PlanResult& result);

// The layer table, the deviation table, the stack line, shortfalls, warnings and timings.
void print_plan_tables(std::FILE* out, const nlohmann::ordered_json& report, bool all_rows);

}  // namespace lamina::cli
