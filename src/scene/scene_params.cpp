// SceneParams, BuildingParams, RoomParams <-> JSON (core/params_json.h): the run report's parameters.scene
// (with its `building` and `room` objects) and --config.
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

const auto building_fields = [](auto& p, auto&& f) {
  f("ground_z", p.ground_z);  // NaN (none given) is written as null
  f("given_ground_wins", p.given_ground_wins);
  f("ground_ring", p.ground_ring);
  f("ground_min_points", p.ground_min_points);
  f("assumed_wall_height", p.assumed_wall_height);
  f("ground_max_angle_deg", p.ground_max_angle_deg);
  f("ground_min_sectors", p.ground_min_sectors);
  f("ground_low_quantile", p.ground_low_quantile);
  f("ground_band", p.ground_band);
  f("ground_band_share", p.ground_band_share);
  f("footprint_cell", p.footprint_cell);
  f("under_roof_gap", p.under_roof_gap);
  f("building_min_height", p.building_min_height);
  f("roof_height_quantile", p.roof_height_quantile);
  f("car_max_width", p.car_max_width);
  f("car_max_height", p.car_max_height);
  f("wing_min_rise", p.wing_min_rise);
  f("wing_reach", p.wing_reach);
  f("wall_max_angle_deg", p.wall_max_angle_deg);
  f("vegetation_rms", p.vegetation_rms);
  f("vegetation_normal_deg", p.vegetation_normal_deg);
  f("min_building_share", p.min_building_share);
  f("far_group_margin", p.far_group_margin);
  f("own_frame", p.own_frame);
  f("main_direction_snap_deg", p.main_direction_snap_deg);
  f("main_direction_smoothing_deg", p.main_direction_smoothing_deg);
  f("main_direction_window_deg", p.main_direction_window_deg);
  f("main_direction_from_rectangle", p.main_direction_from_rectangle);
  f("main_direction_raster_tolerance", p.main_direction_raster_tolerance);
  f("main_direction_min_fill", p.main_direction_min_fill);
  f("wall_merge_distance", p.wall_merge_distance);
  f("outline_min_points", p.outline_min_points);
  f("outline_band", p.outline_band);
  f("outline_min_span", p.outline_min_span);
  f("outline_parallel_deg", p.outline_parallel_deg);
  f("outline_covered_distance", p.outline_covered_distance);
  f("small_plane_points", p.small_plane_points);
  f("small_plane_width", p.small_plane_width);
  f("small_plane_walls", p.small_plane_walls);
  f("small_wall_max_overhang", p.small_wall_max_overhang);
  f("small_roof_max_slope_deg", p.small_roof_max_slope_deg);
  f("small_roof_meets_in_plan", p.small_roof_meets_in_plan);
  f("small_roof_eave_drop", p.small_roof_eave_drop);
  f("finer_outline_points", p.finer_outline_points);
  f("finer_outline_min_gain", p.finer_outline_min_gain);
  f("outline_prism", p.outline_prism);
  f("outline_prism_roof_quantile", p.outline_prism_roof_quantile);
  f("outline_prism_beyond_hull", p.outline_prism_beyond_hull);
  f("finer_outline_runs", p.finer_outline_runs);
  f("finer_outline_runs_on_footprint", p.finer_outline_runs_on_footprint);
  f("tighter_planes_distance", p.tighter_planes_distance);
  f("tighter_planes_second_distance", p.tighter_planes_second_distance);
  f("tighter_planes_second_max_points", p.tighter_planes_second_max_points);
  f("one_second_run_on_footprint", p.one_second_run_on_footprint);
  f("left_out_roof_walls", p.left_out_roof_walls);
  f("left_out_roof_min_points", p.left_out_roof_min_points);
  f("left_out_roof_max_under", p.left_out_roof_max_under);
  f("left_out_roof_under_unexplained", p.left_out_roof_under_unexplained);
  f("left_out_roof_walls_carried", p.left_out_roof_walls_carried);
  f("box_face_roof_walls", p.box_face_roof_walls);
  f("unseen_roof_distance", p.unseen_roof_distance);
  f("footprint_wall_points", p.footprint_wall_points);
  f("gable_halves", p.gable_halves);
  f("gable_half_distance", p.gable_half_distance);
  f("gable_half_min_pitch_deg", p.gable_half_min_pitch_deg);
  f("two_surface_planes", p.two_surface_planes);
  f("split_where_left_far", p.split_where_left_far);
  f("split_below_ridge", p.split_below_ridge);
};

const auto room_fields = [](auto& p, auto&& f) {
  f("absolute_floor", p.absolute_floor);
  f("min_region_points", p.min_region_points);
  f("min_segment_points", p.min_segment_points);
  f("two_faced_slabs", p.two_faced_slabs);
  f("opening_heads", p.opening_heads);
  f("full_detail", p.full_detail);
  f("recovery", p.recovery);
  f("piece_boxes", p.piece_boxes);
  f("free_under_tops", p.free_under_tops);
  f("join_faces", p.join_faces);
  f("one_plane_per_surface", p.one_plane_per_surface);
  f("near_partners", p.near_partners);
  f("evidence_cell", p.evidence_cell);
  f("floor_under_ceiling_share", p.floor_under_ceiling_share);
  f("stray_share", p.stray_share);
  f("min_content_share", p.min_content_share);
  f("inward_slab", p.inward_slab);
  f("inward_lined_share", p.inward_lined_share);
  f("inward_side_cos", p.inward_side_cos);
  f("inward_ratio", p.inward_ratio);
  f("inward_min_sides", p.inward_min_sides);
  f("piece_link", p.piece_link);
};

const auto fields = [](auto& p, auto&& f) {
  f("mode", p.mode);
  f("auto_min_roof_share", p.auto_min_roof_share);
  f("auto_max_layered_share", p.auto_max_layered_share);
  f("auto_roof_deg", p.auto_roof_deg);
  f("auto_steep_roof_deg", p.auto_steep_roof_deg);
  f("auto_level_deg", p.auto_level_deg);
  f("auto_min_levelness", p.auto_min_levelness);
  f("auto_pair_min_sin", p.auto_pair_min_sin);
  f("auto_level_hips", p.auto_level_hips);
  f("auto_layer_cell", p.auto_layer_cell);
  f("auto_layer_gap", p.auto_layer_gap);
  f("auto_layer_gap_share", p.auto_layer_gap_share);
  f("small_scan_size", p.small_scan_size);
  f("small_scan_planes", p.small_scan_planes);
  f("auto_choice_margin", p.auto_choice_margin);
  f("auto_choice_max_points", p.auto_choice_max_points);
  f("auto_choice_min_gain", p.auto_choice_min_gain);
  f("auto_choice_small_scans", p.auto_choice_small_scans);
  f("auto_choice_one_layer_building", p.auto_choice_one_layer_building);
  f("building", p.building);
  f("room", p.room);
};

}  // namespace

void to_json(nlohmann::json& j, const BuildingParams& p) { params_json::write(j, p, building_fields); }
void from_json(const nlohmann::json& j, BuildingParams& p) { params_json::read(j, p, "scene.building", building_fields); }
void to_json(nlohmann::json& j, const RoomParams& p) { params_json::write(j, p, room_fields); }
void from_json(const nlohmann::json& j, RoomParams& p) { params_json::read(j, p, "scene.room", room_fields); }
void to_json(nlohmann::json& j, const SceneParams& p) { params_json::write(j, p, fields); }
void from_json(const nlohmann::json& j, SceneParams& p) { params_json::read(j, p, "scene", fields); }

}  // namespace hsr
