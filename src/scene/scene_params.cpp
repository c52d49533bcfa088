// SceneParams <-> JSON (core/params_json.h): the run report's parameters.scene and --config.
#include "core/params_json.h"
#include "scene/scene.h"

namespace hsr {

void to_json(nlohmann::json& j, SceneMode m) { j = scene_mode_name(m); }
void from_json(const nlohmann::json& j, SceneMode& m) {
  try {
    m = parse_scene_mode(j.get<std::string>());
  } catch (const Error& e) {
    throw Error(Status::BadInput, "config", e.what());
  }
}

namespace {
const auto fields = [](auto& p, auto&& f) {
  f("mode", p.mode);
  f("auto_min_roof_share", p.auto_min_roof_share);
  f("auto_max_layered_share", p.auto_max_layered_share);
  f("ground_z", p.ground_z);  // NaN (none given) is written as null
  f("ground_ring", p.ground_ring);
  f("assumed_wall_height", p.assumed_wall_height);
  f("given_ground_wins", p.given_ground_wins);
  f("ground_max_angle_deg", p.ground_max_angle_deg);
  f("ground_min_sectors", p.ground_min_sectors);
  f("building_min_height", p.building_min_height);
  f("car_max_width", p.car_max_width);
  f("wall_max_angle_deg", p.wall_max_angle_deg);
  f("vegetation_rms", p.vegetation_rms);
  f("vegetation_normal_deg", p.vegetation_normal_deg);
  f("min_building_share", p.min_building_share);
  f("main_direction_snap_deg", p.main_direction_snap_deg);
  f("wall_merge_distance", p.wall_merge_distance);
  f("indoor_absolute_floor", p.indoor_absolute_floor);
  f("indoor_min_region_points", p.indoor_min_region_points);
  f("indoor_full_detail", p.indoor_full_detail);
  f("indoor_recovery", p.indoor_recovery);
  f("indoor_piece_boxes", p.indoor_piece_boxes);
  f("indoor_join_faces", p.indoor_join_faces);
  f("indoor_one_plane_per_surface", p.indoor_one_plane_per_surface);
  f("indoor_near_partners", p.indoor_near_partners);
};
}  // namespace

void to_json(nlohmann::json& j, const SceneParams& p) { params_json::write(j, p, fields); }
void from_json(const nlohmann::json& j, SceneParams& p) { params_json::read(j, p, "scene", fields); }

}  // namespace hsr
