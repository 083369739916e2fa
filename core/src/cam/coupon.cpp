// The calibration coupon (coupon.hpp): one straight slot per (tilt, feed ratio), in rows, each a
// contour of its own — pierce, lead-in, the test cut, lead-out — so the program's markers name the
// cuts and the link can resume it like any sheet. The tilt leans the jet across the travel, the
// way a bevel does, so the slot crosses a path of t / cos tilt.
#include "lamina/core/coupon.hpp"

#include "cam/toolpath_ring.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

namespace lamina {
namespace {

constexpr double kMaxTiltRad = std::numbers::pi / 3.0;  // the heads we post for tilt to 60°


std::expected<void, Error> check(const CouponParams& c) {
  if (c.feed_ratios.empty() || c.tilts_rad.empty()) return std::unexpected(invalid_argument("coupon: needs a feed ratio and a tilt at least"));
  for (double r : c.feed_ratios)
    if (!std::isfinite(r) || r <= 0.0 || r > 2.0) return std::unexpected(invalid_argument(fmt::format("coupon: feed ratio {} must be in (0, 2]", r)));
  for (double t : c.tilts_rad)
    if (!std::isfinite(t) || std::abs(t) > kMaxTiltRad)
      return std::unexpected(invalid_argument(fmt::format("coupon: tilt {:.1f} deg is beyond 60 deg", t * 180.0 / std::numbers::pi)));
  for (auto [name, v] : {std::pair{"thickness_mm", c.thickness_mm}, std::pair{"cut_length_mm", c.cut_length_mm},
                         std::pair{"spacing_mm", c.spacing_mm}, std::pair{"margin_mm", c.margin_mm}})
    if (!std::isfinite(v) || v <= 0.0) return std::unexpected(invalid_argument(fmt::format("coupon: {} = {} must be > 0", name, v)));
  return {};
}

// The jet's travel time between two tips with their axes (the toolpath's rule: top or bottom,
// whichever moves further).
double travel_s(const Eigen::Vector3d& tip0, const Eigen::Vector3d& axis0, const Eigen::Vector3d& tip1,
                const Eigen::Vector3d& axis1, double thickness_mm, double feed_mm_per_s) {
  const auto bottom = [&](const Eigen::Vector3d& tip, const Eigen::Vector3d& axis) -> Eigen::Vector3d {
    return tip - axis * (thickness_mm / axis.z());
  };
  return cam_detail::jet_travel_s(tip0, bottom(tip0, axis0), tip1, bottom(tip1, axis1), feed_mm_per_s);
}

class CouponBuilder {
 public:
  CouponBuilder(const CouponParams& c, const ToolpathParams& p) : c_(c), p_(p) {}

  void park() { rapid({p_.park_mm.x(), p_.park_mm.y(), p_.safe_z_mm}, Eigen::Vector3d::UnitZ(), -1); }

  // One slot along +x at y, from x0 for the cut's length.
  void slot(const CouponCut& cut, double x0_mm, double y_mm) {
    const int id = static_cast<int>(out_.contours.size());
    ToolContour contour;
    contour.label = cut.label;
    contour.first_move = out_.moves.size();
    const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d axis(0.0, -std::sin(cut.tilt_rad), std::cos(cut.tilt_rad));  // leans across the travel
    const Eigen::Vector3d pierce(x0_mm - p_.lead_in_mm, y_mm, 0.0), start(x0_mm, y_mm, 0.0),
        end(x0_mm + c_.cut_length_mm, y_mm, 0.0), out(end.x() + p_.lead_out_mm, y_mm, 0.0);
    contour.pierce_mm = pierce.head<2>();
    rapid({pierce.x(), pierce.y(), p_.safe_z_mm}, up, id);
    rapid(pierce, up, id);
    push({MoveKind::pierce, pierce, up, 0.0, p_.pierce_dwell_s, p_.pierce_dwell_s, true, id});
    const double f = cut.feed_mm_per_s;
    push({MoveKind::lead_in, start, axis, f, travel_s(pierce, up, start, axis, c_.thickness_mm, f), 0.0, true, id});
    push({MoveKind::cut, end, axis, f, travel_s(start, axis, end, axis, c_.thickness_mm, f), 0.0, true, id});
    push({MoveKind::lead_out, out, axis, f, travel_s(end, axis, out, axis, c_.thickness_mm, f), 0.0, true, id});
    rapid({out.x(), out.y(), p_.safe_z_mm}, axis, id);
    contour.end_move = out_.moves.size();
    out_.contours.push_back(contour);
  }

  SheetToolpath finish() {
    out_.thickness_mm = c_.thickness_mm;
    out_.time = cut_time(out_.moves);
    return std::move(out_);
  }

 private:
  void push(const ToolMove& m) { out_.moves.push_back(m); }
  void rapid(const Eigen::Vector3d& tip, const Eigen::Vector3d& axis, int contour) {
    const Eigen::Vector3d from = out_.moves.empty() ? tip : out_.moves.back().tip_mm;
    push({MoveKind::rapid, tip, axis, 0.0, (tip - from).norm() / p_.rapid_mm_per_s, 0.0, false, contour});
  }

  const CouponParams& c_;
  const ToolpathParams& p_;
  SheetToolpath out_;
};

}  // namespace

std::expected<Coupon, Error> calibration_coupon(const CouponParams& c, const Material& material, const ToolpathParams& params) {
  if (auto ok = check(c); !ok) return std::unexpected(ok.error());
  Coupon coupon;
  CouponBuilder builder(c, params);
  builder.park();
  const double x0 = c.margin_mm + params.lead_in_mm;
  double y = c.margin_mm;
  for (double tilt : c.tilts_rad)
    for (double ratio : c.feed_ratios) {
      CouponCut cut;
      cut.tilt_rad = tilt;
      cut.path_mm = c.thickness_mm / std::cos(tilt);
      auto separation = separation_feed_mm_per_s(params.jet, material, params.feed, c.thickness_mm, tilt);
      if (!separation) return std::unexpected(separation.error());
      cut.separation_feed_mm_per_s = *separation;
      // The machine's feed limits win; the ratio is then what it really cut at.
      cut.feed_mm_per_s = std::clamp(ratio * *separation, params.feed.min_feed_mm_per_s, params.feed.max_feed_mm_per_s);
      cut.feed_ratio = cut.feed_mm_per_s / *separation;
      cut.label = fmt::format("T{:.0f}-R{:.2f}", tilt * 180.0 / std::numbers::pi, cut.feed_ratio);
      cut.contour = static_cast<int>(coupon.cuts.size());
      builder.slot(cut, x0, y);
      coupon.cuts.push_back(std::move(cut));
      y += c.spacing_mm;
    }
  builder.park();
  coupon.toolpath = builder.finish();
  coupon.length_mm = x0 + c.cut_length_mm + params.lead_out_mm + c.margin_mm;
  coupon.width_mm = y - c.spacing_mm + c.margin_mm;
  return coupon;
}

}  // namespace lamina
