// The scene stage (DESIGN.md §4): one pipeline, three kinds of scene. `object` (CAD parts, free-form objects)
// is the paper's pipeline as is. `building` (aerial scans of buildings, scene/building/) adds what every
// building reconstructor assumes: up is +z, the building stands on the ground, ground and vegetation are not
// building surface. A `room` (scene/room/) is an object scene scanned from inside, which keeps its furniture.
// This stage decides the mode (when asked to: `auto`, the rule below), and in building mode finds the ground
// and gives every detected plane its role; building_structure() then hands the later stages the building's
// planes alone. Whether an object scene is a room is known once visibility has run; what each kind changes in
// the other stages' parameters is decided in one place, the scene plan (scene/plan.h).
//
// The `auto` rule, on the detected planes and the points (no normals needed, so it works on files without
// them). A file whose LAS classification marks building points (class 6) is a building scan: `building`.
// Otherwise an aerial building scan sees its surfaces from above, so
//   (a) most points lie on planes facing up: share >= auto_min_roof_share of all points on planes within
//       auto_roof_deg (45 degrees) of horizontal; or, when the scene is level (levelness(): at least
//       auto_min_levelness (20 %) of the plane points on planes within auto_level_deg (10 degrees) of horizontal
//       or vertical, or of the adjacent planes (normals apart by a sine of auto_pair_min_sin or more), weighted
//       by the smaller one's inliers, meeting in lines within auto_level_deg of horizontal as roofs do: ridges,
//       valleys, eaves over a wall; or in a hip (auto_level_hips: two tilted planes of one pitch whose slopes run
//       at right angles in plan); not a tilted top over a tilted bottom, as an object's seen all round), the
//       same share of the points on planes (foliage planes left out) within auto_steep_roof_deg (60 degrees):
//       steep gables and hips (45–60 degrees, Vaihingen) are roofs, and points on no plane (trees, a ground too
//       rough for a plane) do not count against the roofs; a tilted frame (its z axis not up: nothing level)
//       gets no such allowance;
//   (b) few places hold two surfaces one above the other: on an xy grid of auto_layer_cell r (3 r) cells, the
//       share of occupied cells whose points' heights have a gap of more than max(auto_layer_gap r (10 r),
//       auto_layer_gap_share (10 %) of the z extent) is at most auto_max_layered_share, one half: an object
//       scanned all round and a room have a top and a bottom over most of their extent, an aerial scan only at
//       wall lines, under trees and through glass roofs.
// Both must hold for `building`. A roof-only scan (nothing under its roofs, or one flat roof alone) is a
// building too: it needs no height of its own. So is a roof alone (roof_alone()) when (b) holds: planes
// (foliage left out) all parallel and within auto_steep_roof_deg of horizontal, however many points lie on no plane:
// object mode could enclose nothing with them (a lean-to or one face of a gable among trees, or at half the
// density). Measured (docs/DECISIONS.md #18): the real buildings of
// airborne/ and airborne_more/ with a roof plane (110 of 112), the aerial files of data/ and the aerial synth
// models have (a) >= 0.72 and (b) <= 0.39 (Dales3d_00052: a sawtooth roof whose glazing shows the floor); the
// CAD parts, the bunny, the rooms, fit4cad_PC3 and the terrestrial synth scans have (a) <= 0.59
// (planefinder_officeCorner: three planes 55 degrees from horizontal, nothing level) or, scanned all round,
// (b) >= 0.62; the corpus octahedron (faces 55 degrees from horizontal) is not level: its equator is a tilted
// top over a tilted bottom.
//
#pragma once

#include "core/types.h"
#include "scene/building/building.h"
#include "scene/room/room.h"
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

