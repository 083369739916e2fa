#include "model_loading.hpp"

#include "lamina/core/elapsed.hpp"
#include "lamina/core/mesh_io.hpp"
#if LAMINA_HAVE_STEP
#include "step_plugin_loader.hpp"
#endif
#include "lamina/core/slice.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <map>
#include <numbers>

namespace lamina::cli {
MeshParams mesh_params_from(const ModelOptions& o) {
  MeshParams p;
  p.scale_to_mm = o.units == "in" ? 25.4 : 1.0;
  p.axis = o.axis == "x" ? BuildAxis::x : o.axis == "y" ? BuildAxis::y : BuildAxis::z;
  if (o.direction.size() == 3) p.direction = Eigen::Vector3d(o.direction[0], o.direction[1], o.direction[2]);
  p.sharp_angle_rad = o.sharp_angle_deg * std::numbers::pi / 180.0;
  p.weld_tolerance_rel = o.weld_tolerance_rel;
  return p;
}

namespace {

std::expected<TriangleSoup, Error> read_cad(const ModelOptions& options) {
  if (options.units != "mm")
    return std::unexpected(Error{ErrorCode::invalid_argument,
                                 fmt::format("{}: a STEP or IGES file names its own units: --units is for meshes", options.path)});
#if LAMINA_HAVE_STEP
  CadReadOptions cad;
  cad.quote_file_text = !options.no_quote_input;
  if (options.chord_tolerance_mm) cad.chord_tolerance_mm = *options.chord_tolerance_mm;
  return read_cad_file_via_plugin(options.path, cad);
#else
  return std::unexpected(Error{ErrorCode::unsupported,
                               fmt::format("{}: this lamina was built without STEP support (OpenCASCADE was not found "
                                           "at build time: scripts/setup installs it); export the part as STL or 3MF",
                                           options.path)});
#endif
}

}  // namespace

std::expected<LoadedModel, Error> load_model(const ModelOptions& options) {
  LoadedModel out;
  auto t0 = std::chrono::steady_clock::now();
  MeshReadOptions read_options;
  read_options.quote_file_text = !options.no_quote_input;
  auto soup = is_cad_path(options.path) ? read_cad(options) : read_mesh_file(options.path, read_options);
  out.read_s = seconds_since(t0);
  if (!soup) return std::unexpected(soup.error());
  out.format = soup->format;
  out.notes = soup->notes;
  if (soup->brep) {
    out.brep = BrepData{{}, {}, soup->brep->faces, soup->brep->solids, soup->brep->length_unit,
                        soup->brep->chord_tolerance_mm};
  }
  t0 = std::chrono::steady_clock::now();
  auto mesh = build_mesh(*soup, mesh_params_from(options));
  out.topology_s = seconds_since(t0);
  if (!mesh) return std::unexpected(mesh.error());
  out.mesh = std::move(*mesh);
  if (options.surface_normals == "facet") out.mesh.corner_normals.clear();
  return out;
}

std::optional<ReportCad> cad_report(const LoadedModel& model, const ModelOptions& options) {
  if (!model.brep) return std::nullopt;
  const BrepData& b = *model.brep;
  ReportCad cad;
  cad.length_unit = b.length_unit;
  cad.chord_tolerance_mm = b.chord_tolerance_mm;
  cad.surface_normals = options.surface_normals;
  for (const BrepSolid& s : b.solids)
    cad.solids.push_back({s.name, static_cast<std::int64_t>(s.faces), static_cast<std::int64_t>(s.triangles)});
  std::map<SurfaceKind, std::int64_t> faces_of_kind;
  for (const BrepFace& f : b.faces) ++faces_of_kind[f.kind];
  for (const auto& [kind, faces] : faces_of_kind) cad.surface_kinds.emplace_back(surface_kind_name(kind), faces);
  return cad;
}

std::expected<DeviationReference, Error> load_reference(const ModelOptions& options, const Mesh& planned) {
  auto model = load_model(options);
  if (!model) return std::unexpected(Error{model.error().code, "the deviation's reference: " + model.error().message});
  if (!model->mesh.usable())
    return std::unexpected(Error{ErrorCode::invalid_argument,
                                 fmt::format("the deviation's reference {} is not usable as a solid (see lamina check {})",
                                             options.path, options.path)});
  ReportDeviationReference echo{options.path, model->format, static_cast<std::int64_t>(model->mesh.summary.triangles),
                                std::nullopt};
  if (model->brep) echo.chord_tolerance_mm = model->brep->chord_tolerance_mm;
  return DeviationReference{std::make_shared<const Mesh>(in_frame_of(std::move(model->mesh), planned)), std::move(echo)};
}

std::vector<std::string> cad_lines(const ReportCad& cad) {
  std::int64_t faces = 0;
  std::string kinds;
  for (const auto& [kind, n] : cad.surface_kinds) {
    faces += n;
    kinds += fmt::format("{}{} {}", kinds.empty() ? "" : ", ", kind, n);
  }
  std::vector<std::string> lines{
      fmt::format("B-rep      {} solid{}, {} faces ({}); unit {}; tessellated to {:g} mm; {} normals", cad.solids.size(),
                  cad.solids.size() == 1 ? "" : "s", faces, kinds, cad.length_unit.empty() ? "not said (mm)" : cad.length_unit,
                  cad.chord_tolerance_mm, cad.surface_normals)};
  // An assembly of a thousand parts is a thousand lines: the first ones, then how many more
  // (all of them are in the JSON).
  constexpr std::size_t kSolidLines = 20;
  for (std::size_t i = 0; i < cad.solids.size() && i < kSolidLines; ++i) {
    const ReportCadSolid& s = cad.solids[i];
    lines.push_back(fmt::format("  solid    {}: {} faces, {} triangles", s.name.empty() ? "(unnamed)" : s.name, s.faces, s.triangles));
  }
  if (cad.solids.size() > kSolidLines)
    lines.push_back(fmt::format("  …        and {} more solids (--json lists them all)", cad.solids.size() - kSolidLines));
  return lines;
}

std::optional<std::string> overlapping_shells(const Mesh& mesh) {
  if (mesh.summary.shells < 2) return std::nullopt;
  const double z0 = mesh.summary.bbox_min_mm.z(), h = mesh.summary.bbox_max_mm.z() - z0;
  std::vector<double> zs;
  for (int i = 0; i < kShellProbePlanes; ++i) zs.push_back(z0 + h * (i + 0.5) / kShellProbePlanes);
  SliceParams params;
  params.parallel = false;
  auto slices = slice_mesh(mesh, zs, params);
  if (!slices) return std::nullopt;
  int overlapping = 0;
  double first_z = 0.0;
  for (const Slice& sl : *slices)
    for (const std::string& w : sl.warnings)
      if (w.find("overlapping shells") != std::string::npos && overlapping++ == 0) first_z = sl.z_mm;
  if (overlapping == 0) return std::nullopt;
  return fmt::format("overlapping_shells: {} shells overlap in {} of {} sections (first at z = {:.3f} mm): the solid is "
                     "their union; the volume above is their sum and counts the overlap more than once",
                     mesh.summary.shells, overlapping, kShellProbePlanes, first_z);
}

std::optional<std::string> implausible_size(const Mesh& mesh, const ModelOptions& o, double sheet_longest_mm) {
  const Eigen::Vector3d size = mesh.summary.bbox_max_mm - mesh.summary.bbox_min_mm;
  const double largest = size.maxCoeff();
  const std::string dims = fmt::format("{:.2f} × {:.2f} × {:.2f} mm", size.x(), size.y(), size.z());
  if (o.units == "mm" && largest < kSmallestPlausiblePartMm)
    return fmt::format("{}: the model is {} ({:.2f} mm at its largest): if the file is in inches, give --units in "
                       "(it would be {:.1f} mm)", o.path, dims, largest, largest * 25.4);
  if (o.units == "in" && largest > sheet_longest_mm)
    return fmt::format("{}: with --units in the model is {}, larger than the {:.0f} mm sheet: if the file is in mm, "
                       "give --units mm (it would be {:.1f} mm at its largest)", o.path, dims, sheet_longest_mm,
                       largest / 25.4);
  return std::nullopt;
}

}  // namespace lamina::cli
