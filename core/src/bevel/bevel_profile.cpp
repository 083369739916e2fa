// Cut lines for one station's profile (paper 3-3 to 3-5), and how far they leave the surface.
// Conventions in bevel_profile.hpp: u along the outward normal, material at u < surface, several
// cuts keep the minimum of their lines.
#include "lamina/core/bevel_profile.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace lamina {

const ChoiceTable<CutSide>& cut_sides() {
  static constexpr Choice<CutSide> rows[] = {
      {CutSide::outside, "outside", "cuts leave material outside the surface (the part is never cut into)"},
      {CutSide::inside, "inside", "cuts stay inside the surface (nothing stands proud of it)"},
      {CutSide::mixed, "mixed", "cuts may cross the surface: the least deviation either way"}};
  static constexpr ChoiceTable<CutSide> table{"cut side", rows};
  return table;
}

const ChoiceTable<BevelStrategy>& bevel_strategies() {
  static constexpr Choice<BevelStrategy> rows[] = {
      {BevelStrategy::curved, "curved", "several tangent cuts on convex edges, one on concave (the paper's form)"},
      {BevelStrategy::sloped, "sloped", "one straight cut from the layer's bottom contour to its top"},
      {BevelStrategy::vertical, "vertical", "a vertical cut (a 2-axis machine's staircase)"}};
  static constexpr ChoiceTable<BevelStrategy> table{"bevel strategy", rows};
  return table;
}

const char* cut_side_name(CutSide side) { return cut_sides().name_of(side); }

const char* bevel_strategy_name(BevelStrategy strategy) { return bevel_strategies().name_of(strategy); }

const char* profile_shape_name(ProfileShape shape) {
  switch (shape) {
    case ProfileShape::straight: return "straight";
    case ProfileShape::convex: return "convex";
    case ProfileShape::concave: return "concave";
    case ProfileShape::mixed: return "mixed";
    case ProfileShape::empty: return "empty";
  }
  return "?";
}

namespace {

struct Point {
  double z, u;
};

// A line u = c + m·(z − z_bottom).
struct Line {
  double c, m;
  double at(double z, double z_bottom) const { return c + m * (z - z_bottom); }
};

class Fitter {
 public:
  Fitter(std::span<const ProfileSample> samples, double z_bottom, double z_top, const ProfileFitParams& params,
         std::span<const ProfileBound> surface, double ceiling)
      : all_(samples), zb_(z_bottom), zt_(z_top), params_(params), ceiling_(ceiling) {
    tan_max_ = params.tilt_max_rad >= 0.5 * M_PI - 1e-9 ? 1e12 : std::tan(params.tilt_max_rad);
    for (const auto& s : samples) {
      if (s.present && std::isfinite(s.u_mm)) present_.push_back({s.z_mm, s.u_mm});
    }
    // Between two samples a surface bulging out can pass beyond a line that only clears the
    // samples. Where the tangents are known, the point where neighbouring tangents meet bounds
    // the bulge; outside lines clear those corners too.
    bounds_ = present_;
    for (const auto& b : surface) bounds_.push_back({b.z_mm, b.u_mm});
    for (std::size_t i = 0; surface.empty() && i + 1 < samples.size(); ++i) {
      const auto& a = samples[i];
      const auto& b = samples[i + 1];
      if (!a.present || !b.present || !std::isfinite(a.slope) || !std::isfinite(b.slope)) continue;
      const double dm = a.slope - b.slope;
      if (dm <= 1e-12) continue;  // not bending back: the chord already bounds it
      const double z = a.z_mm + (b.u_mm - a.u_mm - b.slope * (b.z_mm - a.z_mm)) / dm;
      if (z > a.z_mm && z < b.z_mm) bounds_.push_back({z, a.u_mm + a.slope * (z - a.z_mm)});
    }
  }

  ProfileFit run() {
    ProfileFit fit;
    if (present_.empty()) return fit;  // shape empty, no cut: nothing of the part on this line
    classify(fit);
    std::vector<Line> lines = choose_lines(fit);
    for (Line& l : lines) {
      if (std::max(l.at(zb_, zb_), l.at(zt_, zb_)) > ceiling_) l = support_above(0.0);
    }
    fit.cuts.reserve(lines.size());
    for (const Line& l : lines) fit.cuts.push_back({l.at(zb_, zb_), l.at(zt_, zb_)});
    fit.max_deviation_mm = deviation(lines);
    return fit;
  }

 private:
  double clamp_slope(double m) {
    if (!std::isfinite(m)) m = m > 0 ? tan_max_ : -tan_max_;
    if (std::abs(m) > tan_max_) {
      limited_ = true;
      return std::copysign(tan_max_, m);
    }
    return m;
  }

