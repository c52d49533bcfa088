// What the building kind's files share (not part of the scene stage's interface).
#pragma once

#include "scene/building/building.h"
#include "scene/scene.h"

#include <vector>

namespace hsr::building_detail {

constexpr int kSectors = 16;  ///< angular sectors about the building for "the ground reaches around it"

/// Ground source 4 (building.h), or none. Fills *ground_z from their inliers when found. The caller checks
/// that a roof is left once they are ground.
std::vector<int> find_ground_planes(const PointCloud& cloud, const SceneStructure& s, const BuildingParams& params,
                                    const std::vector<bool>& foliage, double* ground_z);

/// The ground height from the first source of building.h's list that has one; sets out.ground_z and
/// out.ground_source (and out.ground_note when it had to assume). Roles must be set (roof and wall planes
/// define the footprint); the ground planes are those find_ground_planes() returned, at `plane_height`.
void choose_ground(const PointCloud& cloud, const SceneStructure& s, const BuildingParams& params,
                   const SceneGround& ground, double plane_height, SceneResult& out);

/// Roles of the non-ground planes: foliage, low ones (when `low_rule`, against out.ground_z) and far small
/// groups are clutter (building.h); low roofs only while a roof that is not low remains.
void assign_roles(const PointCloud& cloud, const SceneStructure& s, const BuildingParams& params,
                  const std::vector<bool>& foliage, bool low_rule, SceneResult& out);

/// Whether a side of the rectangle in direction `angle` (radians) around `xy` runs through three or more of them,
/// to within `tolerance`: points on a raster's rows (BuildingParams::main_direction_raster_tolerance).
bool sides_on_raster_rows(const std::vector<Vec2>& xy, double angle, double tolerance);

/// Mode of the roof outlines' directions modulo 90 degrees (building.h main_direction_*), or the direction of the
/// rectangle around the roofs' and walls' inliers where it agrees (main_direction_from_rectangle). Radians in [0, pi/2).
double main_direction(const PointCloud& cloud, const SceneStructure& s, const std::vector<PlaneRole>& roles,
                      const BuildingParams& params);

/// A plane upright enough to be a wall (BuildingParams::wall_max_angle_deg).
bool is_wall(const Plane& p, const BuildingParams& params);

/// A small plane that is not upright enough to be a wall is a roof only when its slope is at most
/// small_roof_max_slope_deg (roles.cpp, the why there).
bool small_roof_too_steep(const Plane& p, const BuildingParams& params);

/// What step 7's count needs of the structure `s` after the small planes joined (roof_split.cpp): its roof planes of
/// the detection's size (index under `first_size`) that may be split, its points on no plane, its spacing.
SplitInput split_input_of(const SceneStructure& s, std::size_t first_size, const SceneResult& scene,
                          const BuildingParams& params);

/// Step 7's run (GableHalves::Split, roof_split.cpp): every candidate of `input` (split_candidates) left out, its
/// points and the free points its halves take unassigned, its halves appended as planes (roles Roof; a plane that
/// is a wall or too steep, clutter); `*planes_split` (may be null) gets how many were split.
SceneStructure split_roof_planes(const PointCloud& cloud, SceneStructure s, const SplitInput& input,
                                 const StructureParams& structure, const BuildingParams& params, SceneResult& scene,
                                 KnnGraphCache* graphs, std::size_t* planes_split);

}  // namespace hsr::building_detail
