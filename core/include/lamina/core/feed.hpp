#pragma once
// Abrasive waterjet feed models (paper eq. 3, and Zeng & Kim's machinability model). SI inside:
// metres, kilograms, seconds, pascals; the result in mm/s. Inches, pounds, ksi and minutes exist
// only where a published constant is defined in them, converted in one place (feed.cpp).
#include "lamina/core/choices.hpp"
#include "lamina/core/error.hpp"

#include <cstdint>
#include <expected>
#include <string>
#include <string_view>
#include <vector>

namespace lamina {

enum class FeedModel : std::uint8_t { limbachiya_patel, zeng_kim };
// As typed: "zeng-kim", "limbachiya-patel" (choices.hpp). feed_model_name() is report.json's
// spelling ("zeng_kim"), kept since issue 4; parse_feed_model() reads either.
const ChoiceTable<FeedModel>& feed_models();
const char* feed_model_name(FeedModel model);  // "limbachiya_patel", "zeng_kim"
// The model of a name feed_model_name gives; invalid_argument naming the known names otherwise.
std::expected<FeedModel, Error> parse_feed_model(std::string_view name);

// One material of config/materials.toml.
struct Material {
  std::string name;
  double density_kg_per_m3 = 0.0;
  double specific_energy_j_per_m3 = 0.0;  // μ_job of paper eq. 3: energy to remove a unit volume (0: unknown)
  double machinability = 0.0;             // N_m of Zeng & Kim (aluminium ≈ 213, mild steel ≈ 81; 0: unknown)
};

// The cutting head and pump: what both models need.
struct JetSetup {
  double pressure_pa = 380e6;            // pump pressure at the orifice
  double orifice_diameter_m = 0.33e-3;   // d_o (jewel)
  double focus_diameter_m = 1.02e-3;     // d_i / d_m (focusing tube, "insert")
  double abrasive_rate_kg_per_s = 0.0058;  // M_a (≈ 0.77 lb/min)
  double water_density_kg_per_m3 = 998.0;  // ρ_w
  double discharge_coefficient = 1.0;      // of the orifice, for the water mass flow (eq. 3 assumes 1)
};

struct FeedParams {
  FeedModel model = FeedModel::zeng_kim;
  int quality = 3;                 // Zeng–Kim quality level 1 (separation) … 5 (finest)
  double min_feed_mm_per_s = 0.1;  // the machine's slowest programmable feed
  double max_feed_mm_per_s = 250;  // and its fastest cutting feed
};

// Water mass flow through the orifice, kg/s: ρ_w · (π/4) d_o² · C_d · √(2p/ρ_w).
double water_mass_flow_kg_per_s(const JetSetup& jet);

// Paper eq. 3 (Limbachiya & Patel 2011) in SI: v_f = (π/4) d_o² R (1/(1+R))² p^{3/2} /
// (μ_job d_i h_f) · √(2/ρ_w), R = abrasive / water mass flow, h_f the jet's path through the
// material (t / cos tilt). The hydraulic-power factor (π/4) d_o² p^{3/2} √(2/ρ_w) is taken times
// the discharge coefficient, so it equals the printed formula at C_d = 1 and stays consistent with
// the water mass flow in R otherwise. Returns mm/s, unclamped; inputs are not checked.
double limbachiya_patel_feed_mm_per_s(const JetSetup& jet, const Material& material, double cut_depth_mm);

// Zeng & Kim: u = (f_a N_m p^1.594 d_o^1.374 M_a^0.343 / (C q h d_m^0.618))^1.15 in the published
// units (ksi, in, lb/min, in/min; C = 163, f_a = 1 for garnet), converted to SI. Returns mm/s,
// unclamped; inputs are not checked.
double zeng_kim_feed_mm_per_s(const JetSetup& jet, const Material& material, double cut_depth_mm, int quality);

// The feed a cut line gets: the chosen model at h_f = thickness / cos(tilt), clamped to the
// machine's limits. Errors (invalid_argument) name the parameter and its value: quality outside
// 1–5 (Zeng–Kim), a non-positive or non-finite pressure, diameter, flow, water density, thickness,
// specific energy (eq. 3) or machinability (Zeng–Kim), a discharge coefficient outside (0, 1],
// |tilt| ≥ 90°, min feed ≤ 0 or max feed < min feed. Only what the chosen model uses is checked,
// so a material known by its machinability alone can be cut with Zeng–Kim.
std::expected<double, Error> cut_feed_mm_per_s(const JetSetup& jet, const Material& material,
                                               const FeedParams& params, double thickness_mm, double tilt_rad);

// The separation speed v_s at this path (mm/s, not clamped): the feed that just cuts through —
// Zeng & Kim's quality 1, or eq. 3 (whose μ_job is calibrated to it). The kerf model's feed
// ratio is a feed over this (kerf.hpp). Same checks and errors as cut_feed_mm_per_s.
std::expected<double, Error> separation_feed_mm_per_s(const JetSetup& jet, const Material& material,
                                                      const FeedParams& params, double thickness_mm, double tilt_rad);

}  // namespace lamina
