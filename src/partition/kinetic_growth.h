// Internal to src/partition: face-based kinetic growth of convex polygons inside one convex domain
// (DESIGN.md §2 steps 1-4, paper §3.5). Plain exact data in, one grown region per polygon out; no access to
// the complex being built, so domains can grow in parallel.
//
// Model. Each polygon P lives on its support plane. On that plane, the lines where the other polygons'
// planes cut it, clipped to the domain's section, form a 2D arrangement; P's region is a union of its
// faces. A face is computed lazily (the domain section clipped by the halfplane of every line that
// contains a given point), so only the faces a region actually reaches are ever built.
//
// Time. P reaches point x of its plane at T_P(x) = (R/s) * max(0, g(x) - 1), g the gauge of P's initial
// convex polygon about its vertex average (g = 1 on its boundary), R = sqrt(area / pi), s the speed. T_P is
// piecewise linear, so the time P reaches an arrangement edge (the minimum of T_P over the segment) is
// attained at an endpoint or where the segment crosses a ray from the centre through a vertex of the
// initial polygon: exact rational, one candidate per vertex.
//
// Events (P, face, edge) are processed in the order (exact time, inside-the-initial-polygon first,
// polygon index, face index, edge index). An edge is crossed freely while it meets the interior of P's
// initial polygon (g < 1 somewhere on it): the initial region is every face the polygon overlaps. Walls
// (the domain boundary) are never crossed. Otherwise another polygon Q is *present* on the edge when Q's
// region already covers the edge on both sides in Q's plane (Q has crossed the line P∩Q there). Tie rule:
// when two fronts reach one edge at the same exact time, the one processed first (smaller polygon index)
// sees nobody and crosses; the other then finds it present. "Present" always means "covers both sides", so
// a region always ends in the middle of another region or on a wall: the complement of the regions in the
// domain is a union of convex cells (checked by validate()).
//   kinetic:      c = number of present polygons whose plane P has not paid for yet. c = 0: cross. Else
//                 if c >= P's remaining budget (k at the start) P stops, otherwise the budget drops by c,
//                 those planes are paid (re-crossing their lines later is free) and P crosses.
//   hierarchical: a present polygon adjacent to P (adjacency graph, events C) stops P. Non-adjacent present
//                 polygons (events B) are crossed and paid for while P is on its way to its *bounds*, and
//                 stop P beyond them. P's bounds are the lines of its adjacent polygons that stay out of the
//                 inner half of its initial polygon (gauge >= 1/2 all along the line; a line through the
//                 middle is a T-junction, not an end of P); their halfplanes on the centre's side intersect
//                 in the region K where P's true edges are expected. An event is "on the way" when its face
//                 is inside K and its line is not a bound (the face beyond is then inside K too). A polygon
//                 without bounds (no adjacent polygon around it) has no evidence of where it ends: K is empty
//                 and it stops at its first collision, as kinetic with k = 1. Safety budget: P also stops
//                 when it would pay for more than `max_crossings` distinct planes.
//                 Wait (off by default, DECISIONS #36): at an edge on one of its bounds that nobody covers, P is re-queued once
//                 at the latest time an adjacent owner of the line reaches that edge (re-queued events go
//                 after fresh ones of the same time); the owner then finds nobody and crosses, and P stops
//                 on it. So of two adjacent polygons the one reaching their common line last crosses it.
//                 Trim (off by default): after growth, a face neither on the initial polygon nor inside K is
//                 removed while every edge it shares with the rest of the region is covered on both sides
//                 by another region (polygons in order, faces last-added first, until nothing changes):
//                 beyond its bounds P ends at its first collision even when the other polygon got there
//                 after P. Without adjacency (K empty) hierarchical is then kinetic k = 1 less such faces.
//                 Why bounds: crossing every non-adjacent polygon (the paper's text read literally) sends a
//                 polygon that has passed its true edge across the whole domain: on the 10 shared scans it
//                 gave 3.6x the cells of kinetic (712 vs 199 on average); with bounds 1.7x (336), at the
//                 same accuracy after extraction (mean p2m 0.457% vs 0.440%; kinetic 0.533%). Measured
//                 before the sub-domain change of docs/DECISIONS.md #13 (now 312 cells, 0.454%).
#pragma once

#include "partition/exact_geometry.h"
#include "partition/growth_time.h"

#include <memory>
#include <utility>
#include <vector>

namespace hsr::partition_internal {

struct GrowthPolygon {
  int id = -1;                  ///< caller's polygon id (tie-breaks are by position in the input vector)
  ExactPlane plane;             ///< canonical support plane
  IntPlane integer;             ///< its integer coefficients (int_plane)
  PlaneFrame frame;             ///< 2D frame of `plane` (the complex builder's frame)
  std::vector<P2> shape;        ///< the whole initial convex polygon (CCW, positive area), not clipped
  Rational time_scale;          ///< R / s
  std::vector<P2> domain;       ///< section of the domain by `plane`: convex CCW, positive area
  P2 seed;                      ///< a point strictly inside both `shape` and `domain`: where growth starts
  /// The time function of `shape` and `time_scale`, when the caller shares one between the domains a polygon
  /// grows in (it depends on the polygon only); null: grow_regions builds it.
  std::shared_ptr<const ArrivalTime> time;
};

struct GrowthRules {
  bool hierarchical = false;
  int k = 1;                    ///< kinetic: collisions a polygon survives + 1
  int max_crossings = 8;        ///< hierarchical: safety budget (distinct planes crossed)
  /// hierarchical: adjacent[i] lists (sorted) the indices of the polygons adjacent to polygon i.
  std::vector<std::vector<int>> adjacent;
  // Ablation switches of issue 17 (PartitionParams documents each; these are its values).
  bool cross_to_bounds = true;   ///< hierarchical: events B crossed on the way to the bounds
  bool meet_at_point = false;    ///< a present polygon counts only if it reached P's touch point first
  bool wait_at_bounds = false;   ///< hierarchical: P waits once at a bound its adjacent polygon has not reached
  bool trim = false;             ///< hierarchical: faces beyond the bounds that another region covers removed
};

struct GrownRegion {
  std::vector<std::vector<P2>> faces;  ///< convex CCW faces of the polygon's plane arrangement, in its frame
  std::vector<std::vector<Vec3>> faces3d;  ///< their vertices in 3D, double images (to_double) of the exact ones
  std::vector<std::vector<D2>> faces_d;   ///< the double images (approx) of `faces`, for the callers' filters
  int stops = 0;                       ///< edges where it stopped on another region (statistics)
  int crossings = 0;                   ///< edges crossed past another region (statistics)
};

/// Grows every polygon (all polygons must lie on distinct planes) and returns their regions, in input order.
std::vector<GrownRegion> grow_regions(const std::vector<GrowthPolygon>& polygons, const GrowthRules& rules);

/// True when the point lies in the closed convex CCW polygon.
bool point_in_convex(const P2& p, const std::vector<P2>& polygon);
/// The same with the double images of the point and of the polygon (approx).
bool point_in_convex(const P2& p, const D2& dp, const std::vector<P2>& polygon, const std::vector<D2>& d);

}  // namespace hsr::partition_internal
