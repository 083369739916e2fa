// The z grid of choose_layers: one slice_mesh call for every sub-slice, the stations on them,
// and the achievable-deviation estimate of a layer (layering_internal.hpp has the conventions).
#include "layering/layering_internal.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

namespace lamina::layering_detail {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// More grid lines than this is a mistake in the parameters (0.01 mm steps over a metre): every
// sub-slice is kept in memory with its line index.
constexpr int kMaxGridLines = 100'000;
// A surface flatter than this (|du/dz|, i.e. within ~6° of horizontal) between two slices, or a
// change of loop count, makes the section change "abruptly": stations are read there too.
constexpr double kAbruptSlope = 10.0;

template <class F>
void for_each_index(std::size_t n, bool parallel, std::size_t grain, F&& f) {
  if (!parallel || n < 2 * grain) {
    for (std::size_t i = 0; i < n; ++i) f(i);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
  });
}

double loop_perimeter(const Loop& l) {
  double p = 0.0;
  for (std::size_t i = 0; i < l.size(); ++i) p += (l.points[(i + 1) % l.size()] - l.points[i]).norm();
  return p;
}

}  // namespace

std::expected<std::unique_ptr<Estimator>, Error> Estimator::create(const Mesh& mesh, const LayeringParams& params,
                                                                   std::vector<double> thicknesses) {
  std::unique_ptr<Estimator> e(new Estimator());
  e->params_ = params;
  e->thicknesses_ = std::move(thicknesses);
  if (mesh.faces.empty()) return std::unexpected(Error{ErrorCode::empty_mesh, "layering: the mesh has no facets"});

  double z_lo = mesh.summary.bbox_min_mm.z(), z_hi = mesh.summary.bbox_max_mm.z();
  if (!(z_hi > z_lo) && !mesh.vertices.empty()) {  // a hand-made Mesh without its summary
    z_lo = std::numeric_limits<double>::infinity();
    z_hi = -z_lo;
    for (const auto& v : mesh.vertices) {
      z_lo = std::min(z_lo, v.z());
      z_hi = std::max(z_hi, v.z());
    }
  }
  const double s = params.sub_slice_mm;
  e->step_ = s;
  e->delta_ = std::min(1e-3 * s, 1e-3);
  e->z_base_ = z_lo;
  e->height_ = z_hi - z_lo;
  if (!std::isfinite(e->height_) || e->height_ <= 4 * e->delta_)
    return std::unexpected(Error{ErrorCode::invalid_argument,
                                 fmt::format("layering: the model has no height to layer ({} mm)", e->height_)});
  const double lines = std::ceil((e->height_ - 2 * e->delta_) / s);
  if (!(lines <= kMaxGridLines))
    return std::unexpected(Error{ErrorCode::invalid_argument,
                                 fmt::format("layering: sub_slice_mm = {} gives {:.0f} grid lines over {} mm (at most {})",
                                             s, lines, e->height_, kMaxGridLines)});
  e->top_line_ = std::max(1, static_cast<int>(lines));
  e->max_span_ = static_cast<int>(std::ceil(e->thicknesses_.back() / s)) + 1;
  const double tilt = std::clamp(params.fit.tilt_max_rad, 0.0, 1.5707963267948966);
  e->tan_reach_ = std::clamp(std::tan(tilt), 1.0, 1e3);

  std::vector<double> zs(static_cast<std::size_t>(2 * e->top_line_));
  for (int k = 0; k < e->top_line_; ++k) zs[static_cast<std::size_t>(2 * k)] = z_lo + e->z_line(k) + e->delta_;
  for (int k = 1; k <= e->top_line_; ++k) zs[static_cast<std::size_t>(2 * k - 1)] = z_lo + e->z_line(k) - e->delta_;
  SliceParams sp;
  sp.parallel = params.parallel;
  auto slices = slice_mesh(mesh, zs, sp);
  if (!slices) return std::unexpected(slices.error());
  e->slices_ = std::move(*slices);

  std::size_t repaired = 0, open = 0;
  for (const Slice& sl : e->slices_) {
    if (!sl.warnings.empty()) ++repaired;
    for (const Loop& l : sl.loops) open += l.gap_closed ? 1 : 0;
  }
  if (repaired > 0)
    e->warnings_.push_back(fmt::format("{} of {} sub-slices needed repairs (open or overlapping contours{}); "
                                       "their estimates are approximate",
                                       repaired, e->slices_.size(), open > 0 ? ", gaps closed" : ""));

  e->lines_.resize(e->slices_.size());
  e->net_area_.resize(e->slices_.size());
  for_each_index(e->slices_.size(), params.parallel, 4, [&](std::size_t j) {
    e->lines_[j] = SectionLines(mesh, e->slices_[j]);
    e->net_area_[j] = e->slices_[j].net_area_mm2();
  });
  e->compute_stations();
  e->compute_novelty();
  e->compute_supply();
  e->cache_.resize(e->slices_.size());
  return e;
}

