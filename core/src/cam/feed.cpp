// Abrasive waterjet feed models: paper eq. 3 (an energy balance, in SI) and Zeng & Kim's empirical
// machinability model (defined in inch-pound units; converted here and nowhere else).
#include "lamina/core/feed.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace lamina {
namespace {

// The only place non-SI units exist: Zeng & Kim's constants are fitted in these.
constexpr double kPaPerKsi = 6.894757293168361e6;  // 1 ksi = 1000 lbf/in²
constexpr double kMPerInch = 0.0254;
constexpr double kKgPerLb = 0.45359237;
constexpr double kSPerMin = 60.0;

// Zeng & Kim (1993): C is a system constant fitted with garnet abrasive; f_a = 1 for garnet.
constexpr double kZengKimC = 163.0;
constexpr double kGarnetFactor = 1.0;


// Positive and finite; the message names the parameter, its value and its unit.
std::expected<void, Error> positive(std::string_view name, double v, std::string_view unit) {
  if (std::isfinite(v) && v > 0.0) return {};
  return std::unexpected(invalid_argument(fmt::format("cut feed: {} = {} {} must be a finite number > 0", name, v, unit)));
}

std::expected<void, Error> check_jet(const JetSetup& jet) {
  for (auto r : {positive("jet.pressure_pa", jet.pressure_pa, "Pa"),
                 positive("jet.orifice_diameter_m", jet.orifice_diameter_m, "m"),
                 positive("jet.focus_diameter_m", jet.focus_diameter_m, "m"),
                 positive("jet.abrasive_rate_kg_per_s", jet.abrasive_rate_kg_per_s, "kg/s"),
                 positive("jet.water_density_kg_per_m3", jet.water_density_kg_per_m3, "kg/m³")})
    if (!r) return r;
  const double cd = jet.discharge_coefficient;
  if (!(std::isfinite(cd) && cd > 0.0 && cd <= 1.0))
    return std::unexpected(invalid_argument(fmt::format("cut feed: jet.discharge_coefficient = {} must be in (0, 1]", cd)));
  return {};
}

// What the chosen model reads of the material and params, nothing more.
std::expected<void, Error> check_model_inputs(const Material& m, const FeedParams& params) {
  if (params.model == FeedModel::limbachiya_patel) {
    if (!(std::isfinite(m.specific_energy_j_per_m3) && m.specific_energy_j_per_m3 > 0.0))
      return std::unexpected(invalid_argument(fmt::format(
          "cut feed: material '{}' specific_energy_j_per_m3 = {} J/m³ must be > 0 for the limbachiya_patel model", m.name,
          m.specific_energy_j_per_m3)));
    return {};
  }
  if (!(std::isfinite(m.machinability) && m.machinability > 0.0))
    return std::unexpected(invalid_argument(fmt::format("cut feed: material '{}' machinability = {} must be > 0 for the zeng_kim model",
                                               m.name, m.machinability)));
  if (params.quality < 1 || params.quality > 5)
    return std::unexpected(invalid_argument(
        fmt::format("cut feed: quality = {} is outside 1 (separation cut) … 5 (finest) of the zeng_kim model", params.quality)));
  return {};
}

std::expected<void, Error> check_cut(const FeedParams& params, double thickness_mm, double tilt_rad) {
  if (auto r = positive("thickness_mm", thickness_mm, "mm"); !r) return r;
  // cos(tilt) → 0 makes the jet's path through the sheet infinite; the sign is only the lean direction.
  if (!(std::isfinite(tilt_rad) && std::abs(tilt_rad) < std::numbers::pi / 2))
    return std::unexpected(invalid_argument(fmt::format("cut feed: tilt_rad = {} rad must satisfy |tilt| < π/2 (90°)", tilt_rad)));
  if (auto r = positive("min_feed_mm_per_s", params.min_feed_mm_per_s, "mm/s"); !r) return r;
  if (!(std::isfinite(params.max_feed_mm_per_s) && params.max_feed_mm_per_s >= params.min_feed_mm_per_s))
    return std::unexpected(invalid_argument(fmt::format("cut feed: max_feed_mm_per_s = {} mm/s must be finite and >= min_feed_mm_per_s = {} mm/s",
                                               params.max_feed_mm_per_s, params.min_feed_mm_per_s)));
  return {};
}

}  // namespace

const ChoiceTable<FeedModel>& feed_models() {
  static constexpr Choice<FeedModel> rows[] = {
      {FeedModel::zeng_kim, "zeng-kim", "Zeng & Kim's machinability model, quality levels 1-5"},
      {FeedModel::limbachiya_patel, "limbachiya-patel", "the paper's eq. 3 (specific energy of the material)"}};
  static constexpr ChoiceTable<FeedModel> table{"feed model", rows};
  return table;
}

const char* feed_model_name(FeedModel model) {
  switch (model) {
    case FeedModel::limbachiya_patel: return "limbachiya_patel";
    case FeedModel::zeng_kim: return "zeng_kim";
  }
  return "unknown";
}

std::expected<FeedModel, Error> parse_feed_model(std::string_view name) {
  for (FeedModel m : {FeedModel::limbachiya_patel, FeedModel::zeng_kim})
    if (name == feed_model_name(m)) return m;
  if (auto typed = feed_models().parse(name)) return *typed;
  return std::unexpected(invalid_argument(fmt::format("unknown feed model '{}' (known: limbachiya_patel, zeng_kim)", name)));
}