  // Slope of the surface at sample i of all_: the facet's tangent, or a finite difference where
  // the sample carries none.
  double sample_slope(std::size_t i) const {
    if (std::isfinite(all_[i].slope)) return all_[i].slope;
    return chord_slope_;
  }

  double chord_at(double z) const { return present_.front().u + chord_slope_ * (z - present_.front().z); }

  void classify(ProfileFit& fit) {
    const Point& a = present_.front();
    const Point& b = present_.back();
    if (present_.size() >= 2 && b.z - a.z > 1e-12) {
      chord_slope_ = (b.u - a.u) / (b.z - a.z);
    } else {
      // One sample: the surface's own tangent is all we know.
      chord_slope_ = 0.0;
      for (const auto& s : all_) {
        if (s.present && std::isfinite(s.slope)) { chord_slope_ = s.slope; break; }
      }
    }
    const double tol = params_.straight_tolerance_mm;
    bool above = false, below = false;  // some sample bulges beyond / stays behind the chord
    for (const Point& p : present_) {
      const double d = p.u - chord_at(p.z);
      above |= d > tol;
      below |= d < -tol;
    }
    fit.shape = above && below ? ProfileShape::mixed
              : above          ? ProfileShape::convex
              : below          ? ProfileShape::concave
                               : ProfileShape::straight;
    // The paper's rule: convex when the tangent at the bottom (θ) leans out more than higher up
    // (β), i.e. du/dz decreases upwards.
    if (fit.shape == ProfileShape::convex || fit.shape == ProfileShape::concave) {
      double first = std::numeric_limits<double>::quiet_NaN(), last = first;
      for (std::size_t i = 0; i < all_.size(); ++i) {
        if (!all_[i].present || !std::isfinite(all_[i].slope)) continue;
        if (std::isnan(first)) first = all_[i].slope;
        last = all_[i].slope;
      }
      if (std::isfinite(first) && std::isfinite(last)) {
        const bool slope_says_convex = first > last;
        fit.slope_rule_agrees = slope_says_convex == (fit.shape == ProfileShape::convex);
      }
    }
    shape_ = fit.shape;
  }

  // The line of slope m through the outermost (outside) / innermost (inside) sample.
  Line support_above(double m) const {
    double c = -std::numeric_limits<double>::infinity();
    for (const Point& p : bounds_) c = std::max(c, p.u - m * (p.z - zb_));
    return {c, m};
  }
  Line support_below(double m) const {
    double c = std::numeric_limits<double>::infinity();
    for (const Point& p : present_) c = std::min(c, p.u - m * (p.z - zb_));
    return {c, m};
  }
  // Chebyshev: the line of slope m centred between the samples.
  Line centred(double m, double* half_width) const {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Point& p : present_) {
      const double r = p.u - m * (p.z - zb_);
      lo = std::min(lo, r);
      hi = std::max(hi, r);
    }
    if (half_width) *half_width = 0.5 * (hi - lo);
    return {0.5 * (hi + lo), m};
  }

  // Candidate slopes for a single best line: the chord, the surface tangents, and the slopes
  // between every pair of samples (the hull edges are among them).
  std::vector<double> candidate_slopes() {
    std::vector<double> ms{chord_slope_};
    for (std::size_t i = 0; i < all_.size(); ++i) {
      if (all_[i].present && std::isfinite(all_[i].slope)) ms.push_back(all_[i].slope);
    }
    for (std::size_t i = 0; i < present_.size(); ++i) {
      for (std::size_t j = i + 1; j < present_.size(); ++j) {
        const double dz = present_[j].z - present_[i].z;
        if (dz > 1e-12) ms.push_back((present_[j].u - present_[i].u) / dz);
      }
    }
    for (double& m : ms) m = clamp_slope(m);
    return ms;
  }

  // One supporting line (outside: above every sample; inside: below) with the smallest gap.
  Line best_support(bool above) {
    Line best{0, 0};
    double best_gap = std::numeric_limits<double>::infinity();
    const bool was_limited = limited_;
    bool best_limited = false;
    for (double m : candidate_slopes()) {
      limited_ = false;
      const double mm = clamp_slope(m);
      const Line l = above ? support_above(mm) : support_below(mm);
      double gap = 0;
      for (const Point& p : present_) gap = std::max(gap, std::abs(l.at(p.z, zb_) - p.u));
      if (gap < best_gap - 1e-12) {
        best_gap = gap;
        best = l;
        best_limited = std::abs(mm) >= tan_max_ * (1 - 1e-12) && std::abs(m) >= tan_max_;
      }
    }
    limited_ = was_limited || best_limited;
    return best;
  }

