// The room scene kind (DESIGN.md §4, issue 25): a room scanned from inside (object mode's planes, with an
// enclosure of floor, walls and ceiling seen from within). What makes a scene a room (room_evidence,
// is_a_room, normals_face_inward) and the room's own structure (room_structure: the floor, walls and ceiling
// as whole planes, each piece of furniture's faces whole). What a room changes in the other stages' parameters
// is decided in one place, the scene plan (scene/plan.h), from RoomParams' switches. Every threshold is a field
// of RoomParams with its unit; the rules cite their docs/DECISIONS.md entries.
#pragma once

#include "core/types.h"
#include "recovery/recovery.h"
#include "structure/structure.h"
#include "visibility/visibility.h"

#include <nlohmann/json.hpp>

#include <vector>

namespace hsr {

/// The room kind's switches (what a room gets from the plan) and thresholds. r is the scan's point spacing.
/// A room holds its furniture as structure the points support, and two defaults that are shares of the whole
/// scene hide it (issue 25, DECISIONS #61): the smallest plane as a share of all the points
/// (StructureParams::min_region_fraction: 0.3 % of a hall is 700 points, a desk's side 40) and the clean-up's
/// price, a mean displacement over the whole surface (a desk is a ten-thousandth of a hall's).
struct RoomParams {
  /// Detection runs again with the absolute floor only (min_region_points), the share set to 0, and segments
  /// of min_segment_points boundary points. Off when the user chose the share (--min-plane-share).
  bool absolute_floor = true;
  /// A room's smallest plane, in points, with absolute_floor (0: StructureParams::region_k + 1, 13 by
  /// default). Its furniture has faces of 10-30 points (a crate's top of 0.5 m at 60 points/m²: 15); the
  /// fewest a plane can have is one more than a neighbourhood of region growing: a region of region_k points
  /// or fewer is a single point's neighbourhood, which fits any normal it was estimated from. The user's
  /// --min-plane-points when given.
  int min_region_points = 0;
  /// With absolute_floor: segments of at most this many boundary points (StructureParams::min_segment_points):
  /// 3 is the fewest whose line fit has a residual: a face of 30 points has edges of 5 or 6 boundary points,
  /// and without segments on them recovery cannot find the face the scanners missed beside it (DECISIONS #65).
  int min_segment_points = 3;
  /// With absolute_floor, when the room was told by its normals (normals_face_inward: they point at the
  /// scanners, consistently): region growing takes only inliers whose normal faces the way its seed's does
  /// (StructureParams::signed_normals). The two faces of a partition thinner than max_distance (12 cm against
  /// 2 r = 22 cm at 80 points/m²) then stay two planes, a slab; grown unsigned they were one plane through the
  /// partition's middle, air on both sides, and the partition was lost (issue 41; DECISIONS #93). Estimated
  /// normals (MST-oriented) can flip patches, so a room told otherwise keeps unsigned growing. On by default
  /// since it was measured on the office, the halls, the meeting room and the shared inputs (DECISIONS #95):
  /// every partition back, the halls unchanged. A 4 cm chair back seen from both sides is then two planes too,
  /// which can move a piece's faces either way (DECISIONS #95). Off with --config (scene.room.two_faced_slabs).
  bool two_faced_slabs = true;
  /// The min-cut's faces are kept (Detail::Full: no clean-up, full's λ). Off when the user chose the detail
  /// (--detail, --face-price or --lambda).
  bool full_detail = true;
  /// A room's missing planes (RecoveryParams::split_regions, level_caps and level_sides, DECISIONS #66, #67):
  /// regions grown across the room through the floor are split into the pieces where their segments are,
  /// furniture whose top no scanner saw gets a level plane over it, and a raised top's edge with no side seen
  /// under it an upright plane down to the floor.
  bool recovery = true;
  /// With recovery (RecoveryParams::piece_boxes, DECISIONS #70): each piece of furniture (points off the
  /// enclosure, linked within the alpha radius, whose planes are its own) gets the faces of its box, standing
  /// on the floor, that no plane of it covers (a crate no plane holds: all five).
  bool piece_boxes = true;
  /// With recovery (RecoveryParams::free_under_tops, DECISIONS #100): a raised top with the floor seen under it
  /// (a table on legs, a chair's seat) keeps the free space under it: its sides and its piece's box reach down
  /// to its underside, not to the floor (issue 41 item 2).
  bool free_under_tops = true;
  /// With recovery (RecoveryParams::opening_heads, DECISIONS #97, #98): an opening through a slab (a doorway in a
  /// partition) gets its two jambs (upright planes across the slab) and a level plane under its lintel, so the
  /// doorway is a cell of its own: the free space stays connected through it and no block stands across it
  /// (issue 41 item 5).
  bool opening_heads = true;
  /// A piece of furniture's planes that lie on a larger plane of it (within r on average, normals within
  /// max_angle, facing the same way) join it: one face cut in two by a shadow (room_structure, DECISIONS #71).
  bool join_faces = true;
  /// A recovered plane lying within r of a plane already there (parallel within r_a, its centre within r of
  /// that plane's extent) is left out; a surface is one plane (RecoveryParams::one_plane_per_surface, #73).
  bool one_plane_per_surface = true;
  /// A boundary segment's points extend the hull of its partner only when that partner reaches to within
  /// recovery's r_d of them (HullsParams::expand_reach; DECISIONS #74): furniture stands in rows, and a line
  /// through a row reaches planes metres away.
  bool near_partners = true;

