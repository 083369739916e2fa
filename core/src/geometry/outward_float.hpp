#pragma once
// Doubles stored as floats for memory, rounded away from what they bound, so that a box or a
// height range kept in floats still holds what it held in doubles (triangle-tree boxes,
// bevel/facets_by_z.hpp). Half the bytes; only the pruning they serve gets a hair looser.
#include <cmath>
#include <limits>

namespace lamina::geometry_detail {

// The nearest float at or below x.
inline float float_at_most(double x) {
  const float f = static_cast<float>(x);
  return static_cast<double>(f) <= x ? f : std::nextafter(f, -std::numeric_limits<float>::infinity());
}

// The nearest float at or above x.
inline float float_at_least(double x) {
  const float f = static_cast<float>(x);
  return static_cast<double>(f) >= x ? f : std::nextafter(f, std::numeric_limits<float>::infinity());
}

}  // namespace lamina::geometry_detail
