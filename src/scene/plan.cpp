// The scene plan (plan.h): every stage's parameters from what the user set and what the scene is.
#include "scene/plan.h"

#include "core/error.h"
#include "core/params_json.h"

#include <algorithm>
#include <cmath>

namespace hsr {

namespace {

/// A room's smallest plane, in points: the user's --min-plane-points when given, else
/// RoomParams::min_region_points (0: region_k + 1, DECISIONS #69).
int room_min_region_points(const StageParams& given, const UserChoices& user) {
  const int points = user.min_plane_points ? given.structure.min_region_points : given.scene.room.min_region_points;
  return points > 0 ? points : given.structure.region_k + 1;
}

/// Whether a room gets the absolute floor: RoomParams::absolute_floor, unless the user chose the share
/// (--min-plane-share), and only when the share floor is on at all.
bool room_absolute_floor(const StageParams& given, const UserChoices& user) {
  return given.scene.room.absolute_floor && !user.min_plane_share && given.structure.min_region_fraction > 0;
}

/// Whether a room's region growing compares its normals' signs (RoomParams::two_faced_slabs): only when the room
/// was told by its normals pointing at the scanners (`told_by_normals`), which are then oriented consistently.
/// Why: the two faces of a partition thinner than max_distance are seen from opposite sides; grown unsigned they
/// are one plane through its middle and the partition is lost.
bool room_two_faced_slabs(const StageParams& given, bool told_by_normals) {
  return given.scene.room.two_faced_slabs && told_by_normals;
}

/// The detection a room gets (RoomParams::absolute_floor, DECISIONS #61, #65, #69, #93): no share floor, the
/// room's smallest plane, segments of RoomParams::min_segment_points, signed normals when told by them.
StructureParams room_detection(const StageParams& given, const UserChoices& user, bool told_by_normals) {
  StructureParams p = given.structure;
  p.min_region_fraction = 0.0;
  p.min_region_points = room_min_region_points(given, user);
  p.min_segment_points = std::min(p.min_segment_points, given.scene.room.min_segment_points);
  p.signed_normals = p.signed_normals || room_two_faced_slabs(given, told_by_normals);
  return p;
}

/// A building (DESIGN.md §4): its missing walls are vertical through its roof outlines, turned onto the main
/// directions (recovery); they reach the ground (hulls); it is seen from outside, never closed as a room
/// (visibility). (The building energy of the extraction: plan_final_scene.)
void plan_building_stages(const SceneResult& scene, const StageParams& given, StageParams& stages) {
  stages.visibility.close_room = false;
  stages.recovery.vertical = true;
  stages.recovery.main_direction = scene.main_direction;
  stages.recovery.snap_deg = given.scene.building.main_direction_snap_deg;
  stages.hulls.walls_to_ground = true;
  stages.hulls.ground_z = scene.ground_z;  // until plan_building_box puts it on the box's bottom
}

/// A room (issue 25, DECISIONS #61–#74): it holds its furniture as structure the points support, so what
/// RoomParams switches on and the user did not choose otherwise: detection with the absolute floor, the
/// min-cut's faces (full detail), the room closed in visibility, near partners in the hulls, and a room's
/// recovery (split regions, level caps and sides, piece boxes, one plane per surface). Returns what changed;
/// nothing changed means no room plan.
RoomChoice plan_room_stages(const StageParams& given, const UserChoices& user, bool told_by_normals,
                            StageParams& stages) {
  const RoomParams& room = given.scene.room;
  RoomChoice out;
  out.absolute_floor = room_absolute_floor(given, user);
  if (out.absolute_floor) stages.structure = room_detection(given, user, told_by_normals);
  if (room.full_detail && !user.detail) apply_detail(Detail::Full, stages.extraction);
  out.full_detail = stages.extraction.face_price != given.extraction.face_price ||
                    stages.extraction.lambda != given.extraction.lambda;
  stages.visibility.room = true;  // closed (VisibilityParams::close_room) whatever the normals say
  if (room.near_partners) stages.hulls.expand_reach = given.recovery.distance;
  out.recovery = room.recovery && !given.recovery.vertical;
  if (out.recovery) {
    RecoveryParams& r = stages.recovery;
    r.split_regions = r.level_caps = r.level_sides = true;
    r.piece_boxes = room.piece_boxes;
    r.free_under_tops = room.free_under_tops;
    r.opening_heads = room.opening_heads;
    r.one_plane_per_surface = room.one_plane_per_surface;
    r.min_piece_points = room_min_region_points(given, user);
  }
  return out;
}

}  // namespace

namespace {
const auto user_fields = [](auto& u, auto&& f) {
  f("detail", u.detail);
  f("min_plane_share", u.min_plane_share);
  f("min_plane_points", u.min_plane_points);
};
}  // namespace

void to_json(nlohmann::json& j, const UserChoices& u) { params_json::write(j, u, user_fields); }
void from_json(const nlohmann::json& j, UserChoices& u) { params_json::read(j, u, "user_choices", user_fields); }

const char* scene_kind_name(SceneKind k) {
  switch (k) {
    case SceneKind::Building: return "building";
    case SceneKind::Room: return "room";
    case SceneKind::Object: break;
  }
  return "object";
}

std::optional<SceneMode> plan_scene_choice(const SceneParams& given, const SceneResult& scene, std::size_t points,
                                           std::size_t building_class_points, bool small_scan) {
  if (given.mode != SceneMode::Auto || building_class_points > 0) return std::nullopt;
  if (!small_enough_to_run_again(points, given)) return std::nullopt;
  // A small scan's figures rest on two or three planes: no margin is worth the name (auto_choice_small_scans).
  if (small_scan && given.auto_choice_small_scans && !scene.is_building()) return SceneMode::Building;
  if (std::abs(scene_margin(scene, given)) > given.auto_choice_margin) return std::nullopt;
  return scene.is_building() ? SceneMode::Object : SceneMode::Building;
}

std::size_t choose_scene(const SceneCandidate& first, const SceneCandidate& second, const SceneParams& params) {
  if (first.valid != second.valid) return first.valid ? 0 : 1;
  const bool first_building = first.mode == SceneMode::Building;
  const SceneCandidate& building = first_building ? first : second;
  const SceneCandidate& object = first_building ? second : first;
  if (params.auto_choice_one_layer_building && building.one_layer) return first_building ? 0 : 1;  // never a slab
  const bool object_wins = object.explained_share >= building.explained_share + params.auto_choice_min_gain;
  return object_wins == first_building ? 1 : 0;
}

StructureParams plan_detection(const PointCloud& cloud, const StageParams& given, const UserChoices& user,
                               bool* guessed_room) {
  *guessed_room = given.scene.mode != SceneMode::Building && room_absolute_floor(given, user) &&
                  normals_face_inward(cloud, given.scene.room);
  return *guessed_room ? room_detection(given, user, /*told_by_normals=*/true) : given.structure;
}

std::optional<StructureParams> plan_small_scan(std::size_t points, const StructureParams& tried,
                                               const SceneParams& scene) {
  const auto floor = static_cast<std::size_t>(tried.min_region_points);
  const auto size = static_cast<std::size_t>(scene.small_scan_size), planes = static_cast<std::size_t>(scene.small_scan_planes);
  if (planes == 0 || points >= size * floor) return std::nullopt;
  StructureParams small = tried;
  const std::size_t half_floor = (floor + 1) / 2, share = (points + planes - 1) / planes;  // both rounded up
  small.min_region_points = static_cast<int>(std::max(half_floor, share));
  if (small.min_region_points >= tried.min_region_points) return std::nullopt;
  return small;
}

VisibilityParams plan_visibility(const SceneResult& scene, const VisibilityParams& given) {
  VisibilityParams v = given;
  if (scene.is_building()) v.close_room = false;  // a building is seen from outside, never a room
  return v;
}

ScenePlan plan_stages(const PointCloud& cloud, const SceneStructure& structure, const SceneResult& scene,
                      const std::vector<bool>& enclosing, bool scanned_from_inside, const StageParams& given,
                      const UserChoices& user, bool guessed_room) {
  ScenePlan plan;
  plan.stages = given;
  plan.guessed_room = guessed_room;
  plan.stages.partition.exact_volumes = false;  // the extraction uses no volume
  const double tolerance = given.structure.max_distance * structure.spacing;
  if (is_a_room(cloud, structure, scene.is_building(), enclosing, scanned_from_inside, tolerance,
                given.scene.building.wall_max_angle_deg, given.scene.room)) {
    StageParams room = plan.stages;
    const RoomChoice choice = plan_room_stages(given, user, guessed_room, room);
    if (choice.absolute_floor || choice.full_detail || choice.recovery) {
      plan.kind = SceneKind::Room;
      plan.room = choice;
      plan.stages = std::move(room);
    }
  }
  plan.detect_again = guessed_room != plan.room.absolute_floor;
  return plan;
}

void plan_final_scene(const SceneResult& scene, const StageParams& given, ScenePlan& plan) {
  plan.stages.extraction.building = scene.is_building();  // the building energy for buildings alone
  if (!scene.is_building()) return;
  plan.kind = SceneKind::Building;
  plan_building_stages(scene, given, plan.stages);
}

namespace {

BBox building_box(const PointCloud& cloud, const SceneStructure& building, const RecoveryResult& recovery,
                  double ground_z, const Footprint& footprint) {
  BBox box;
  for (const DetectedPlane& p : building.planes)
    for (int i : p.inliers) box.extend(cloud.points[static_cast<std::size_t>(i)]);
  if (!box.valid()) return box;
  const double top = box.max.z();
  for (const RecoveredPlane& wall : recovery.recovered)
    for (const Vec3& q : wall.reach) box.extend(Vec3(q.x(), q.y(), top));
  for (const FootprintPolygon& f : footprint)
    for (const Vec2& q : f.outer) box.extend(Vec3(q.x(), q.y(), ground_z));
  box.min.z() = ground_z;
  box.max.z() = std::max(box.max.z(), ground_z);
  return box;
}

}  // namespace

void plan_building_box(const PointCloud& cloud, const SceneStructure& building, const RecoveryResult& recovery,
                       SceneResult& scene, const Footprint& footprint, ScenePlan& plan) {
  ExactPoint lo, hi;
  partition_box(building_box(cloud, building, recovery, scene.ground_z, footprint), plan.stages.partition.bbox_margin,
                lo, hi);
  scene.ground_z = lo.z.get_d();
  plan.ground_z = plan.stages.hulls.ground_z = scene.ground_z;
  plan.building_box = building_box(cloud, building, recovery, scene.ground_z, footprint);
}

nlohmann::json to_json(const ScenePlan& plan) {
  const StageParams& s = plan.stages;
  nlohmann::json j = {{"kind", scene_kind_name(plan.kind)},
                      {"guessed_room", plan.guessed_room},
                      {"detect_again", plan.detect_again}};
  j["stages"] = {{"structure", s.structure}, {"scene", s.scene},           {"visibility", s.visibility},
                 {"recovery", s.recovery},   {"hulls", s.hulls},           {"partition", s.partition},
                 {"extraction", s.extraction}};
  if (plan.kind == SceneKind::Building) j["ground_z"] = plan.ground_z;
  return j;
}

std::string room_plan_summary(const ScenePlan& plan) {
  const StageParams& s = plan.stages;
  return std::string("[scene] scanned from inside: a room, its furniture kept:") +
         (plan.room.absolute_floor ? " planes of " + std::to_string(s.structure.min_region_points) +
                                         " points or more, whatever their share of the scene (--min-plane-share to choose);"
                                   : "") +
         (plan.room.full_detail ? " the min-cut's faces, detail full (--detail to choose);" : "") +
         (plan.room.recovery ? " missing planes where their segments are, level tops over furniture, upright sides under its tops" +
                                   std::string(s.recovery.piece_boxes ? ", each piece's box where no plane covers a face" : "")
                             : "");
}

nlohmann::json room_plan_json(const ScenePlan& plan) {
  return {{"absolute_floor", plan.room.absolute_floor},   {"full_detail", plan.room.full_detail},
          {"recovery", plan.room.recovery},               {"piece_boxes", plan.stages.recovery.piece_boxes},
          {"guessed_from_normals", plan.guessed_room},    {"min_segment_points", plan.stages.structure.min_segment_points}};
}

}  // namespace hsr
