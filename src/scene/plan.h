// The scene plan: the one place that turns what the user set and what the scene is (object, building or room)
// into the parameters every stage runs with. run_pipeline (pipeline.cpp) reads the plan and never changes a
// stage's parameters itself; the CLI, the Python module and the drivers only say what the user chose
// (UserChoices), never a scene's default.
//
// The kind is known in steps, so the plan is made in steps:
//   0. around the whole chain, plan_scene_choice(): `auto` near the edge of its rule (or making no model) on a
//      small scan runs the chain the other way too, and choose_scene() keeps one (issue 42 item 2);
//   1. before detection, plan_detection(): a scan whose normals point into its box (room.h
//      normals_face_inward) is detected at once as a room is (RoomParams::absolute_floor), else with the
//      user's detection; a small scan where no plane was found, plan_small_scan(): smaller planes;
//   2. after the scene stage, plan_visibility(): a building is seen from outside (never a closed room);
//   3. after visibility, plan_stages(): the kind (a room is an object scene scanned from inside, room.h
//      is_a_room) and the parameters of every later stage, and whether detection must run again (the first
//      pass's guess was wrong, or a room was found with the share floor);
//   3b. once detection is final, plan_final_scene(): a building's stages, from its final scene;
//   4. a building, once recovery has found its walls' ends, plan_building_box(): the partition's box and the
//      ground the model stands on (the box's bottom).
#pragma once

#include "core/footprint.h"
#include "extraction/extraction.h"
#include "hulls/hulls.h"
#include "partition/partition.h"
#include "recovery/recovery.h"
#include "scene/scene.h"
#include "structure/structure.h"
#include "visibility/visibility.h"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

