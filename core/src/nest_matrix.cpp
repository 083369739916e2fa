// Matrix nesting (the paper's layout): parts' bounding boxes in rows (shelves), first-fit
// decreasing by row height, each part at 0° or 90°.
#include "nest_internal.hpp"

#include <algorithm>
#include <numbers>

namespace lamina::detail {

namespace {

constexpr double kTol = 1e-9;  // mm; sizes that match to this fit

struct Orientation {
  double angle = 0.0;
  Bounds bounds;
};

struct Shelf {
  double y = 0.0;       // bottom of the row
  double height = 0.0;  // set by the row's first (tallest) part
  double x_next = 0.0;  // where the next box may start
};

struct SheetState {
  std::vector<Shelf> shelves;
  double y_next = 0.0;  // where the next row may start
  PackedSheet packed;
};

}  // namespace

std::vector<PackedSheet> pack_matrix(std::span<const Part> parts, std::span<const int> which, SheetSize size,
                                     const NestParams& params, std::vector<int>& unplaced) {
  const double x0 = params.margin_mm;
  const double y0 = params.margin_mm;
  const double x1 = size.length_mm - params.margin_mm;
  const double y1 = size.width_mm - params.margin_mm;
  const double gap = params.spacing_mm;

  // Per part: the "flat" orientation (lower box) first, the "upright" one second.
  struct Item {
    int part = -1;
    Orientation flat;
    Orientation upright;
  };
  std::vector<Item> items;
  items.reserve(which.size());
  for (int p : which) {
    Orientation a{0.0, rotated_bounds(parts[p].footprint_mm, 0.0)};
    Orientation b{0.5 * std::numbers::pi, rotated_bounds(parts[p].footprint_mm, 0.5 * std::numbers::pi)};
    if (b.bounds.dy() < a.bounds.dy() - kTol) std::swap(a, b);
    items.push_back({p, a, b});
  }
  // Larger parts first: taller flat box, then longer, then input order (stable).
  std::stable_sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
    if (a.flat.bounds.dy() != b.flat.bounds.dy()) return a.flat.bounds.dy() > b.flat.bounds.dy();
    return a.flat.bounds.dx() > b.flat.bounds.dx();
  });

  std::vector<SheetState> sheets;
  auto put = [&](SheetState& sheet, Shelf& shelf, const Item& item, const Orientation& o) {
    Placement pl;
    pl.part = item.part;
    pl.rotation_rad = o.angle;
    pl.offset_mm = Eigen::Vector2d(shelf.x_next, shelf.y) - o.bounds.min;
    sheet.packed.placements.push_back(pl);
    shelf.x_next += o.bounds.dx() + gap;
  };
  // Orientations fitting in a row of that height from x, narrower first.
  auto choose = [&](const Item& item, double x, double height) -> const Orientation* {
    const Orientation* best = nullptr;
    for (const Orientation* o : {&item.flat, &item.upright}) {
      if (o->bounds.dy() > height + kTol || x + o->bounds.dx() > x1 + kTol) continue;
      if (!best || o->bounds.dx() < best->bounds.dx() - kTol) best = o;
    }
    return best;
  };
  // A new row on the sheet: the flat box if it is within the sheet's length, else upright.
  auto open_row = [&](SheetState& sheet, const Item& item) -> bool {
    for (const Orientation* o : {&item.flat, &item.upright}) {
      if (o->bounds.dx() > x1 - x0 + kTol) continue;
      if (sheet.y_next + o->bounds.dy() > y1 + kTol) continue;
      sheet.shelves.push_back({sheet.y_next, o->bounds.dy(), x0});
      sheet.y_next += o->bounds.dy() + gap;
      put(sheet, sheet.shelves.back(), item, *o);
      return true;
    }
    return false;
  };

  for (const Item& item : items) {
    bool placed = false;
    for (SheetState& sheet : sheets) {
      for (Shelf& shelf : sheet.shelves) {
        if (const Orientation* o = choose(item, shelf.x_next, shelf.height)) {
          put(sheet, shelf, item, *o);
          placed = true;
          break;
        }
      }
      if (!placed) placed = open_row(sheet, item);
      if (placed) break;
    }
    if (!placed) {
      sheets.emplace_back();
      sheets.back().y_next = y0;
      // fits_on_sheet guarantees one orientation fits an empty sheet; if not, the driver is told.
      if (!open_row(sheets.back(), item)) {
        unplaced.push_back(item.part);
        sheets.pop_back();
      }
    }
  }
  std::vector<PackedSheet> out;
  out.reserve(sheets.size());
  for (SheetState& s : sheets) out.push_back(std::move(s.packed));
  return out;
}

}  // namespace lamina::detail
