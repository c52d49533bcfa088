#include "core/hull2d.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/convex_hull_2.h>

#include <algorithm>
#include <cmath>
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

void plane_frame(const Vec3& n, Vec3& u, Vec3& v) {
  const Vec3 helper = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  u = n.cross(helper).normalized();
  v = n.cross(u);
}

bool within_convex(const std::vector<Vec2>& hull, const Vec2& q, double margin) {
  if (hull.empty()) return false;
  if (hull.size() < 3) {  // a point or a segment: the distance to it
    const Vec2 a = hull.front(), d = hull.back() - a;
    const double t = d.squaredNorm() > 0 ? std::clamp((q - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
    return (a + t * d - q).norm() <= margin;
  }
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Vec2 a = hull[i], d = hull[(i + 1) % hull.size()] - a;
    const double length = d.norm();
    if (!(length > 0)) continue;
    if ((d.x() * (q.y() - a.y()) - d.y() * (q.x() - a.x())) / length < -margin) return false;  // right of the edge
  }
  return true;
}

std::vector<Vec2> offset_convex(const std::vector<Vec2>& hull, double d) {
  if (!(d > 0) || hull.size() < 3) return hull;
  const std::size_t n = hull.size();
  const auto outward = [&](std::size_t i) {  // of the edge from vertex i to i + 1 (counter-clockwise: its right)
    const Vec2 t = (hull[(i + 1) % n] - hull[i]).normalized();
    return Vec2(t.y(), -t.x());
  };
  std::vector<Vec2> out;
  out.reserve(2 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 n0 = outward((i + n - 1) % n), n1 = outward(i);
    const double c = n0.dot(n1);
    if (c >= -0.5) {
      out.push_back(hull[i] + d * (n0 + n1) / (1.0 + c));  // the moved edges' meeting point, at most 2 d away
    } else {
      out.push_back(hull[i] + d * n0);
      out.push_back(hull[i] + d * n1);
    }
  }
  return out;
}

}  // namespace hsr