/// The scene stage's parameters: the mode, the `auto` rule's thresholds (the file comment; r is the point
/// spacing), and each kind's own (scene/building/building.h, scene/room/room.h).
struct SceneParams {
  SceneMode mode = SceneMode::Auto;  ///< `auto` decides by the rule above
  double auto_min_roof_share = 0.7;     ///< rule (a): share of the points on planes facing up
  double auto_max_layered_share = 0.5;  ///< rule (b): share of occupied 3 r xy cells holding two layers
  /// Rule (a): planes facing up are within this of horizontal, degrees (45: a roof, not a wall).
  double auto_roof_deg = 45.0;
  /// Rule (a) in a level scene: steep gables and hips count as roofs up to this from horizontal, degrees
  /// (45-60 degrees, Vaihingen).
  double auto_steep_roof_deg = 60.0;
  /// Rule (a)'s "level": planes within this of horizontal or vertical, and plane pairs meeting in lines within
  /// this of horizontal, degrees.
  double auto_level_deg = 10.0;
  /// Rule (a): a scene is level when at least this share of its plane points (or of its adjacent pairs) is.
  double auto_min_levelness = 0.2;
  /// Rule (a): two adjacent planes meet in a line when the sine of the angle between them is at least this
  /// (nearly parallel planes have no line to judge).
  double auto_pair_min_sin = 0.1;
  /// Rule (a)'s "level": a hip (two tilted planes of one pitch whose slopes run at right angles in plan, both
  /// within auto_level_deg; scene.cpp hip_pair) counts as a line of a level roof, as a ridge does, where no
  /// adjacent pair is a tilted top over a tilted bottom (DECISIONS #203). false: ridges, valleys and eaves alone.
  bool auto_level_hips = true;
  /// Rule (b): the plan cells, in r, and the height gap of two layers: more than max(auto_layer_gap r,
  /// auto_layer_gap_share of the z extent).
  double auto_layer_cell = 3.0;
  double auto_layer_gap = 10.0;
  double auto_layer_gap_share = 0.1;
  /// The small-scan rule (scene/plan.h plan_small_scan): a scan of fewer than small_scan_size x
  /// StructureParams::min_region_points points where no plane is found is one small object (a shed, a garage:
  /// a few hundred points at survey density) whose planes each hold at least 1 / small_scan_planes of it
  /// (Vaihingen_00015: 95 points, planes of 41 and 34).
  int small_scan_size = 10;
  int small_scan_planes = 5;
  /// No hard edge for `auto` (issue 42 item 2; scene/plan.h plan_scene_choice): when its figures lie within
  /// auto_choice_margin of the edge of rules (a) and (b) (scene_margin, a share of the points), a scan of at
  /// most auto_choice_max_points points is reconstructed both ways (the kind chosen may make no model). The
  /// building is kept unless the object explains at least auto_choice_min_gain more of its points (a share) on a
  /// scan of more than one layer (auto_choice_one_layer_building), or only one of them is a valid solid. The measured figures (the file comment) put every non-building scan
  /// at least 0.11 from the edge, so 0.1 leaves them alone.
  double auto_choice_margin = 0.1;
  int auto_choice_max_points = 200000;
  double auto_choice_min_gain = 0.02;
  /// A small scan is tried as a building whatever its margin (issue 42 item 2; DECISIONS #136): when detection
  /// found no plane of the smallest size and took the small-scan rule's smaller planes (plan_small_scan: fewer
  /// than small_scan_size x the smallest plane's points, a shed or a garage at survey density) and `auto` says
  /// object, step 0 runs the chain as a building too and choose_scene decides as near the edge. Why: such a
  /// scan's figures rest on two or three planes of 20-40 points, and one plane's role moves rule (a)'s share by
  /// its whole weight, so no margin is worth the name (Vaihingen_00015: 95 points, a 41-point wall and a 34-point
  /// level roof, 0.45 against 0.70, object in every variant, p2m 27.3 % at half density where the building
  /// gives 7.1 %). Only that way: a small scan `auto` calls a building is not tried as an object (the
  /// small-scan rule's premise is a building); every non-building scan measured holds thousands of points.
  /// false: the margin alone decides, as #84.
  bool auto_choice_small_scans = true;
  /// A roof-only scan is never a slab (issue 42 item 2; DECISIONS #203; scene/plan.h choose_scene): where step 0
  /// tried both kinds of a scan with one layer (rule (b) holds: nothing under its roofs), a valid building is
  /// kept whatever the object explains. Why: the points say nothing of what lies under the roof, so the points
  /// explained cannot tell a building from a slab over the same roof, and a slab thick enough to take in a few
  /// points above the roof explains more (Vaihingen_00021 at half density: 96 points, a 2 m slab explaining
  /// 0.99 of them against the building's 0.94, City3D -> hsr 4.8 % against 3.0 %). false: #84's comparison.
  bool auto_choice_one_layer_building = true;
  BuildingParams building;  ///< the building kind's rules (scene/building/building.h)
  RoomParams room;          ///< the room kind's switches and thresholds (scene/room/room.h)
};