double Estimator::z_line(int k) const { return k < top_line_ ? k * step_ : height_; }

int Estimator::nearest_line(double z_rel) const {
  if (!(z_rel > 0.0)) return 0;
  if (z_rel >= height_) return top_line_;
  int k0 = std::clamp(static_cast<int>(std::floor(z_rel / step_)), 0, top_line_ - 1);
  return (z_rel - z_line(k0) <= z_line(k0 + 1) - z_rel) ? k0 : k0 + 1;
}

GridSpan Estimator::span(double z_rel, double thickness) const {
  GridSpan g;
  g.ka = std::min(nearest_line(z_rel), top_line_ - 1);
  g.kb = std::max(nearest_line(z_rel + thickness), g.ka + 1);
  return g;
}

StackEnd Estimator::stack_end(double top_rel) const {
  StackEnd e;
  const double h = height_;
  switch (params_.fit.side) {
    case CutSide::outside:
      e.final = top_rel >= h - kReachEps;
      e.off_top_mm = std::max(0.0, top_rel - h);
      break;
    case CutSide::inside:
      e.allowed = top_rel <= h + kReachEps;
      e.final = e.allowed && top_rel + params_.bond_mm + thicknesses_.front() > h + kReachEps;
      e.off_top_mm = std::max(0.0, h - top_rel);
      break;
    case CutSide::mixed:
      e.final = top_rel >= h - 0.5 * thicknesses_.front() - kReachEps;
      e.off_top_mm = std::abs(top_rel - h);
      break;
  }
  if (e.off_top_mm <= kReachEps) e.off_top_mm = 0.0;
  return e;
}

double Estimator::search_width(int thickness_index) const {
  return thicknesses_[static_cast<std::size_t>(thickness_index)] * tan_reach_ + 2 * step_;
}

void Estimator::compute_stations() {
  station_begin_.assign(slices_.size() + 1, 0);
  std::vector<double> len;
  for (std::size_t j = 0; j < slices_.size(); ++j) {
    for (const Loop& l : slices_[j].loops) {
      const std::size_t n = l.size();
      if (n < 2) continue;
      len.assign(n, 0.0);
      double total = 0.0;
      std::size_t usable = 0;
      for (std::size_t i = 0; i < n; ++i) {
        len[i] = (l.points[(i + 1) % n] - l.points[i]).norm();
        total += len[i];
        usable += len[i] > 1e-12 ? 1 : 0;
      }
      const std::size_t m = std::min<std::size_t>(kMaxStationsPerLoop, usable);
      if (m == 0) continue;
      // Station q at arc length (q + ½)·total/m: the midpoint of the vector holding that length.
      std::size_t i = 0, last = n;
      double acc = 0.0;
      for (std::size_t q = 0; q < m; ++q) {
        const double target = (static_cast<double>(q) + 0.5) * total / static_cast<double>(m);
        while (i + 1 < n && (acc + len[i] < target || len[i] <= 1e-12)) acc += len[i++];
        if (i == last || len[i] <= 1e-12) continue;
        last = i;
        const Eigen::Vector2d a = l.points[i], b = l.points[(i + 1) % n];
        const Eigen::Vector2d d = b - a;
        stations_.push_back(Station{0.5 * (a + b), Eigen::Vector2d(d.y(), -d.x()) / len[i]});
      }
    }
    station_begin_[j + 1] = static_cast<std::uint32_t>(stations_.size());
  }
}

