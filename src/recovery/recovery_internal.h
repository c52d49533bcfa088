// Stage 3's own header, internal to src/recovery: what recovery.cpp (paper §3.3 and run_recovery's chain),
// building_walls.cpp (a building's walls, DECISIONS #22, #54) and room_rules.cpp (a room's rules, DECISIONS #66,
// #67, #70, #72-#74) share. Not for other stages; the rules themselves are described in recovery.h.
#pragma once

#include "recovery/recovery.h"

#include <cstddef>
#include <vector>

namespace hsr::recovery_internal {

// --- shared (recovery.cpp)

/// Centroid of a segment: the mean of its supporting points, or its midpoint when it has none.
Vec3 segment_centroid(const PointCloud& cloud, const BoundarySegment& s);

/// The recovered plane of `segments` (any order) on `plane`, supported by their points: the invariants of
/// RecoveredPlane (segments sorted, support the sorted union).
RecoveredPlane recovered_plane(const SceneStructure& structure, const Plane& plane, std::vector<SegmentRef> segments);

// --- a building (building_walls.cpp)

/// Building mode: a detected (vertical) wall that explains a singular roof segment `s` (centroid `c`), or -1.
int explaining_wall(const SceneStructure& structure, const BoundarySegment& s, const Vec3& c, double join, double r_d,
                    double cos_a);

/// Building mode: vertical walls grown over singular roof segments (see recovery.h).
std::vector<RecoveredPlane> recover_walls(const PointCloud& cloud, const SceneStructure& structure,
                                          const RecoveryParams& params, const RecoveryResult& res);

/// Building mode: the four walls around a roof plane the model left out (run_recovery's walls_around_roofs; see recovery.h).
std::vector<RecoveredPlane> walls_around_roof(const PointCloud& cloud, const SceneStructure& structure, int roof,
                                              const RecoveryParams& params);

/// Building mode: `side` (a side of walls_around_roof) takes the plane of the nearest wall of `walls` within
/// `cos_a` of parallel whose plane both its ends lie within `distance` of (RecoveryParams::around_side_same_wall).
void take_the_plane_of_a_wall_there(const std::vector<RecoveredPlane>& walls, double distance, double cos_a,
                                    RecoveredPlane& side);

// --- a room (room_rules.cpp)

/// split_regions: the region's segments in pieces whose supporting points come within `link` of each other.
std::vector<std::vector<SegmentRef>> pieces_of_region(const PointCloud& cloud, const SceneStructure& structure,
                                                      const std::vector<SegmentRef>& region, double link);

/// piece_boxes' pieces: the points `off` linked within `link`, each group split into the parts of it that are
/// objects of their own (linked within `split_link`, one plane's inliers together but where `min_points` of them
/// lie in each of two parts, at least `min_points` points holding a plane's inliers; the rest joins the nearest
/// part). Each sorted, by first point; `*groups_out` (when given) gets each piece's whole group.
std::vector<std::vector<int>> furniture_pieces(const std::vector<Vec3>& points, const std::vector<int>& point_plane,
                                               const std::vector<int>& off, double link, double split_link,
                                               int min_points, bool across_planes,
                                               std::vector<std::vector<int>>* groups_out = nullptr);

/// level_caps: the tops no scanner saw, as level planes.
std::vector<RecoveredPlane> level_caps(const PointCloud& cloud, const SceneStructure& structure,
                                       const RecoveryParams& params);

/// level_sides: the sides no scanner saw under a raised level top, as upright planes down to the floor.
std::vector<RecoveredPlane> level_sides(const PointCloud& cloud, const SceneStructure& structure,
                                        const RecoveryResult& res, const RecoveryParams& params);

/// opening_heads: each opening through a slab, its two jambs (upright, across the slab) and its head (level).
std::vector<RecoveredPlane> slab_openings(const PointCloud& cloud, const SceneStructure& structure,
                                          const RecoveryParams& params);

/// A plane's extent: its points' convex hull in its frame (see recovery.h, one_plane_per_surface), and their
/// mean on it.
struct PlaneExtent {
  Plane plane;
  Vec3 u = Vec3::UnitX(), v = Vec3::UnitY();
  std::vector<Vec2> hull;
  Vec3 centre = Vec3::Zero();
};

/// The extents of the detected planes (their inliers).
std::vector<PlaneExtent> detected_extents(const PointCloud& cloud, const SceneStructure& structure);

/// one_plane_per_surface: the recovered planes whose surface no plane already stands for, in their order;
/// `dropped` counts the others.
std::vector<RecoveredPlane> one_plane_per_surface(const PointCloud& cloud, const std::vector<PlaneExtent>& detected,
                                                  std::vector<RecoveredPlane> recovered, double cos_a, double r,
                                                  std::size_t* dropped);

/// piece_boxes: each piece's box completes the faces no plane of it covers; `corner` marks the recovered planes
/// across a boxed piece's corners; `slabs` gets the slabs of the boxes hanging from raised tops (solid_slabs).
std::vector<RecoveredPlane> piece_boxes(const PointCloud& cloud, const SceneStructure& structure,
                                         const std::vector<bool>& enclosure, const RecoveryParams& params,
                                         const std::vector<RecoveredPlane>& recovered, std::size_t* pieces,
                                         std::vector<char>& corner, std::vector<std::vector<Plane>>& slabs);

}  // namespace hsr::recovery_internal