/// Every field of SceneParams as JSON and back (scene_params.cpp; core/params_json.h): the run report's
/// parameters and `hsr reconstruct --config`; ground_z's NaN (none given) is null. from_json keeps fields
/// the object lacks, and throws Error(BadInput, "config") on a key it does not know or a value of the
/// wrong type.
void to_json(nlohmann::json& j, const SceneParams& p);
void from_json(const nlohmann::json& j, SceneParams& p);

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
/// parameters out of range, and in building mode when no plane is left to be a roof (every plane foliage,
/// clutter, ground or wall): Error(DegenerateInput) with wall planes left, Error(NoPlanes) without.
SceneResult run_scene(const PointCloud& cloud, const SceneStructure& structure, const SceneParams& params = {},
                      const SceneGround& ground = {});

/// Building mode: the structure of the building alone (scene/building/building.h building_planes). Object
/// mode: `structure` as is.
SceneStructure building_structure(const PointCloud& cloud, const SceneStructure& structure, const SceneResult& scene,
                                  const SceneParams& params);

/// The points the model must explain (issue 42; the run report's counts.points_unexplained): every point but
/// those a named rule of the scene stage left out. Object mode: every point. Building mode: not the inliers of
/// a ground plane (the ground rule) or of a clutter plane (building.h: foliage, low and far planes), nor a point
/// on no plane lower than building_min_height r above the ground (the low rule's height: terrain, cars, hedges
/// too small or rough for a plane). A roof part, a wall, a tree over the roof or a neighbour's wall are to be
/// explained: the model is judged on them. `detected` is the structure run_scene was given (every plane).
struct PointsToExplain {
  std::vector<bool> explain;              ///< per point of the cloud
  std::size_t ground_plane_points = 0;    ///< left out: inliers of ground planes
  std::size_t clutter_plane_points = 0;   ///< left out: inliers of clutter planes (foliage, low, far)
  std::size_t low_points = 0;             ///< left out: on no plane, under the low rule's height
};
PointsToExplain points_to_explain(const PointCloud& cloud, const SceneStructure& detected, const SceneResult& scene,
                                  const SceneParams& params);

/// How far `auto`'s figures are from the edge of rules (a) and (b) (scene.h file comment; issue 42): positive
/// on the building side (roof_share >= auto_min_roof_share and layered_share <= auto_max_layered_share), the
/// smaller of the two distances; negative on the object side, minus the larger of the two shortfalls. Its
/// absolute value is how much a figure must move for the rules' answer to change.
double scene_margin(const SceneResult& scene, const SceneParams& params);

/// Whether a scan of `points` points is small enough to be reconstructed more than once (at most
/// SceneParams::auto_choice_max_points): step 0's other kind, steps 5, 6 and 7, and the memo of the first run's
/// detection they share (pipeline_runs.h). Why: a small scan's second run is cheap, a survey's largest pieces'
/// would double their time.
bool small_enough_to_run_again(std::size_t points, const SceneParams& params);

/// Report fields: mode, reason, the rule's figures, and in building mode the ground (height, source,
/// planes) and the number of planes per role.
nlohmann::json to_json(const SceneResult& scene);

}  // namespace hsr
