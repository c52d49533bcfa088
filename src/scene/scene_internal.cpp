// The scene stage's shared helpers (scene_internal.h).
#include "scene/scene_internal.h"

#include <algorithm>

namespace hsr::scene_detail {

std::vector<double> heights_of(const PointCloud& cloud, const std::vector<int>& idx) {
  std::vector<double> z;
  z.reserve(idx.size());
  for (int i : idx) z.push_back(cloud.points[static_cast<std::size_t>(i)].z());
  return z;
}

/// The key of p's plan cell: xy cells of side `cell` counted from `origin`, shifted by (dx, dy) cells.
std::int64_t plan_cell(const Vec3& p, const Vec2& origin, double cell, int dx, int dy) {
  const auto ix = static_cast<std::int64_t>(std::floor((p.x() - origin.x()) / cell)) + dx;
  const auto iy = static_cast<std::int64_t>(std::floor((p.y() - origin.y()) / cell)) + dy;
  return ix * 0x100000000ll + iy;
}

/// Plane b joins plane a: inliers, boundary and segments joined, a's normal through their common centroid.
/// (a's boundary_edges stay a's: they index the first slots of the joined boundary.)
void join_plane(DetectedPlane& a, const DetectedPlane& b) {
  const double wa = static_cast<double>(a.inliers.size()), wb = static_cast<double>(b.inliers.size());
  a.centroid = (wa * a.centroid + wb * b.centroid) / (wa + wb);
  a.plane.offset = -a.plane.normal.dot(a.centroid);
  a.inliers.insert(a.inliers.end(), b.inliers.begin(), b.inliers.end());
  std::sort(a.inliers.begin(), a.inliers.end());
  a.boundary.insert(a.boundary.end(), b.boundary.begin(), b.boundary.end());
  a.boundary_points.insert(a.boundary_points.end(), b.boundary_points.begin(), b.boundary_points.end());
  a.boundary_normals.insert(a.boundary_normals.end(), b.boundary_normals.begin(), b.boundary_normals.end());
  a.segments.insert(a.segments.end(), b.segments.begin(), b.segments.end());
  a.area += b.area;
}

/// After join_plane: the points and neighbours of each joined plane (head[k] >= 0 and != k: the plane it
/// joined) go to that plane.
void redirect_joined(SceneStructure& s, const std::vector<int>& head) {
  for (int& k : s.point_plane)
    if (k >= 0 && head[static_cast<std::size_t>(k)] >= 0) k = head[static_cast<std::size_t>(k)];
  for (std::size_t i = 0; i < s.planes.size(); ++i) {  // the joined planes' neighbours go to their head
    if (head[i] < 0 || head[i] == static_cast<int>(i)) continue;
    auto& into = s.adjacency[static_cast<std::size_t>(head[i])];
    into.insert(into.end(), s.adjacency[i].begin(), s.adjacency[i].end());
  }
  for (std::size_t i = 0; i < s.planes.size(); ++i) {
    auto& adj = s.adjacency[i];
    for (int& j : adj)
      if (head[static_cast<std::size_t>(j)] >= 0) j = head[static_cast<std::size_t>(j)];
    adj.erase(std::remove(adj.begin(), adj.end(), static_cast<int>(i)), adj.end());
    std::sort(adj.begin(), adj.end());
    adj.erase(std::unique(adj.begin(), adj.end()), adj.end());
  }
}

}  // namespace hsr::scene_detail
