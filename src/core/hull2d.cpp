#include "core/hull2d.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/convex_hull_2.h>

#include <iterator>

namespace hsr {

std::vector<Vec2> convex_hull_2d(const std::vector<Vec2>& points) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  std::vector<K::Point_2> pts, hull;
  pts.reserve(points.size());
  for (const Vec2& p : points) pts.emplace_back(p.x(), p.y());
  CGAL::convex_hull_2(pts.begin(), pts.end(), std::back_inserter(hull));
  std::vector<Vec2> out;
  out.reserve(hull.size());
  for (const auto& h : hull) out.emplace_back(h.x(), h.y());
  return out;
}

}  // namespace hsr
