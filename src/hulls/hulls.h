// Stage 4: one convex polygon per plane for the partition, with its level and growth speed
// (paper §3.4, §3.5 "speed"; DESIGN.md §1 stage 4).
//
// Expanded hull of a detected plane k: the 2D convex hull, in k's plane, of k's inliers plus the
// supporting points of every non-singular segment whose partner is k (a segment of plane i lying on the
// line i ∩ k is "contained by" i and k, paper §3.3, so k is extended up to it: the paper's compensation for
// missing data, §3.4). Hull of a recovered plane: the convex hull of its supporting points projected on it.
// Levels: 1 highly visible, 2 barely visible, 3 recovered. Speed: within levels 1 and 2 the visibility ratio
// mapped linearly to [0.5, 1] (all ratios of the level equal: 1); recovered planes 1.
// plane_id: detected plane k -> k; recovered plane q -> structure.planes.size() + q.
#pragma once

#include "partition/cell_complex.h"
#include "recovery/recovery.h"
#include "structure/structure.h"
#include "visibility/visibility.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace hsr {

struct HullsParams {
  /// Drop hulls whose area is below this fraction of the largest hull's area (degenerate slivers).
  double min_area_fraction = 0.0;
  bool expand = true;             ///< add partner segments' supporting points to detected planes' hulls
  /// With `expand`, a segment's points extend its partner's hull only when the partner's boundary comes within
  /// this distance of them (their mean), in r (the points' spacing); 0: every partner's (the paper). A room sets
  /// it to recovery's r_d, 5 r (RoomParams::near_partners, DECISIONS #74): a partner is the plane whose
  /// line with the segment's plane passes nearest the segment, and among furniture in rows that line is often a
  /// plane's metres away, so its polygon was stretched across the room and cut slivers off every piece it passed.
  double expand_reach = 0.0;
  bool recovered_planes = true;   ///< emit level-3 polygons for recovered planes (false: --no-recovery)
  double min_speed = 0.5;         ///< lowest speed of a level (its least visible plane); the most visible gets 1
  /// Building mode (DESIGN.md §4): walls stand on the ground, so the polygon of every vertical plane (detected
  /// or recovered; normal exactly horizontal, as scene.h and the vertical recovery make them) reaches down
  /// to `ground_z`: the hull of its points and of their vertical projections onto z = ground_z. And walls
  /// are the building's frame, not planes of lesser rank: every wall is level 1, speed 1, growing with the
  /// roofs (a roof part's growth then stops at its own walls, events C, instead of spreading over the
  /// building until a level-3 wall cuts it later).
  bool walls_to_ground = false;
  double ground_z = 0.0;          ///< local coordinates
};

/// Every field of HullsParams as JSON and back (hulls_params.cpp; core/params_json.h): the run report's
/// parameters and `hsr reconstruct --config`. from_json keeps fields the object lacks, and throws
/// Error(BadInput, "config") on a key it does not know or a value of the wrong type.
void to_json(nlohmann::json& j, const HullsParams& p);
void from_json(const nlohmann::json& j, HullsParams& p);

/// Legacy form (no visibility, no recovery): the inliers' convex hull of each detected plane, level 1,
/// speed 1. plane_id = index in structure.planes.
std::vector<ConvexPolygon> run_hulls(const PointCloud& cloud, const SceneStructure& structure,
                                     const HullsParams& params = {});

/// Full stage 4. `visibility` must come from run_visibility and `recovery` from run_recovery on the same
/// structure (throws hsr::Error(Internal) on a size mismatch). Polygons are ordered by plane_id; planes with a
/// degenerate hull (fewer than 3 hull vertices or zero area) are skipped.
std::vector<ConvexPolygon> run_hulls(const PointCloud& cloud, const SceneStructure& structure,
                                     const VisibilityResult& visibility, const RecoveryResult& recovery,
                                     const HullsParams& params = {});

/// Adjacent plane pairs in ConvexPolygon::plane_id numbering (the hierarchical partition's events C):
/// the structure stage's adjacency graph, plus each recovered plane (id planes.size() + q) with every
/// detected plane whose segment supports it (a level cap: with the planes it caps; a piece's box face: with the piece's planes and
/// its other faces). Each pair once, (smaller,
/// larger), sorted.
std::vector<std::pair<int, int>> polygon_adjacency(const SceneStructure& structure, const RecoveryResult& recovery);

/// Speeds of one level: ratios mapped linearly to [min_speed, 1]; all equal (or one) -> 1. Exposed for tests.
std::vector<double> speeds_from_ratios(const std::vector<double>& ratios, double min_speed = 0.5);

/// --dump outputs, in DIR (created): visibility.ply (inliers coloured by visibility ratio, blue 0 -> red 1),
/// levels.ply (inliers coloured by level: green 1, orange 2; supporting points of recovered planes red),
/// recovered.ply (recovered planes' hull polygons as faces, then their supporting points as loose vertices).
/// ASCII PLY, atomic per file.
void write_hulls_dump(const PointCloud& cloud, const SceneStructure& structure, const VisibilityResult& visibility,
                      const RecoveryResult& recovery, const std::vector<ConvexPolygon>& polygons,
                      const std::string& dir);

/// Adds to planes[k] (one JSON object per detected plane, as in structure.json; created when missing) the
/// fields visibility_ratio, visibility_ratio_sphere, highly_visible, level, speed, outward_normal,
/// singular_segments, segments. Returns the recovered planes as a JSON array (normal, offset,
/// segments [[plane, segment]...], support count, plane_id, hull vertex count).
nlohmann::json add_hulls_fields(nlohmann::json& planes, const SceneStructure& structure,
                                const VisibilityResult& visibility, const RecoveryResult& recovery,
                                const std::vector<ConvexPolygon>& polygons);

}  // namespace hsr
