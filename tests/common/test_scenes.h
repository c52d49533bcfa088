// Hand-made scenes for tests: axis-aligned rectangles of grid points, each a plane of a SceneStructure
// (recovery's level caps and sides, the room's enclosure in scene and visibility).
#pragma once

#include "core/types.h"
#include "structure/structure.h"

#include <algorithm>
#include <cmath>

namespace hsr {

/// Points on a grid of spacing `step` on each plane. Each plane is an axis-aligned rectangle from lo to hi
/// (one of the extents zero; an upright one runs from lo to hi in plan); its points' normals are `normal`.
/// Adjacency is given by link().
struct RectScene {
  PointCloud cloud;
  SceneStructure s;
  double step = 0.05;
  int add(Vec3 lo, Vec3 hi, Vec3 normal) {
    DetectedPlane dp;
    dp.plane.normal = normal;
    dp.plane.offset = -normal.dot(lo);
    const Vec3 ext = hi - lo;
    const int nu = std::max(1, static_cast<int>(std::lround(std::max(ext.x(), ext.y()) / step)));
    const int nz = std::max(1, static_cast<int>(std::lround((ext.z() > 0 ? ext.z() : ext.y()) / step)));
    const bool level = std::abs(normal.z()) > 0.5;
    for (int i = 0; i <= nu; ++i)
      for (int k = 0; k <= nz; ++k) {
        const double u = static_cast<double>(i) / nu, w = static_cast<double>(k) / nz;
        const Vec3 q = level ? Vec3(lo.x() + u * ext.x(), lo.y() + w * ext.y(), lo.z())
                             : Vec3(lo.x() + u * ext.x(), lo.y() + u * ext.y(), lo.z() + w * ext.z());
        dp.inliers.push_back(static_cast<int>(cloud.points.size()));
        cloud.points.push_back(q);
        cloud.normals.push_back(normal);
        dp.centroid += q;
      }
    dp.centroid /= static_cast<double>(dp.inliers.size());
    s.planes.push_back(dp);
    s.point_plane.resize(cloud.points.size(), -1);
    for (int i : s.planes.back().inliers) s.point_plane[static_cast<std::size_t>(i)] = static_cast<int>(s.planes.size()) - 1;
    return static_cast<int>(s.planes.size()) - 1;
  }
  void link(int a, int b) {
    s.adjacency.resize(s.planes.size());
    s.adjacency[static_cast<std::size_t>(a)].push_back(b);
    s.adjacency[static_cast<std::size_t>(b)].push_back(a);
  }
};

}  // namespace hsr