void Estimator::compute_novelty() {
  const std::size_t n = slices_.size();
  novel_.assign(n, 0);
  same_as_next_.assign(n, 0);
  std::vector<double> perimeter(n, 0.0);
  for (std::size_t j = 0; j < n; ++j)
    for (const Loop& l : slices_[j].loops) perimeter[j] += loop_perimeter(l);
  for (std::size_t j = 1; j < n; ++j) {
    const Slice& a = slices_[j - 1];
    const Slice& b = slices_[j];
    const double dz = b.z_mm - a.z_mm;
    const bool topology = a.outer_count() != b.outer_count() || a.hole_count() != b.hole_count();
    const bool flat = std::abs(net_area_[j] - net_area_[j - 1]) >
                      kAbruptSlope * dz * std::max(perimeter[j], perimeter[j - 1]) + 1e-9;
    if (topology || flat) novel_[j - 1] = novel_[j] = 1;
    // The two slices around an interior grid line (j odd, j + 1 even) are 2δ apart.
    if (j % 2 == 0 && static_cast<int>(j) < slice_count() - 1 && !topology && !flat) same_as_next_[j - 1] = 1;
  }
  for (std::size_t j = 0; j < n; ++j)
    if (novel_[j]) novel_list_.push_back(static_cast<int>(j));
}

void Estimator::fill_samples(int slice, std::size_t station) {
  SliceCache& c = cache_[static_cast<std::size_t>(slice)];
  const Station& st = stations_[station_begin_[static_cast<std::size_t>(slice)] + station];
  const std::size_t width = static_cast<std::size_t>(c.hi - c.lo + 1);
  Sample* out = c.samples.data() + station * width;
  const double w_max = search_width(static_cast<int>(thicknesses_.size()) - 1);
  for (int j = c.hi; j >= c.lo; --j) {
    Sample& s = out[j - c.lo];
    if (same_as_next_[static_cast<std::size_t>(j)] && j < c.hi) {
      s = out[j + 1 - c.lo];  // no flat face on the line: the section 2δ higher is the same
      continue;
    }
    const SectionLines& lines = lines_[static_cast<std::size_t>(j)];
    // One query over the full width: it walks outwards from the station and stops past the
    // nearest crossing (a narrow first query, then the full one when it missed, walked the
    // narrow window twice).
    const auto hit = lines.exit_crossing(st.point, st.normal, -w_max, w_max, CrossingPick::nearest_zero);
    if (hit) {
      s.u = hit->u_mm;
      s.slope = profile_slope(hit->normal, st.normal);
    } else {
      s.u = kNaN;
      s.slope = 0.0;
    }
  }
}

void Estimator::ensure_samples(std::vector<int> slices) {
  std::sort(slices.begin(), slices.end());
  slices.erase(std::unique(slices.begin(), slices.end()), slices.end());
  std::vector<std::pair<int, std::size_t>> tasks;
  const int reach = 2 * max_span_;
  for (int j : slices) {
    SliceCache& c = cache_[static_cast<std::size_t>(j)];
    if (c.ready) continue;
    // Even slices (just above a line) start layers and read upwards; odd ones end them and read
    // downwards; abrupt ones sit inside layers and read both ways.
    const bool novel = novel_[static_cast<std::size_t>(j)] != 0;
    const bool bottom = j % 2 == 0;
    c.lo = (novel || !bottom) ? std::max(0, j - reach) : j;
    // One more slice on top: an odd slice may take its samples from the one above it.
    c.hi = std::min(slice_count() - 1, ((novel || bottom) ? j + reach : j) + 1);
    const std::size_t count = station_begin_[static_cast<std::size_t>(j) + 1] - station_begin_[static_cast<std::size_t>(j)];
    c.samples.assign(count * static_cast<std::size_t>(c.hi - c.lo + 1), Sample{});
    for (std::size_t q = 0; q < count; ++q) tasks.emplace_back(j, q);
  }
  for_each_index(tasks.size(), params_.parallel, 8, [&](std::size_t i) { fill_samples(tasks[i].first, tasks[i].second); });
  for (int j : slices) cache_[static_cast<std::size_t>(j)].ready = true;
}

