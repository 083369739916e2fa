#pragma once
// JSON reports of the CLI. Slices are streamed (a 1000-slice run holds millions of contour
// vectors), the small parts go through nlohmann::json.
#include "lamina/core/slice.hpp"
#include "model_loading.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <span>

namespace lamina::cli {

nlohmann::json mesh_json(const LoadedModel& model);

// {"model":…, "mesh":…, "slices":[…], "timing_s":{…}} written to `out`.
void write_slice_report(std::FILE* out, const ModelOptions& options, const LoadedModel& model,
                        std::span<const Slice> slices, const nlohmann::json& timing);

}  // namespace lamina::cli
