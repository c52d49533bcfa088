// Scene modes (DESIGN.md §4): one pipeline, two priors. `object` (CAD parts, free-form objects, rooms) is
// the paper's pipeline as is. `building` (aerial scans of buildings) adds what every building
// reconstructor assumes: up is +z, the building stands on the ground, ground and vegetation are not
// building surface. This stage decides the mode (when asked to: `auto`), finds the ground and gives every
// detected plane its role; building_structure() then hands the later stages the building's planes alone.
// The walls the scan missed are recovered by stage 3 (recovery.h, vertical prior) and the solid under the
// roofs is extracted by stage 6 (extraction.h, building energy).
//
// The `auto` rule, on the detected planes and the points (no normals needed, so it works on files without
// them). A file whose LAS classification marks building points (class 6) is a building scan: `building`.
// Otherwise an aerial building scan sees its surfaces from above, so
//   (a) most points lie on planes facing up: share >= auto_min_roof_share of all points on planes within 45
//       degrees of horizontal; or, when the scene is level (levelness(): at least 20 % of the plane points on
//       planes within 10 degrees of horizontal or vertical, or of the adjacent planes, weighted by the smaller
//       one's inliers, meeting in lines within 10 degrees of horizontal as roofs do: ridges, valleys, eaves over
//       a wall; not a tilted top over a tilted bottom, as an object's seen all round), the same share of the
//       points on planes (foliage planes left out, see below) within 60 degrees: steep gables and hips (45–60
//       degrees, Vaihingen) are roofs, and points on no plane (trees, a ground too rough for a plane) do not
//       count against the roofs; a tilted frame (its z axis not up: nothing level) gets no such allowance;
//   (b) few places hold two surfaces one above the other: on an xy grid of 3 r cells, the share of occupied
//       cells whose points' heights have a gap of more than max(10 r, 10 % of the z extent) is at most
//       auto_max_layered_share, one half: an object scanned all round and a room have a top and a bottom over
//       most of their extent, an aerial scan only at wall lines, under trees and through glass roofs.
// Both must hold for `building`. A roof-only scan (nothing under its roofs, or one flat roof alone) is a
// building too: it needs no height of its own. So is a roof alone (roof_alone()) when (b) holds: planes
// (foliage left out) all parallel and within 60 degrees of horizontal, however many points lie on no plane:
// object mode could enclose nothing with them (a lean-to or one face of a gable among trees, or at half the
// density). Measured (docs/DECISIONS.md #18): the real buildings of
// airborne/ and airborne_more/ with a roof plane (110 of 112), the aerial files of data/ and the aerial synth
// models have (a) >= 0.72 and (b) <= 0.39 (Dales3d_00052: a sawtooth roof whose glazing shows the floor); the
// CAD parts, the bunny, the rooms, fit4cad_PC3 and the terrestrial synth scans have (a) <= 0.59
// (planefinder_officeCorner: three planes 55 degrees from horizontal, nothing level) or, scanned all round,
// (b) >= 0.62; the corpus octahedron (faces 55 degrees from horizontal) is not level: its equator is a tilted
// top over a tilted bottom.
//
// Ground, the height the solid stands on, from the first source that has one (SceneResult::ground_source):
//   1. given: SceneParams::ground_z (the CLI's --ground-z);
//   2. raster: a terrain model (SceneGround::raster, the CLI's --ground DTM.tif) sampled under the building's
//      roof and wall points, the median of the samples;
//   3. classified points: the points the file classes as ground (LAS class 2, SceneGround::points) within a
//      ring around the building's footprint (xy within ground_ring r of a roof or wall inlier, not under one),
//      their median height (at least 3 of them);
//   4. a ground plane: the near-horizontal planes (normal within ground_max_angle_deg of +z) lying at the
//      bottom of the data (mean height within max(6 r, 5 % of the z extent) of the 1st percentile of the
//      points' heights), whose inliers reach around the rest (at least ground_min_sectors of 16 angular sectors
//      about the other planes' centre) while a plane that is not foliage rises clearly above them (its median
//      height at least building_min_height above), and a roof is left once they are ground; then one rising
//      building_min_height r or more above the lowest of them is a low roof standing on the ground, not a
//      second ground (a wing a storey over the terrain, within 6 r of the lowest points); the ground is the
//      remaining ones' inliers' median height. (A flat roof under a tree, or a flat roof with a few small
//      things on it and nothing else, is a roof, not the ground.) A detected ground plane's points are ground
//      whatever the source of the height;
//   5. the lowest building point: the lowest inlier of a roof or wall, or of the points on no plane that stand
//      on the building's footprint (xy within 2 r cells of a roof or wall inlier: walls too sparse to be a
//      plane, ground at their foot), so terrain further out does not pull the building down — when it lies at
//      least 2 r (the inlier distance) below the lowest roof point;
//   6. assumed: nothing in the scan lies under its roofs (a roof-only scan, a flat roof alone) and no ground is
//      known: the walls are assumed_wall_height (one storey) tall under the lowest roof point, and a warning
//      names --ground-z and --ground.
// Roles: ground planes; walls (within wall_max_angle_deg of vertical); roofs (the rest); clutter: planes
// not part of the building: foliage (a loose layer: RMS distance to the plane >= vegetation_rms r and the
// inliers' normals >= vegetation_normal_deg off the plane's on average; measured: roofs of the 12 airborne
// scans have RMS 0.04-0.99 r and normals 0-28 degrees off, never both above 0.6 r and 20 degrees except one
// 46-point plane of Vaihingen_00010), below building_min_height over the ground (cars, hedges, terrain; not
// a low roof adjacent to a roof that is not low, nor one wider than car_max_width that meets such a roof in
// plan: a lean-to, a garage or an annex whose wall the scan missed), or
// in a connected group of planes (structure adjacency) that is far from the main group (the one with the
// most inliers; "far": their xy boxes, grown by 4 r, do not overlap) and small (fewer inliers than
// min_building_share of the main group's; a large one is another building and is kept). The clutter rules
// never take the last roof: a scan of a building holds one, so when every roof would be low or far, the low
// and far ones stay roofs (a shed lower than 4 r over its ground is still the building of its scan).
#pragma once