  std::vector<Line> choose_lines(ProfileFit& fit) {
    std::vector<Line> lines;
    const auto& st = params_.strategy;
    const auto& side = params_.side;
    const bool curved = st == BevelStrategy::curved;
    if (side == CutSide::mixed) {
      const double m = st == BevelStrategy::vertical ? 0.0 : clamp_slope(chord_slope_);
      lines.push_back(centred(m, nullptr));
    } else if (st == BevelStrategy::vertical) {
      lines.push_back(side == CutSide::outside ? support_above(0.0) : support_below(0.0));
    } else if (side == CutSide::outside) {
      if (curved && shape_ == ProfileShape::convex) {
        lines = per_sample_lines([&](std::size_t i) {
          return support_above(clamp_slope(sample_slope(i)));  // the tangent there (raised if clamped)
        });
      } else if (curved && shape_ == ProfileShape::mixed) {
        lines.push_back(best_support(true));
      } else {
        lines.push_back(support_above(clamp_slope(chord_slope_)));  // concave/straight: the chord
      }
    } else {  // inside
      if (curved && shape_ == ProfileShape::convex) {
        // Chords of neighbouring samples: their intersection is the inscribed polyline.
        lines = per_sample_lines([&](std::size_t i) { return chord_line_after(i); });
      } else if (curved && (shape_ == ProfileShape::mixed || shape_ == ProfileShape::concave)) {
        lines.push_back(best_support(false));
      } else {
        lines.push_back(support_below(clamp_slope(chord_slope_)));
      }
    }
    fit.tilt_limited = limited_;
    return lines;
  }

  // One line per sample of all_ (so passes line up across stations); samples without material
  // take the line of the nearest sample with material.
  template <class MakeLine>
  std::vector<Line> per_sample_lines(MakeLine make) {
    std::vector<Line> lines(all_.size());
    std::vector<int> nearest(all_.size(), -1);
    int last = -1;
    for (std::size_t i = 0; i < all_.size(); ++i) {
      if (all_[i].present && std::isfinite(all_[i].u_mm)) last = static_cast<int>(i);
      nearest[i] = last;
    }
    int next = -1;
    for (std::size_t k = all_.size(); k-- > 0;) {
      if (all_[k].present && std::isfinite(all_[k].u_mm)) next = static_cast<int>(k);
      if (nearest[k] < 0 || (next >= 0 && next - static_cast<int>(k) < static_cast<int>(k) - nearest[k])) nearest[k] = next;
    }
    for (std::size_t i = 0; i < all_.size(); ++i) {
      if (nearest[i] == static_cast<int>(i)) lines[i] = make(i);
    }
    for (std::size_t i = 0; i < all_.size(); ++i) lines[i] = lines[static_cast<std::size_t>(nearest[i])];
    return lines;
  }

  // Inside multi-cut: the chord from sample i to the next sample with material (the last one
  // takes the chord before it), its slope held at the tilt limit.
  Line chord_line_after(std::size_t i) {
    std::size_t j = i + 1;
    while (j < all_.size() && !all_[j].present) ++j;
    std::size_t a = i, b = j;
    if (j >= all_.size()) {
      b = i;
      a = i;
      while (a > 0 && (a == i || !all_[a].present)) --a;
      if (a == i || !all_[a].present) return support_below(clamp_slope(chord_slope_));
    }
    const double dz = all_[b].z_mm - all_[a].z_mm;
    const double m = clamp_slope(dz > 1e-12 ? (all_[b].u_mm - all_[a].u_mm) / dz : chord_slope_);
    const double c = all_[a].u_mm - m * (all_[a].z_mm - zb_);
    return {c, m};
  }

