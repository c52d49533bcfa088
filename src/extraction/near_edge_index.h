// Internal to src/extraction: the points whose coordinates lie in an edge's bounding box, for the T-junction
// insertion (surface.cpp) and the rounding check (simple_polygons.cpp). One order of the point ids per axis;
// a query scans the slab of the axis along which the box is thinnest. Doubles only choose candidates: each
// caller decides with its own test (exact, or with its tolerance).
#pragma once

#include "core/types.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace hsr {

class NearEdgeIndex {
 public:
  /// `points` must outlive the index; `ids`: the points to index.
  NearEdgeIndex(const std::vector<Vec3>& points, const std::vector<std::uint32_t>& ids) : points_(points) {
    for (int k = 0; k < 3; ++k) {
      for (std::uint32_t v : ids) by_axis_[k].push_back({points[v][k], v});
      std::sort(by_axis_[k].begin(), by_axis_[k].end());
    }
  }

  /// Calls visit(w) for every indexed point w other than a and b inside the bounding box of the edge (a, b)
  /// enlarged by `margin` on every side, in increasing order of the scanned axis (then of w).
  template <class Visit>
  void for_each_in_edge_box(std::uint32_t a, std::uint32_t b, double margin, Visit&& visit) const {
    const Vec3& pa = points_[a];
    const Vec3& pb = points_[b];
    const Vec3 lo = pa.cwiseMin(pb) - Vec3::Constant(margin), hi = pa.cwiseMax(pb) + Vec3::Constant(margin);
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (hi[k] - lo[k] < hi[axis] - lo[axis]) axis = k;
    const auto& order = by_axis_[axis];
    for (auto it = std::lower_bound(order.begin(), order.end(), std::make_pair(lo[axis], std::uint32_t{0}));
         it != order.end() && it->first <= hi[axis]; ++it) {
      const std::uint32_t w = it->second;
      if (w == a || w == b) continue;
      const Vec3& pw = points_[w];
      if ((pw.array() < lo.array()).any() || (pw.array() > hi.array()).any()) continue;
      visit(w);
    }
  }

 private:
  const std::vector<Vec3>& points_;
  std::array<std::vector<std::pair<double, std::uint32_t>>, 3> by_axis_;
};

}  // namespace hsr
