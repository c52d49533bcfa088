// The convex hull of points in a plane (CGAL's convex_hull_2): a room's floor, walls and ceiling taken as
// whole planes (visibility.h close_room).
#pragma once

#include "core/types.h"

#include <vector>

namespace hsr {

/// The convex hull of `points`, counter-clockwise, without collinear vertices; fewer than 3 vertices when
/// the points do not span an area.
std::vector<Vec2> convex_hull_2d(const std::vector<Vec2>& points);

}  // namespace hsr
