// The convex hull of points in a plane (CGAL's convex_hull_2): a room's floor, walls and ceiling taken as
// whole planes (visibility.h close_room), a plane's extent (stage 4's polygons, recovery's one plane per surface).
#pragma once

#include "core/types.h"

#include <vector>

namespace hsr {

/// The convex hull of `points`, counter-clockwise, without collinear vertices; fewer than 3 vertices when
/// the points do not span an area.
std::vector<Vec2> convex_hull_2d(const std::vector<Vec2>& points);

/// Orthonormal (u, v) spanning the plane of unit normal `n`, with u × v = n (so counter-clockwise in (u, v) is
/// counter-clockwise seen from the normal's side).
void plane_frame(const Vec3& n, Vec3& u, Vec3& v);

/// Whether `q` lies in the convex polygon `hull` (counter-clockwise, as convex_hull_2d returns it) with its edges
/// moved out by `margin` (>= 0); a hull of one or two vertices (points on a line) is its segment grown by
/// `margin`; an empty hull contains nothing.
bool within_convex(const std::vector<Vec2>& hull, const Vec2& q, double margin);

/// The convex polygon `hull` (counter-clockwise, no collinear vertices, at least 3) with each edge moved out by
/// `d` (>= 0): each vertex where its two moved edges meet, or, where that corner would reach farther than 2 d from
/// the vertex (an angle under 60 degrees), two vertices cutting it square (each a moved edge's end). `hull` as
/// it is for d = 0 or fewer than 3 vertices.
std::vector<Vec2> offset_convex(const std::vector<Vec2>& hull, double d);

}  // namespace hsr
