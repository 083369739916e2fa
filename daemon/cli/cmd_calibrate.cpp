// lamina calibrate fit MEASUREMENTS.csv --material M: a coupon's measured cuts in, the kerf
// model's coefficients out (docs/jet.md) — the residuals printed, so a person sees which cut
// disagrees — into the kerf file, where the material's earlier calibration is replaced.
#include "commands.hpp"
#include "kerf_files.hpp"
#include "machine_config.hpp"
#include "materials_config.hpp"
#include "toml_file.hpp"

#include "lamina/core/coupon.hpp"
#include "lamina/core/kerf.hpp"
#include "lamina/core/post.hpp"
#include "plan_cam.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

namespace lamina::cli {
namespace {

namespace fs = std::filesystem;

struct FitOptions {
  std::string measurements, material, kerf_file, materials_file;
};

int fail(const Error& e) {
  fmt::print(stderr, "error [{}]: {}\n", error_code_name(e.code), e.message);
  return 1;
}

void print_fit(const KerfFit& fit, const std::string& material) {
  const KerfModel& m = fit.model;
  fmt::print("kerf of {} from {} cuts:\n", material, fit.residuals.size());
  fmt::print("  top width    w_t = {:.4f} {:+.4f}·r mm\n", m.top_width_mm, m.top_width_per_ratio_mm);
  fmt::print("  taper        (w_t - w_b)/h_f = {:.5f}·(r - {:.3f})\n", m.taper_per_ratio, m.taper_free_ratio);
  fmt::print("  trail-back   {:.4f}·h_f·r^{:.3f} mm\n\n", m.trail_back_factor, m.trail_back_exponent);
  fmt::print("{:<16} {:>10} {:>10} {:>10}   (measured - model, mm)\n", "cut", "top", "bottom", "trail");
  for (const KerfResidual& r : fit.residuals)
    if (r.through)
      fmt::print("{:<16} {:>+10.4f} {:>+10.4f} {:>+10.4f}\n", r.label, r.top_width_mm, r.bottom_width_mm, r.trail_back_mm);
    else
      fmt::print("{:<16} {:>+10.4f}   not through: only its top fitted\n", r.label, r.top_width_mm);
  for (const KerfResidual& r : fit.residuals)
    if (!r.through)
      fmt::print("note: {} did not cut through: this machine's separation speed there is below the feed model's; "
                 "slow the fastest cuts or check the material's machinability\n", r.label);
  fmt::print("rms: widths {:.4f} mm, trail-back {:.4f} mm\n", fit.rms_width_mm, fit.rms_trail_back_mm);
}

// The kerf file with this material's calibration replaced; written whole to a temporary file
// and renamed, so a crash leaves the old file or the new one, never half of one.
std::expected<void, Error> store(const FitOptions& o, const KerfFit& fit) {
  KerfCalibrations all;
  if (fs::exists(o.kerf_file)) {
    auto text = read_config_file(o.kerf_file, "kerf");
    if (!text) return std::unexpected(text.error());
    auto parsed = parse_kerf_toml(*text, o.kerf_file);
    if (!parsed) return std::unexpected(parsed.error());
    all = std::move(*parsed);
  }
  all[o.material] = {fit.model, static_cast<std::int64_t>(fit.residuals.size()), fit.rms_width_mm, fit.rms_trail_back_mm,
                     fs::path(o.measurements).filename().string()};
  const std::string temp = o.kerf_file + ".new";
  {
    std::ofstream out(temp, std::ios::trunc);
    out << kerf_toml(all);
    out.flush();
    if (!out) return std::unexpected(Error{ErrorCode::io_error, fmt::format("cannot write {}", temp)});
  }
  std::error_code ec;
  fs::rename(temp, o.kerf_file, ec);
  if (ec) return std::unexpected(Error{ErrorCode::io_error, fmt::format("cannot replace {}: {}", o.kerf_file, ec.message())});
  return {};
}

int run_fit(const FitOptions& o) {
  // The name `lamina plan` will look the calibration up by: one of the materials file's.
  auto materials = load_materials(o.materials_file);
  if (!materials) return fail(materials.error());
  if (auto known = find_material(*materials, o.material); !known) return fail(known.error());
  auto text = read_config_file(o.measurements, "measurements");
  if (!text) return fail(text.error());
  auto cuts = parse_kerf_measurements(*text, o.measurements);
  if (!cuts) return fail(cuts.error());
  auto fit = fit_kerf_model(*cuts);
  if (!fit) return fail(fit.error());
  print_fit(*fit, o.material);
  if (auto stored = store(o, *fit); !stored) return fail(stored.error());
  fmt::print("wrote the kerf of {} to {}\n", o.material, o.kerf_file);
  return 0;
}

struct CouponOptions {
  CamOptions cam;
  double thickness_mm = 0.0;
  std::string out_dir;
};

std::expected<void, Error> write_file(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::trunc);
  out << text;
  out.flush();
  if (!out) return std::unexpected(Error{ErrorCode::io_error, fmt::format("cannot write {}", path.string())});
  return {};
}

// The CSV a person fills in: each cut's label, path and feed ratio, the measurements left empty.
std::string measurement_sheet(const Coupon& coupon, const std::string& material, double thickness_mm) {
  std::string csv = fmt::format("# calibration coupon: {} mm {}; measure each slot's top and bottom width and its\n"
                                "# trail-back (mm), fill in the last three columns, then: lamina calibrate fit THIS.csv --material '{}'\n"
                                "label,path_mm,feed_ratio,top_width_mm,bottom_width_mm,trail_back_mm\n",
                                thickness_mm, material, material);
  for (const CouponCut& c : coupon.cuts) csv += fmt::format("{},{:.4f},{:.4f},,,\n", c.label, c.path_mm, c.feed_ratio);
  return csv;
}

int run_coupon(const CouponOptions& o) {
  auto settings = resolve_cam_settings(o.cam);
  if (!settings) return fail(settings.error());
  auto material = find_material(settings->materials, o.cam.material.value_or(""));
  if (!material) return fail(material.error());
  CouponParams params;
  params.thickness_mm = o.thickness_mm;
  auto coupon = calibration_coupon(params, *material, settings->machine.cutting);
  if (!coupon) return fail(coupon.error());
  PostParams post = settings->machine.post;
  post.title = fmt::format("CALIBRATION COUPON {:g}MM {}", o.thickness_mm, material->name);
  auto program = post_program(coupon->toolpath, settings->machine.head, post);
  if (!program) return fail(program.error());
  std::error_code ec;
  fs::create_directories(o.out_dir, ec);
  const fs::path dir(o.out_dir);
  for (auto [name, text] : {std::pair{"coupon.nc", program->text}, std::pair{"coupon.csv", measurement_sheet(*coupon, material->name, o.thickness_mm)}})
    if (auto w = write_file(dir / name, text); !w) return fail(w.error());
  fmt::print("{:<12} {:>8} {:>8} {:>10} {:>12}\n", "cut", "path mm", "ratio", "feed mm/min", "v_s mm/min");
  for (const CouponCut& c : coupon->cuts)
    fmt::print("{:<12} {:>8.3f} {:>8.3f} {:>10.1f} {:>12.1f}\n", c.label, c.path_mm, c.feed_ratio, c.feed_mm_per_s * 60.0,
               c.separation_feed_mm_per_s * 60.0);
  fmt::print("sheet at least {:.0f} x {:.0f} mm; about {:.0f} s of cutting\nwrote {} and {}\n", coupon->length_mm, coupon->width_mm,
             coupon->toolpath.time.total_s, (dir / "coupon.nc").string(), (dir / "coupon.csv").string());
  return 0;
}

}  // namespace