const Sample& Estimator::sample(int station_slice, std::uint32_t station, int at_slice) const {
  const SliceCache& c = cache_[static_cast<std::size_t>(station_slice)];
  const std::size_t width = static_cast<std::size_t>(c.hi - c.lo + 1);
  return c.samples[station * width + static_cast<std::size_t>(at_slice - c.lo)];
}

void Estimator::stations_of(GridSpan span, std::vector<std::pair<int, std::uint32_t>>& out) const {
  const int jb = 2 * span.ka, jt = 2 * span.kb - 1;
  auto add = [&](int j) {
    const std::uint32_t n = station_begin_[static_cast<std::size_t>(j) + 1] - station_begin_[static_cast<std::size_t>(j)];
    for (std::uint32_t q = 0; q < n; ++q) out.emplace_back(j, q);
  };
  add(jb);
  add(jt);
  for (auto it = std::upper_bound(novel_list_.begin(), novel_list_.end(), jb); it != novel_list_.end() && *it < jt; ++it)
    add(*it);
}

double Estimator::station_deviation(GridSpan span, int thickness_index, int slice, std::uint32_t station) const {
  const int jb = 2 * span.ka, jt = 2 * span.kb - 1;
  const double w = search_width(thickness_index);
  auto read = [&](int j) {
    const Sample& s = sample(slice, station, j);
    ProfileSample p;
    p.z_mm = slices_[static_cast<std::size_t>(j)].z_mm;
    p.present = std::isfinite(s.u) && std::abs(s.u) <= w;
    p.u_mm = p.present ? s.u : 0.0;
    p.slope = s.slope;
    return p;
  };
  // Around an interior grid line the two slices are 2δ apart: keep both only where they differ
  // (a flat face on the line), otherwise the profile would carry every point twice.
  const double same_u = 2 * kAbruptSlope * delta_ + 1e-9;
  thread_local std::vector<ProfileSample> samples;
  samples.clear();
  bool vertical = true;  // every sample present at the same u on a vertical facet
  for (int j = jb; j <= jt; ++j) {
    ProfileSample p = read(j);
    if (j % 2 == 1 && j > jb && j < jt) {
      const ProfileSample q = read(j + 1);
      if (p.present == q.present && (!p.present || std::abs(p.u_mm - q.u_mm) <= same_u)) continue;
    }
    samples.push_back(p);
    vertical = vertical && p.present && p.slope == 0.0 && std::abs(p.u_mm - samples.front().u_mm) <= 1e-9;
  }
  if (vertical) return 0.0;  // a vertical wall: one vertical cut is exact
  const ProfileFit fit = fit_profile(samples, z_base_ + z_line(span.ka), z_base_ + z_line(span.kb), params_.fit);
  return fit.max_deviation_mm;
}

void Estimator::estimate(std::span<const std::pair<GridSpan, int>> layers, std::span<double> out, double fail_above) {
  auto key_of = [&](std::size_t i) { return std::make_tuple(layers[i].first.ka, layers[i].first.kb, layers[i].second); };
  // A memo entry answers when it is exact, or when it already shows the layer fails.
  auto answered = [&](const Memo& m) { return m.exact || m.value > fail_above; };
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < layers.size(); ++i) {
    if (measured_.count(key_of(i))) continue;
    if (auto it = memo_.find(key_of(i)); it != memo_.end() && answered(it->second)) continue;
    if (std::find_if(todo.begin(), todo.end(), [&](std::size_t t) { return layers[t] == layers[i]; }) == todo.end())
      todo.push_back(i);
  }
  if (!todo.empty()) {
    struct Task {
      std::size_t slot;  // index into todo
      int slice;
      std::uint32_t station;
    };
    std::vector<Task> tasks;
    std::vector<int> need;
    std::vector<std::pair<int, std::uint32_t>> st;
    for (std::size_t t = 0; t < todo.size(); ++t) {
      st.clear();
      stations_of(layers[todo[t]].first, st);
      for (const auto& [j, q] : st) {
        tasks.push_back({t, j, q});
        if (need.empty() || need.back() != j) need.push_back(j);
      }
    }
    ensure_samples(need);
    // Stations of a layer that already failed are skipped: whether a layer fails does not
    // depend on the order, only the (unused) lower bound reached does.
    std::vector<double> dev(tasks.size(), 0.0);
    std::unique_ptr<std::atomic<bool>[]> failed(new std::atomic<bool>[todo.size()]);
    for (std::size_t t = 0; t < todo.size(); ++t) failed[t].store(false, std::memory_order_relaxed);
    const bool may_stop = std::isfinite(fail_above);
    for_each_index(tasks.size(), params_.parallel, 4, [&](std::size_t i) {
      const Task& k = tasks[i];
      if (may_stop && failed[k.slot].load(std::memory_order_relaxed)) return;
      const auto& layer = layers[todo[k.slot]];
      dev[i] = station_deviation(layer.first, layer.second, k.slice, k.station);
      if (may_stop && dev[i] > fail_above) failed[k.slot].store(true, std::memory_order_relaxed);
    });
    std::vector<double> worst(todo.size(), 0.0);
    for (std::size_t i = 0; i < tasks.size(); ++i) worst[tasks[i].slot] = std::max(worst[tasks[i].slot], dev[i]);
    for (std::size_t t = 0; t < todo.size(); ++t) memo_[key_of(todo[t])] = Memo{worst[t], !(worst[t] > fail_above)};
  }
  for (std::size_t i = 0; i < layers.size(); ++i) {
    const auto m = measured_.find(key_of(i));
    out[i] = m != measured_.end() ? m->second : memo_.at(key_of(i)).value;
  }
}