  // Largest distance in the profile plane between the cut edge and the surface, both ways.
  // Squared distances, one root at the end (the root is monotone and correctly rounded: the same
  // result), and each point compared only with the segments its height can reach (ZWindow): the
  // full double loop was O(samples²) per station, 8 % of the 1M sphere's plan.
  double deviation(const std::vector<Line>& lines) const {
    const std::vector<Point> edge_pts = edge_polyline(lines);
    const std::vector<Seg> surface = surface_segments();
    const ZWindow near_surface(surface);
    double worst2 = 0.0;
    for (const Point& e : edge_pts) {
      const double best2 = near_surface.nearest2(e, surface);
      if (std::isfinite(best2)) worst2 = std::max(worst2, best2);
    }
    std::vector<Seg> edge_segs;
    for (std::size_t i = 0; i + 1 < edge_pts.size(); ++i) edge_segs.push_back({edge_pts[i], edge_pts[i + 1]});
    if (edge_pts.size() == 1) edge_segs.push_back({edge_pts[0], edge_pts[0]});
    const ZWindow near_edge(edge_segs);
    for (const Point& p : present_) {
      double best2 = near_edge.nearest2(p, edge_segs);
      // The layer's faces are its surface too: a sample inside the layer's material lies no
      // farther from the layer than from its nearer face (what the 3-D measure of a layer reads,
      // its closed shell, bevel_distance.cpp). Without them a sample near a face on a shallow
      // slope measured its way along the face to the cut: the layering's estimates of the 1M
      // sphere's sloped layers were 2.3 times their measures (0.266 against 0.117 mm), and the
      // verification replanned the stack in five rounds.
      if (p.u <= edge_at(p.z, lines, edge_pts)) {
        const double face = std::min(p.z - zb_, zt_ - p.z);  // below 0: outside the layer, no bound
        best2 = std::min(best2, face > 0.0 ? face * face : 0.0);
      }
      worst2 = std::max(worst2, best2);
    }
    return std::sqrt(worst2);
  }

  // The edge at height z: read off edge_polyline's points where z is one of them (the same
  // expression, so the same value), else the innermost line there.
  double edge_at(double z, const std::vector<Line>& lines, const std::vector<Point>& edge_pts) const {
    const auto it = std::lower_bound(edge_pts.begin(), edge_pts.end(), z, [](const Point& q, double v) { return q.z < v; });
    if (it != edge_pts.end() && it->z == z) return it->u;
    double u = std::numeric_limits<double>::infinity();
    for (const Line& l : lines) u = std::min(u, l.at(z, zb_));
    return u;
  }

  struct Seg {
    Point a, b;
  };

  static double dist2_to_seg(const Point& p, const Point& a, const Point& b) {
    const double dz = b.z - a.z, du = b.u - a.u;
    const double len2 = dz * dz + du * du;
    double t = len2 > 0 ? ((p.z - a.z) * dz + (p.u - a.u) * du) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    const double ez = a.z + t * dz - p.z, eu = a.u + t * du - p.u;
    return ez * ez + eu * eu;
  }

  // Segments ordered by their lower height. A segment whose heights all lie more than the nearest
  // distance found so far from the point's height cannot be nearer: the search walks out from the
  // point's height both ways and stops there. The bound is widened by a relative 1e-9 so that no
  // segment rounding could make nearer is skipped: the nearest is the full search's, bit for bit.
  class ZWindow {
   public:
    explicit ZWindow(const std::vector<Seg>& segs) {
      order_.resize(segs.size());
      for (std::size_t i = 0; i < segs.size(); ++i) {
        const double lo = std::min(segs[i].a.z, segs[i].b.z), hi = std::max(segs[i].a.z, segs[i].b.z);
        order_[i] = {lo, i};
        longest_ = std::max(longest_, hi - lo);
      }
      std::sort(order_.begin(), order_.end());
    }

    double nearest2(const Point& p, const std::vector<Seg>& segs) const {
      double best2 = std::numeric_limits<double>::infinity();
      auto beyond = [&](double gap) {  // no segment this far in height can be nearer
        if (!(gap > 0.0)) return false;
        const double g = gap * (1.0 - 1e-9) - 1e-12;
        return g > 0.0 && g * g > best2;
      };
      const auto start = std::lower_bound(order_.begin(), order_.end(), std::pair{p.z, std::size_t{0}});
      for (auto it = start; it != order_.end() && !beyond(it->first - p.z); ++it)
        best2 = std::min(best2, dist2_to_seg(p, segs[it->second].a, segs[it->second].b));
      for (auto it = start; it != order_.begin();) {
        --it;
        if (beyond(p.z - it->first - longest_)) break;
        best2 = std::min(best2, dist2_to_seg(p, segs[it->second].a, segs[it->second].b));
      }
      return best2;
    }

   private:
    std::vector<std::pair<double, std::size_t>> order_;  // (lower height, segment)
    double longest_ = 0.0;                               // the largest height any segment spans
  };

