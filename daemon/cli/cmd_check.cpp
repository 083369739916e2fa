// lamina check MODEL: one line per defect class; exit 0 if the mesh is usable (maybe after
// repair), 1 if not.
#include "commands.hpp"
#include "json_output.hpp"
#include "model_options.hpp"

#include <fmt/format.h>

#include <memory>

namespace lamina::cli {

void add_check_command(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<ModelOptions>();
  auto json_path = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("check", "Read a mesh, repair what can be repaired and diagnose the rest");
  add_model_options(*cmd, *options);
  cmd->add_option("--json", *json_path, "Also write the diagnosis as JSON");
  cmd->callback([options, json_path, &exit_code] {
    auto model = load_model(*options);
    if (!model) {
      fmt::print(stderr, "error [{}]: {}\n", error_code_name(model.error().code), model.error().message);
      exit_code = 1;
      return;
    }
    const MeshSummary& s = model->mesh.summary;
    fmt::print("{} ({})\n", options->path, model->format);
    fmt::print("  triangles  {} read, {} kept; {} vertices after welding\n", s.triangles_read, s.triangles, s.vertices);
    fmt::print("  size       {:.4g} x {:.4g} x {:.4g} mm (build axis {}, units {})\n",
               s.bbox_max_mm.x() - s.bbox_min_mm.x(), s.bbox_max_mm.y() - s.bbox_min_mm.y(),
               s.bbox_max_mm.z() - s.bbox_min_mm.z(), options->axis, options->units);
    fmt::print("  volume     {:.6g} mm3{}\n", s.volume_mm3, s.watertight ? "" : " (not closed: approximate)");
    fmt::print("  shells {}, surfaces {}, watertight {}\n", s.shells, s.surfaces, s.watertight ? "yes" : "no");
    const auto cad = cad_report(*model, *options);
    if (cad)
      for (const std::string& line : cad_lines(*cad)) fmt::print("  {}\n", line);
    for (const ReadNote& n : model->notes) fmt::print("  [note]     {}: {}\n", n.code, n.message);
    for (const Defect& d : model->mesh.defects) fmt::print("  [{}] {}: {}\n", severity_name(d.severity), d.code, d.message);
    const auto overlap = overlapping_shells(model->mesh);
    if (overlap) fmt::print("  [warning] {}\n", *overlap);
    if (model->notes.empty() && model->mesh.defects.empty() && !overlap) fmt::print("  no defects found\n");
    const bool usable = model->mesh.usable();
    fmt::print("{}\n", usable ? "usable" : "NOT usable as a solid");
    if (!json_path->empty()) {
      std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(json_path->c_str(), "w"), &std::fclose);
      if (!f) {
        fmt::print(stderr, "error [io_error]: cannot write {}\n", *json_path);
        exit_code = 1;
        return;
      }
      nlohmann::json j = mesh_json(*model);
      if (cad) j["cad"] = nlohmann::json::parse(report_cad_json(*cad));
      fmt::print(f.get(), "{}\n", j.dump(2));
    }
    exit_code = usable ? 0 : 1;
  });
}

}  // namespace lamina::cli
