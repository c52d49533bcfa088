// Internal to src/partition: small exact (GMP rational) routines shared by the partitioners and by
// validate(). No CGAL: every predicate is a sign of a rational polynomial, evaluated exactly.
//
// Plane frames. A point of a plane is described in 2D by two of its 3D coordinates: the axis with the
// largest |normal component| is dropped (ties -> lowest axis) and the two others are kept, swapped when
// needed so that counter-clockwise in 2D means counter-clockwise seen from the plane's positive side.
// Projecting and lifting are exact and affine, so 2D orientation, interpolation and (scaled) area are
// exact images of the 3D ones.
#pragma once

#include "partition/cell_complex.h"

#include <vector>

namespace hsr::partition_internal {

struct P2 {
  Rational u, v;
  bool operator==(const P2& o) const { return u == o.u && v == o.v; }
  bool operator<(const P2& o) const { return u < o.u || (u == o.u && v < o.v); }
};

struct ExactPointLess {
  bool operator()(const ExactPoint& a, const ExactPoint& b) const {
    int c = cmp(a.x, b.x);
    if (c != 0) return c < 0;
    c = cmp(a.y, b.y);
    if (c != 0) return c < 0;
    return cmp(a.z, b.z) < 0;
  }
};

/// Exact plane of a double plane, canonical: the first non-zero of (a, b, c) is exactly 1, so two
/// coplanar planes (whatever their orientation) have identical coefficients. Throws BadInput on a zero
/// or non-finite normal.
ExactPlane canonical_plane(const Plane& plane);
/// Divides by the first non-zero normal coefficient (must exist).
void canonicalize(ExactPlane& plane);
bool same_plane(const ExactPlane& a, const ExactPlane& b);
/// Strict weak order on canonical planes (for maps).
bool plane_less(const ExactPlane& a, const ExactPlane& b);

Rational evaluate(const ExactPlane& plane, const ExactPoint& p);
int side(const ExactPlane& plane, const ExactPoint& p);  ///< -1, 0, +1 (exact, double-filtered)

/// How points of one plane are mapped to 2D (see the header comment).
struct PlaneFrame {
  int drop = 2;       ///< dropped axis
  bool swap = false;  ///< (u, v) = (second kept, first kept) instead of (first kept, second kept)
};
PlaneFrame frame_of(const ExactPlane& plane);
P2 to_2d(const PlaneFrame& frame, const ExactPoint& p);
/// The point of `plane` whose 2D image is `q`.
ExactPoint lift(const ExactPlane& plane, const PlaneFrame& frame, const P2& q);
/// Factor from 2D area to 3D area: |n| / |n_drop| (double, for ordering only).
double area_scale(const ExactPlane& plane, const PlaneFrame& frame);

/// Point of segment pq on `plane`, given sp = evaluate(plane, p), sq = evaluate(plane, q) of opposite signs.
ExactPoint intersect_segment(const ExactPoint& p, const ExactPoint& q, const Rational& sp, const Rational& sq);

Rational orient(const P2& a, const P2& b, const P2& c);  ///< twice the signed area of abc
/// Exact sign of orient(a, b, c); a double evaluation with a rigorous error bound decides most cases,
/// the rational one the rest.
int orient_sign(const P2& a, const P2& b, const P2& c);
/// Convex hull, counter-clockwise, no duplicate or collinear vertices (empty if < 3 non-collinear points).
std::vector<P2> convex_hull(std::vector<P2> points);
/// Twice the signed area (shoelace).
Rational twice_area(const std::vector<P2>& polygon);
/// Two convex CCW polygons (collinear vertices allowed) have interiors that intersect (positive-area overlap).
bool interiors_overlap(const std::vector<P2>& a, const std::vector<P2>& b);
/// Intersection of convex CCW `subject` with convex CCW `clipper` (may be empty or degenerate).
std::vector<P2> clip_convex(const std::vector<P2>& subject, const std::vector<P2>& clipper);
/// Keeps the part of the 2D polygon (on `plane`) where `halfspace` >= 0 (sign * halfspace evaluation).
std::vector<P2> clip_by_halfspace(const std::vector<P2>& polygon, const ExactPlane& plane, const PlaneFrame& frame,
                                  const ExactPlane& halfspace, int keep_sign);
/// Indices of `points` sorted counter-clockwise around their centroid. The points must be in convex
/// position (all on the boundary of their convex hull, which has positive area).
std::vector<int> sort_ccw(const std::vector<P2>& points);

/// The input polygon on its support plane: 2D convex hull (in `frame` of `plane`) of its vertices'
/// kept coordinates, i.e. the vertices projected onto the exact plane along the dropped axis.
std::vector<P2> project_polygon(const ConvexPolygon& polygon, const ExactPlane& plane, const PlaneFrame& frame);
/// `polygon2d` (on `plane`) clipped to the box [lo, hi].
std::vector<P2> clip_to_box(const std::vector<P2>& polygon2d, const ExactPlane& plane, const PlaneFrame& frame,
                            const ExactPoint& lo, const ExactPoint& hi);

/// The plane x_axis = value (canonical).
ExactPlane axis_plane(int axis, const Rational& value);

Vec3 to_double(const ExactPoint& p);

}  // namespace hsr::partition_internal
