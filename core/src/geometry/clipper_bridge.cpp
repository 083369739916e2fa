#include "geometry/clipper_bridge.hpp"

#include <algorithm>
#include <cmath>

namespace lamina {

double signed_area_mm2(const Polygon2& ring) {
  const std::size_t n = ring.size();
  double twice = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& a = ring[i];
    const auto& b = ring[(i + 1) % n];
    twice += a.x() * b.y() - b.x() * a.y();
  }
  return 0.5 * twice;
}

}  // namespace lamina

namespace lamina::geometry_detail {

ClipperLib::Path to_clipper(const Polygon2& ring) {
  ClipperLib::Path path;
  path.reserve(ring.size());
  for (const auto& p : ring) {
    path.emplace_back(static_cast<ClipperLib::cInt>(std::llround(p.x() * kClipperUnitsPerMm)),
                      static_cast<ClipperLib::cInt>(std::llround(p.y() * kClipperUnitsPerMm)));
  }
  return path;
}

ClipperLib::Paths to_clipper(const std::vector<Polygon2>& rings) {
  ClipperLib::Paths paths;
  paths.reserve(rings.size());
  for (const auto& r : rings) paths.push_back(to_clipper(r));
  return paths;
}

Polygon2 from_clipper(const ClipperLib::Path& path) {
  Polygon2 ring;
  ring.reserve(path.size());
  for (const auto& p : path) {
    ring.emplace_back(static_cast<double>(p.X) / kClipperUnitsPerMm, static_cast<double>(p.Y) / kClipperUnitsPerMm);
  }
  return ring;
}

std::vector<Polygon2> from_clipper(const ClipperLib::Paths& paths) {
  std::vector<Polygon2> rings;
  rings.reserve(paths.size());
  for (const auto& p : paths) rings.push_back(from_clipper(p));
  return rings;
}

double area_mm2(const ClipperLib::Paths& paths) {
  double sum = 0.0;
  for (const auto& p : paths) sum += ClipperLib::Area(p);
  return sum / (kClipperUnitsPerMm * kClipperUnitsPerMm);
}

ClipperLib::Paths slice_material(const Slice& slice) {
  ClipperLib::Paths loops;
  loops.reserve(slice.loops.size());
  for (const Loop& l : slice.loops) loops.push_back(to_clipper(l.points));
  const bool clean = slice.open_chains.empty() &&
                     std::none_of(slice.loops.begin(), slice.loops.end(), [](const Loop& l) { return l.gap_closed; });
  if (clean) return loops;
  ClipperLib::Clipper c;
  c.AddPaths(loops, ClipperLib::ptSubject, true);
  ClipperLib::Paths united;
  c.Execute(ClipperLib::ctUnion, united, ClipperLib::pftPositive, ClipperLib::pftPositive);
  return united;
}

ClipperLib::Paths boolean(ClipperLib::ClipType op, const ClipperLib::Paths& subject, const ClipperLib::Paths& clip) {
  ClipperLib::Clipper c;
  c.AddPaths(subject, ClipperLib::ptSubject, true);
  c.AddPaths(clip, ClipperLib::ptClip, true);
  ClipperLib::Paths out;
  c.Execute(op, out, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  return out;
}

ClipperLib::Paths offset_mitre(const ClipperLib::Paths& paths, double delta_mm) {
  ClipperLib::ClipperOffset off;  // MiterLimit 2: squared beyond, the square's edge at |delta|
  off.AddPaths(paths, ClipperLib::jtMiter, ClipperLib::etClosedPolygon);
  ClipperLib::Paths out;
  off.Execute(out, delta_mm * kClipperUnitsPerMm);
  return out;
}

}  // namespace lamina::geometry_detail
