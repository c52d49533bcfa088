#include "hulls/hulls.h"

#include "core/error.h"
#include "core/hull2d.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/convex_hull_2.h>

#include <algorithm>
#include <set>
#include <cmath>

namespace hsr {

namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;

/// Convex hull of `points` projected on `plane`, CCW seen from the normal side. Returns false when
/// degenerate (fewer than 3 vertices or zero area); `area` receives its area.
bool hull_on_plane(const std::vector<Vec3>& points, const Plane& plane, std::vector<Vec3>& out, double& area) {
  const Vec3 n = plane.normal;
  const Vec3 origin = -plane.offset * n;  // foot of the perpendicular from 0
  Vec3 u, v;
  plane_frame(n, u, v);
  std::vector<K::Point_2> pts;
  pts.reserve(points.size());
  for (const Vec3& p : points) {
    const Vec3 d = p - origin;
    pts.emplace_back(d.dot(u), d.dot(v));
  }
  std::vector<K::Point_2> hull;
  CGAL::convex_hull_2(pts.begin(), pts.end(), std::back_inserter(hull));  // CCW
  out.clear();
  area = 0;
  if (hull.size() < 3) return false;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const auto& a = hull[i];
    const auto& b = hull[(i + 1) % hull.size()];
    area += a.x() * b.y() - b.x() * a.y();
  }
  area *= 0.5;
  if (!(area > 0)) return false;
  for (const auto& h : hull) out.push_back(origin + h.x() * u + h.y() * v);
  return true;
}

std::vector<ConvexPolygon> drop_slivers(std::vector<ConvexPolygon> polygons, const std::vector<double>& areas,
                                        double fraction) {
  if (!(fraction > 0) || areas.empty()) return polygons;
  const double largest = *std::max_element(areas.begin(), areas.end());
  std::vector<ConvexPolygon> kept;
  for (std::size_t i = 0; i < polygons.size(); ++i)
    if (areas[i] >= fraction * largest) kept.push_back(std::move(polygons[i]));
  return kept;
}

std::vector<Vec3> gather(const PointCloud& cloud, const std::vector<int>& idx) {
  std::vector<Vec3> pts;
  pts.reserve(idx.size());
  for (int i : idx) pts.push_back(cloud.points[static_cast<std::size_t>(i)]);
  return pts;
}

/// Building mode: a vertical plane's points get their shadows on the ground, so its hull stands on it.
void drop_to_ground(const Plane& plane, const HullsParams& params, std::vector<Vec3>& pts) {
  if (!params.walls_to_ground || plane.normal.z() != 0.0) return;
  const std::size_t n = pts.size();
  for (std::size_t i = 0; i < n; ++i) pts.emplace_back(pts[i].x(), pts[i].y(), params.ground_z);
}
}  // namespace

std::vector<double> speeds_from_ratios(const std::vector<double>& ratios, double min_speed) {
  std::vector<double> speeds(ratios.size(), 1.0);
  if (ratios.empty()) return speeds;
  const auto [lo, hi] = std::minmax_element(ratios.begin(), ratios.end());
  if (!(*hi > *lo)) return speeds;
  for (std::size_t i = 0; i < ratios.size(); ++i)
    speeds[i] = min_speed + (1.0 - min_speed) * (ratios[i] - *lo) / (*hi - *lo);
  return speeds;
}

std::vector<ConvexPolygon> run_hulls(const PointCloud& cloud, const SceneStructure& structure,
                                     const HullsParams& params) {
  std::vector<ConvexPolygon> polygons;
  std::vector<double> areas;
  for (std::size_t id = 0; id < structure.planes.size(); ++id) {
    const DetectedPlane& dp = structure.planes[id];
    ConvexPolygon poly;
    double area = 0;
    if (!hull_on_plane(gather(cloud, dp.inliers), dp.plane, poly.vertices, area)) continue;
    poly.plane_id = static_cast<int>(id);
    poly.plane = dp.plane;
    polygons.push_back(std::move(poly));
    areas.push_back(area);
  }
  return drop_slivers(std::move(polygons), areas, params.min_area_fraction);
}