bool Estimator::set_measured(GridSpan span, int thickness_index, double deviation_mm) {
  return measured_.insert_or_assign(std::make_tuple(span.ka, span.kb, thickness_index), deviation_mm).second;
}

double Estimator::estimate(GridSpan span, int thickness_index) {
  const std::pair<GridSpan, int> one{span, thickness_index};
  double out = 0.0;
  estimate(std::span<const std::pair<GridSpan, int>>(&one, 1), std::span<double>(&out, 1));
  return out;
}

Estimator::GreedyCheck Estimator::greedy_check(GridSpan span, int thickness_index) {
  GreedyCheck r;
  const int jb = 2 * span.ka, jt = 2 * span.kb - 1;
  const double a_bottom = net_area_[static_cast<std::size_t>(jb)];
  const double a_top = net_area_[static_cast<std::size_t>(jt)];
  const double a_max = std::max(std::abs(a_bottom), std::abs(a_top));
  r.area_deviation = a_max > 0.0 ? std::abs(a_top - a_bottom) / a_max : 0.0;
  r.area_ok = r.area_deviation <= params_.greedy_area_deviation;

  // The staircase triangle at every station of the bottom and top contours: the horizontal step
  // to the other face's contour along the station's normal, times half the thickness.
  const bool tiny = std::abs(a_bottom) <= step_ * step_ && std::abs(a_top) <= step_ * step_;
  const double t = thicknesses_[static_cast<std::size_t>(thickness_index)];
  const double w = search_width(thickness_index);
  ensure_samples({jb, jt});
  bool missing = false;
  for (const auto& [own, other] : {std::pair{jb, jt}, std::pair{jt, jb}}) {
    const std::uint32_t n = station_begin_[static_cast<std::size_t>(own) + 1] - station_begin_[static_cast<std::size_t>(own)];
    for (std::uint32_t q = 0; q < n; ++q) {
      const Sample& s = sample(own, q, other);
      if (!std::isfinite(s.u) || std::abs(s.u) > w) {
        missing = true;
        continue;
      }
      r.worst_triangle_mm2 = std::max(r.worst_triangle_mm2, 0.5 * t * std::abs(s.u));
    }
  }
  if (missing && !tiny) r.worst_triangle_mm2 = std::numeric_limits<double>::infinity();
  r.triangle_ok = r.worst_triangle_mm2 <= params_.greedy_triangle_area_mm2;
  return r;
}

void Estimator::release_below(int k) {
  const int limit = std::min(2 * k, slice_count());
  for (; released_ < limit; ++released_) cache_[static_cast<std::size_t>(released_)] = SliceCache{};
  // The memo is kept (a few numbers per position): a second pass (layer_verified) reuses it.
}

}  // namespace lamina::layering_detail
