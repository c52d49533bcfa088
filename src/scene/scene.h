// Scene modes (DESIGN.md §4): one pipeline, two priors. `object` (CAD parts, free-form objects, rooms) is
// the paper's pipeline as is. `building` (aerial scans of buildings) adds what every building
// reconstructor assumes: up is +z, the building stands on the ground, ground and vegetation are not
// building surface. This stage decides the mode (when asked to: `auto`), finds the ground and gives every
// detected plane its role; building_structure() then hands the later stages the building's planes alone.
// The walls the scan missed are recovered by stage 3 (recovery.h, vertical prior) and the solid under the
// roofs is extracted by stage 6 (extraction.h, building energy).
//
// The `auto` rule, on the detected planes and the points (no normals needed, so it works on files without
// them): an aerial building scan sees its surfaces from above, so
//   (a) most points lie on planes facing up: share >= auto_min_roof_share of the points on planes within
//       45 degrees of horizontal, or within 60 degrees (steep roofs) when the scene is level: at least 20 %
//       of the points on planes within 10 degrees of horizontal or vertical, or of the adjacent planes
//       (weighted by the smaller one's inliers) meeting in lines within 10 degrees of horizontal (ridges);
//   (b) few places hold two surfaces one above the other: on an xy grid of 3 r cells, the share of occupied
//       cells whose points' heights have a gap of more than max(10 r, 10 % of the z extent) is at most
//       auto_max_layered_share (objects scanned all round and rooms have a top and a bottom nearly
//       everywhere; an aerial scan only at wall lines and under trees).
// Both must hold for `building`, and the data must rise (z extent, or the height over a given ground_z, at
// least building_min_height): a flat patch has no building on it. Measured (docs/DECISIONS.md): the 12 airborne scans and the aerial files
// of data/ (city3d_bldg94, cgal_b9, cgal_urban) have (a) >= 0.82 and (b) <= 0.17; the CAD parts, the bunny,
// the rooms and the terrestrial synth scans have (a) <= 0.59 (officeCorner: three planes 55 degrees from
// horizontal, its z axis is not up, nothing in it is level) or (b) >= 0.40.
//
// Ground: the near-horizontal planes (normal within ground_max_angle_deg of +z) lying at the bottom of the
// data (mean height within max(6 r, 5 % of the z extent) of the 1st percentile of the points' heights),
// whose inliers reach around the rest (at least ground_min_sectors of 16 angular sectors about the other
// planes' centre) while the other planes rise clearly above them (some plane's median height at least
// building_min_height above). Their inliers' median height is the ground height. Else the given
// ground_z, else the lowest building point: the lowest inlier of a roof or wall, or of the points on no
// plane that stand on the building's footprint (xy within 2 r cells of a roof or wall inlier: walls too
// sparse to be a plane, ground at their foot), so terrain further out does not pull the building down.
// Roles: ground planes; walls (within wall_max_angle_deg of vertical); roofs (the rest); clutter: planes
// not part of the building: foliage (a loose layer: RMS distance to the plane >= vegetation_rms r and the
// inliers' normals >= vegetation_normal_deg off the plane's on average; measured: roofs of the 12 airborne
// scans have RMS 0.04-0.99 r and normals 0-28 degrees off, never both above 0.6 r and 20 degrees except one
// 46-point plane of Vaihingen_00010), below building_min_height over the ground (cars, hedges, terrain), or
// in a connected group of planes (structure adjacency) that is far from the main group (the one with the
// most inliers; "far": their xy boxes, grown by 4 r, do not overlap) and small (fewer inliers than
// min_building_share of the main group's; a large one is another building and is kept).
#pragma once

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
  double auto_min_roof_share = 0.7;      ///< rule (a): share of all points on planes facing up
  double auto_max_layered_share = 0.25;  ///< rule (b): share of occupied 3 r xy cells holding two layers
  /// A given ground height (local coordinates; the CLI's --ground-z is in file coordinates and is shifted).
  /// Used when no ground plane is found. NaN: none given.
  double ground_z = std::numeric_limits<double>::quiet_NaN();
  /// With ground_z given: it is the ground, and no detected plane is taken for the ground (`hsr city` sets it:
  /// a building's points there hold no ground, and a low roof beside a higher block is a roof, not ground).
  bool given_ground_wins = false;
  double ground_max_angle_deg = 10.0;  ///< a ground plane's normal is within this of +z, degrees
  int ground_min_sectors = 8;          ///< of 16 sectors about the building's centre, reached by the ground
  double building_min_height = 4.0;    ///< roofs rise at least this far above the ground, in r
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
};

/// Every field of SceneParams as JSON and back (scene_params.cpp; core/params_json.h): the run report's
/// parameters and `hsr reconstruct --config`; ground_z's NaN (none given) is null. from_json keeps fields
/// the object lacks, and throws Error(BadInput, "config") on a key it does not know or a value of the
/// wrong type.
void to_json(nlohmann::json& j, const SceneParams& p);
void from_json(const nlohmann::json& j, SceneParams& p);

enum class PlaneRole { Object, Roof, Wall, Ground, Clutter };
const char* plane_role_name(PlaneRole r);  ///< "object", "roof", "wall", "ground", "clutter"

enum class GroundSource { None, Plane, Given, LowestPoints };
const char* ground_source_name(GroundSource g);  ///< "none", "plane", "given", "lowest building point"

/// Invariants: mode is Object or Building (never Auto); roles.size() == structure.planes.size(); in object
/// mode every role is Object and ground_source is None; in building mode ground_z is finite.
struct SceneResult {
  SceneMode mode = SceneMode::Object;
  std::string reason;            ///< one line: why this mode (the rule's figures, or "given")
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
/// parameters out of range.
SceneResult run_scene(const PointCloud& cloud, const SceneStructure& structure, const SceneParams& params = {});

/// Building mode: the structure of the building alone: roof and wall planes (ground and clutter planes
/// dropped, their points unassigned), walls made exactly vertical and turned onto the main directions when
/// within main_direction_snap_deg, walls that became coplanar merged into one, and each roof's outline
/// completed along the main directions where its segments miss a side (see scene.cpp); adjacency, second
/// order and intersection lines follow (subset_planes). Object mode: `structure` as is.
SceneStructure building_structure(const PointCloud& cloud, const SceneStructure& structure, const SceneResult& scene,
                                  const SceneParams& params);

/// Building mode: roofs are seen from above, so every non-vertical plane's outward normal points up
/// (n_z > 0); `outward` is one unit normal per plane of the building structure (visibility.h's
/// outward_normal), turned where the vote said otherwise. Returns how many were turned. Object mode: 0.
std::size_t orient_roofs_up(const SceneStructure& building, const SceneResult& scene, std::vector<Vec3>& outward);

/// Report fields: mode, reason, the rule's figures, and in building mode the ground (height, source,
/// planes) and the number of planes per role.
nlohmann::json to_json(const SceneResult& scene);

}  // namespace hsr
