#pragma once
// A uniform grid of square cells over a set of axis-aligned boxes: each box is listed in every
// cell it touches, in box order (CSR: one offset per cell into one array of box indices). The
// bevel's section lines (a slice's contour vectors) and its slab of facets (their footprints)
// both bucket with it; each picks its own cell size from the extent and the number of boxes.
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace lamina {

struct Box2 {
  Eigen::Vector2d lo, hi;
};

class BoxGrid {
 public:
  BoxGrid() = default;
  // `cell_mm(size, count)` gives the cell edge for `count` boxes whose union spans `size` (at
  // least 1e-9 mm each way). The grid's origin is the union's lower corner.
  template <class CellSize>
  BoxGrid(const std::vector<Box2>& boxes, CellSize&& cell_mm) {
    if (boxes.empty()) return;
    Eigen::Vector2d lo = boxes.front().lo, hi = boxes.front().hi;
    for (const Box2& b : boxes) {
      lo = lo.cwiseMin(b.lo);
      hi = hi.cwiseMax(b.hi);
    }
    const Eigen::Vector2d size = (hi - lo).cwiseMax(1e-9);
    build(boxes, lo, size, cell_mm(size, boxes.size()));
  }

  bool empty() const { return nx_ == 0; }
  const Eigen::Vector2d& origin() const { return origin_; }
  double cell_mm() const { return cell_mm_; }
  int nx() const { return nx_; }
  int ny() const { return ny_; }
  // The column / row holding x / y, clamped to the grid.
  int column(double x) const { return clamped((x - origin_.x()) / cell_mm_, nx_); }
  int row(double y) const { return clamped((y - origin_.y()) / cell_mm_, ny_); }
  std::size_t cell(int column, int row) const { return static_cast<std::size_t>(row) * nx_ + column; }
  // The boxes touching a cell, by their index in the constructor's vector, ascending.
  std::span<const std::uint32_t> items(std::size_t cell) const {
    return {items_.data() + begin_[cell], items_.data() + begin_[cell + 1]};
  }

 private:
  static int clamped(double v, int n) { return std::clamp(static_cast<int>(std::floor(v)), 0, n - 1); }

  void build(const std::vector<Box2>& boxes, const Eigen::Vector2d& lo, const Eigen::Vector2d& size, double cell_mm) {
    origin_ = lo;
    cell_mm_ = cell_mm;
    nx_ = std::max(1, static_cast<int>(std::ceil(size.x() / cell_mm_)));
    ny_ = std::max(1, static_cast<int>(std::ceil(size.y() / cell_mm_)));
    begin_.assign(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_) + 1, 0);
    auto each_cell = [&](const Box2& b, auto&& fn) {
      const int x0 = column(b.lo.x()), x1 = column(b.hi.x());
      const int y0 = row(b.lo.y()), y1 = row(b.hi.y());
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) fn(cell(x, y));
    };
    for (const Box2& b : boxes) each_cell(b, [&](std::size_t c) { ++begin_[c + 1]; });
    for (std::size_t c = 0; c + 1 < begin_.size(); ++c) begin_[c + 1] += begin_[c];
    items_.resize(begin_.back());
    std::vector<std::uint32_t> fill(begin_.begin(), begin_.end() - 1);
    for (std::uint32_t i = 0; i < boxes.size(); ++i) each_cell(boxes[i], [&](std::size_t c) { items_[fill[c]++] = i; });
  }

  Eigen::Vector2d origin_{0, 0};
  double cell_mm_ = 1.0;
  int nx_ = 0, ny_ = 0;
  std::vector<std::uint32_t> begin_, items_;
};

}  // namespace lamina
