// run_pipeline: the paper's chain (DESIGN.md §1), each stage with the parameters the scene plan resolved
// (scene/plan.h). The stages' own rules live in their folders; the scene kinds' in src/scene/; the runs decided
// by their result (step 0, #159's walls, steps 5 to 7) and the prisms in the files pipeline_runs.h names.
#include "pipeline/pipeline.h"

#include "core/threads.h"
#include "partition/footprint_prism.h"
#include "partition/partition.h"
#include "pipeline/pipeline_internal.h"
#include "pipeline/pipeline_runs.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <optional>

namespace hsr {

namespace pipeline_detail {

namespace {

/// A volume needs planes in at least two directions; anything less cannot enclose anything but the box.
/// Building mode needs one roof (its walls are recovered, the ground closes it).
void check_planes_can_enclose(const SceneStructure& s, const SceneResult& scene) {
  if (scene.is_building()) {
    for (const DetectedPlane& p : s.planes)
      if (p.plane.normal.z() != 0.0) return;
    throw Error(Status::DegenerateInput, "scene",
                "building mode: no roof plane rises above the ground (z = " + std::to_string(scene.ground_z) +
                    " local): pass --ground-z, or --scene object");
  }
  if (s.planes.empty()) throw Error(Status::NoPlanes, "structure", "no plane found");
  if (!all_parallel(s)) return;
  throw Error(Status::DegenerateInput, "structure",
              std::to_string(s.planes.size()) + " plane(s) found, all parallel (points on one plane?): "
              "no volume can be enclosed");
}

// Stage 1: structure, and again with smaller planes when a small scan holds none (plan_small_scan); the
// memo's detection with new segments when it is the one asked for (DetectionMemo).
SceneStructure structure_stage(const PointCloud& input, const StructureParams& params, Run& run) {
  DetectionMemo* memo = run.memo;
  const bool reuse = memo && memo->detected && same_detection(memo->asked, params);
  StructureParams used = params;
  const SceneStructure detected = timed_stage("structure", run.report, [&] {
    if (reuse) {
      used = with_segment_fields(memo->used, params);
      if (!same_detection(memo->asked, memo->used)) run.report["structure_small_scan"] = used.min_region_points;
      log::verbose("[structure] the first run's planes and boundaries, their segments found again");
      return resegment_structure(input, *memo->detected, used);
    }
    KnnGraphCache* keep = memo && memo->record ? &memo->graph : nullptr;
    try {
      return run_structure(input, params, keep);
    } catch (const Error& e) {
      const auto small = e.status() == Status::NoPlanes ? plan_small_scan(input.size(), params, run.params.scene)
                                                        : std::nullopt;
      if (!small) throw;
      log::warn("[structure] no plane of " + std::to_string(params.min_region_points) + " points in a scan of " +
                std::to_string(input.size()) + ": trying planes of " + std::to_string(small->min_region_points) +
                " (a small scan; --min-plane-points sets it)");
      run.report["structure_small_scan"] = small->min_region_points;
      used = *small;
      return run_structure(input, *small, keep);
    }
  });
  if (memo && memo->record && !memo->detected) {
    memo->detected = detected;
    memo->asked = params;
    memo->used = used;
  }
  run.report["resolved"]["structure"] = detected.params;
  run.report["counts"]["planes"] = detected.planes.size();
  const auto on_no_plane = std::count(detected.point_plane.begin(), detected.point_plane.end(), -1);
  run.report["counts"]["points_on_no_plane"] = on_no_plane;
  log::info("[structure] " + std::to_string(detected.planes.size()) + " planes, spacing r = " +
            std::to_string(detected.spacing) + "; " + std::to_string(on_no_plane) + " points on no plane");
  return detected;
}

// The scene stage (DESIGN.md §4): the mode (object, or building: ground, roofs, walls) and the planes the
// later stages use.
void scene_stage(const PointCloud& input, const SceneStructure& first, const StructureParams& detection,
                 const SceneGround& ground, Run& run, SceneStage& s) {
  const PipelineParams& params = run.params;
  s.scene = timed_stage("scene", run.report, [&] { return run_scene(input, first, params.scene, ground); });
  if (run.seen) *run.seen = s.scene;
  // A building's small planes, among the points the first planes left (BuildingParams::small_plane_points).
  SceneStructure with_small;
  const bool small = s.scene.is_building() && params.scene.building.small_plane_points > 0;
  // The gable halves and two surfaces (BuildingParams::gable_halves, two_surface_planes): where step 7 may run (a
  // scan the memo records), what their count needs is kept with the model (counted on the kept model only), and
  // they are split in step 7's run.
  const GableHalves gables = !run.memo || !run.memo->record ? GableHalves::Off
                             : run.memo->split_gables      ? GableHalves::Split
                                                           : GableHalves::Count;
  s.split_input.reset();
  SplitInput split_input;
  std::size_t planes_split = 0;
  if (small)
    with_small = timed_stage("small_planes", run.report, [&] {
      return building_small_planes(input, first, detection, params.scene.building, s.scene,
                                   run.memo && run.memo->record ? &run.memo->graph : nullptr, gables, &split_input,
                                   &planes_split);
    });
  const SceneStructure& detected = small ? with_small : first;
  if (small) run.report["counts"]["small_planes"] = detected.planes.size() - first.planes.size();
  const bool splits = small && splits_roof_planes(params.scene.building);
  if (splits && gables == GableHalves::Split) run.report["counts"]["gable_half_candidates"] = planes_split;
  s.structure = building_structure(input, detected, s.scene, params.scene);
  if (splits && gables == GableHalves::Count) {  // counted on the kept model only (try_gable_halves, DECISIONS #239)
    split_input.min_region_points =
        s.structure.params.value("min_region_points", static_cast<std::size_t>(params.structure.min_region_points));
    s.split_input = std::move(split_input);
  }
  s.explain = points_to_explain(input, detected, s.scene, params.scene);
  pipeline_detail::report_scene(input, s.scene, s.structure, params.ground_raster, run.report);
  if (params.artifacts) {
    params.artifacts->structure = s.structure;
    params.artifacts->scene = s.scene;
  }
  if (run.dump) {
    write_structure_dump(input, s.structure, params.dump_dir);
    pipeline_detail::write_scene_dump(s.scene, run.dump_path("scene.json"));
  }
  check_planes_can_enclose(s.structure, s.scene);
}

// Stage 2: visibility. Its outward normal per plane decides which side of each plane is outside; every
// inlier's normal (the structure's, turned) is flipped to agree with it, so extraction does not depend on how
// well the input (or the MST propagation of stage 1) oriented the normals. The structure's normals are moved
// into s.normals (no later stage reads them there): one copy fewer of a vector per point.
void visibility_stage(const PointCloud& input, const VisibilityParams& params, Run& run, SceneStage& s) {
  nlohmann::json& report = run.report;
  s.visibility = timed_stage("visibility", report, [&] { return run_visibility(input, s.structure, params); });
  if (s.scene.is_building()) s.visibility.scanned_from_inside = false;  // aerial scans are seen from above
  report["counts"]["roofs_turned_up"] = orient_roofs_up(s.structure, s.scene, s.visibility.outward_normal);
  s.normals = std::move(s.structure.normals);
  s.structure.normals.clear();
  const std::size_t flipped = orient_inlier_normals(s.structure, s.visibility, s.normals);
  if (run.params.artifacts) {
    run.params.artifacts->visibility = s.visibility;
    run.params.artifacts->cloud = input;
    run.params.artifacts->cloud.normals = s.normals;
  }
  const auto highly = std::count(s.visibility.highly.begin(), s.visibility.highly.end(), true);
  report["counts"]["highly_visible_planes"] = highly;
  report["counts"]["closed_rays"] = s.visibility.closed_rays;  // a room's escapes closed (VisibilityParams::close_room)
  report["counts"]["normals_flipped"] = flipped;
  report["visibility"]["scanned_from_inside"] = s.visibility.scanned_from_inside;
  log::info("[visibility] " + std::to_string(highly) + " highly / " +
            std::to_string(s.structure.planes.size() - static_cast<std::size_t>(highly)) +
            " barely visible planes, " + std::to_string(flipped) +
            " inlier normals flipped to their plane's outward side");
}

// Stages 1, scene and 2 with the given detection and visibility.
SceneStage detect(const PointCloud& cloud, const SceneGround& ground, const StructureParams& structure,
                  const VisibilityParams& visibility, Run& run) {
  SceneStage s;
  scene_stage(cloud, structure_stage(cloud, structure, run), structure, ground, run, s);
  visibility_stage(cloud, plan_visibility(s.scene, visibility), run, s);
  return s;
}

/// A room's floor, walls and ceiling as whole planes (room.h room_structure): the pieces of them the
/// furniture's shadows cut off join them, and (RoomParams::join_faces) so do the pieces of a piece of
/// furniture's face. Each plane keeps its visibility (a piece is gone; the plane it joined keeps its label and
/// outward side), and the pieces' inliers' normals turn to that side. Said in the log and the report.
void join_room_pieces(const PointCloud& cloud, const StageParams& stages, Run& run, SceneStage& s) {
  RoomStructure room = room_structure(cloud, s.structure, s.visibility.highly, stages.structure.max_angle_deg,
                                      stages.scene.room.join_faces ? s.visibility.outward_normal : std::vector<Vec3>{},
                                      stages.scene.room);
  run.report["counts"]["room_pieces_joined"] = room.joined - room.joined_faces;
  run.report["counts"]["furniture_faces_joined"] = room.joined_faces;
  if (room.joined == 0) return;
  log::info("[scene] room: " + std::to_string(room.joined - room.joined_faces) +
            " pieces of its floor, walls and ceiling and " + std::to_string(room.joined_faces) +
            " of its furniture's faces (cut off by shadows) joined their plane");
  s.structure = std::move(room.structure);
  s.visibility = subset_visibility(s.visibility, room.from);
  orient_inlier_normals(s.structure, s.visibility, s.normals);
  if (run.params.artifacts) {
    run.params.artifacts->structure = s.structure;
    run.params.artifacts->visibility = s.visibility;
    run.params.artifacts->cloud.normals = s.normals;
  }
}

// Stage 3: recovery of planes the scanner missed (building: walls through roof outlines, where one segment
// and the vertical suffice; a room: its pieces and their boxes).
RecoveryResult recovery_stage(const PointCloud& cloud, const SceneStage& s, const RecoveryParams& params, Run& run,
                              const std::vector<int>& walls_around_roofs = {}) {
  RecoveryResult recovery = timed_stage("recovery", run.report, [&] {
    // the enclosure: its pieces' boxes; walls_around_roofs: walls_for_left_out_roofs's second pass
    return run_recovery(cloud, s.structure, params, s.visibility.highly, walls_around_roofs);
  });
  if (run.params.artifacts) run.params.artifacts->recovery = recovery;
  const bool used = run.params.hulls.recovered_planes;
  run.report["counts"]["singular_segments"] = recovery.num_singular();
  run.report["counts"]["recovered_planes"] = used ? recovery.recovered.size() : 0;
  run.report["counts"]["recovered_planes_covered"] = recovery.covered;  // one_plane_per_surface
  run.report["resolved"]["recovery"] = {{"distance", params.distance * s.structure.spacing},
                                        {"vertical", params.vertical},
                                        {"main_direction", params.main_direction},
                                        {"snap_deg", params.snap_deg}};
  log::info("[recovery] " + std::to_string(recovery.num_singular()) + " singular segments, " +
            std::to_string(recovery.recovered.size()) + " missing planes recovered" +
            (used ? "" : " (not used: --no-recovery)"));
  return recovery;
}

// Stage 4: one convex polygon per plane, with its level and speed (building: walls reach the ground).
std::vector<ConvexPolygon> hulls_stage(const PointCloud& cloud, const SceneStage& s, const RecoveryResult& recovery,
                                       const HullsParams& params, Run& run) {
  std::vector<ConvexPolygon> polygons = timed_stage("hulls", run.report, [&] {
    return run_hulls(cloud, s.structure, s.visibility, recovery, params);
  });
  if (run.params.artifacts) run.params.artifacts->polygons = polygons;
  run.report["counts"]["polygons"] = polygons.size();
  run.report["resolved"]["hulls"] = {{"walls_to_ground", params.walls_to_ground},
                                     {"ground_z", params.ground_z},
                                     {"expand_reach", params.expand_reach * s.structure.spacing}};
  if (run.dump) {
    write_hulls_dump(cloud, s.structure, s.visibility, recovery, polygons, run.params.dump_dir);
    pipeline_detail::add_stage_fields_to_structure_json(run.params.dump_dir, s.structure, s.visibility, recovery, polygons);
  }
  return polygons;
}

// Stage 5, a building with a footprint: the walls that stand for a footprint edge (footprint_prism.h
// walls_standing_for_footprint) are left out, the footprint's own walls take their place.
std::vector<ConvexPolygon> walls_left_to_footprint(const PointCloud& cloud, const SceneStage& s,
                                                   const std::vector<ConvexPolygon>& polygons, const StageParams& stages,
                                                   Run& run) {
  const double r = s.structure.spacing;
  // Every point above the ground's band (a roof part too small or sparse for a plane still holds points).
  const double band = stages.partition.footprint_wall_band * r;
  std::vector<Vec2> above_ground;
  for (const Vec3& p : cloud.points)
    if (p.z() > s.scene.ground_z + band) above_ground.push_back(p.head<2>());
  const int small = stages.scene.building.small_plane_points;
  const std::size_t roof_part = static_cast<std::size_t>(small > 0 ? small : stages.structure.min_region_points);
  const std::vector<bool> left = walls_standing_for_footprint(polygons, run.params.footprint, above_ground,
                                                              stages.partition.footprint_wall_offset * r,
                                                              stages.partition.footprint_wall_angle_deg, band, roof_part);
  std::vector<ConvexPolygon> kept;
  for (std::size_t i = 0; i < polygons.size(); ++i)
    if (!left[i]) kept.push_back(polygons[i]);
  run.report["counts"]["walls_left_to_footprint"] = polygons.size() - kept.size();
  return kept;
}

// Stage 5: the partition of the box (a building's: plan_building_box) by the polygons; with a footprint
// (partition/footprint_prism.h) its walls cut the box too and the cells outside its prism are removed.
CellComplex partition_stage(const PointCloud& cloud, const SceneStage& s, const RecoveryResult& recovery,
                            const std::vector<ConvexPolygon>& polygons, const ScenePlan& plan, Run& run) {
  const Footprint& footprint = run.params.footprint;
  const bool building = s.scene.is_building(), cut = building && !footprint.empty();
  PartitionInput pin;
  pin.polygons = cut ? walls_left_to_footprint(cloud, s, polygons, plan.stages, run) : polygons;
  pin.points_bbox = building ? plan.building_box : bounding_box(cloud.points);
  pin.adjacent_planes = polygon_adjacency(s.structure, recovery);
  if (cut) {  // the footprint's walls, from below the box to above it, with plane ids after all others
    const double reach = 0.1 * pin.points_bbox.diagonal() + 1.0;  // any height beyond the box
    pin.cuts = footprint_wall_polygons(footprint, pin.points_bbox.min.z() - reach, pin.points_bbox.max.z() + reach,
                                       static_cast<int>(s.structure.planes.size() + recovery.recovered.size()));
  }
  if (run.dump) pipeline_detail::write_partition_input_dump(pin, run.params.dump_dir);
  CellComplex complex = timed_stage("partition", run.report, [&] {
    CellComplex cx = run_partition(pin, plan.stages.partition);
    if (!cut) return cx;
    std::size_t removed = 0;
    CellComplex kept = keep_cells_in_prism(cx, footprint, &removed);
    run.report["counts"]["cells_outside_footprint"] = removed;
    if (kept.cells.empty())
      throw Error(Status::DegenerateInput, "partition", "the footprint does not overlap the building's points");
    return kept;
  });
  if (run.params.artifacts) run.params.artifacts->complex = complex;
  run.report["counts"]["cells"] = complex.cells.size();
  run.report["counts"]["partition_facets"] = complex.facets.size();
  log::info("[partition] " + std::string(partitioner_name(plan.stages.partition.method)) + ": " +
            std::to_string(complex.cells.size()) + " cells, " + std::to_string(complex.facets.size()) + " facets");
  if (run.dump) write_partition_dump(complex, run.dump_path("partition.ply"));
  return complex;
}

// Stage 6: extraction of the surface by min-cut (then repair and the label clean-up). A room's pieces'
// boxes vote with the points they hold (room.h room_piece_votes).
PolygonMesh extraction_stage(const PointCloud& cloud, SceneStage& s, const RecoveryResult& recovery,
                             const CellComplex& complex, const ExtractionParams& params, Run& run) {
  nlohmann::json& report = run.report;
  std::vector<int> piece_point_plane;  // the structure's, with a room's pieces' points on their boxes (or empty)
  const std::size_t piece_points = room_piece_votes(
      s.structure, s.visibility, recovery, run.params.structure.max_distance * s.structure.spacing,
      run.params.scene.building.wall_max_angle_deg, piece_point_plane, s.normals);
  report["counts"]["piece_box_points"] = piece_points;
  ExtractionInput ein;
  ein.complex = &complex;
  ein.cloud = &cloud;
  ein.normals = &s.normals;
  ein.point_plane = piece_points ? &piece_point_plane : &s.structure.point_plane;
  ein.spacing = s.structure.spacing;
  if (!recovery.solid_slabs.empty()) ein.solid_slabs = &recovery.solid_slabs;  // a room's tops' slabs (#230)
  std::vector<int> wall_point_plane;  // with a footprint: the structure's, with footprint_wall_points' points
  std::vector<Vec3> wall_normals;
  if (s.scene.is_building() && !run.params.footprint.empty() && run.params.scene.building.footprint_wall_points &&
      !piece_points) {
    std::vector<bool> in_complex;
    for (const SupportPlane& sp : complex.planes)
      for (int id : sp.input_planes)
        if (id >= 0) {
          if (static_cast<std::size_t>(id) >= in_complex.size()) in_complex.resize(static_cast<std::size_t>(id) + 1, false);
          in_complex[static_cast<std::size_t>(id)] = true;
        }
    wall_point_plane = s.structure.point_plane;
    wall_normals = s.normals;
    const std::size_t given = footprint_wall_points(
        cloud.points, run.params.footprint, static_cast<int>(s.structure.planes.size() + recovery.recovered.size()), in_complex,
        run.params.structure.max_distance * s.structure.spacing, s.scene.ground_z, wall_point_plane, wall_normals);
    report["counts"]["footprint_wall_points"] = given;
    if (given) {
      ein.point_plane = &wall_point_plane;
      ein.normals = &wall_normals;
    }
  }
  std::vector<char> vouched;  // a room's pieces' faces: their rules vouch for them (ExtractionParams::vouched_area_weight)
  if (params.vouched_area_weight != 1.0) {
    vouched.assign(s.structure.planes.size() + recovery.recovered.size(), 0);
    for (std::size_t q = 0; q < recovery.recovered.size(); ++q)
      vouched[s.structure.planes.size() + q] = recovery.recovered[q].piece >= 0;
    ein.vouched = &vouched;
  }
  ExtractionResult extraction = timed_stage("extraction", report, [&] { return run_extraction(ein, params); });
  report["resolved"]["extraction"] = {{"building", params.building}};
  report["counts"]["forced_cells"] = extraction.forced_cells;
  if (run.params.artifacts) run.params.artifacts->inside = extraction.inside;
  report["counts"]["inside_cells"] =
      static_cast<std::size_t>(std::count(extraction.inside.begin(), extraction.inside.end(), true));
  report["counts"]["surface_facets"] = extraction.surface_facets;
  report["counts"]["voting_points"] = extraction.voting_points;
  report["counts"]["repaired_cells"] = extraction.repaired_cells;
  report["counts"]["cleanup_cells"] = extraction.cleanup_cells;
  report["counts"]["cleanup_skipped"] = extraction.cleanup_skipped;
  report["counts"]["sub_precision_edges"] = extraction.sub_precision_edges;
  report["counts"]["sub_precision_necks"] = extraction.sub_precision_necks;
  if (run.dump) write_labels_dump(complex, extraction.inside, run.dump_path("labels.ply"));
  return std::move(extraction.mesh);
}

// Stage 7: evaluation — the output is checked before anyone writes it; an invalid one stops the run
// unless --force.
// Then the points the model leaves unexplained (issue 42): a part left out is said, not silent.
void evaluation_stage(const PointCloud& cloud, const SceneStage& s, PipelineResult& out, Run& run) {
  out.eval = timed_stage("eval", run.report, [&] {
    EvalResult eval = run_eval(cloud, out.mesh, run.params.truth, run.params.eval,
                               run.m2p_later ? MeshToPoints::Later : MeshToPoints::Now);
    pipeline_detail::report_unexplained(cloud, s.explain.explain, s.structure.spacing, out.mesh, eval.point_distance,
                                        run.params.eval, run.report);
    if (!run.keep_point_distance) std::vector<double>().swap(eval.point_distance);  // read (8 bytes a point)
    return eval;
  });
  pipeline_detail::report_eval(out, run.report);
}

/// A building reconstructed in its own frame (BuildingParams::own_frame): the chain again on the points turned
/// by `turn` about z, so that its main direction lies along x and the partition's axis-aligned box fits its
/// walls; the model is turned back. Distances and validity do not depend on the turn; the report's geometry,
/// the dumps and the HTML report's stages are the turned run's (scene.own_frame_turn_deg says by how much).
void run_in_own_frame(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params, double turn,
                      PipelineResult& out, std::optional<SceneResult>& seen) {
  const nlohmann::json& seconds = out.report["seconds"];
  const double first_pass = seconds.value("structure", 0.0) + seconds.value("scene", 0.0) + seconds.value("visibility", 0.0);
  PolygonMesh truth;
  PipelineParams in_frame = pipeline_detail::turned_params(params, turn, truth);
  in_frame.scene.building.own_frame = false;  // once
  SceneGround turned_ground = ground;
  turned_ground.points = pipeline_detail::turned_points(ground.points, turn);
  log::info("[scene] building: reconstructing in its own frame, turned " + std::to_string(turn * 180.0 / M_PI) +
            " degrees about z");
  run_chain(pipeline_detail::turned_cloud(cloud, turn), turned_ground, in_frame, out, seen);
  pipeline_detail::turn_mesh(out.mesh, -turn);
  out.report["scene"]["own_frame_turn_deg"] = turn * 180.0 / M_PI;
  out.report["seconds"]["own_frame_first_pass"] = first_pass;
}

}  // namespace

/// Stages 3 to 7 on the scene stage's result `s` with the plan: out's mesh and evaluation, and the report's
/// (run.report, out.report) stage fields. `walls_around_roofs`: run_recovery's (walls_for_left_out_roofs).
void model_stages(const PointCloud& cloud, SceneStage& s, ScenePlan& plan, Run& run, PipelineResult& out,
                  const std::vector<int>& walls_around_roofs) {
  nlohmann::json& report = run.report;
  {  // the recovery, the hulls and the complex are freed before the evaluation (its peak is above theirs)
    const RecoveryResult recovery = recovery_stage(cloud, s, plan.stages.recovery, run, walls_around_roofs);
    if (s.scene.is_building()) {  // the box is known now (it holds the recovered walls' ends)
      plan_building_box(cloud, s.structure, recovery, s.scene, run.params.footprint, plan);
      report["scene"]["ground_z"] = s.scene.ground_z;
      report["scene"]["ground_z_file"] = s.scene.ground_z + cloud.origin.z();
      if (run.params.artifacts) run.params.artifacts->scene = s.scene;
    }
    report["plan"] = to_json(plan);  // every decision the stages below run with
    const std::vector<ConvexPolygon> polygons = hulls_stage(cloud, s, recovery, plan.stages.hulls, run);
    const CellComplex complex = partition_stage(cloud, s, recovery, polygons, plan, run);
    out.mesh = extraction_stage(cloud, s, recovery, complex, plan.stages.extraction, run);
  }
  out.mesh.origin = cloud.origin;
  evaluation_stage(cloud, s, out, run);
}

/// The first run where no run follows it (later_runs_may_follow): the memo's detection and kNN graph freed, the
/// evaluation's distances not kept (Run::keep_point_distance) and its mesh -> points figures measured in the
/// evaluation (Run::m2p_later; the same figures). Why: a room's first run held the memo through its partition and
/// the stages after it, and measured the mesh -> points figures after its evaluation with a kd-tree of its own,
/// for runs a room seldom makes (the office at six rooms: 3.5 MB each for the graph and the detection, its peak the
/// partition's or later).
void no_run_follows(Run& run, DetectionMemo& memo) {
  memo.detected.reset();
  memo.graph = KnnGraphCache{};
  run.keep_point_distance = false;
  run.m2p_later = false;
}

/// The chain on the scene's points (stages 1 to 7 with the plan's steps 1 to 4): out's mesh, eval and the
/// report's stage fields. `seen` gets the scene stage's result as soon as it has one (a run that fails later
/// keeps it: step 0 decides on it).
void run_chain(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params, PipelineResult& out,
               std::optional<SceneResult>& seen, OutlineGate* gate, DetectionMemo* memo,
               const std::function<void(const DetectionMemo&)>& detected) {
  nlohmann::json& report = out.report;
  const bool first_run = memo && memo->record && !memo->building_ran;
  const bool records_memo = memo && memo->record && !memo->detected;  // this run's detection goes into the memo
  Run run{params, report, !params.dump_dir.empty(), &seen, memo, memo && memo->record, memo && memo->record, first_run};
  // Stages 1, scene and 2, then the plan; again with the plan's detection when the first pass's was not the
  // kind's (the first pass's seconds kept apart, `seconds.indoor_first_pass`).
  bool guessed_room = false;
  const StructureParams detection = plan_detection(cloud, params, params.user, &guessed_room);
  SceneStage s = detect(cloud, ground, detection, params.visibility, run);
  if (memo && s.scene.is_building()) memo->building_ran = true;
  if (s.scene.is_building() && params.scene.building.own_frame && !ground.raster) {
    const double turn = pipeline_detail::own_frame_turn(s.scene.main_direction);
    if (turn != 0.0) return run_in_own_frame(cloud, ground, params, turn, out, seen);
  }
  if (detected && memo && s.scene.is_building()) detected(*memo);
  ScenePlan plan = plan_stages(cloud, s.structure, s.scene, s.visibility.highly, s.visibility.scanned_from_inside,
                               params, params.user, guessed_room);
  if (plan.detect_again) {
    const double first_pass = report["seconds"]["structure"].get<double>() + report["seconds"]["scene"].get<double>() +
                              report["seconds"]["visibility"].get<double>();
    s = detect(cloud, ground, plan.stages.structure, plan.stages.visibility, run);
    report["seconds"]["indoor_first_pass"] = first_pass;
  }
  if (plan.kind == SceneKind::Room) {
    log::info(room_plan_summary(plan));
    join_room_pieces(cloud, plan.stages, run, s);
    report["scene"]["indoor"] = room_plan_json(plan);
  }
  plan_final_scene(s.scene, params, plan);
  if (!params.footprint.empty()) plan.stages.recovery.wall_beyond_points = 0.0;  // its walls stand where it says (#219)
  if (s.scene.is_building()) {
    std::size_t segments = 0;
    for (const DetectedPlane& p : s.structure.planes) segments += p.segments.size();
    report["counts"]["outline_segments"] = segments;
    if (gate && segments == gate->first_segments) {
      gate->same = true;
      return;
    }
  }

  if (records_memo && seen && !later_runs_may_follow(cloud, ground, params, *seen, s.scene, report, *memo))
    no_run_follows(run, *memo);
  const SceneResult scene_before_box = s.scene;  // plan_building_box rounds its ground down (walls_for_left_out_roofs)
  // a later run of the building: walls around the roofs the first run's kept model has walls around (#166)
  std::vector<int> carried;
  if (s.scene.is_building() && !run.first_run && memo && !memo->walled_roofs.empty() &&
      params.scene.building.left_out_roof_walls && params.scene.building.left_out_roof_walls_carried)
    carried = carried_roofs(s.structure, memo->walled_roofs);
  model_stages(cloud, s, plan, run, out, carried);
  if (!carried.empty()) report["scene"]["left_out_roofs_carried"] = carried;
  if (s.scene.is_building()) walls_for_left_out_roofs(cloud, scene_before_box, plan, run, s, out);
  out.split_input = std::move(s.split_input);  // step 7's count, made on the kept model only (try_gable_halves)
  pipeline_detail::report_quality(s.scene, s.explain, params.scene, report);
}

}  // namespace pipeline_detail

using namespace pipeline_detail;

namespace {

/// The first run of the chain and step 0 (the other kind too where `auto` was near its rule's edge or the scan is a
/// small one, plan_scene_choice), the run kept in `out`; throws when no run made a model.
void first_run_and_choice(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                          const nlohmann::json& header, PipelineResult& out, DetectionMemo& memo,
                          const std::function<void(const DetectionMemo&)>& detected) {
  std::optional<SceneResult> seen;
  std::optional<Error> failed;
  try {
    run_chain(cloud, ground, params, out, seen, nullptr, &memo, detected);
  } catch (const Error& e) {
    if (!made_no_model(e) || !seen) throw;
    failed = e;
  }
  choose_by_result(cloud, ground, params, header, out, seen, failed, memo);
}

}  // namespace

PipelineResult run_pipeline(const PointCloud& input, const PipelineParams& params) {
  const BudgetScope budget_scope(params.budget);  // --max-seconds / --max-memory for the whole run
  const int threads = resolve_thread_count(params.threads);
  const ThreadLimit thread_limit(threads);
  PipelineResult out;
  nlohmann::json& report = out.report;
  pipeline_detail::report_header(input, params, threads, report);
  const double start = log::now_seconds(), cpu_start = log::cpu_seconds();

  // The scene's points: a classified cloud (LAS/LAZ) loses ground, vegetation and noise (scene.h
  // split_by_class); the ground points give a building its ground. Object mode takes the points as they are.
  ClassSplit split = params.scene.mode == SceneMode::Object ? ClassSplit{} : split_by_class(input);
  if (split.applied && split.building.empty())
    throw Error(Status::DegenerateInput, "scene",
                "every point is classed ground, vegetation, noise or water: no building point to reconstruct");
  pipeline_detail::report_class_split(split, report);
  const PointCloud& cloud = split.applied ? split.building : input;
  SceneGround ground;
  ground.points = std::move(split.ground);
  ground.raster = params.ground_raster;
  ground.origin = cloud.origin;
  ground.building_class_points = split.building_class_points;
  report["counts"]["reconstructed_points"] = cloud.size();

  // The chain, and with `auto` near its rule's edge the other kind's too (step 0: no hard edge, issue 42).
  const nlohmann::json header = report;
  DetectionMemo memo;  // the first run's detection and kNN graph, for steps 0, 5 and 6 (only where they may run)
  memo.record = small_enough_to_run_again(cloud.size(), params.scene);
  TighterPlanesAhead ahead(cloud, ground, params, header);  // step 6's run beside the first (DECISIONS #201)
  if (params.footprint_prism && params.scene.mode != SceneMode::Object) {  // too few points for a run (DECISIONS #165)
    outline_prism_run(cloud, ground, params, header,
                      Error(Status::DegenerateInput, "scene",
                            "the footprint prism was asked for (" + std::to_string(cloud.size()) + " points)"),
                      out);
  } else try {
    try {
      first_run_and_choice(cloud, ground, params, header, out, memo, ahead.hook());
    } catch (const Error& e) {  // no model either way: a small scan's smaller planes (DECISIONS #227)
      std::optional<DetectionMemo> small = small_planes_after_no_model(cloud, params, e, memo);
      if (!small) throw;
      memo = std::move(*small);
      out = PipelineResult{};
      out.report = header;
      first_run_and_choice(cloud, ground, params, header, out, memo, {});
    }
  } catch (const Error& e) {  // no model on a footprint: its prism (#174); no plane at all: the outline prism (#135, #231)
    if (footprint_prism_for_failure(params, e))
      outline_prism_run(cloud, ground, params, header, e, out, true);
    else if (outline_prism_for_failure(params, ground, cloud, e))
      outline_prism_run(cloud, ground, params, header, e, out);
    else
      throw;
  }
  // Steps 5 and 6; with threads to spare, step 6's run on the first run's segments beside step 5's (taken
  // unless step 5 keeps a finer outline: the same model either way).
  std::optional<TighterPlanesRun> early = ahead.take(out.report, memo);
  const nlohmann::json first_scene = out.report.value("scene", nlohmann::json::object());
  const bool step6 = tighter_planes_apply(cloud, params, out.report);
  const auto beside = [&] {
    early = run_tighter_planes(cloud, ground, params, header, first_scene, params.structure.min_segment_points,
                               params.scene.building.tighter_planes_distance, memo);
    early->beside = "step 5";
  };
  // Steps 5 to 7 and the kept run's mesh -> points figures; given a turn, on the core the next building leaves idle
  const auto last = [&] {
    try_finer_outline(cloud, ground, params, header, out, memo, step6 ? std::function<void()>(beside) : nullptr);
    try_tighter_planes(cloud, ground, params, header, out, memo, early);
    try_tighter_planes_second(cloud, ground, params, header, out, memo);
    try_gable_halves(cloud, ground, params, header, out, memo);
    out.split_input.reset();                              // step 7's only
    std::vector<double>().swap(out.eval.point_distance);  // kept for steps 6 and 7 only (Run::keep_point_distance)
    if (out.eval.m2p_later) {  // the kept run's mesh -> points figures only (Run::m2p_later)
      add_mesh_to_points(cloud, out.mesh, params.eval, out.eval);
      pipeline_detail::report_eval(out, report);
    }
  };
  if (params.turn_over) {
    params.turn_over();  // the next building may begin (DECISIONS #235)
    run_on_idle_core(last);
  } else {
    last();
  }
  report["seconds"]["total"] = log::now_seconds() - start;
  report["cpu_seconds"]["total"] = log::cpu_seconds() - cpu_start;
  report["peak_memory_mb"] = log::peak_memory_mb();

  if (!out.eval.validity.valid()) {
    report["forced"] = params.force;
    const std::string what = "output mesh is not valid (" + out.eval.validity.summary() + ")";
    if (!params.force) throw Error(Status::InvalidOutput, "extraction", what + "; --force writes it anyway");
    log::warn(what + "; written anyway because of --force");
  }
  return out;
}

}  // namespace hsr
