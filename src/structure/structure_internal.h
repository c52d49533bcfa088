// Internal helpers of stage 1 shared between its .cpp files (not part of the public interface).
#pragma once

#include "core/kd_tree.h"
#include "structure/structure.h"

#include <vector>

namespace hsr::structure_detail {

/// k nearest neighbours of every point (self excluded), nearest first, stored row by row.
struct KnnGraph {
  int k = 0;
  std::vector<int> neighbors;  ///< size n*k; row i = neighbours of point i
  const int* row(std::size_t i) const { return neighbors.data() + i * static_cast<std::size_t>(k); }
};

/// Builds the kNN graph on `tree` (built over `points`; k is clamped to n - 1). Row i: the k points nearest
/// to i by (distance, index), i itself left out. Parallel; the same rows whatever the thread count.
KnnGraph build_knn_graph(const std::vector<Vec3>& points, const KdTree& tree, int k);

/// PCA normal of each point from itself and the first k neighbours of its row (unit, sign arbitrary).
std::vector<Vec3> estimate_normals(const std::vector<Vec3>& points, const KnnGraph& g, int k);

/// Orients `normals` along a minimum spanning tree of the first k neighbours of each row (CGAL's
/// mst_orient_normals algorithm, see structure.cpp). Returns per point whether the tree reached it (the
/// others keep their sign).
std::vector<char> mst_orient(const std::vector<Vec3>& points, std::vector<Vec3>& normals, const KnnGraph& g, int k);

/// Least-squares plane of the given points (normal sign arbitrary but deterministic) and their centroid.
Plane fit_plane(const std::vector<Vec3>& points, const std::vector<int>& indices, Vec3* centroid);

/// The smallest plane, absolute (StructureParams::min_region_points, min_region_width; the optional
/// min_region_fraction folded into points).
struct MinimumPlane {
  std::size_t points = 0;  ///< inliers, at least
  double width = 0.0;      ///< the inliers' extent across their plane's narrow direction, at least (absolute)
  bool distinct = false;   ///< count inliers at distinct positions (StructureParams::min_region_distinct)
};

/// The extent of the points `region` on the plane with unit normal n across its narrowest direction:
/// sqrt(12 x the smaller eigenvalue of their 2D covariance) (a uniformly filled rectangle's shorter side).
double projected_width(const std::vector<Vec3>& points, const std::vector<int>& region, const Vec3& n);

/// A region is a plane when it has at least min.points points (at distinct positions if min.distinct) and, projected to the
/// plane `n`, is at least min.width wide (projected_width; tested only when the count passes).
bool is_large_enough(const std::vector<Vec3>& points, const std::vector<int>& region, const Vec3& n,
                     const MinimumPlane& min);

/// Region growing on the kNN graph (region_growing.cpp). Returns inlier lists (each sorted), in detection
/// order, each large enough (is_large_enough on its fit plane). Points with taken[i] (when not empty) neither
/// seed nor join a region.
std::vector<std::vector<int>> detect_planes_region_growing(const std::vector<Vec3>& points,
                                                           const std::vector<Vec3>& normals, const KnnGraph& g,
                                                           const StructureParams& params, double r,
                                                           const MinimumPlane& min, const std::vector<char>& taken = {});

/// Efficient RANSAC (CGAL), deterministic for params.seed. Returns inlier lists (each sorted).
std::vector<std::vector<int>> detect_planes_ransac(const std::vector<Vec3>& points, const std::vector<Vec3>& normals,
                                                   const StructureParams& params, double r,
                                                   std::size_t min_points);

/// Fills frame, area, boundary points/normals and segments of `plane` (its inliers and equation are set).
void compute_boundary(const std::vector<Vec3>& points, int plane_index, DetectedPlane& plane,
                      const StructureParams& params, double r);

/// The segments of `plane` (replaced) from its boundary as compute_boundary left it (boundary, boundary_edges,
/// boundary_normals, frame) under params' segment fields (segment_*, min_segment_points, regularize_segments).
void segment_boundary(const std::vector<Vec3>& points, int plane_index, DetectedPlane& plane,
                      const StructureParams& params, double r);

/// SceneStructure::second_order from SceneStructure::adjacency (see structure.h).
void compute_second_order(SceneStructure& s);

/// SceneStructure::lines (replaced) for every non-parallel adjacent or second-order-adjacent pair of planes.
void compute_lines(SceneStructure& s, double min_line_angle_deg);

}  // namespace hsr::structure_detail
