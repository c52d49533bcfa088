// What the scene stage's files share (not part of its interface): heights, plan cells, and joining one
// detected plane into another (the building's coplanar walls, the room's pieces of a plane).
#pragma once

#include "core/types.h"
#include "structure/structure.h"

#include <cmath>
#include <cstdint>
#include <vector>

namespace hsr::scene_detail {

constexpr const char* kStage = "scene";
constexpr double kDeg = M_PI / 180.0;

/// The heights (z) of the points `idx` of `cloud`.
std::vector<double> heights_of(const PointCloud& cloud, const std::vector<int>& idx);

/// The key of p's plan cell: xy cells of side `cell` counted from `origin`, shifted by (dx, dy) cells.
std::int64_t plan_cell(const Vec3& p, const Vec2& origin, double cell, int dx = 0, int dy = 0);

/// Plane b joins plane a: inliers, boundary and segments joined, a's normal through their common centroid.
/// (a's boundary_edges stay a's: they index the first slots of the joined boundary.)
void join_plane(DetectedPlane& a, const DetectedPlane& b);

/// After join_plane: the points and neighbours of each joined plane (head[k] >= 0 and != k: the plane it
/// joined) go to that plane.
void redirect_joined(SceneStructure& s, const std::vector<int>& head);

}  // namespace hsr::scene_detail
