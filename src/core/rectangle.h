// The smallest-area rectangle around points in the plane (CGAL's min_rectangle_2 on their convex hull):
// scene/building/roles.cpp's main direction takes each roof's as a vote (a roof with few outline segments still has one),
// and a room's pieces without an upright plane (recovery.h) have their boxes on it.
#pragma once

#include "core/types.h"

#include <vector>

namespace hsr {

/// Direction of one side of the smallest-area rectangle holding `xy`, radians in [0, pi/2), its perimeter and
/// its shorter side (both 0 when the points do not span an area: fewer than 3, or all on a line).
struct RectangleDirection {
  double angle = 0.0;
  double perimeter = 0.0;
  double width = 0.0;
};
RectangleDirection min_area_rectangle(const std::vector<Vec2>& xy);

}  // namespace hsr