#include "core/raster.h"
#include "core/types.h"
#include "structure/structure.h"

#include <nlohmann/json.hpp>

#include <limits>
#include <string>
#include <vector>

namespace hsr {

enum class SceneMode { Auto, Object, Building };

/// "auto", "object", "building".
const char* scene_mode_name(SceneMode m);
/// Inverse of scene_mode_name(); throws Error(BadInput) naming the unknown value.
SceneMode parse_scene_mode(const std::string& name);

struct SceneParams {
  SceneMode mode = SceneMode::Auto;  ///< `auto` decides by the rule above
  double auto_min_roof_share = 0.7;     ///< rule (a): share of the points on planes facing up
  double auto_max_layered_share = 0.5;  ///< rule (b): share of occupied 3 r xy cells holding two layers
  /// A given ground height (local coordinates; the CLI's --ground-z is in file coordinates and is shifted).
  /// Wins over every other source of the ground. NaN: none given.
  double ground_z = std::numeric_limits<double>::quiet_NaN();
  /// Ground source 3: the classified ground points within this distance of the building's footprint, in r.
  double ground_ring = 10.0;
  /// Ground source 6: with no ground known and nothing under the roofs, the walls are this tall under the
  /// lowest roof point, in the file's length unit (one storey in metres, the unit of survey data).
  double assumed_wall_height = 3.0;
  /// With ground_z given: it is the ground, and no detected plane is taken for the ground (`hsr city` sets it:
  /// a building's points there hold no ground, and a low roof beside a higher block is a roof, not ground).
  bool given_ground_wins = false;
  double ground_max_angle_deg = 10.0;  ///< a ground plane's normal is within this of +z, degrees
  int ground_min_sectors = 8;          ///< of 16 sectors about the building's centre, reached by the ground
  double building_min_height = 4.0;    ///< roofs rise at least this far above the ground, in r
  /// A low roof narrower than this (across its smallest-area rectangle in plan) may be a car; a wider one that
  /// meets a roof that is not low is a wing of the building. File length unit (metres: cars are at most 2.5 m
  /// wide, a garage is wider).
  double car_max_width = 2.5;
  double wall_max_angle_deg = 10.0;    ///< a plane within this of vertical is a wall (made exactly vertical)
  double vegetation_rms = 0.6;         ///< foliage: RMS distance of the inliers to their plane at least this, in r
  double vegetation_normal_deg = 20.0; ///< ... and their normals this far off the plane's on average, degrees
  double min_building_share = 0.1;     ///< a far group of planes with fewer inliers than this share of the
                                       ///< main group's is clutter; more, another building
  /// Walls whose direction is within this of the building's main directions (the mode of its roof
  /// outlines' directions, modulo 90°) are turned onto them, degrees; 0: no snapping.
  double main_direction_snap_deg = 5.0;
  /// Upright walls facing the same way (or opposite) whose offsets differ by less than this are one wall
  /// (a sparse facade detected in pieces), in r.
  double wall_merge_distance = 2.0;
  /// An indoor scene (object mode, scanned from inside: VisibilityResult::scanned_from_inside, a room seen
  /// from within) holds its furniture as structure the points support, and two defaults that are shares of
  /// the whole scene hide it (issue 25, DECISIONS #61): the smallest plane as a share of all the points
  /// (StructureParams::min_region_fraction: 0.3 % of a hall is 700 points, a desk's side 40) and the
  /// clean-up's price, a mean displacement over the whole surface (a desk is a ten-thousandth of a hall's).
  /// indoor_absolute_floor: detection runs again with the absolute floor only (indoor_min_region_points), the share
  /// set to 0, and segments of 3 boundary points (StructureParams::min_segment_points at most 3, the fewest
  /// whose line fit has a residual: a face of 30 points has edges of 5 or 6 boundary points, and without
  /// segments on them recovery cannot find the face the scanners missed beside it; DECISIONS #65).
  /// indoor_full_detail: the min-cut's faces are kept (Detail::Full: no clean-up, full's λ). The
  /// CLI turns the first off when --min-plane-share is given, the second when --detail, --face-price or
  /// --lambda is.
  /// indoor_recovery: a room's missing planes (RecoveryParams::split_regions, level_caps and level_sides,
  /// DECISIONS #66, #67): regions grown across the room through the floor are split into the pieces where their
  /// segments are, furniture whose top no scanner saw gets a level plane over it, and a raised top's edge with
  /// no side seen under it an upright plane down to the floor.
  /// indoor_piece_boxes (with indoor_recovery; RecoveryParams::piece_boxes, DECISIONS #70): each piece of
  /// furniture (points off the enclosure, linked within the alpha radius, whose planes are its own) gets the
  /// faces of its box, standing on the floor, that no plane of it covers (a crate no plane holds: all five).
  bool indoor_absolute_floor = true;
  /// A room's smallest plane, in points, with indoor_absolute_floor (0: StructureParams::region_k + 1, 13 by
  /// default). Its furniture has faces of 10-30 points (a crate's top of 0.5 m at 60 points/m²: 15); the
  /// fewest a plane can have is one more than a neighbourhood of region growing: a region of region_k points
  /// or fewer is a single point's neighbourhood, which fits any normal it was estimated from. The CLI sets
  /// it to --min-plane-points when that is given.
  int indoor_min_region_points = 0;
  bool indoor_full_detail = true;
  bool indoor_recovery = true;
  bool indoor_piece_boxes = true;
  /// A room's piece of furniture: its planes that lie on a larger plane of it (within r on average, normals
  /// within max_angle, facing the same way) join it: one face cut in two by a shadow (scene.h room_structure,
  /// DECISIONS #71).
  bool indoor_join_faces = true;
  /// A room's recovered planes: one lying within r of a plane already there (parallel within r_a, its centre
  /// within r of that plane's extent) is left out; a surface is one plane (RecoveryParams::
  /// one_plane_per_surface, DECISIONS #73).
  bool indoor_one_plane_per_surface = true;
  /// A room's hulls: a boundary segment's points extend the hull of its partner (the plane whose line with its
  /// own passes nearest) only when that partner reaches to within recovery's r_d of them (HullsParams::
  /// expand_reach; DECISIONS #74): furniture stands in rows, and a line through a row reaches planes metres away.
  bool indoor_near_partners = true;
};

/// Whether the points were scanned from inside a room, judged by their normals (a file's normals point at
/// the scanner): the top of the bounding box and at least three of its four sides are each lined with
/// points (at least 0.5 % of them within 1 % of the largest extent of that side, normal within 60 degrees
/// of its axis) whose normals point into the box at least three times as often as out of it. The bottom is
/// left out (the ground under a building scanned from outside faces up, into the box); an airborne scan's
/// sides are not lined (its ground reaches them), so normals turned inward do not make it a room. False
/// without normals (MST-estimated normals carry no scanner side).
bool normals_face_inward(const PointCloud& cloud);  // (the pictures' view, and the pipeline's room guess)

/// Every field of SceneParams as JSON and back (scene_params.cpp; core/params_json.h): the run report's
/// parameters and `hsr reconstruct --config`; ground_z's NaN (none given) is null. from_json keeps fields
/// the object lacks, and throws Error(BadInput, "config") on a key it does not know or a value of the
/// wrong type.
void to_json(nlohmann::json& j, const SceneParams& p);
void from_json(const nlohmann::json& j, SceneParams& p);

enum class PlaneRole { Object, Roof, Wall, Ground, Clutter };
const char* plane_role_name(PlaneRole r);  ///< "object", "roof", "wall", "ground", "clutter"

enum class GroundSource { None, Plane, Given, LowestPoints, Raster, ClassifiedPoints, Assumed };
/// "none", "plane", "given", "lowest building point", "raster", "classified ground points", "assumed storey"
const char* ground_source_name(GroundSource g);

/// What the scene stage may know of the ground besides the points it reconstructs (see the file comment).
struct SceneGround {
  std::vector<Vec3> points;       ///< points classed as ground (LAS class 2), local coordinates; may be empty
  const Raster* raster = nullptr;  ///< a terrain model, global coordinates; null: none
  Vec3 origin = Vec3::Zero();      ///< the cloud's local-to-global shift (to sample the raster)
  /// Points the file classes as building (LAS class 6) among those reconstructed: > 0 makes `auto` pick
  /// `building`.
  std::size_t building_class_points = 0;
};

/// A classified cloud (PointCloud::attributes.classification) split for building mode: `building` keeps
/// every point but ground (class 2), vegetation (3, 4, 5), noise (7, 18) and water (9), with its normals and
/// attributes; `ground` holds the class-2 points (local coordinates, the same origin). `applied` is false
/// (and `building` empty) when the cloud has no classification, or no point of those classes.
struct ClassSplit {
  bool applied = false;
  PointCloud building;
  std::vector<Vec3> ground;
  std::size_t building_class_points = 0;  ///< class 6 among `building`
  std::size_t left_out = 0;               ///< vegetation, noise and water points dropped
};
ClassSplit split_by_class(const PointCloud& cloud);

/// Invariants: mode is Object or Building (never Auto); roles.size() == structure.planes.size(); in object
/// mode every role is Object and ground_source is None; in building mode ground_z is finite.
struct SceneResult {
  SceneMode mode = SceneMode::Object;
  std::string reason;            ///< one line: why this mode (the rule's figures, or "given")
  std::string ground_note;       ///< building mode: how the ground was found when it needs saying (assumed)
  double roof_share = 0.0;       ///< rule (a)'s figure
  double layered_share = 0.0;    ///< rule (b)'s figure
  // Building mode:
  double ground_z = 0.0;         ///< the ground height (local coordinates); the solid stands on it
  GroundSource ground_source = GroundSource::None;
  std::vector<int> ground_planes;  ///< detected planes that are the ground
  std::vector<PlaneRole> roles;    ///< per detected plane
  /// The building's main direction in the xy plane, radians in [0, pi/2): walls along it or across it.
  double main_direction = 0.0;
  bool is_building() const { return mode == SceneMode::Building; }
  std::size_t count(PlaneRole r) const;
};

/// Runs the stage. `structure` must come from run_structure on `cloud`. Throws Error(BadInput) on
/// parameters out of range, Error(DegenerateInput) in building mode when no plane is left to be a roof (every
/// plane foliage or ground).
SceneResult run_scene(const PointCloud& cloud, const SceneStructure& structure, const SceneParams& params = {},
                      const SceneGround& ground = {});

/// Building mode: the structure of the building alone: roof and wall planes (ground and clutter planes
/// dropped, their points unassigned), walls made exactly vertical and turned onto the main directions when
/// within main_direction_snap_deg, walls that became coplanar merged into one, and each roof's outline
/// completed along the main directions where its segments miss a side (see scene.cpp); adjacency, second
/// order and intersection lines follow (subset_planes). Object mode: `structure` as is.
SceneStructure building_structure(const PointCloud& cloud, const SceneStructure& structure, const SceneResult& scene,
                                  const SceneParams& params);

/// A room (pipeline.cpp indoor_params): its floor, walls and ceiling are whole planes. A plane that lies on
/// an enclosing one (`enclosure`: the planes visibility found highly visible) — its inliers within the
/// spacing r of its plane on average, the normals within max_angle_deg; anywhere in the room, since the
/// strips that shadows cut off lie beyond the enclosing plane's own points — is a piece of it the
/// furniture's shadows cut off (a strip of floor along a wall lined with cabinets): it joins that plane
/// (inliers, boundary and segments; the enclosing plane keeps its normal), largest enclosing plane first.
/// A tilted duplicate of the floor would otherwise cut the partition's cells along the whole room.
/// With `outward` (one outward normal per plane, visibility.h; SceneParams::indoor_join_faces), the same for
/// each piece of furniture (DECISIONS #71): within a piece (the points off the enclosure, linked within the
/// alpha radius), a plane that lies on a larger plane of the piece and faces the same way (outward normals
/// within max_angle_deg: a thin panel's two faces stay two) joins it, largest first: one face of a pillar that
/// a desk's shadow cut in two is one plane again, not two planes a centimetre apart that leave slivers.
/// Adjacency, second order and lines follow (subset_planes).
struct RoomStructure {
  SceneStructure structure;
  std::vector<int> from;   ///< per plane of `structure`, the input plane it was (the pieces joined into it)
  std::size_t joined = 0;  ///< input planes that joined another (0: `structure` is the input as it was)
  std::size_t joined_faces = 0;  ///< of them, planes of a piece of furniture that joined a larger one of it
};
RoomStructure room_structure(const PointCloud& cloud, const SceneStructure& structure,
                             const std::vector<bool>& enclosure, double max_angle_deg,
                             const std::vector<Vec3>& outward = {});

/// Building mode: roofs are seen from above, so every non-vertical plane's outward normal points up
/// (n_z > 0); `outward` is one unit normal per plane of the building structure (visibility.h's
/// outward_normal), turned where the vote said otherwise. Returns how many were turned. Object mode: 0.
std::size_t orient_roofs_up(const SceneStructure& building, const SceneResult& scene, std::vector<Vec3>& outward);

/// Report fields: mode, reason, the rule's figures, and in building mode the ground (height, source,
/// planes) and the number of planes per role.
nlohmann::json to_json(const SceneResult& scene);

/// DESIGN.md §4, issue 25 (DECISIONS #61): whether a scene is a room, from its structure and the highly
/// visible planes (`enclosing`, visibility's level 1) — the pipeline's indoor defaults follow from it.

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
/// and a level one at the bottom (centroids within `tolerance`, the inlier distance, of the highest / lowest
/// point; level within `level_deg`, the scene's wall angle); the floor seen under most of the ceiling (of the
/// 3 r plan cells holding ceiling inliers, at least half hold floor inliers: from inside the floor is seen
/// under the ceiling but where furniture hides it; from outside, the ground is never seen under a roof); and,
/// as a scanner inside sees nothing beyond them, fewer than 1 % of the points (stray returns) more than the
/// inlier distance above the ceiling or below the floor. The content: points between the two, farther than
/// the inlier distance from every enclosing plane (the furniture; none on a box scanned from outside).
RoomEvidence room_evidence(const PointCloud& cloud, const SceneStructure& structure, const std::vector<bool>& enclosing,
                           double tolerance, double level_deg);

/// A room: its enclosure has a ceiling over its floor (room_evidence), and either the input's normals say it
/// was scanned from inside (`scanned_from_inside`, visibility's: the normals point at the scanners), or,
/// without normals in the input (estimated ones carry no scanner side), there is content between floor and
/// ceiling beyond the stray share (1 %): a box scanned from outside has nothing inside it, a room has its
/// furniture. The normals decide when they are there: a table scanned from above also has a top over a floor.
bool is_a_room(const PointCloud& cloud, const SceneStructure& structure, const SceneResult& scene,
               const std::vector<bool>& enclosing, bool scanned_from_inside, double tolerance, double level_deg);

}  // namespace hsr
