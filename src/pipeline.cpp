// run_pipeline: the paper's chain (DESIGN.md §1), each stage with the parameters the scene plan resolved
// (scene/plan.h). The stages' own rules live in their folders; the scene kinds' in src/scene/.
#include "pipeline.h"

#include "core/kd_tree.h"
#include "core/spacing.h"
#include "core/threads.h"
#include "partition/footprint_prism.h"
#include "partition/partition.h"
#include "pipeline_internal.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>

#include <tbb/global_control.h>
#include <tbb/task_group.h>

namespace hsr {

namespace {

using pipeline_detail::timed_stage;

/// The memo of steps 0, 5 and 6 (choose_by_result, try_finer_outline, try_tighter_planes): the first run's detection
/// (run_structure's result) with the parameters it was asked for and run with, and its kNN graph. A later run of the
/// same points asking for the same detection but other segments gets it with its segments found again
/// (structure.h resegment_structure): the structure run_structure would give, without finding the planes, normals
/// and boundaries again. A run asking for another detection (step 6's tighter planes) gets the graph (#150).
struct DetectionMemo {
  bool record = false;  ///< the first run stores its detection (a copy: only where steps 0 and 5 may run)
  std::optional<SceneStructure> detected;
  StructureParams asked, used;  ///< used: plan_small_scan's when the scan held no plane of the asked size
  KnnGraphCache graph;          ///< the detection's kNN graph, for every run's small planes (DECISIONS #145)
  /// The inliers (sorted) of each roof the first run's kept model has walls around (walls_for_left_out_roofs);
  /// the later runs give walls to their planes holding them (carried_roofs, DECISIONS #166).
  std::vector<std::vector<int>> walled_roofs;
  /// A building's run has begun (its scene stage said building): the runs after it are not the building's first
  /// (Run::first_run). Why not the first run of all: step 0's building run after an object's first run is the
  /// building's first, and lacked walls_for_left_out_roofs (DECISIONS #203: Vaihingen_00021 at half density).
  bool building_ran = false;
  /// Step 7's run (try_gable_halves): the building's roof planes that hold a gable's two halves are split
  /// (building_small_planes' GableHalves::Split); in the other runs they are only counted.
  bool split_gables = false;
};

/// What every stage step below shares: the run's parameters as given, its report, and whether to dump.
struct Run {
  const PipelineParams& params;
  nlohmann::json& report;
  bool dump;
  std::optional<SceneResult>* seen = nullptr;  ///< the scene stage's result as soon as it has one (step 0)
  DetectionMemo* memo = nullptr;               ///< steps 0, 5 and 6's (DetectionMemo)
  /// The evaluation's distances are kept in the result (EvalResult::point_distance) for step 6's counts
  /// (points_farther); run_pipeline empties them at its end. Only where step 6 may run (DetectionMemo::record).
  bool keep_point_distance = false;
  /// The evaluation leaves its mesh -> points figures for later (MeshToPoints::Later): where steps 0, 5 and 6
  /// may run, only the kept run's are measured, at run_pipeline's end (add_mesh_to_points; the same figures).
  bool m2p_later = false;
  /// The building's first run (the first where the memo is kept, or step 0's building run after an object's:
  /// DetectionMemo::building_ran): only it gives walls to the roofs its model left out (walls_for_left_out_roofs,
  /// DECISIONS #159); the later runs of steps 5 and 6 are measured against its model.
  bool first_run = false;
  std::string dump_path(const char* file) const { return (std::filesystem::path(params.dump_dir) / file).string(); }
};

/// The scene as stages 1–2 left it: the planes later stages use (building mode: ground and clutter left out),
/// their outward sides, and every point's normal turned to its plane's outward side.
struct SceneStage {
  SceneResult scene;
  SceneStructure structure;
  VisibilityResult visibility;
  std::vector<Vec3> normals;
  PointsToExplain explain;  ///< the points the model must explain (scene.h points_to_explain)
};

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
  // The gable halves (BuildingParams::gable_halves): counted where step 7 may run (a scan the memo records),
  // split in step 7's run.
  const GableHalves gables = !run.memo || !run.memo->record ? GableHalves::Off
                             : run.memo->split_gables      ? GableHalves::Split
                                                           : GableHalves::Count;
  std::size_t gable_candidates = 0;
  if (small)
    with_small = timed_stage("small_planes", run.report, [&] {
      return building_small_planes(input, first, detection, params.scene.building, s.scene,
                                   run.memo && run.memo->record ? &run.memo->graph : nullptr, gables,
                                   &gable_candidates);
    });
  const SceneStructure& detected = small ? with_small : first;
  if (small) run.report["counts"]["small_planes"] = detected.planes.size() - first.planes.size();
  if (small && gables != GableHalves::Off && params.scene.building.gable_halves)
    run.report["counts"]["gable_half_candidates"] = gable_candidates;
  s.structure = building_structure(input, detected, s.scene, params.scene);
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

/// Step 5's gate (try_finer_outline): the first run's count of the building planes' outline segments; the
/// second run stops after the scene stage when its count is the same (`same`).
struct OutlineGate {
  std::size_t first_segments = 0;
  bool same = false;
};

/// `detected`, when given, is called with the memo once the chain's building is detected (stages 1, scene and 2;
/// not in the own frame): TighterPlanesAhead begins step 6's run there.
void run_chain(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params, PipelineResult& out,
               std::optional<SceneResult>& seen, OutlineGate* gate = nullptr, DetectionMemo* memo = nullptr,
               const std::function<void(const DetectionMemo&)>& detected = {});

/// Stages 3 to 7 on the scene stage's result `s` with the plan: out's mesh and evaluation, and the report's
/// (run.report, out.report) stage fields. `walls_around_roofs`: run_recovery's (walls_for_left_out_roofs).
void model_stages(const PointCloud& cloud, SceneStage& s, ScenePlan& plan, Run& run, PipelineResult& out,
                  const std::vector<int>& walls_around_roofs = {}) {
  nlohmann::json& report = run.report;
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
  out.mesh.origin = cloud.origin;
  evaluation_stage(cloud, s, out, run);
}

/// The scan's points farther than `distance` from the model, on every point's distance to it.
std::size_t farther_than(const std::vector<double>& d, double distance) {
  return static_cast<std::size_t>(std::count_if(d.begin(), d.end(), [distance](double x) { return x > distance; }));
}

/// The scan's points farther than a distance from two models: the one kept so far and a later run's (the whole
/// scan when that run failed). keep_tighter_planes' far points.
struct FarPoints {
  std::size_t before = 0;  ///< from the model kept so far
  std::size_t after = 0;   ///< from the later run's model; the scan's size when it failed
};

/// Whether a later run's model (`other`, unless it `failed`) replaces the model kept so far (`out`), by the
/// result: keep_tighter_planes on the two evaluations and their far points. One judgement for the runs of
/// walls_for_left_out_roofs and of steps 6 and 7 (which also ask for the same ground, same_ground).
bool later_run_explains_more(const PipelineResult& out, const PipelineResult& other, bool failed, FarPoints far,
                             const BuildingParams& b) {
  return !failed && keep_tighter_planes(out.eval.validity.valid(), out.eval.accuracy.p2m_mean,
                                        out.eval.face_sizes.small_faces, far.before, other.eval.validity.valid(),
                                        other.eval.accuracy.p2m_mean, other.eval.face_sizes.small_faces, far.after, b);
}

/// A later run's report (scene.left_out_roofs, scene.tighter_planes, scene.gable_halves): whether it gave a valid
/// solid, and the figures later_run_explains_more judged, before and (unless it failed) after.
nlohmann::json later_run_json(const PipelineResult& out, const PipelineResult& other, bool failed, FarPoints far) {
  nlohmann::json j = {{"valid", !failed && other.eval.validity.valid()},
                      {"p2m_before", out.eval.accuracy.p2m_mean},
                      {"small_faces_before", out.eval.face_sizes.small_faces},
                      {"far_points_before", far.before}};
  if (!failed) {
    j["p2m"] = other.eval.accuracy.p2m_mean;
    j["small_faces"] = other.eval.face_sizes.small_faces;
    j["far_points"] = far.after;
  }
  return j;
}

/// The scan's points as unseen_roof_area reads them: their kd-tree, and their highest z per cell of a plan grid.
struct SeenFromAbove {
  KdTree kd;                              ///< the scan's points
  double cell = 0.0;                      ///< the plan grid's cell (the unseen distance)
  std::map<std::pair<std::int64_t, std::int64_t>, double> top;  ///< the points' highest z per plan cell
};
SeenFromAbove seen_from_above(const PointCloud& cloud, double distance) {
  SeenFromAbove out{KdTree(cloud.points), distance, {}};
  for (const Vec3& p : cloud.points) {
    auto [it, fresh] = out.top.try_emplace({static_cast<std::int64_t>(std::floor(p.x() / distance)),
                                            static_cast<std::int64_t>(std::floor(p.y() / distance))}, p.z());
    if (!fresh) it->second = std::max(it->second, p.z());
  }
  return out;
}

/// The surface of `mesh` that a scan from above would see but no point of `cloud` does, each piece's area
/// times its distance to the nearest point (in the points' units cubed: with the scan's density, 1 / r², the
/// sum of the distances of the points such a surface would have had). The surface: farther than
/// `distance` from every point (BuildingParams::unseen_roof_distance; `mesh` in the cloud's coordinates), on a
/// face facing up (more than `wall_max_angle_deg` from upright) or higher by more than `distance` than every
/// point within about `distance` of it in plan (the points' highest in its cell of a `distance` grid and the 8
/// around it; `seen`: seen_from_above with `distance`). Walls under the roof's points are not counted: a scan
/// from above sees them poorly; a face standing over the points (a gable's end filled up to the ridge) is. Each
/// face's triangles (triangulate_polygon) are cut into a grid of equal triangles of sides at most `step` (r: a
/// point's share of the surface), each counted at its centroid: the same figure whatever the thread count.
/// 0 for an empty cloud.
double unseen_roof_area(const SeenFromAbove& seen, const PolygonMesh& mesh, double distance, double step,
                        double wall_max_angle_deg) {
  if (seen.kd.size() == 0 || !(step > 0) || !(distance > 0)) return 0.0;
  const auto highest_near = [&](const Vec3& q) {  // the points' highest in q's cell and the 8 around it
    const std::int64_t cx = static_cast<std::int64_t>(std::floor(q.x() / seen.cell));
    const std::int64_t cy = static_cast<std::int64_t>(std::floor(q.y() / seen.cell));
    double z = -std::numeric_limits<double>::infinity();
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        if (auto it = seen.top.find({cx + dx, cy + dy}); it != seen.top.end()) z = std::max(z, it->second);
    return z;
  };
  const double min_up = std::sin(wall_max_angle_deg * M_PI / 180.0), d2max = distance * distance;
  constexpr int kMaxCuts = 256;  // a side cut in at most this many: the grid's count stays bounded on a large face
  double area = 0.0;
  std::vector<Vec3> loop;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  for (const std::vector<std::uint32_t>& face : mesh.faces) {
    loop.clear();
    for (std::uint32_t v : face) loop.push_back(mesh.vertices[v]);
    Vec3 n = Vec3::Zero();  // Newell's normal
    for (std::size_t i = 0; i < loop.size(); ++i) n += loop[i].cross(loop[(i + 1) % loop.size()]);
    if (!(n.norm() > 0)) continue;
    const bool facing_up = n.z() > min_up * n.norm();
    triangles.clear();
    triangulate_polygon(loop, triangles);
    for (const auto& t : triangles) {
      const Vec3 &a = loop[t[0]], &b = loop[t[1]], &c = loop[t[2]];
      const double side = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
      const int m = std::clamp(static_cast<int>(std::ceil(side / step)), 1, kMaxCuts);
      const double piece = 0.5 * (b - a).cross(c - a).norm() / (static_cast<double>(m) * m);
      const Vec3 u = (b - a) / m, w = (c - a) / m;
      for (int i = 0; i < m; ++i)
        for (int j = 0; i + j < m; ++j)
          for (int k = 0; k < (i + j + 1 < m ? 2 : 1); ++k) {  // the grid's triangle pointing up, then down
            const double f = k == 0 ? 1.0 / 3.0 : 2.0 / 3.0;
            const Vec3 q = a + (i + f) * u + (j + f) * w;
            if (!facing_up && !(q.z() > highest_near(q) + distance)) continue;  // a wall under the points
            double d2 = 0.0;
            seen.kd.nearest(q, &d2);
            if (d2 > d2max) area += piece * std::sqrt(d2);
          }
    }
  }
  return area;
}

/// Two models of one building judged both ways for the keep rules of the runs decided by the result: each one's
/// sum of its points' distances to it (p2m mean times the diagonal times the points) and the sum of distances of
/// the points its unseen surface would have had (unseen_roof_area / r²), and whether the second may be kept
/// (no_more_unseen_roof). `first` and `second` evaluated on `cloud`, in its coordinates; `r` the scan's spacing.
struct UnseenRoof {
  double first = 0.0, second = 0.0;            ///< the unseen surface's distance sums
  double first_p2m = 0.0, second_p2m = 0.0;    ///< the points' distance sums
  bool may_keep = true;
};
UnseenRoof compare_unseen_roof(const PointCloud& cloud, const PipelineResult& first, const PipelineResult& second,
                               double r, const BuildingParams& b) {
  UnseenRoof out;
  if (!(b.unseen_roof_distance > 0) || !(r > 0)) return out;
  const double distance = b.unseen_roof_distance * r, n = static_cast<double>(cloud.size());
  const SeenFromAbove seen = seen_from_above(cloud, distance);
  out.first = unseen_roof_area(seen, first.mesh, distance, r, b.wall_max_angle_deg) / (r * r);
  out.second = unseen_roof_area(seen, second.mesh, distance, r, b.wall_max_angle_deg) / (r * r);
  out.first_p2m = first.eval.accuracy.p2m_mean * first.eval.diagonal * n;
  out.second_p2m = second.eval.accuracy.p2m_mean * second.eval.diagonal * n;
  out.may_keep = no_more_unseen_roof(out.first_p2m, out.first, out.second_p2m, out.second, b);
  return out;
}

/// The report's figures of compare_unseen_roof, in `j` (scene.left_out_roofs, scene.finer_outline.tried[],
/// scene.tighter_planes).
void report_unseen_roof(const UnseenRoof& u, nlohmann::json& j) {
  j["unseen_before"] = u.first;
  j["unseen"] = u.second;
  j["p2m_sum_before"] = u.first_p2m;
  j["p2m_sum"] = u.second_p2m;
}

/// Whether a face of `mesh` lies on a side of the partition's box of `plan` (x or y at one of the box's bounds,
/// every vertex): nothing but the box stopped the model there (BuildingParams::box_face_roof_walls).
bool model_reaches_the_box(const PolygonMesh& mesh, const ScenePlan& plan) {
  ExactPoint lo, hi;
  partition_box(plan.building_box, plan.stages.partition.bbox_margin, lo, hi);
  const double bounds[2][2] = {{lo.x.get_d(), hi.x.get_d()}, {lo.y.get_d(), hi.y.get_d()}};
  const double tol = 1e-9 * (1.0 + plan.building_box.diagonal());
  for (const auto& face : mesh.faces)
    for (int axis = 0; axis < 2; ++axis)
      for (double at : bounds[axis])
        if (!face.empty() && std::all_of(face.begin(), face.end(), [&](std::uint32_t v) {
              return std::abs(mesh.vertices[v][axis] - at) <= tol;
            }))
          return true;
  return false;
}

/// Every roof plane of the building (role Roof), for the second pass of a model that reaches the box.
std::vector<int> building_roofs(const SceneResult& scene) {
  std::vector<int> roofs;
  for (std::size_t k = 0; k < scene.roles.size(); ++k)
    if (scene.roles[k] == PlaneRole::Roof) roofs.push_back(static_cast<int>(k));
  return roofs;
}

/// Walls around the roofs the model left out (BuildingParams::left_out_roof_walls, DECISIONS #159): when the
/// model of stages 3 to 7 (`out`) leaves out a roof plane of real size (left_out_roofs: half of its inliers or
/// more farther than the detection's inlier distance from it), stages 3 to 7 run again with four walls around
/// each such roof (run_recovery's walls_around_roofs) on the same planes, and that model replaces `out` when
/// keep_tighter_planes says so (valid; p2m lower by finer_outline_min_gain of it; no more slivers unless it
/// leaves fewer points beyond the inlier distance). Why: a roof part standing on another roof, whose outline
/// no segment follows, has no wall under it and the min-cut leaves it out (AHN3_11936); walls for every roof's
/// rectangle on every building would cut every partition (issue 43: time), so only where a roof is left out,
/// and the result decides. Only in the building's first run (Run::first_run): the runs of steps 5 and 6 are then
/// kept only when they beat its model (in every run, the AHN3 tile's pipelines took 31 % more time than without
/// the rule; in the first run alone 12 %, DECISIONS #159), and where the evaluation kept its distances
/// (Run::keep_point_distance: a scan where steps 5 and 6 may run); not for a room or an object. The second pass
/// writes no dumps (they are the first's). When no roof is left out but the model reaches the partition's box
/// (model_reaches_the_box), the second pass has walls around every roof (BuildingParams::box_face_roof_walls,
/// DECISIONS #183), kept by the same rule.
/// Report: scene.left_out_roofs (the roofs, why, their inliers, p2m and far points before and after, kept).
void walls_for_left_out_roofs(const PointCloud& cloud, const SceneResult& scene_before_box, const ScenePlan& plan,
                              Run& run, SceneStage& s, PipelineResult& out) {
  const BuildingParams& b = run.params.scene.building;
  if (!b.left_out_roof_walls || !run.first_run || out.eval.point_distance.size() != cloud.size()) return;
  const double inlier_distance =
      s.structure.params.value("max_distance", run.params.structure.max_distance * s.structure.spacing);
  std::vector<int> left = left_out_roofs(cloud, s.structure, out.eval.point_distance, inlier_distance,
                                         static_cast<std::size_t>(b.left_out_roof_min_points), b.left_out_roof_max_under);
  // no roof left out, but the model runs to the box: walls around every roof (box_face_roof_walls, #183)
  const bool to_box = left.empty() && b.box_face_roof_walls && model_reaches_the_box(out.mesh, plan);
  if (to_box) left = building_roofs(s.scene);
  if (left.empty()) return;
  const double t0 = log::now_seconds();
  ScenePlan again = plan;
  PipelineParams params = run.params;
  PipelineArtifacts artifacts;
  params.artifacts = run.params.artifacts ? &artifacts : nullptr;
  params.dump_dir.clear();
  PipelineResult other;
  other.report = out.report;
  Run second{params, other.report, false, nullptr, run.memo, run.keep_point_distance, run.m2p_later, false};
  const SceneResult first_scene = s.scene;
  s.scene = scene_before_box;  // the same planes; the box is planned again from the scene before it
  bool failed = false;
  try {
    model_stages(cloud, s, again, second, other, left);
  } catch (const Error& e) {
    if (e.status() == Status::BudgetExceeded) throw;  // the run's budget holds for every pass
    failed = true;  // the first model stands
  }
  const FarPoints far = {farther_than(out.eval.point_distance, inlier_distance),
                         failed ? cloud.size() : farther_than(other.eval.point_distance, inlier_distance)};
  const bool by_p2m = later_run_explains_more(out, other, failed, far, b);
  // both ways: no more roof that no point sees (no_more_unseen_roof; only where p2m would keep it, and of two
  // valid solids)
  const UnseenRoof unseen = by_p2m && out.eval.validity.valid()
                                ? compare_unseen_roof(cloud, out, other, s.structure.spacing, b)
                                : UnseenRoof{};
  const bool keep = by_p2m && unseen.may_keep;
  nlohmann::json roofs = nlohmann::json::array();
  for (int k : left) roofs.push_back({{"plane", k}, {"inliers", s.structure.planes[static_cast<std::size_t>(k)].inliers.size()}});
  nlohmann::json j = later_run_json(out, other, failed, far);
  j["roofs"] = roofs;
  j["why"] = to_box ? "box" : "left out";
  j["kept"] = keep;
  if (by_p2m && out.eval.validity.valid() && b.unseen_roof_distance > 0) {
    report_unseen_roof(unseen, j);
  }
  log::info("[scene] building: " + std::to_string(left.size()) +
            (to_box ? " roof(s), the model reaching the partition's box" : " roof(s) left out of the model") +
            ", walls around them: p2m " +
            std::to_string(out.eval.accuracy.p2m_mean) + " -> " + (failed ? std::string("failed") : std::to_string(other.eval.accuracy.p2m_mean)) +
            (keep ? ", kept" : ", not kept"));
  if (keep) {
    out = std::move(other);
    if (run.memo && b.left_out_roof_walls_carried) {
      run.memo->walled_roofs.clear();
      for (int k : left) {
        std::vector<int> inliers = s.structure.planes[static_cast<std::size_t>(k)].inliers;
        std::sort(inliers.begin(), inliers.end());
        run.memo->walled_roofs.push_back(std::move(inliers));
      }
    }
    if (run.params.artifacts) {
      run.params.artifacts->scene = artifacts.scene;
      run.params.artifacts->recovery = std::move(artifacts.recovery);
      run.params.artifacts->polygons = std::move(artifacts.polygons);
      run.params.artifacts->complex = std::move(artifacts.complex);
      run.params.artifacts->inside = std::move(artifacts.inside);
    }
  } else {
    s.scene = first_scene;
  }
  out.report["scene"]["left_out_roofs"] = j;
  out.report["seconds"]["left_out_roofs"] = log::now_seconds() - t0;
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

/// The chain on the scene's points (stages 1 to 7 with the plan's steps 1 to 4): out's mesh, eval and the
/// report's stage fields. `seen` gets the scene stage's result as soon as it has one (a run that fails later
/// keeps it: step 0 decides on it).
void run_chain(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params, PipelineResult& out,
               std::optional<SceneResult>& seen, OutlineGate* gate, DetectionMemo* memo,
               const std::function<void(const DetectionMemo&)>& detected) {
  nlohmann::json& report = out.report;
  const bool first_run = memo && memo->record && !memo->building_ran;
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
  if (s.scene.is_building()) {
    std::size_t segments = 0;
    for (const DetectedPlane& p : s.structure.planes) segments += p.segments.size();
    report["counts"]["outline_segments"] = segments;
    if (gate && segments == gate->first_segments) {
      gate->same = true;
      return;
    }
  }

  const SceneResult scene_before_box = s.scene;  // plan_building_box rounds its ground down (walls_for_left_out_roofs)
  // a later run of the building: walls around the roofs the first run's kept model has walls around (#166)
  std::vector<int> carried;
  if (s.scene.is_building() && !run.first_run && memo && !memo->walled_roofs.empty() &&
      params.scene.building.left_out_roof_walls && params.scene.building.left_out_roof_walls_carried)
    carried = carried_roofs(s.structure, memo->walled_roofs);
  model_stages(cloud, s, plan, run, out, carried);
  if (!carried.empty()) report["scene"]["left_out_roofs_carried"] = carried;
  if (s.scene.is_building()) walls_for_left_out_roofs(cloud, scene_before_box, plan, run, s, out);
  pipeline_detail::report_quality(s.scene, s.explain, params.scene, report);
}

/// Step 0's failures that are a kind's, not the input's: no plane, nothing to enclose (the other kind may
/// make a model where this one made none).
bool made_no_model(const Error& e) { return e.status() == Status::NoPlanes || e.status() == Status::DegenerateInput; }

/// A run of step 0 as it ended (no mesh when it failed).
SceneCandidate candidate(SceneMode mode, const PipelineResult& r, bool failed) {
  SceneCandidate c;
  c.mode = mode;
  c.valid = !failed && r.eval.validity.valid();
  if (!failed) c.explained_share = r.report["quality"].value("points_explained_share", 0.0);
  return c;
}

nlohmann::json candidate_json(const SceneCandidate& c, const PipelineResult& r, const std::string& error) {
  nlohmann::json j = {{"scene", scene_mode_name(c.mode)}, {"valid", c.valid}, {"points_explained_share", c.explained_share}};
  if (r.report.contains("scene")) {
    j["roof_share"] = r.report["scene"].value("roof_share", 0.0);
    j["layered_share"] = r.report["scene"].value("layered_share", 0.0);
  }
  if (!error.empty()) j["error"] = error;
  return j;
}

/// Step 0 (scene/plan.h plan_scene_choice): the chain again with the other kind when `auto` was near its
/// rule's edge (whether or not its kind made a model), and the run choose_scene keeps in `out` (report: scene.choice). Rethrows
/// the first run's error when neither made a valid solid and the first made none.
void choose_by_result(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                      const nlohmann::json& header, PipelineResult& out, const std::optional<SceneResult>& seen,
                      const std::optional<Error>& failed, DetectionMemo& memo) {
  const bool small_scan = out.report.contains("structure_small_scan");  // plan_small_scan's planes were used
  const std::optional<SceneMode> other =
      seen ? plan_scene_choice(params.scene, *seen, cloud.size(), ground.building_class_points, small_scan)
           : std::nullopt;
  if (!other) {
    if (failed) throw *failed;
    return;
  }
  const double margin = scene_margin(*seen, params.scene);
  log::info("[scene] auto chose " + std::string(scene_mode_name(seen->mode)) +
            (failed ? " and made no model" : " by a margin of " + std::to_string(margin)) +
            (small_scan ? " on a small scan's planes" : "") + ": reconstructing as " + scene_mode_name(*other) +
            " too, keeping the valid solid that explains more of the points");
  PipelineParams again = params;
  again.scene.mode = *other;
  again.dump_dir.clear();  // the dumps are the first run's
  PipelineArtifacts artifacts;
  if (params.artifacts) again.artifacts = &artifacts;
  PipelineResult second;
  second.report = header;
  std::optional<SceneResult> seen_again;
  std::string second_error;
  const double t0 = log::now_seconds();
  try {
    run_chain(cloud, ground, again, second, seen_again, nullptr, &memo);
  } catch (const Error& e) {
    if (!made_no_model(e)) throw;
    second_error = e.what();
  }
  const double seconds = log::now_seconds() - t0;
  SceneCandidate first = candidate(seen->mode, out, failed.has_value());
  SceneCandidate then = candidate(*other, second, !second_error.empty());
  first.one_layer = then.one_layer = seen->layered_share <= params.scene.auto_max_layered_share;  // both runs' figures
  if (!first.valid && !then.valid && failed) throw *failed;
  const std::size_t kept = first.valid || then.valid ? choose_scene(first, then, params.scene) : 0;
  const nlohmann::json choice = {
      {"candidates", {candidate_json(first, out, failed ? failed->what() : ""), candidate_json(then, second, second_error)}},
      {"kept", scene_mode_name(kept == 0 ? first.mode : then.mode)},
      {"margin", margin},
      {"max_margin", params.scene.auto_choice_margin},
      {"min_gain", params.scene.auto_choice_min_gain},
      {"one_layer", first.one_layer},
      {"small_scan", small_scan},
      {"seconds_other", seconds}};
  if (kept == 1) {
    out = std::move(second);
    if (params.artifacts) *params.artifacts = std::move(artifacts);
  }
  out.report["scene"]["choice"] = choice;
  out.report["quality"]["scene_choice"] = "auto, both tried";
  log::info("[scene] kept " + std::string(scene_mode_name(kept == 0 ? first.mode : then.mode)) + " (explains " +
            std::to_string(kept == 0 ? first.explained_share : then.explained_share) + " of its points)");
}

/// One of step 5's runs (try_finer_outline): the chain with outline segments of `points` boundary points.
struct FinerOutlineRun {
  int points = 0;
  PipelineResult result;
  PipelineArtifacts artifacts;
  bool failed = false;         ///< the chain threw an Error: the model kept so far stands
  std::exception_ptr budget;   ///< it ran out of the run's budget (rethrown when the run counts)
  bool stopped = false;        ///< stopped after the scene stage by its OutlineGate (no model)
};

/// One of step 5's runs in `run` (its `points` set), stopped after the scene stage when its count of outline
/// segments is `gate_segments` (OutlineGate); none: never stopped.
void run_finer_outline(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& again,
                       const nlohmann::json& header, std::optional<std::size_t> gate_segments, DetectionMemo& memo,
                       FinerOutlineRun& run) {
  PipelineParams params = again;
  params.structure.min_segment_points = run.points;
  params.artifacts = again.artifacts ? &run.artifacts : nullptr;
  run.result = PipelineResult{};
  run.result.report = header;
  OutlineGate gate{gate_segments.value_or(0)};
  std::optional<SceneResult> seen;
  try {
    run_chain(cloud, ground, params, run.result, seen, gate_segments ? &gate : nullptr, &memo);
  } catch (const Error& e) {
    if (e.status() == Status::BudgetExceeded) run.budget = std::current_exception();
    else run.failed = true;
  }
  run.stopped = gate.same;
}

/// Whether a step-5 run found as many outline segments as the run before it (`last_segments`): nothing new to
/// recover, so it is no candidate (OutlineGate stops such a run after the scene stage).
bool same_outline(const PipelineResult& r, std::size_t last_segments) {
  const nlohmann::json& counts = r.report.value("counts", nlohmann::json::object());
  return counts.contains("outline_segments") && counts["outline_segments"].get<std::size_t>() == last_segments;
}

/// Step 5's runs, each in `runs` (its `points` set): with one thread one after the other, each stopped after the
/// scene stage when its count of segments is the run before it's (OutlineGate); with more, all at once
/// (tbb::task_group), each on its own copy of the memo and stopped when its count is the first run's
/// (`last_segments`), with `beside` (step 6's run, try_tighter_planes) in the same group. The runs do not depend
/// on each other's models, and try_finer_outline decides on them in their order either way (a run stopped at the
/// first run's count that a run before it changed is run again whole): the same model kept, the same bytes.
/// Why: on two cores a building's three runs took as long as three first runs, and one in three found no new
/// segment (issue 43).
void run_finer_outlines(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& again,
                        const nlohmann::json& header, std::size_t last_segments, const DetectionMemo& memo,
                        std::vector<FinerOutlineRun>& runs, const std::function<void()>& beside) {
  const std::size_t threads = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  if (threads <= 1 || runs.size() + (beside ? 1 : 0) <= 1) {  // one run and nothing beside: no group
    DetectionMemo own = memo;
    for (FinerOutlineRun& run : runs) {
      run_finer_outline(cloud, ground, again, header, last_segments, own, run);
      if (run.budget) return;  // rethrown by the caller
      last_segments = run.result.report["counts"].value("outline_segments", last_segments);
    }
    return;
  }
  std::vector<DetectionMemo> own(runs.size(), memo);
  tbb::task_group group;
  for (std::size_t k = 0; k < runs.size(); ++k)
    group.run([&, k] { run_finer_outline(cloud, ground, again, header, last_segments, own[k], runs[k]); });
  if (beside) group.run(beside);
  group.wait();
}

/// Whether steps 5 and 6 are one run (BuildingParams::one_second_run_on_footprint, DECISIONS #189): a building
/// given its footprint, with both steps on.
bool one_second_run(const PipelineParams& params) {
  const BuildingParams& b = params.scene.building;
  return b.one_second_run_on_footprint && !params.footprint.empty() && b.finer_outline_points > 0 &&
         b.finer_outline_points < params.structure.min_segment_points && b.tighter_planes_distance > 0.0 &&
         b.tighter_planes_distance < params.structure.max_distance;
}

/// Step 5 (BuildingParams::finer_outline_points, DECISIONS #116): a building scan, small enough
/// (SceneParams::auto_choice_max_points), is reconstructed again with roof outline segments of fewer boundary
/// points, one fewer at a time down to finer_outline_points (the last finer_outline_runs of those counts, #132;
/// finer_outline_runs_on_footprint of them with a footprint, #172; none with one_second_run, #189),
/// and keep_finer_outline decides by the result which model is kept (report: scene.finer_outline). Why: at half
/// the density a roof's short side holds too few boundary points for a segment, its wall is not recovered and
/// the roof part beyond is cut off; fewer points everywhere helps some buildings and hurts others. A run stops
/// after the scene stage when its building has as many outline segments as the run before it (nothing new to
/// recover).
void try_finer_outline(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                       const nlohmann::json& header, PipelineResult& out, DetectionMemo& memo,
                       const std::function<void()>& beside) {
  const BuildingParams& b = params.scene.building;
  if (b.finer_outline_points <= 0 || b.finer_outline_points >= params.structure.min_segment_points) return;
  if (cloud.size() > static_cast<std::size_t>(params.scene.auto_choice_max_points)) return;
  if (out.report["quality"].value("scene", "") != "building" || !out.report["counts"].contains("outline_segments"))
    return;
  if (out.report["scene"].contains("own_frame_turn_deg")) return;  // the own frame's run: not tried (#94, off)
  if (one_second_run(params)) return;  // step 6's run takes step 5's finer outline
  const nlohmann::json first_scene = out.report["scene"], first_choice = out.report["quality"]["scene_choice"];
  PipelineParams again = params;
  if (first_scene.contains("choice")) again.scene.mode = SceneMode::Building;  // step 0 kept the building
  again.dump_dir.clear();  // the dumps are the first run's
  nlohmann::json tried = nlohmann::json::array();
  int kept_points = params.structure.min_segment_points;
  std::size_t last_segments = out.report["counts"]["outline_segments"].get<std::size_t>();
  const double t0 = log::now_seconds();
  const int count = params.footprint.empty() ? b.finer_outline_runs : b.finer_outline_runs_on_footprint;
  const int coarsest = std::min(params.structure.min_segment_points - 1, b.finer_outline_points + count - 1);
  std::vector<FinerOutlineRun> runs;
  for (int points = coarsest; points >= b.finer_outline_points; --points) {
    runs.emplace_back();
    runs.back().points = points;
  }
  run_finer_outlines(cloud, ground, again, header, last_segments, memo, runs, beside);
  for (FinerOutlineRun& run : runs) {
    const int points = run.points;
    PipelineResult& other = run.result;
    nlohmann::json t = {{"segment_points", points}};
    if (same_outline(other, last_segments)) {  // nothing new to recover: not a candidate
      t["same_segments"] = true;
      tried.push_back(t);
      continue;
    }
    if (run.stopped) {  // stopped at the first run's count, which a run before it changed: now whole
      DetectionMemo own = memo;
      run_finer_outline(cloud, ground, again, header, std::nullopt, own, run);
    }
    if (run.budget) std::rethrow_exception(run.budget);  // the run's budget holds for every run
    const bool failed = run.failed;
    PipelineArtifacts& artifacts = run.artifacts;
    last_segments = other.report["counts"].value("outline_segments", last_segments);
    const bool kept_valid = out.eval.validity.valid(), valid = !failed && other.eval.validity.valid();
    const bool by_p2m = !failed && keep_finer_outline(kept_valid, out.eval.accuracy.p2m_mean, out.eval.face_sizes.small_faces,
                                                      valid, other.eval.accuracy.p2m_mean,
                                                      other.eval.face_sizes.small_faces, b);
    // both ways: no more roof that no point sees (no_more_unseen_roof), of two valid solids
    const UnseenRoof unseen = by_p2m && kept_valid
                                  ? compare_unseen_roof(cloud, out, other, average_spacing(cloud.points), b)
                                  : UnseenRoof{};
    const bool keep = by_p2m && unseen.may_keep;
    t["outline_segments"] = last_segments;
    t["valid"] = valid;
    if (!failed) t["p2m"] = other.eval.accuracy.p2m_mean;
    if (by_p2m && kept_valid && b.unseen_roof_distance > 0) {
      report_unseen_roof(unseen, t);
    }
    t["kept"] = keep;
    tried.push_back(t);
    if (!keep) continue;
    log::info("[scene] building: outline segments of " + std::to_string(points) + " points: p2m " +
              std::to_string(out.eval.accuracy.p2m_mean) + " -> " + std::to_string(other.eval.accuracy.p2m_mean) +
              ", kept");
    kept_points = points;
    out = std::move(other);
    if (params.artifacts) *params.artifacts = std::move(artifacts);
  }
  if (kept_points != params.structure.min_segment_points) {
    if (first_scene.contains("choice")) out.report["scene"]["choice"] = first_scene["choice"];
    if (first_scene.contains("left_out_roofs")) out.report["scene"]["left_out_roofs"] = first_scene["left_out_roofs"];
    out.report["quality"]["scene_choice"] = first_choice;
  }
  out.report["scene"]["finer_outline"] = {{"tried", tried},
                                          {"kept_segment_points", kept_points},
                                          {"min_gain", b.finer_outline_min_gain}};
  out.report["seconds"]["finer_outline"] = log::now_seconds() - t0;
}

/// Whether a second run of the same building (step 6) stands on the first run's ground: the same source, and no
/// more points in ground planes. Why: the scene decides on the planes of the first detection (DECISIONS #99); with
/// tighter planes a flat roof under a tree can become a ground plane and the tree the building (AHN3_15708 at
/// half density: the roof's 247 points taken for ground, the tree's points modelled; p2m lower, the building gone).
bool same_ground(const nlohmann::json& first, const nlohmann::json& second) {
  const auto quality = [](const nlohmann::json& r) { return r.value("quality", nlohmann::json::object()); };
  const auto source = [&](const nlohmann::json& r) { return quality(r).value("ground_source", std::string()); };
  const auto ground_points = [&](const nlohmann::json& r) {
    return quality(r).value("removed_points", nlohmann::json::object()).value("ground_planes", 0);
  };
  return source(first) == source(second) && ground_points(second) <= ground_points(first);
}

/// The scan's points farther than `distance` from r's model: counted on the distances its evaluation kept
/// (Run::keep_point_distance), measured again only where it kept none.
std::size_t points_farther(const PointCloud& cloud, const PipelineResult& r, double distance) {
  const std::vector<double>& d = r.eval.point_distance;
  if (d.size() != cloud.size()) return count_farther(cloud.points, r.mesh, distance);
  return farther_than(d, distance);
}

/// FarPoints of steps 6 and 7 (points_farther) at the first detection's inlier distance: StructureParams::
/// max_distance as the first run's report.resolved (`first_resolved`) gives it in the scan's units, else
/// max_distance r.
FarPoints far_points_of_runs(const PointCloud& cloud, const PipelineParams& params, const nlohmann::json& first_resolved,
                             const PipelineResult& out, const PipelineResult& other, bool failed) {
  const nlohmann::json resolved = first_resolved.value("structure", nlohmann::json::object());
  const double inlier_distance = resolved.contains("max_distance") ? resolved["max_distance"].get<double>()
                                                                   : params.structure.max_distance * average_spacing(cloud.points);
  return {points_farther(cloud, out, inlier_distance), failed ? cloud.size() : points_farther(cloud, other, inlier_distance)};
}

/// Whether step 6 (try_tighter_planes) runs on the model `report` is of: a building scan, small enough
/// (SceneParams::auto_choice_max_points), not the outline prism (no planes), not the own frame's run (#94, off),
/// and the tighter distance tighter than the detection's.
bool tighter_planes_apply(const PointCloud& cloud, const PipelineParams& params, const nlohmann::json& report) {
  const BuildingParams& b = params.scene.building;
  if (!(b.tighter_planes_distance > 0.0 && b.tighter_planes_distance < params.structure.max_distance)) return false;
  if (cloud.size() > static_cast<std::size_t>(params.scene.auto_choice_max_points)) return false;
  if (report["quality"].value("scene", "") != "building" || !report["counts"].contains("outline_segments"))
    return false;
  return !report["scene"].contains("own_frame_turn_deg") && !report["quality"].contains("fallback");
}

/// Step 6's run (try_tighter_planes): the chain with the planes' inliers within tighter_planes_distance r and
/// outline segments of `segment_points` points, as it ended.
struct TighterPlanesRun {
  int segment_points = 0;
  PipelineResult result;
  PipelineArtifacts artifacts;
  bool failed = false;        ///< the chain threw an Error: the model kept so far stands
  std::exception_ptr budget;  ///< it ran out of the run's budget (rethrown by try_tighter_planes)
  std::string beside;         ///< made beside another: "first run" (TighterPlanesAhead), "step 5"; report: scene.tighter_planes.beside
};

/// Step 6's run on the model whose scene report is `scene` (step 0's choice kept: building mode), with outline
/// segments of `segment_points` points. `memo` is read only (the first run's kNN graph, #150).
TighterPlanesRun run_tighter_planes(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                                    const nlohmann::json& header, const nlohmann::json& scene, int segment_points,
                                    DetectionMemo& memo) {
  TighterPlanesRun run;
  run.segment_points = segment_points;
  PipelineParams again = params;
  if (scene.contains("choice")) again.scene.mode = SceneMode::Building;  // step 0 kept the building
  again.structure.min_segment_points = segment_points;
  again.structure.max_distance = params.scene.building.tighter_planes_distance;
  again.dump_dir.clear();  // the dumps are the first run's
  again.artifacts = params.artifacts ? &run.artifacts : nullptr;
  run.result.report = header;
  std::optional<SceneResult> seen_again;
  try {
    run_chain(cloud, ground, again, run.result, seen_again, nullptr, &memo);
  } catch (const Error& e) {
    if (e.status() == Status::BudgetExceeded) run.budget = std::current_exception();
    else run.failed = true;
  }
  return run;
}

/// The outline segments' count of boundary points of step 6's run: step 5's finest with one second run
/// (one_second_run), else the count step 5 kept (`scene`: the kept model's scene report).
int step6_segment_points(const PipelineParams& params, const nlohmann::json& scene) {
  if (one_second_run(params)) return params.scene.building.finer_outline_points;
  return scene.contains("finer_outline")
             ? scene["finer_outline"].value("kept_segment_points", params.structure.min_segment_points)
             : params.structure.min_segment_points;
}

/// Step 6's run begun beside the first run (issue 43; DECISIONS #201). With a footprint (one_second_run) the run's
/// outline segments are known before the first run ends (finer_outline_points), and its detection needs of the
/// first run only the kNN graph and normals its detection left in the memo; so with threads to spare it runs on a
/// copy of the memo as the first detection left it, beside the first run's stages 3 to 7. take() gives it to
/// try_tighter_planes (as `early`) only where it ran on what step 6's run after the first would have had: no
/// step 0 choice (which puts step 6's run in building mode), no roof walled by the first run (carried to later
/// runs: carried_roofs); else it is dropped and step 6 runs as before. The same model either way; why: on one
/// job a building's runs left the second core idle, step 6's run being half of a city tile's pipeline time.
class TighterPlanesAhead {
 public:
  TighterPlanesAhead(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                     const nlohmann::json& header)
      : cloud_(cloud), ground_(ground), params_(params), header_(header) {}
  TighterPlanesAhead(const TighterPlanesAhead&) = delete;
  TighterPlanesAhead& operator=(const TighterPlanesAhead&) = delete;
  ~TighterPlanesAhead() {
    try {
      group_.wait();
    } catch (...) {  // the run that ended the pipeline first is the one reported
    }
  }

  /// run_chain's `detected` for the first run: empty where the run cannot begin early (one thread, no footprint,
  /// a scan too large for step 6, or object mode).
  std::function<void(const DetectionMemo&)> hook() {
    const std::size_t threads = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
    if (threads <= 1 || !one_second_run(params_) || params_.scene.mode == SceneMode::Object) return {};
    if (cloud_.size() > static_cast<std::size_t>(params_.scene.auto_choice_max_points)) return {};
    return [this](const DetectionMemo& memo) {
      if (memo_) return;  // begun already
      memo_ = memo;
      group_.run([this] {
        run_ = run_tighter_planes(cloud_, ground_, params_, header_, nlohmann::json::object(),
                                  params_.scene.building.finer_outline_points, *memo_);
        run_->beside = "first run";
      });
    };
  }

  /// Waits for the run; it, where it stands for step 6's run on the first run's model `report` and `memo`.
  std::optional<TighterPlanesRun> take(const nlohmann::json& report, const DetectionMemo& memo) {
    group_.wait();
    if (!run_) return std::nullopt;
    const bool chosen = report.value("scene", nlohmann::json::object()).contains("choice");
    if ((chosen && params_.scene.mode != SceneMode::Building) || !memo.walled_roofs.empty()) return std::nullopt;
    return std::move(run_);
  }

 private:
  const PointCloud& cloud_;
  const SceneGround& ground_;
  const PipelineParams& params_;
  const nlohmann::json& header_;
  tbb::task_group group_;
  std::optional<DetectionMemo> memo_;   ///< the first detection's, the run's own
  std::optional<TighterPlanesRun> run_;
};

/// Step 6 (BuildingParams::tighter_planes_distance, DECISIONS #137): a building scan (tighter_planes_apply) is
/// reconstructed once more with its planes' inliers within tighter_planes_distance r instead of
/// StructureParams::max_distance r, with the outline segments step 5 kept, and keep_tighter_planes decides by the
/// result which model is kept (report: scene.tighter_planes). Why: the inlier distance is in r, so at half the
/// density it is 1.4 times as long in metres and more than a roof's step; a lower roof's region grows over the
/// step into the higher roof, its refit tilts between the two and the model puts a ridge where the scan has a
/// step. A tighter distance everywhere splits noisy roofs, so the result decides. `early`: the run made beside
/// step 5's (run_pipeline), taken when it ran with the segments step 5 kept.
void try_tighter_planes(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                        const nlohmann::json& header, PipelineResult& out, DetectionMemo& memo,
                        std::optional<TighterPlanesRun>& early) {
  const BuildingParams& b = params.scene.building;
  if (!tighter_planes_apply(cloud, params, out.report)) return;
  const nlohmann::json first_scene = out.report["scene"], first_choice = out.report["quality"]["scene_choice"];
  const nlohmann::json first_seconds = out.report["seconds"], first_resolved = out.report["resolved"];
  // the outline segments' count of points of step 6's run (step 5's kept one, or its finest with one second run)
  const int segment_points = step6_segment_points(params, first_scene);
  const double t0 = log::now_seconds();
  TighterPlanesRun run = early && early->segment_points == segment_points
                             ? std::move(*early)
                             : run_tighter_planes(cloud, ground, params, header, first_scene, segment_points, memo);
  early.reset();
  if (run.budget) std::rethrow_exception(run.budget);  // the run's budget holds for every run
  const bool failed = run.failed;
  PipelineResult& other = run.result;
  const FarPoints far = far_points_of_runs(cloud, params, first_resolved, out, other, failed);
  const bool by_p2m = same_ground(out.report, other.report) && later_run_explains_more(out, other, failed, far, b);
  // both ways: no more roof that no point sees (no_more_unseen_roof), of two valid solids
  const UnseenRoof unseen = by_p2m && out.eval.validity.valid()
                                ? compare_unseen_roof(cloud, out, other, average_spacing(cloud.points), b)
                                : UnseenRoof{};
  const bool keep = by_p2m && unseen.may_keep;
  nlohmann::json t = later_run_json(out, other, failed, far);
  t["distance"] = b.tighter_planes_distance;
  t["kept"] = keep;
  if (!failed) t["same_ground"] = same_ground(out.report, other.report);
  if (by_p2m && out.eval.validity.valid() && b.unseen_roof_distance > 0) {
    report_unseen_roof(unseen, t);
  }
  if (keep) {
    log::info("[scene] building: planes' inliers within " + std::to_string(b.tighter_planes_distance) + " r: p2m " +
              std::to_string(out.eval.accuracy.p2m_mean) + " -> " + std::to_string(other.eval.accuracy.p2m_mean) +
              ", kept");
    out = std::move(other);
    if (params.artifacts) *params.artifacts = std::move(run.artifacts);
    if (first_scene.contains("choice")) out.report["scene"]["choice"] = first_scene["choice"];
    if (first_scene.contains("finer_outline")) out.report["scene"]["finer_outline"] = first_scene["finer_outline"];
    if (first_scene.contains("left_out_roofs")) out.report["scene"]["left_out_roofs"] = first_scene["left_out_roofs"];
    if (first_seconds.contains("finer_outline")) out.report["seconds"]["finer_outline"] = first_seconds["finer_outline"];
    out.report["quality"]["scene_choice"] = first_choice;
  }
  if (one_second_run(params)) t["outline_segment_points"] = segment_points;  // step 5's with it (#189)
  if (!run.beside.empty()) t["beside"] = run.beside;
  out.report["scene"]["tighter_planes"] = t;
  out.report["seconds"]["tighter_planes"] = log::now_seconds() - t0;
}

/// Step 7 (BuildingParams::gable_halves, DECISIONS #215): a building scan whose kept model's run found a roof
/// plane holding a gable's two halves (counts.gable_half_candidates, building_small_planes) is reconstructed once
/// more with those planes split (DetectionMemo::split_gables), with the kept model's detection and outline
/// segments, and keep_tighter_planes decides by the result as in step 6 (valid; p2m lower by
/// finer_outline_min_gain of it; no more slivers unless fewer points are far; the same ground). Report:
/// scene.gable_halves. Why: see BuildingParams::gable_halves.
void try_gable_halves(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                      const nlohmann::json& header, PipelineResult& out, DetectionMemo& memo) {
  const BuildingParams& b = params.scene.building;
  if (!b.gable_halves || b.small_plane_points <= 0 || !memo.record) return;
  if (out.report["counts"].value("gable_half_candidates", 0) <= 0) return;
  if (out.report["quality"].value("scene", "") != "building" || out.report["quality"].contains("fallback") ||
      out.report["scene"].contains("own_frame_turn_deg"))
    return;
  const double t0 = log::now_seconds();
  const nlohmann::json first_scene = out.report["scene"], first_choice = out.report["quality"]["scene_choice"];
  const nlohmann::json first_seconds = out.report["seconds"], first_resolved = out.report["resolved"];
  // the kept model's detection and outline segments: step 6's when it was kept, else step 5's (or the first's)
  const bool tighter_kept = first_scene.contains("tighter_planes") && first_scene["tighter_planes"].value("kept", false);
  PipelineParams again = params;
  if (first_scene.contains("choice")) again.scene.mode = SceneMode::Building;  // step 0 kept the building
  again.structure.min_segment_points = tighter_kept || !one_second_run(params) ? step6_segment_points(params, first_scene)
                                                                               : params.structure.min_segment_points;
  if (tighter_kept) again.structure.max_distance = b.tighter_planes_distance;
  again.dump_dir.clear();  // the dumps are the first run's
  PipelineArtifacts artifacts;
  again.artifacts = params.artifacts ? &artifacts : nullptr;
  PipelineResult other;
  other.report = header;
  DetectionMemo own = memo;
  own.split_gables = true;
  std::optional<SceneResult> seen_again;
  bool failed = false;
  try {
    run_chain(cloud, ground, again, other, seen_again, nullptr, &own);
  } catch (const Error& e) {
    if (e.status() == Status::BudgetExceeded) throw;  // the run's budget holds for every run
    failed = true;  // the model kept so far stands
  }
  const FarPoints far = far_points_of_runs(cloud, params, first_resolved, out, other, failed);
  const bool keep = same_ground(out.report, other.report) && later_run_explains_more(out, other, failed, far, b);
  nlohmann::json t = later_run_json(out, other, failed, far);
  t["candidates"] = out.report["counts"]["gable_half_candidates"];
  t["kept"] = keep;
  log::info("[scene] building: a gable's two halves for " + t["candidates"].dump() + " roof plane(s): p2m " +
            std::to_string(out.eval.accuracy.p2m_mean) + " -> " +
            (failed ? std::string("failed") : std::to_string(other.eval.accuracy.p2m_mean)) + (keep ? ", kept" : ", not kept"));
  if (keep) {
    out = std::move(other);
    if (params.artifacts) *params.artifacts = std::move(artifacts);
    for (const char* key : {"choice", "finer_outline", "left_out_roofs", "tighter_planes"})
      if (first_scene.contains(key)) out.report["scene"][key] = first_scene[key];
    for (const char* key : {"finer_outline", "tighter_planes"})
      if (first_seconds.contains(key)) out.report["seconds"][key] = first_seconds[key];
    out.report["quality"]["scene_choice"] = first_choice;
  }
  out.report["scene"]["gable_halves"] = t;
  out.report["seconds"]["gable_halves"] = log::now_seconds() - t0;
}

/// Whether a scan without planes is seen from above, as `auto`'s rule (a) asks of its planes, on the points: the
/// file gives normals and at least auto_min_roof_share of them lie within auto_steep_roof_deg of +z. Why: with no
/// plane the rule has no figures; an aerial scan's normals point to the sensor, above (Vaihingen_00026: 0.90 of
/// them, 0.80 at half density), an object's every way (ten points of a box's side: none). Without normals
/// nothing tells, and `auto` makes no model.
bool normals_face_up(const PointCloud& cloud, const SceneParams& params) {
  if (cloud.normals.size() != cloud.size() || cloud.empty()) return false;
  const double cos_max = std::cos(params.auto_steep_roof_deg * M_PI / 180.0);
  const auto up = std::count_if(cloud.normals.begin(), cloud.normals.end(),
                                [&](const Vec3& n) { return n.z() >= cos_max * n.norm(); });
  return static_cast<double>(up) >= params.auto_min_roof_share * static_cast<double>(cloud.size());
}

/// Whether a run whose detection found no plane gets the outline prism (BuildingParams::outline_prism): a
/// building scan by the user's word (`--scene building`) or the file's (LAS class 6), or `auto` on a scan small
/// enough for the small-scan rule (SceneParams::small_scan_size x the smallest plane: a shed, a garage of a few
/// hundred points at survey density) whose normals face up (normals_face_up). Never in object mode: an object
/// without planes is no block.
bool outline_prism_applies(const PipelineParams& params, const SceneGround& ground, const PointCloud& cloud) {
  if (!params.scene.building.outline_prism || params.scene.mode == SceneMode::Object) return false;
  if (params.scene.mode == SceneMode::Building || ground.building_class_points > 0) return true;
  const auto small = static_cast<std::size_t>(params.scene.small_scan_size) *
                     static_cast<std::size_t>(std::max(params.structure.min_region_points, 1));
  return cloud.size() < small && normals_face_up(cloud, params.scene);
}

/// Whether the run's footprint can be the prism's outline: one polygon without holes (outline_prism takes one ring).
bool footprint_is_one_ring(const PipelineParams& params) {
  return params.footprint.size() == 1 && params.footprint.front().holes.empty();
}

/// Whether a building run on a footprint that made no model (`e`) gets the footprint prism instead
/// (PipelineParams::footprint_prism_when_no_model, DECISIONS #174). Why: in a 1,000-building synthetic city a
/// shed of 147 points (0.7 per m²: only a strip along one wall in the points) held two wall planes and no roof,
/// and the whole tile exited 1; the footprint says a building stands there and its points give the roof's height.
/// Not the partition's errors: a footprint off the points (or a box of zero extent) is an input at fault, not a
/// building without a roof.
bool footprint_prism_for_failure(const PipelineParams& params, const Error& e) {
  return params.footprint_prism_when_no_model && made_no_model(e) && e.stage() != "partition" &&
         params.scene.mode != SceneMode::Object && footprint_is_one_ring(params);
}

/// The outline prism's run (scene/building/building.h outline_prism) in `out`, when the chain found no plane
/// (`why`; with `on_footprint`, when it made no model on a footprint: the footprint prism, #174): the model, its
/// evaluation, the points it leaves unexplained and the quality, which says `fallback: outline prism` or
/// `footprint prism` (report: scene.fallback). Rethrows `why` when the points make no prism.
void outline_prism_run(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                       const nlohmann::json& header, const Error& why, PipelineResult& out, bool on_footprint = false) {
  const double r = average_spacing(cloud.points);
  on_footprint = on_footprint || (params.footprint_prism && footprint_is_one_ring(params));
  OutlinePrism prism = outline_prism(cloud, r, params.scene.building, ground, on_footprint ? &params.footprint.front().outer : nullptr);
  if (prism.mesh.faces.empty()) throw why;
  const std::string model = on_footprint ? "footprint prism" : "outline prism";
  out = PipelineResult{};
  out.report = header;
  nlohmann::json& report = out.report;
  SceneResult scene;
  scene.mode = SceneMode::Building;
  scene.reason = !on_footprint ? "no plane found: the outline prism (a block over the points' outline, BuildingParams::outline_prism)"
                 : params.footprint_prism ? "too few points for a run: the footprint prism (the footprint extruded, PipelineParams::footprint_prism)"
                                          : "the run made no model: the footprint prism (the footprint extruded, PipelineParams::footprint_prism_when_no_model)";
  scene.ground_z = prism.ground_z;
  scene.ground_source = prism.ground_source;
  scene.ground_note = prism.ground_note;
  const std::size_t roof_points = cloud.size() - prism.under_roof_points;
  log::warn(std::string("[scene] ") + why.what() + ": the model is the " + model + " of the " +
            std::to_string(roof_points) + " roof points, from the ground (" + ground_source_name(prism.ground_source) +
            ") to the " + std::to_string(params.scene.building.outline_prism_roof_quantile) +
            " quantile of their heights (scene.fallback)");
  if (!prism.ground_note.empty()) log::warn("[scene] " + prism.ground_note);
  report["scene"] = to_json(scene);
  report["scene"]["ground_z_file"] = prism.ground_z + cloud.origin.z();
  report["scene"]["fallback"] = {{"model", model},
                                 {"why", why.what()},
                                 {"spacing", r},
                                 {"roof_points", roof_points},
                                 {"under_roof_points", prism.under_roof_points},
                                 {"roof_quantile", params.scene.building.outline_prism_roof_quantile},
                                 {"roof_z", prism.roof_z},
                                 {"roof_z_file", prism.roof_z + cloud.origin.z()},
                                 {"outline_vertices", prism.mesh.faces.front().size()}};
  report["counts"]["planes"] = 0;
  out.mesh = std::move(prism.mesh);
  out.mesh.origin = cloud.origin;
  out.eval = timed_stage("eval", report, [&] {
    EvalResult eval = run_eval(cloud, out.mesh, params.truth, params.eval);
    pipeline_detail::report_unexplained(cloud, prism.roof, r, out.mesh, eval.point_distance, params.eval, report);
    std::vector<double>().swap(eval.point_distance);
    return eval;
  });
  pipeline_detail::report_eval(out, report);
  PointsToExplain explain;
  explain.low_points = prism.under_roof_points;  // under the roof's gap: the ground or a wall's foot, on no plane
  pipeline_detail::report_quality(scene, explain, params.scene, report);
  report["quality"].erase("scene_margin");  // no plane, no figures of the `auto` rule
  report["quality"]["fallback"] = model;
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
  memo.record = cloud.size() <= static_cast<std::size_t>(params.scene.auto_choice_max_points);
  std::optional<SceneResult> seen;
  std::optional<Error> failed;
  TighterPlanesAhead ahead(cloud, ground, params, header);  // step 6's run beside the first (DECISIONS #201)
  if (params.footprint_prism && params.scene.mode != SceneMode::Object) {  // too few points for a run (DECISIONS #165)
    outline_prism_run(cloud, ground, params, header,
                      Error(Status::DegenerateInput, "scene",
                            "the footprint prism was asked for (" + std::to_string(cloud.size()) + " points)"),
                      out);
  } else try {
    try {
      run_chain(cloud, ground, params, out, seen, nullptr, &memo, ahead.hook());
    } catch (const Error& e) {
      if (!made_no_model(e) || !seen) throw;
      failed = e;
    }
    choose_by_result(cloud, ground, params, header, out, seen, failed, memo);
  } catch (const Error& e) {  // no model on a footprint: its prism (#174); no plane at all: the outline prism (#135)
    if (footprint_prism_for_failure(params, e))
      outline_prism_run(cloud, ground, params, header, e, out, true);
    else if (e.status() == Status::NoPlanes && outline_prism_applies(params, ground, cloud))
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
    early = run_tighter_planes(cloud, ground, params, header, first_scene, params.structure.min_segment_points, memo);
    early->beside = "step 5";
  };
  try_finer_outline(cloud, ground, params, header, out, memo, step6 ? std::function<void()>(beside) : nullptr);
  try_tighter_planes(cloud, ground, params, header, out, memo, early);
  try_gable_halves(cloud, ground, params, header, out, memo);
  std::vector<double>().swap(out.eval.point_distance);  // kept for step 6 only (Run::keep_point_distance)
  if (out.eval.m2p_later) {  // the kept run's mesh -> points figures only (Run::m2p_later)
    add_mesh_to_points(cloud, out.mesh, params.eval, out.eval);
    pipeline_detail::report_eval(out, report);
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
