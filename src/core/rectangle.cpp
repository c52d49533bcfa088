#include "core/rectangle.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/convex_hull_2.h>
#include <CGAL/min_quadrilateral_2.h>

#include <algorithm>
#include <cmath>
#include <iterator>

namespace hsr {

RectangleDirection min_area_rectangle(const std::vector<Vec2>& xy) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  std::vector<K::Point_2> pts, hull;
  pts.reserve(xy.size());
  for (const Vec2& p : xy) pts.emplace_back(p.x(), p.y());
  CGAL::convex_hull_2(pts.begin(), pts.end(), std::back_inserter(hull));
  RectangleDirection out;
  if (hull.size() < 3) return out;
  std::vector<K::Point_2> rect;
  CGAL::min_rectangle_2(hull.begin(), hull.end(), std::back_inserter(rect));
  if (rect.size() != 4) return out;
  const double ax = rect[1].x() - rect[0].x(), ay = rect[1].y() - rect[0].y();
  const double bx = rect[2].x() - rect[1].x(), by = rect[2].y() - rect[1].y();
  out.perimeter = 2.0 * (std::hypot(ax, ay) + std::hypot(bx, by));
  out.width = std::min(std::hypot(ax, ay), std::hypot(bx, by));
  out.angle = std::fmod(std::atan2(ay, ax) + 2.0 * M_PI, M_PI / 2.0);
  if (!(out.angle >= 0 && out.angle < M_PI / 2.0)) out.angle = 0.0;
  return out;
}

}  // namespace hsr
