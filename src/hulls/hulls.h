// Stage 4: one convex polygon per plane for the partition (paper §3.4, DESIGN.md stage 4).
// Current state: the 2D convex hull of each detected plane's inliers, projected on its plane, all at
// level 1 with speed 1. The expanded hulls, levels and speeds of the visibility/recovery stages come later.
#pragma once

#include "partition/cell_complex.h"
#include "structure/structure.h"

#include <vector>

namespace hsr {

struct HullsParams {
  /// Drop hulls whose area is below this fraction of the largest hull's area (degenerate slivers).
  double min_area_fraction = 0.0;
};

/// One ConvexPolygon per detected plane with a non-degenerate hull; plane_id = index in structure.planes.
std::vector<ConvexPolygon> run_hulls(const PointCloud& cloud, const SceneStructure& structure,
                                     const HullsParams& params = {});

}  // namespace hsr