double water_mass_flow_kg_per_s(const JetSetup& jet) {
  // Bernoulli: the jet leaves the orifice at √(2p/ρ_w); C_d folds contraction and friction losses.
  const double area_m2 = std::numbers::pi / 4.0 * jet.orifice_diameter_m * jet.orifice_diameter_m;
  const double velocity_m_per_s = std::sqrt(2.0 * jet.pressure_pa / jet.water_density_kg_per_m3);
  return jet.water_density_kg_per_m3 * area_m2 * jet.discharge_coefficient * velocity_m_per_s;
}

// Dimensional check of eq. 3 (SI), done by hand:
//   (π/4) d_o²            m²
//   p^{3/2}               (kg m⁻¹ s⁻²)^{3/2} = kg^{3/2} m^{-3/2} s⁻³
//   √(2/ρ_w)              (m³/kg)^{1/2}      = m^{3/2} kg^{-1/2}
//   numerator             m² · kg s⁻³                       (= W: the jet's hydraulic power)
//   μ_job d_i h_f         (J/m³ = kg m⁻¹ s⁻²) · m · m = kg m s⁻²
//   ratio                 m² kg s⁻³ / (kg m s⁻²) = m/s.  R and 1/(1+R) are dimensionless.
// So the printed formula is a speed as it stands. Its reading: (π/4) d_o² p √(2p/ρ_w) is the water's
// power p·Q; R/(1+R)² is the share of it the abrasive carries after momentum mixing
// (v_a = v_w/(1+R), ½ṁ_a v_a² = R/(1+R)² · ½ṁ_w v_w²); divided by μ_job that is a removed volume per
// second, and by the kerf cross-section d_i · h_f a traverse speed.
double limbachiya_patel_feed_mm_per_s(const JetSetup& jet, const Material& material, double cut_depth_mm) {
  const double water_kg_per_s = water_mass_flow_kg_per_s(jet);
  const double r = jet.abrasive_rate_kg_per_s / water_kg_per_s;
  // ṁ_w · p/ρ_w = (π/4) d_o² C_d p^{3/2} √(2/ρ_w): the printed numerator at C_d = 1.
  const double hydraulic_power_w = water_kg_per_s * jet.pressure_pa / jet.water_density_kg_per_m3;
  const double abrasive_power_w = hydraulic_power_w * r / ((1.0 + r) * (1.0 + r));
  const double h_f_m = cut_depth_mm * 1e-3;
  const double feed_m_per_s = abrasive_power_w / (material.specific_energy_j_per_m3 * jet.focus_diameter_m * h_f_m);
  return feed_m_per_s * 1e3;
}

double zeng_kim_feed_mm_per_s(const JetSetup& jet, const Material& material, double cut_depth_mm, int quality) {
  // SI → the published units, once.
  const double p_ksi = jet.pressure_pa / kPaPerKsi;
  const double d_o_in = jet.orifice_diameter_m / kMPerInch;
  const double d_m_in = jet.focus_diameter_m / kMPerInch;
  const double m_a_lb_per_min = jet.abrasive_rate_kg_per_s * kSPerMin / kKgPerLb;
  const double h_in = cut_depth_mm * 1e-3 / kMPerInch;
  const double base = kGarnetFactor * material.machinability * std::pow(p_ksi, 1.594) * std::pow(d_o_in, 1.374) *
                      std::pow(m_a_lb_per_min, 0.343) /
                      (kZengKimC * static_cast<double>(quality) * h_in * std::pow(d_m_in, 0.618));
  const double u_in_per_min = std::pow(base, 1.15);
  return u_in_per_min * kMPerInch * 1e3 / kSPerMin;  // in/min → mm/s
}

namespace {

// The chosen model's feed at this quality, checked and unclamped.
std::expected<double, Error> model_feed_mm_per_s(const JetSetup& jet, const Material& material, const FeedParams& params,
                                                 double thickness_mm, double tilt_rad) {
  if (auto r = check_jet(jet); !r) return std::unexpected(r.error());
  if (auto r = check_model_inputs(material, params); !r) return std::unexpected(r.error());
  if (auto r = check_cut(params, thickness_mm, tilt_rad); !r) return std::unexpected(r.error());
  // A tilted jet crosses the sheet along its axis: the depth it must erode is t / cos(tilt).
  const double h_f_mm = thickness_mm / std::cos(tilt_rad);
  return params.model == FeedModel::limbachiya_patel ? limbachiya_patel_feed_mm_per_s(jet, material, h_f_mm)
                                                     : zeng_kim_feed_mm_per_s(jet, material, h_f_mm, params.quality);
}

}  // namespace

std::expected<double, Error> cut_feed_mm_per_s(const JetSetup& jet, const Material& material, const FeedParams& params,
                                               double thickness_mm, double tilt_rad) {
  auto feed = model_feed_mm_per_s(jet, material, params, thickness_mm, tilt_rad);
  if (!feed) return feed;
  return std::clamp(*feed, params.min_feed_mm_per_s, params.max_feed_mm_per_s);
}

std::expected<double, Error> separation_feed_mm_per_s(const JetSetup& jet, const Material& material, const FeedParams& params,
                                                      double thickness_mm, double tilt_rad) {
  FeedParams separation = params;
  separation.quality = 1;
  return model_feed_mm_per_s(jet, material, separation, thickness_mm, tilt_rad);
}

}  // namespace lamina
