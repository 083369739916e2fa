// The kerf model and its fit from test cuts (kerf.hpp). Three small linear least-squares
// problems, solved with Eigen's column-pivoting QR (rank-revealing: two cuts at one speed cannot
// separate a slope from an intercept, and are refused rather than answered with noise).
#include "lamina/core/kerf.hpp"

#include <Eigen/Core>
#include <Eigen/QR>
#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <set>
#include <utility>

namespace lamina {
namespace {


bool positive(double v) { return std::isfinite(v) && v > 0.0; }

std::expected<void, Error> check_cut(const KerfMeasurement& m, std::size_t row) {
  const std::string name = m.label.empty() ? fmt::format("row {}", row + 1) : fmt::format("cut '{}'", m.label);
  if (!positive(m.path_mm)) return std::unexpected(invalid_argument(fmt::format("{}: path {} mm must be > 0", name, m.path_mm)));
  if (!positive(m.feed_ratio))
    return std::unexpected(invalid_argument(fmt::format("{}: feed ratio {} must be > 0 (feed / separation feed)", name, m.feed_ratio)));
  const bool not_through = m.bottom_width_mm == 0.0;
  if (!positive(m.top_width_mm) || (!positive(m.bottom_width_mm) && !not_through))
    return std::unexpected(invalid_argument(fmt::format("{}: widths {} / {} mm must be > 0 (top / bottom; a bottom of 0: not through)", name,
                                           m.top_width_mm, m.bottom_width_mm)));
  if (not_through) return {};
  if (!positive(m.trail_back_mm))
    return std::unexpected(invalid_argument(fmt::format("{}: trail-back {} mm must be > 0 (a real cut always lags; 0 is a missing reading)",
                                           name, m.trail_back_mm)));
  return {};
}

// y ≈ a + b·x by least squares; nullopt when the xs do not tell a slope (all equal).
std::optional<std::pair<double, double>> line_fit(const Eigen::VectorXd& x, const Eigen::VectorXd& y) {
  Eigen::MatrixXd design(x.size(), 2);
  design.col(0).setOnes();
  design.col(1) = x;
  const auto qr = design.colPivHouseholderQr();
  if (qr.rank() < 2) return std::nullopt;
  const Eigen::Vector2d ab = qr.solve(y);
  return std::pair{ab(0), ab(1)};
}

double rms(const Eigen::VectorXd& v) { return v.size() ? std::sqrt(v.squaredNorm() / static_cast<double>(v.size())) : 0.0; }

// Each cut's measured − model, and the RMS over what was measured (a cut that did not go through
// has a top width only).
void add_residuals(KerfFit& fit, std::span<const KerfMeasurement> cuts) {
  std::vector<double> widths, lags;
  const KerfModel& m = fit.model;
  for (const KerfMeasurement& c : cuts) {
    KerfResidual res{c.label, 0.0, 0.0, 0.0, c.bottom_width_mm != 0.0};
    const double top_mm = m.top_width_mm + m.top_width_per_ratio_mm * c.feed_ratio;
    res.top_width_mm = c.top_width_mm - top_mm;
    widths.push_back(res.top_width_mm);
    if (res.through) {
      const double bottom_mm = top_mm - c.path_mm * m.taper_per_ratio * (c.feed_ratio - m.taper_free_ratio);
      res.bottom_width_mm = c.bottom_width_mm - bottom_mm;
      res.trail_back_mm = c.trail_back_mm - m.trail_back_factor * c.path_mm * std::pow(c.feed_ratio, m.trail_back_exponent);
      widths.push_back(res.bottom_width_mm);
      lags.push_back(res.trail_back_mm);
    }
    fit.residuals.push_back(std::move(res));
  }
  fit.rms_width_mm = rms(Eigen::Map<const Eigen::VectorXd>(widths.data(), static_cast<Eigen::Index>(widths.size())));
  fit.rms_trail_back_mm = rms(Eigen::Map<const Eigen::VectorXd>(lags.data(), static_cast<Eigen::Index>(lags.size())));
}

}  // namespace

std::expected<KerfShape, Error> kerf_at(const KerfModel& model, double path_mm, double feed_ratio) {
  if (!positive(path_mm)) return std::unexpected(invalid_argument(fmt::format("kerf: path {} mm must be > 0", path_mm)));
  if (!positive(feed_ratio))
    return std::unexpected(invalid_argument(fmt::format("kerf: feed ratio {} must be > 0 (feed / separation feed)", feed_ratio)));
  KerfShape k;
  k.top_width_mm = model.top_width_mm + model.top_width_per_ratio_mm * feed_ratio;
  const double taper_mm = path_mm * model.taper_per_ratio * (feed_ratio - model.taper_free_ratio);
  k.bottom_width_mm = k.top_width_mm - taper_mm;
  if (!(k.top_width_mm > 0.0) || !(k.bottom_width_mm > 0.0))
    return std::unexpected(invalid_argument(fmt::format("kerf: at {:.3g} mm and feed ratio {:.3g} the model gives widths {:.3g} / {:.3g} mm "
                                           "(top / bottom): beyond what it was calibrated for",
                                           path_mm, feed_ratio, k.top_width_mm, k.bottom_width_mm)));
  k.wall_lean_rad = std::atan2(taper_mm / 2.0, path_mm);
  k.trail_back_mm = model.trail_back_factor * path_mm * std::pow(feed_ratio, model.trail_back_exponent);
  return k;
}

std::expected<KerfFit, Error> fit_kerf_model(std::span<const KerfMeasurement> cuts) {
  std::set<double> ratios;
  std::vector<const KerfMeasurement*> through;
  for (std::size_t i = 0; i < cuts.size(); ++i) {
    if (auto ok = check_cut(cuts[i], i); !ok) return std::unexpected(ok.error());
    if (cuts[i].bottom_width_mm == 0.0) continue;
    ratios.insert(cuts[i].feed_ratio);
    through.push_back(&cuts[i]);
  }
  if (ratios.size() < 2)
    return std::unexpected(invalid_argument(fmt::format("kerf fit: {} cut(s) through the sheet at {} feed ratio(s); it needs cuts at two "
                                           "speeds at least",
                                           through.size(), ratios.size())));
  const auto n = static_cast<Eigen::Index>(cuts.size()), nt = static_cast<Eigen::Index>(through.size());
  Eigen::VectorXd r(n), top(n), rt(nt), taper(nt), log_r(nt), log_lag(nt);
  for (Eigen::Index i = 0; i < n; ++i) {
    r(i) = cuts[static_cast<std::size_t>(i)].feed_ratio;
    top(i) = cuts[static_cast<std::size_t>(i)].top_width_mm;
  }
  for (Eigen::Index i = 0; i < nt; ++i) {
    const KerfMeasurement& c = *through[static_cast<std::size_t>(i)];
    rt(i) = c.feed_ratio;
    taper(i) = (c.top_width_mm - c.bottom_width_mm) / c.path_mm;
    log_r(i) = std::log(c.feed_ratio);
    log_lag(i) = std::log(c.trail_back_mm / c.path_mm);
  }
  const auto width_line = line_fit(r, top), taper_line = line_fit(rt, taper), lag_line = line_fit(log_r, log_lag);
  if (!width_line || !taper_line || !lag_line) return std::unexpected(invalid_argument("kerf fit: the feed ratios do not separate slope and intercept"));
  KerfFit fit;
  fit.model.top_width_mm = width_line->first;
  fit.model.top_width_per_ratio_mm = width_line->second;
  fit.model.taper_per_ratio = taper_line->second;
  // Taper k·(r − r0) = a + k·r: r0 = −a / k. A taper that does not change with speed has no r0.
  if (std::abs(taper_line->second) < 1e-12)
    return std::unexpected(invalid_argument("kerf fit: the taper does not change with the feed; the model's taper needs it to"));
  fit.model.taper_free_ratio = -taper_line->first / taper_line->second;
  fit.model.trail_back_factor = std::exp(lag_line->first);
  fit.model.trail_back_exponent = lag_line->second;

  add_residuals(fit, cuts);
  return fit;
}

}  // namespace lamina