std::vector<ConvexPolygon> run_hulls(const PointCloud& cloud, const SceneStructure& structure,
                                     const VisibilityResult& visibility, const RecoveryResult& recovery,
                                     const HullsParams& params) {
  const std::size_t m = structure.planes.size();
  if (visibility.ratio.size() != m || visibility.highly.size() != m || recovery.singular.size() != m ||
      recovery.partner.size() != m)
    throw Error(Status::Internal, "hulls", "visibility/recovery results do not match the structure's planes");

  // Extra points of each plane: supporting points of the segments it contains as partner.
  std::vector<std::vector<int>> extra(m);
  const double reach = params.expand_reach * structure.spacing;
  if (params.expand)
    for (std::size_t i = 0; i < m; ++i)
      for (std::size_t j = 0; j < recovery.partner[i].size(); ++j) {
        const int k = recovery.partner[i][j];
        if (k < 0 || static_cast<std::size_t>(k) >= m) continue;
        const auto& sup = structure.planes[i].segments[j].support;
        const DetectedPlane& partner = structure.planes[static_cast<std::size_t>(k)];
        if (reach > 0 && !sup.empty() && !(partner.boundary_distance(cloud.mean_of(sup)) < reach))
          continue;  // the partner is elsewhere: its line only passes by
        extra[static_cast<std::size_t>(k)].insert(extra[static_cast<std::size_t>(k)].end(), sup.begin(), sup.end());
      }

  // Speeds per level.
  std::vector<double> speed(m, 1.0);
  for (int level = 1; level <= 2; ++level) {
    std::vector<std::size_t> members;
    std::vector<double> ratios;
    for (std::size_t k = 0; k < m; ++k)
      if ((visibility.highly[k] ? 1 : 2) == level) { members.push_back(k); ratios.push_back(visibility.ratio[k]); }
    const std::vector<double> s = speeds_from_ratios(ratios, params.min_speed);
    for (std::size_t t = 0; t < members.size(); ++t) speed[members[t]] = s[t];
  }

  std::vector<ConvexPolygon> polygons;
  std::vector<double> areas;
  for (std::size_t k = 0; k < m; ++k) {
    const DetectedPlane& dp = structure.planes[k];
    std::vector<Vec3> pts = gather(cloud, dp.inliers);
    for (int p : extra[k]) pts.push_back(cloud.points[static_cast<std::size_t>(p)]);
    drop_to_ground(dp.plane, params, pts);
    ConvexPolygon poly;
    double area = 0;
    if (!hull_on_plane(pts, dp.plane, poly.vertices, area)) continue;
    poly.plane_id = static_cast<int>(k);
    poly.plane = dp.plane;
    poly.level = visibility.highly[k] ? 1 : 2;
    poly.speed = speed[k];
    if (params.walls_to_ground && dp.plane.normal.z() == 0.0) poly.level = 1, poly.speed = 1.0;
    polygons.push_back(std::move(poly));
    areas.push_back(area);
  }
  if (params.recovered_planes)
    for (std::size_t q = 0; q < recovery.recovered.size(); ++q) {
      const RecoveredPlane& rp = recovery.recovered[q];
      ConvexPolygon poly;
      double area = 0;
      std::vector<Vec3> pts = gather(cloud, rp.support);
      pts.insert(pts.end(), rp.reach.begin(), rp.reach.end());  // building mode: the wall spans its eave
      drop_to_ground(rp.plane, params, pts);
      if (!hull_on_plane(pts, rp.plane, poly.vertices, area)) continue;
      poly.plane_id = static_cast<int>(m + q);
      poly.plane = rp.plane;
      poly.level = params.walls_to_ground && rp.plane.normal.z() == 0.0 ? 1 : 3;
      poly.speed = 1.0;
      polygons.push_back(std::move(poly));
      areas.push_back(area);
    }
  return drop_slivers(std::move(polygons), areas, params.min_area_fraction);
}

std::vector<std::pair<int, int>> polygon_adjacency(const SceneStructure& structure, const RecoveryResult& recovery) {
  std::set<std::pair<int, int>> pairs;
  for (std::size_t i = 0; i < structure.adjacency.size(); ++i)
    for (int j : structure.adjacency[i])
      if (static_cast<int>(i) != j) pairs.insert({std::min<int>(i, j), std::max<int>(i, j)});
  const int first_recovered = static_cast<int>(structure.planes.size());
  for (std::size_t q = 0; q < recovery.recovered.size(); ++q) {
    for (const SegmentRef& seg : recovery.recovered[q].segments)
      pairs.insert({seg.plane, first_recovered + static_cast<int>(q)});
    for (int k : recovery.recovered[q].caps) pairs.insert({k, first_recovered + static_cast<int>(q)});  // a level cap
    const int piece = recovery.recovered[q].piece;  // a piece's box faces, listed one after the other
    for (std::size_t o = q; piece >= 0 && o-- > 0 && recovery.recovered[o].piece == piece;)
      pairs.insert({first_recovered + static_cast<int>(o), first_recovered + static_cast<int>(q)});
  }
  return {pairs.begin(), pairs.end()};
}

}  // namespace hsr
