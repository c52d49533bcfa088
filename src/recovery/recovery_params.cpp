// RecoveryParams <-> JSON (core/params_json.h): the run report's parameters.recovery and --config.
#include "core/params_json.h"
#include "recovery/recovery.h"

namespace hsr {
namespace {
const auto fields = [](auto& p, auto&& f) {
  f("angle_deg", p.angle_deg);
  f("distance", p.distance);
  f("min_segments", p.min_segments);
  f("vertical", p.vertical);
  f("main_direction", p.main_direction);
  f("snap_deg", p.snap_deg);
  f("min_wall_length", p.min_wall_length);
  f("wall_join_distance", p.wall_join_distance);
  f("around_side_same_wall", p.around_side_same_wall);
  f("partner_max_behind", p.partner_max_behind);
  f("wall_edge_quantile", p.wall_edge_quantile);
  f("wall_beyond_points", p.wall_beyond_points);
  f("roof_min_tilt_deg", p.roof_min_tilt_deg);
  f("split_regions", p.split_regions);
  f("level_caps", p.level_caps);
  f("level_sides", p.level_sides);
  f("piece_boxes", p.piece_boxes);
  f("free_under_tops", p.free_under_tops);
  f("top_thickness", p.top_thickness);
  f("upright_min_inliers", p.upright_min_inliers);
  f("rim_underside", p.rim_underside);
  f("rim_min_points", p.rim_min_points);
  f("solid_slabs", p.solid_slabs);
  f("box_side_gap", p.box_side_gap);
  f("min_piece_depth", p.min_piece_depth);
  f("depth_from_seen_face", p.depth_from_seen_face);
  f("post_min_points", p.post_min_points);
  f("post_link", p.post_link);
  f("post_min_width", p.post_min_width);
  f("board_thickness", p.board_thickness);
  f("board_min_points", p.board_min_points);
  f("boards_over_underside", p.boards_over_underside);
  f("round_sides", p.round_sides);
  f("edge_boards", p.edge_boards);
  f("edge_board_min_points", p.edge_board_min_points);
  f("edge_board_height", p.edge_board_height);
  f("edge_board_min_width", p.edge_board_min_width);
  f("piece_top_height", p.piece_top_height);
  f("free_under_seats", p.free_under_seats);
  f("free_under_lone_tops", p.free_under_lone_tops);
  f("panels_as_posts", p.panels_as_posts);
  f("step_min_free", p.step_min_free);
  f("step_min_width", p.step_min_width);
  f("step_min_points", p.step_min_points);
  f("seat_min_points", p.seat_min_points);
  f("inner_face_depth", p.inner_face_depth);
  f("opening_heads", p.opening_heads);
  f("slab_thickness", p.slab_thickness);
  f("lintel_gap", p.lintel_gap);
  f("jamb_angle_deg", p.jamb_angle_deg);
  f("jamb_at_edge", p.jamb_at_edge);
  f("one_plane_per_surface", p.one_plane_per_surface);
  f("min_piece_points", p.min_piece_points);
  f("piece_link", p.piece_link);
  f("piece_split_link", p.piece_split_link);
  f("piece_split_across_planes", p.piece_split_across_planes);
};
}  // namespace

void to_json(nlohmann::json& j, const RecoveryParams& p) { params_json::write(j, p, fields); }
void from_json(const nlohmann::json& j, RecoveryParams& p) { params_json::read(j, p, "recovery", fields); }

}  // namespace hsr