void add_calibrate_command(CLI::App& app, int& exit_code) {
  auto* calibrate = app.add_subcommand("calibrate", "Calibrate the jet's kerf (taper, trail-back) from test cuts (docs/jet.md)");
  calibrate->require_subcommand(1);
  auto o = std::make_shared<FitOptions>();
  auto* fit = calibrate->add_subcommand("fit", "Fit the kerf model to a coupon's measured cuts and store it for the material");
  fit->add_option("measurements", o->measurements, "CSV: label,path_mm,feed_ratio,top_width_mm,bottom_width_mm,trail_back_mm")
      ->required();
  fit->add_option("--material", o->material, "the material the coupon was cut from (as in the materials file)")->required();
  fit->add_option("--kerf-file", o->kerf_file, "where calibrations are kept (default: kerf.toml beside the materials file)");
  fit->add_option("--materials", o->materials_file, "the materials file the name is from (default: <config>/materials.toml)");
  auto c = std::make_shared<CouponOptions>();
  auto* coupon = calibrate->add_subcommand("coupon", "Write a test program of labelled slots at several speeds and tilts, and the CSV to measure them into");
  coupon->add_option("--material", c->cam.material, "the sheet's material (as in the materials file)")->required();
  coupon->add_option("--thickness", c->thickness_mm, "the sheet's thickness, mm")->required()->check(CLI::PositiveNumber);
  coupon->add_option("--out", c->out_dir, "folder for coupon.nc and coupon.csv")->required();
  coupon->add_option("--machine", c->cam.machine_file, "machine file (default: <config>/machine.toml)");
  coupon->add_option("--materials", c->cam.materials_file, "materials file (default: <config>/materials.toml)");
  coupon->callback([c, &exit_code] { exit_code = run_coupon(*c); });
  fit->callback([o, &exit_code] {
    if (o->materials_file.empty()) o->materials_file = (fs::path(default_config_dir()) / "materials.toml").string();
    // Beside the materials file: where lamina plan looks for it.
    if (o->kerf_file.empty()) o->kerf_file = (fs::path(o->materials_file).parent_path() / "kerf.toml").string();
    exit_code = run_fit(*o);
  });
}

}  // namespace lamina::cli
