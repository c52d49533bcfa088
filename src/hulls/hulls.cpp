#include "hulls/hulls.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/convex_hull_2.h>

#include <algorithm>
#include <cmath>

namespace hsr {

namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;

/// Orthonormal (u, v) spanning the plane, with u × v = normal (so CCW in (u, v) is CCW seen from the
/// normal side).
void plane_frame(const Vec3& n, Vec3& u, Vec3& v) {
  const Vec3 helper = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  u = n.cross(helper).normalized();
  v = n.cross(u);
}
}  // namespace

std::vector<ConvexPolygon> run_hulls(const PointCloud& cloud, const SceneStructure& structure,
                                     const HullsParams& params) {
  std::vector<ConvexPolygon> polygons;
  std::vector<double> areas;
  for (std::size_t id = 0; id < structure.planes.size(); ++id) {
    const DetectedPlane& dp = structure.planes[id];
    const Vec3 n = dp.plane.normal;
    const Vec3 origin = -dp.plane.offset * n;  // foot of the perpendicular from 0
    Vec3 u, v;
    plane_frame(n, u, v);
    std::vector<K::Point_2> pts;
    pts.reserve(dp.inliers.size());
    for (int i : dp.inliers) {
      const Vec3 d = cloud.points[static_cast<std::size_t>(i)] - origin;
      pts.emplace_back(d.dot(u), d.dot(v));
    }
    std::vector<K::Point_2> hull;
    CGAL::convex_hull_2(pts.begin(), pts.end(), std::back_inserter(hull));  // CCW
    if (hull.size() < 3) continue;
    double area = 0;
    for (std::size_t i = 0; i < hull.size(); ++i) {
      const auto& a = hull[i];
      const auto& b = hull[(i + 1) % hull.size()];
      area += a.x() * b.y() - b.x() * a.y();
    }
    area *= 0.5;
    if (!(area > 0)) continue;
    ConvexPolygon poly;
    poly.plane_id = static_cast<int>(id);
    poly.plane = dp.plane;
    for (const auto& h : hull) poly.vertices.push_back(origin + h.x() * u + h.y() * v);
    polygons.push_back(std::move(poly));
    areas.push_back(area);
  }
  if (params.min_area_fraction > 0 && !areas.empty()) {
    const double largest = *std::max_element(areas.begin(), areas.end());
    std::vector<ConvexPolygon> kept;
    for (std::size_t i = 0; i < polygons.size(); ++i)
      if (areas[i] >= params.min_area_fraction * largest) kept.push_back(std::move(polygons[i]));
    polygons = std::move(kept);
  }
  return polygons;
}

}  // namespace hsr
