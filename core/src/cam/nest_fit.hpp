#pragma once
// Private: the polygon algebra of no-fit and inner-fit regions on Clipper 6 paths (1 unit = 1 nm),
// for placing parts inside other parts' holes (nest_holes.cpp) and hulls for nest_shape.cpp.
// Rings are simple and counter-clockwise unless said otherwise. Regions are Paths read with the
// non-zero rule (outer rings CCW, holes CW), as Clipper returns them.
#include "geometry/clipper_bridge.hpp"

namespace lamina::cam_detail {

// Andrew's monotone chain; counter-clockwise (y up), no repeated point, collinear points dropped.
ClipperLib::Path convex_hull(ClipperLib::Path pts);

// The polygon bounded by the hull's supporting lines in k evenly spaced directions: it contains
// the hull, and every corner is where two neighbouring supporting lines meet.
ClipperLib::Path circumscribed(const ClipperLib::Path& hull, int k);

// No reflex corner (collinear corners allowed).
bool is_convex(const ClipperLib::Path& ring);

// A ring containing `ring`, with few corners when that costs little room: its convex hull when
// the hull adds at most 2 % of the area (circumscribed by 64 supporting lines beyond 64 corners,
// ≤ 0.12 % of the radius off a round part), else simplified_outside(ring).
ClipperLib::Path outer_proxy(const ClipperLib::Path& ring);

// A simple ring containing `ring`, 25-75 µm outside it, with fewer corners (Douglas–Peucker on
// the ring grown by 50 µm); the ring itself when that fails or saves nothing.
ClipperLib::Path simplified_outside(const ClipperLib::Path& ring);

// A simple ring inside `ring`, 25-75 µm inside it, with fewer corners (Douglas–Peucker on the ring
// eroded by 50 µm); the ring itself when that fails or saves nothing.
ClipperLib::Path simplified_inside(const ClipperLib::Path& ring);

// A ring contained in `ring`: for a convex ring of more than 64 corners, 64 of its corners evenly
// picked (their hull lies in any convex set holding them); for a nearly convex one (pockets no
// deeper than 0.1 % of its size), the same from its hull eroded by the deepest pocket; else
// simplified_inside(ring) (the Menger sponge's holes: 136 corners → 60, and the inner fit's cost
// grows with the product of the room's and the candidate's corners).
ClipperLib::Path inner_proxy(const ClipperLib::Path& ring);

// A ⊕ B = {a + b} for two simple rings: exactly the hull of the corner sums when both are convex;
// else the edge-by-edge parallelograms ∂A ⊕ ∂B (Clipper's MinkowskiSum) together with A + b0 and
// B + a0. Why that is all of it: if x = a + b is in neither parallelogram set, the boundaries of A
// and x − B do not cross, and the two Jordan domains meet (at a), so one holds the other — then
// a0 ∈ x − B or x − b0 ∈ A.
ClipperLib::Paths minkowski_sum(const ClipperLib::Path& a, const ClipperLib::Path& b);

// `fit` less the no-fit region G ⊕ (−C) of every ring G of `children`: the same region as
// subtracting each minkowski_sum(G, negated(C)), but only the pieces that meet fit's bounds are
// built, and they are not united first.
ClipperLib::Paths without_no_fit(const ClipperLib::Paths& fit, const std::vector<ClipperLib::Path>& children,
                                 const ClipperLib::Path& c);

// {t : C + t ⊂ room} for a ring C. Convex room ring: the room's edges, each moved inwards by the
// extreme corner of C's hull (half-plane intersection; a convex room holds C iff it holds the hull). Otherwise, for any region:
// (room − c0) minus, for every ring r of the room, ∂r ⊕ ∂(−C) and r[0] − C. Why: C + t stays in
// the room iff one point (c0 + t) is in it and C + t meets no boundary ring; C + t meets ring r
// iff its boundary crosses r (the parallelograms) or r lies wholly inside C + t (then r[0] does).
ClipperLib::Paths inner_fit(const ClipperLib::Paths& room, const ClipperLib::Path& c);

// The general formula alone (tests compare it with the convex shortcut).
ClipperLib::Paths inner_fit_general(const ClipperLib::Paths& room, const ClipperLib::Path& c);

ClipperLib::Path translated(const ClipperLib::Path& ring, ClipperLib::IntPoint by);
ClipperLib::Path negated(const ClipperLib::Path& ring);  // −C, still counter-clockwise

using geometry_detail::boolean;       // clipper_bridge.hpp
using geometry_detail::offset_mitre;  // clipper_bridge.hpp

}  // namespace lamina::cam_detail