  // The edge the lines leave (the innermost of them at each height) as a polyline: layer faces
  // and sample heights, plus the corner where the active line changes between two of them
  // (O(heights × lines), not all pairs of lines).
  std::vector<Point> edge_polyline(const std::vector<Line>& lines) const {
    auto edge = [&](double z) {
      double u = std::numeric_limits<double>::infinity();
      for (const Line& l : lines) u = std::min(u, l.at(z, zb_));
      return u;
    };
    std::vector<double> zs{zb_, zt_};
    for (const auto& s : all_) zs.push_back(std::clamp(s.z_mm, zb_, zt_));
    std::sort(zs.begin(), zs.end());
    zs.erase(std::unique(zs.begin(), zs.end(), [](double a, double b) { return std::abs(a - b) < 1e-12; }), zs.end());
    std::vector<Point> edge_pts;
    edge_pts.reserve(2 * zs.size());
    std::size_t prev = lines.size();
    for (double z : zs) {
      // The first innermost line at z, and the edge there (the least of the lines).
      std::size_t a = 0;
      double u = lines.empty() ? std::numeric_limits<double>::infinity() : lines[0].at(z, zb_);
      for (std::size_t i = 1; i < lines.size(); ++i) {
        const double ui = lines[i].at(z, zb_);
        if (ui < u) a = i, u = ui;
      }
      if (prev < lines.size() && a != prev) {
        const double dm = lines[prev].m - lines[a].m;
        if (std::abs(dm) > 1e-12) {
          const double zc = zb_ + (lines[a].c - lines[prev].c) / dm;
          if (zc > edge_pts.back().z && zc < z) edge_pts.push_back({zc, edge(zc)});
        }
      }
      edge_pts.push_back({z, u});
      prev = a;
    }
    return edge_pts;
  }

  // The surface as segments: neighbouring samples with material joined; where material stops
  // (the surface turned horizontal between two sub-slices) a ledge runs inwards half-way.
  // Sub-slices are read just inside the layer's faces: the surface continues to the face along
  // its tangent.
  std::vector<Seg> surface_segments() const {
    std::vector<Seg> surface;
    constexpr double kInward = 1e6;
    for (std::size_t i = 0; i < all_.size(); ++i) {
      const auto& s = all_[i];
      if (!s.present) continue;
      const Point p{s.z_mm, s.u_mm};
      if (i + 1 < all_.size()) {
        const auto& n = all_[i + 1];
        if (n.present) {
          surface.push_back({p, {n.z_mm, n.u_mm}});
        } else {
          const double zh = 0.5 * (s.z_mm + n.z_mm);
          surface.push_back({p, {zh, s.u_mm}});
          surface.push_back({{zh, s.u_mm}, {zh, s.u_mm - kInward}});
        }
      }
      if (i > 0 && !all_[i - 1].present) {
        const double zh = 0.5 * (s.z_mm + all_[i - 1].z_mm);
        surface.push_back({p, {zh, s.u_mm}});
        surface.push_back({{zh, s.u_mm}, {zh, s.u_mm - kInward}});
      }
      if (present_.size() == 1) surface.push_back({p, p});
    }
    auto extend = [&](const ProfileSample& s, double z_face) {
      if (!s.present || std::abs(z_face - s.z_mm) > 0.05 * (zt_ - zb_)) return;
      const double m = std::isfinite(s.slope) ? std::clamp(s.slope, -1e3, 1e3) : 0.0;
      surface.push_back({{s.z_mm, s.u_mm}, {z_face, s.u_mm + m * (z_face - s.z_mm)}});
    };
    if (!all_.empty()) {
      extend(all_.front(), zb_);
      extend(all_.back(), zt_);
    }
    return surface;
  }

  std::span<const ProfileSample> all_;
  double zb_, zt_;
  ProfileFitParams params_;
  double ceiling_;
  double tan_max_ = 0.0;
  std::vector<Point> present_;
  std::vector<Point> bounds_;  // present_ plus the tangent corners between them
  double chord_slope_ = 0.0;
  ProfileShape shape_ = ProfileShape::empty;
  bool limited_ = false;
};

}  // namespace

ProfileFit fit_profile(std::span<const ProfileSample> samples, double z_bottom_mm, double z_top_mm,
                       const ProfileFitParams& params, std::span<const ProfileBound> bounds, double u_ceiling_mm) {
  return Fitter(samples, z_bottom_mm, z_top_mm, params, bounds, u_ceiling_mm).run();
}

double cut_edge_at(const ProfileFit& fit, double z_mm, double z_bottom_mm, double z_top_mm) {
  const double span = z_top_mm - z_bottom_mm;
  const double t = span > 0 ? (z_mm - z_bottom_mm) / span : 0.0;
  double u = std::numeric_limits<double>::infinity();
  for (const auto& c : fit.cuts) u = std::min(u, c.u_bottom_mm + t * (c.u_top_mm - c.u_bottom_mm));
  return u;
}

}  // namespace lamina
