// Matrix nesting (the paper's layout): parts' bounding boxes in rows (shelves), first-fit
// decreasing by row height, each part at 0° or 90°.
#include "cam/nest_internal.hpp"

#include <algorithm>
#include <numbers>

namespace lamina::cam_detail {

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

// Per part: the "flat" orientation (lower box) first, the "upright" one second.
struct Item {
  int part = -1;
  Orientation flat;
  Orientation upright;
};

// Larger parts first: taller flat box, then longer, then input order (stable).
std::vector<Item> items_largest_first(std::span<const Part> parts, std::span<const int> which) {
  std::vector<Item> items;
  items.reserve(which.size());
  for (int p : which) {
    Orientation a{0.0, rotated_bounds(parts[p].footprint_mm, 0.0)};
    Orientation b{0.5 * std::numbers::pi, rotated_bounds(parts[p].footprint_mm, 0.5 * std::numbers::pi)};
    if (b.bounds.dy() < a.bounds.dy() - kTol) std::swap(a, b);
    items.push_back({p, a, b});
  }
  std::stable_sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
    if (a.flat.bounds.dy() != b.flat.bounds.dy()) return a.flat.bounds.dy() > b.flat.bounds.dy();
    return a.flat.bounds.dx() > b.flat.bounds.dx();
  });
  return items;
}

// Rows (shelves) on sheets of one size, within the margin.
struct ShelfPacker {
  double x0, y0, x1, y1, gap;

  void put(SheetState& sheet, Shelf& shelf, const Item& item, const Orientation& o) const {
    Placement pl;
    pl.part = item.part;
    pl.rotation_rad = o.angle;
    pl.offset_mm = Eigen::Vector2d(shelf.x_next, shelf.y) - o.bounds.min;
    sheet.packed.placements.push_back(pl);
    shelf.x_next += o.bounds.dx() + gap;
  }
  // Orientations fitting in a row of that height from x, narrower first.
  const Orientation* choose(const Item& item, double x, double height) const {
    const Orientation* best = nullptr;
    for (const Orientation* o : {&item.flat, &item.upright}) {
      if (o->bounds.dy() > height + kTol || x + o->bounds.dx() > x1 + kTol) continue;
      if (!best || o->bounds.dx() < best->bounds.dx() - kTol) best = o;
    }
    return best;
  }
  // A new row on the sheet: the flat box if it is within the sheet's length, else upright.
  bool open_row(SheetState& sheet, const Item& item) const {
    for (const Orientation* o : {&item.flat, &item.upright}) {
      if (o->bounds.dx() > x1 - x0 + kTol) continue;
      if (sheet.y_next + o->bounds.dy() > y1 + kTol) continue;
      sheet.shelves.push_back({sheet.y_next, o->bounds.dy(), x0});
      sheet.y_next += o->bounds.dy() + gap;
      put(sheet, sheet.shelves.back(), item, *o);
      return true;
    }
    return false;
  }
  // In the first row of the first sheet it fits, else a new row there, else a new sheet; false
  // when not even an empty sheet takes it.
  bool place(const Item& item, std::vector<SheetState>& sheets) const {
    for (SheetState& sheet : sheets) {
      for (Shelf& shelf : sheet.shelves)
        if (const Orientation* o = choose(item, shelf.x_next, shelf.height)) {
          put(sheet, shelf, item, *o);
          return true;
        }
      if (open_row(sheet, item)) return true;
    }
    sheets.emplace_back();
    sheets.back().y_next = y0;
    if (open_row(sheets.back(), item)) return true;
    sheets.pop_back();
    return false;
  }
};

}  // namespace

std::vector<PackedSheet> pack_matrix(std::span<const Part> parts, std::span<const int> which, SheetSize size,
                                     const NestParams& params, std::vector<int>& unplaced) {
  const ShelfPacker packer{params.margin_mm, params.margin_mm, size.length_mm - params.margin_mm,
                           size.width_mm - params.margin_mm, params.spacing_mm};
  std::vector<SheetState> sheets;
  for (const Item& item : items_largest_first(parts, which))
    // fits_on_sheet guarantees one orientation fits an empty sheet; if not, the driver is told.
    if (!packer.place(item, sheets))
      unplaced.push_back(item.part);
    else if (params.on_placed)
      params.on_placed();
  std::vector<PackedSheet> out;
  out.reserve(sheets.size());
  for (SheetState& s : sheets) out.push_back(std::move(s.packed));
  return out;
}

}  // namespace lamina::cam_detail