namespace hsr {

/// Which parameters the user chose (flags given on the command line, keywords given in Python, fields of a
/// --config): a scene kind's defaults never override a choice.
struct UserChoices {
  bool detail = false;            ///< --detail, --lambda or --face-price (Python: detail, lambda_, face_price)
  bool min_plane_share = false;   ///< --min-plane-share (Python: min_region_fraction)
  bool min_plane_points = false;  ///< --min-plane-points (Python: min_region_points)
};

/// Every field as JSON and back (plan.cpp; the run report's parameters.user_choices, read back by --config).
void to_json(nlohmann::json& j, const UserChoices& u);
void from_json(const nlohmann::json& j, UserChoices& u);

/// The parameters of the stages, as the user set them (PipelineParams holds them) or as the plan resolved them.
struct StageParams {
  StructureParams structure;
  SceneParams scene;  ///< object / building / auto (default auto; DESIGN.md §4)
  VisibilityParams visibility;
  RecoveryParams recovery;
  HullsParams hulls;  ///< hulls.recovered_planes = false is the paper's "no recovery" ablation
  PartitionParams partition;
  ExtractionParams extraction;
};

enum class SceneKind { Object, Building, Room };
const char* scene_kind_name(SceneKind k);  ///< "object", "building", "room"

/// What the plan changed for a room (the report's scene.indoor and the log).
struct RoomChoice {
  bool absolute_floor = false;  ///< detection without the share floor (RoomParams::absolute_floor)
  bool full_detail = false;     ///< the min-cut's faces (RoomParams::full_detail)
  bool recovery = false;        ///< a room's recovery: regions split into pieces, level caps, sides, boxes
};

/// The plan. Invariant: `stages` are the parameters the stages run with from the step that made the plan on.
struct ScenePlan {
  SceneKind kind = SceneKind::Object;
  StageParams stages;
  bool guessed_room = false;  ///< step 1 guessed a room from the normals
  bool detect_again = false;  ///< step 3: detection and visibility run again with `stages`
  RoomChoice room;            ///< a room: what it changed
  /// A building (step 4): the partition's box (local coordinates) and the ground height at its bottom.
  BBox building_box;
  double ground_z = 0.0;
};

/// Step 0 (issue 42 item 2; SceneParams::auto_choice_*): the kind to try besides the one `auto` chose, when
/// `auto` decided by its figures (not given, not by the file's LAS class 6: `building_class_points` is
/// SceneGround's), the scan has at most auto_choice_max_points points and the figures lie within
/// auto_choice_margin of the rule's edge (|scene_margin|; the kind chosen may have made no model), or the
/// detection took the small-scan rule's planes (`small_scan`, plan_small_scan) and `auto` said object
/// (auto_choice_small_scans: the building). Nothing otherwise: far from the edge a kind that makes no model is
/// an error, as before.
std::optional<SceneMode> plan_scene_choice(const SceneParams& given, const SceneResult& scene, std::size_t points,
                                           std::size_t building_class_points, bool small_scan = false);

/// A kind tried by step 0, as its run ended.
struct SceneCandidate {
  SceneMode mode = SceneMode::Object;
  bool valid = false;              ///< the run made a valid solid
  double explained_share = 0.0;    ///< quality.points_explained_share of its run (0 without a model)
  bool one_layer = false;          ///< the scan holds one layer: rule (b) holds on its figures (both runs')
};

/// Step 0's choice of two candidates, at least one valid (their index): a valid solid beats none; of two the
/// building, unless the object explains at least auto_choice_min_gain more of its points and the scan holds more
/// than one layer (`one_layer`, with auto_choice_one_layer_building): a roof-only scan is never a slab. A
/// building's solid stands on its ground; the points of a roof-only scan say nothing of what lies under it, so a
/// slab over the same roof may explain as many or, thick enough to take in points above the roof, more.
std::size_t choose_scene(const SceneCandidate& first, const SceneCandidate& second, const SceneParams& params);

/// Step 1: the detection of the first pass (see the file comment). `guessed_room` says whether the normals
/// made it a room's.
StructureParams plan_detection(const PointCloud& cloud, const StageParams& given, const UserChoices& user,
                               bool* guessed_room);

/// Step 1, when detection found no plane: the small-scan rule (SceneParams::small_scan_*): a small scan is
/// detected again with the smallest plane at 1 / small_scan_planes of its points, at least half of
/// min_region_points (below 15 points nothing is fitted). Nothing when the scan is not small or the plane
/// would not be smaller.
std::optional<StructureParams> plan_small_scan(std::size_t points, const StructureParams& tried,
                                               const SceneParams& scene);

/// Step 2: the visibility a scene gets (a building is never closed as a room is).
VisibilityParams plan_visibility(const SceneResult& scene, const VisibilityParams& given);

/// Step 3: the kind and the parameters of every later stage. `structure`, `scene` and the visibility figures
/// (`enclosing`: the highly visible planes, `scanned_from_inside`) are the first pass's; `guessed_room` is
/// step 1's.
ScenePlan plan_stages(const PointCloud& cloud, const SceneStructure& structure, const SceneResult& scene,
                      const std::vector<bool>& enclosing, bool scanned_from_inside, const StageParams& given,
                      const UserChoices& user, bool guessed_room);

/// Step 3b, once detection is final (after the second pass, if any): a building's stages (vertical walls on its
/// main directions, walls to the ground, the building energy, no closed room). Nothing for other scenes.
void plan_final_scene(const SceneResult& scene, const StageParams& given, ScenePlan& plan);

/// Step 4, a building: the partition box holds the building's planes' inliers (not the ground and clutter around
/// them), the ends of the walls recovered from their outlines (RecoveredPlane::reach: the walls stand a little
/// beyond the outermost roof points, so the points' own box would cut the corners where two meet), with a
/// footprint also the footprint's corners (the building fills its footprint: a box cut short by the points'
/// extent closed its corners with closure faces), and reaches down to the ground height. The ground is the
/// box's bottom, which the partition rounds down to its grid (at most diagonal / 1000, partition_box): the
/// ground height becomes that value (plan.ground_z, and the hulls' ground_z), so walls dropped to it end on the
/// box's bottom and the report gives the height the model stands on. `scene.ground_z` becomes it too.
void plan_building_box(const PointCloud& cloud, const SceneStructure& building, const RecoveryResult& recovery,
                       SceneResult& scene, const Footprint& footprint, ScenePlan& plan);

/// The report's `plan`: the kind, the steps taken and every stage's parameters as the plan resolved them.
nlohmann::json to_json(const ScenePlan& plan);

/// The log line and the report's scene.indoor for a room's plan.
std::string room_plan_summary(const ScenePlan& plan);
nlohmann::json room_plan_json(const ScenePlan& plan);

}  // namespace hsr
