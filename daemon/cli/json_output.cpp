#include "json_output.hpp"

#include <fmt/format.h>

namespace lamina::cli {
namespace {
nlohmann::json vec3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
}  // namespace

nlohmann::json mesh_json(const LoadedModel& model) {
  const MeshSummary& s = model.mesh.summary;
  nlohmann::json defects = nlohmann::json::array();
  for (const ReadNote& n : model.notes)
    defects.push_back({{"code", n.code}, {"severity", "warning"}, {"count", nullptr}, {"message", n.message}});
  for (const Defect& d : model.mesh.defects) {
    nlohmann::json j{{"code", d.code}, {"severity", severity_name(d.severity)}, {"count", d.count}, {"message", d.message}};
    if (d.where) j["where_mm"] = vec3(*d.where);
    defects.push_back(std::move(j));
  }
  return {{"format", model.format},
          {"triangles_read", s.triangles_read},
          {"triangles", s.triangles},
          {"vertices", s.vertices},
          {"watertight", s.watertight},
          {"usable", model.mesh.usable()},
          {"volume_mm3", s.volume_mm3},
          {"bbox_min_mm", vec3(s.bbox_min_mm)},
          {"bbox_max_mm", vec3(s.bbox_max_mm)},
          {"shells", s.shells},
          {"surfaces", s.surfaces},
          {"boundary_edges", s.boundary_edges},
          {"nonmanifold_edges", s.nonmanifold_edges},
          {"defects", std::move(defects)}};
}

void write_slice_report(std::FILE* out, const ModelOptions& options, const LoadedModel& model,
                        std::span<const Slice> slices, const nlohmann::json& timing) {
  nlohmann::json head{{"file", options.path}, {"units", options.units}, {"axis", options.axis}};
  if (!options.direction.empty()) head["direction"] = options.direction;
  fmt::print(out, "{{\"model\":{},\n\"mesh\":{},\n\"slices\":[", head.dump(), mesh_json(model).dump());
  for (std::size_t si = 0; si < slices.size(); ++si) {
    const Slice& sl = slices[si];
    nlohmann::json warnings = sl.warnings;
    fmt::print(out, "{}\n{{\"z_mm\":{},\"outer\":{},\"holes\":{},\"net_area_mm2\":{},\"open_chains\":{},\"warnings\":{},\"loops\":[",
               si ? "," : "", sl.z_mm, sl.outer_count(), sl.hole_count(), sl.net_area_mm2(),
               sl.open_chains.size(), warnings.dump());
    for (std::size_t li = 0; li < sl.loops.size(); ++li) {
      const Loop& loop = sl.loops[li];
      fmt::print(out, "{}\n {{\"orientation\":\"{}\",\"area_mm2\":{},\"depth\":{},\"parent\":{},\"gap_closed\":{},\"vectors\":[",
                 li ? "," : "", loop.is_hole() ? "cw" : "ccw", loop.area_mm2, loop.depth, loop.parent,
                 loop.gap_closed);
      for (std::size_t vi = 0; vi < loop.size(); ++vi) {
        const ContourVector v = sl.vector(model.mesh, li, vi);
        fmt::print(out, "{}{{\"start\":[{},{}],\"end\":[{},{}],\"facet\":{},\"normal\":[{},{},{}],\"surface\":{}}}",
                   vi ? "," : "", v.start_mm.x(), v.start_mm.y(), v.end_mm.x(), v.end_mm.y(), v.facet,
                   v.normal.x(), v.normal.y(), v.normal.z(), v.surface_id);
      }
      fmt::print(out, "]}}");
    }
    fmt::print(out, "]}}");
  }
  fmt::print(out, "],\n\"timing_s\":{}}}\n", timing.dump());
}

}  // namespace lamina::cli