  // What makes a room (room_evidence, normals_face_inward):
  /// Plan cells comparing the floor with the ceiling, in r.
  double evidence_cell = 3.0;
  /// The floor is seen under at least this share of the ceiling's plan cells (from inside the floor is seen
  /// under the ceiling but where furniture hides it; from outside, the ground is never seen under a roof).
  double floor_under_ceiling_share = 0.5;
  /// Fewer than this share of the points lie beyond the ceiling or the floor (stray returns: a scanner inside
  /// sees nothing beyond them).
  double stray_share = 0.01;
  /// Without normals: a room holds more than this share of its points between floor and ceiling on no
  /// enclosing plane (its furniture; a box scanned from outside has none).
  double min_content_share = 0.01;
  /// normals_face_inward: a side of the bounding box is lined when at least inward_lined_share of the points
  /// lie within inward_slab (a share of the box's largest extent) of it with normals whose cosine to its axis
  /// is at least inward_side_cos (0.5: within 60 degrees); it faces in when inward_ratio times as many of
  /// those normals point in as out; a room has its top
  /// and at least inward_min_sides of its four sides facing in.
  double inward_slab = 0.01;
  double inward_lined_share = 0.005;
  double inward_side_cos = 0.5;
  double inward_ratio = 3.0;
  int inward_min_sides = 3;
  /// room_structure: a piece of furniture's points are linked within the alpha radius, or this many r when the
  /// structure has none.
  double piece_link = 3.0;
};

/// Every field as JSON and back (scene_params.cpp; the run report's parameters.scene.room).
void to_json(nlohmann::json& j, const RoomParams& p);
void from_json(const nlohmann::json& j, RoomParams& p);

/// Whether the points were scanned from inside a room, judged by their normals (a file's normals point at
/// the scanner): the top of the bounding box and at least inward_min_sides of its four sides are each lined
/// with points whose normals point into the box (RoomParams::inward_*). The bottom is left out (the ground
/// under a building scanned from outside faces up, into the box); an airborne scan's sides are not lined (its
/// ground reaches them), so normals turned inward do not make it a room. False without normals
/// (MST-estimated normals carry no scanner side).
bool normals_face_inward(const PointCloud& cloud, const RoomParams& params = {});

/// A room's floor and ceiling among its `enclosing` planes: the largest level one (normal within `level_deg` of
/// vertical) whose centroid lies within `tolerance` of the lowest / highest point (structure.bbox); -1 for none.
struct RoomEnds {
  int floor = -1, ceiling = -1;
};
RoomEnds room_ends(const SceneStructure& structure, const std::vector<bool>& enclosing, double tolerance,
                   double level_deg);

/// What makes a scene a room (is_a_room): its enclosure's ceiling over its floor, and content between them.
struct RoomEvidence {
  bool ceiling_over_floor = false;  ///< see room_evidence()
  double content_share = 0.0;       ///< share of the points between floor and ceiling on no enclosing plane
};

/// A room has a ceiling over its floor: among the `enclosing` planes a level one at the top of the points
/// and a level one at the bottom (room_ends: centroids within `tolerance`, the inlier distance, of the highest
/// / lowest point; level within `level_deg`, the scene's wall angle); the floor seen under most of the ceiling
/// (floor_under_ceiling_share of the ceiling's evidence_cell plan cells); and fewer than stray_share of the
/// points more than the inlier distance above the ceiling or below the floor. The content: points between the
/// two, farther than the inlier distance from every enclosing plane (the furniture).
RoomEvidence room_evidence(const PointCloud& cloud, const SceneStructure& structure, const std::vector<bool>& enclosing,
                           double tolerance, double level_deg, const RoomParams& params = {});

/// A room: its enclosure has a ceiling over its floor (room_evidence), and either the input's normals say it
/// was scanned from inside (`scanned_from_inside`, visibility's: the normals point at the scanners), or,
/// without normals in the input (estimated ones carry no scanner side), there is content between floor and
/// ceiling beyond min_content_share: a box scanned from outside has nothing inside it, a room has its
/// furniture. The normals decide when they are there: a table scanned from above also has a top over a floor.
/// `building`: the scene is a building (never a room).
bool is_a_room(const PointCloud& cloud, const SceneStructure& structure, bool building,
               const std::vector<bool>& enclosing, bool scanned_from_inside, double tolerance, double level_deg,
               const RoomParams& params = {});

/// A room's floor, walls and ceiling as whole planes. A plane that lies on an enclosing one (`enclosure`: the
/// planes visibility found highly visible) — its inliers within the spacing r of its plane on average, the
/// normals within max_angle_deg; anywhere in the room, since the strips that shadows cut off lie beyond the
/// enclosing plane's own points — is a piece of it the furniture's shadows cut off (a strip of floor along a
/// wall lined with cabinets): it joins that plane (inliers, boundary and segments; the enclosing plane keeps
/// its normal), largest enclosing plane first. A tilted duplicate of the floor would otherwise cut the
/// partition's cells along the whole room.
/// With `outward` (one outward normal per plane, visibility.h; RoomParams::join_faces), the same for each
/// piece of furniture (DECISIONS #71): within a piece (the points off the enclosure, linked within the alpha
/// radius), a plane that lies on a larger plane of the piece and faces the same way (outward normals within
/// max_angle_deg: a thin panel's two faces stay two) joins it, largest first: one face of a pillar that a
/// desk's shadow cut in two is one plane again, not two planes a centimetre apart that leave slivers.
/// Adjacency, second order and lines follow (subset_planes).
struct RoomStructure {
  SceneStructure structure;
  std::vector<int> from;   ///< per plane of `structure`, the input plane it was (the pieces joined into it)
  std::size_t joined = 0;  ///< input planes that joined another (0: `structure` is the input as it was)
  std::size_t joined_faces = 0;  ///< of them, planes of a piece of furniture that joined a larger one of it
};
RoomStructure room_structure(const PointCloud& cloud, const SceneStructure& structure,
                             const std::vector<bool>& enclosure, double max_angle_deg,
                             const std::vector<Vec3>& outward = {}, const RoomParams& params = {});

/// A room's pieces' boxes (RecoveryParams::piece_boxes, DECISIONS #70): the pieces' points on no detected plane
/// vote on their box's faces as a plane's inliers vote on its facets: each is assigned to its face (plane id
/// planes.size() + q), its normal turned to the side where the piece's inside takes the label of what lies
/// under the room's floor (the floor: room_ends, as the room rule found it, within `tolerance` and `level_deg`;
/// a room's model is its air, so a piece is outside). `point_plane` becomes the structure's with those points
/// assigned, and stays empty when there are none. Returns how many points were assigned.
std::size_t room_piece_votes(const SceneStructure& structure, const VisibilityResult& visibility,
                             const RecoveryResult& recovery, double tolerance, double level_deg,
                             std::vector<int>& point_plane, std::vector<Vec3>& normals);

}  // namespace hsr
