#include "pipeline.h"

#include "core/atomic_file.h"
#include "core/budget.h"
#include "core/error.h"
#include "core/face_class.h"
#include "core/log.h"
#include "core/threads.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <new>
#include <optional>

namespace hsr {

namespace {

std::string fmt_seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f s", s);
  return buf;
}

/// Times one stage, logs it, records it in the report, and re-labels foreign exceptions with the stage.
/// Also records the stage's CPU seconds (all threads) and the process's peak memory when it ended.
template <class F>
auto timed_stage(const char* name, nlohmann::json& report, F&& body) {
  const double t0 = log::now_seconds(), c0 = log::cpu_seconds();
  check_budget(name);  // between stages (and log::Progress checks inside long loops)
  try {
    auto result = body();
    check_budget(name);
    const double dt = log::now_seconds() - t0;
    report["seconds"][name] = dt;
    report["cpu_seconds"][name] = log::cpu_seconds() - c0;
    report["peak_memory_mb_after"][name] = log::peak_memory_mb();
    log::verbose(std::string("[") + name + "] done in " + fmt_seconds(dt) + " (CPU " +
                 fmt_seconds(log::cpu_seconds() - c0) + ")");
    return result;
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw Error(Status::BudgetExceeded, name, "out of memory");
  } catch (const std::exception& e) {
    throw Error(Status::Internal, name, e.what());
  }
}

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

/// The footprint in file coordinates: [[outer ring, hole, ...], ...], each ring [[x, y], ...].
nlohmann::json footprint_to_json(const Footprint& footprint, const Vec3& origin) {
  nlohmann::json polygons = nlohmann::json::array();
  auto ring_json = [&](const std::vector<Vec2>& ring) {
    nlohmann::json r = nlohmann::json::array();
    for (const Vec2& p : ring) r.push_back({p.x() + origin.x(), p.y() + origin.y()});
    return r;
  };
  for (const FootprintPolygon& p : footprint) {
    nlohmann::json rings = nlohmann::json::array({ring_json(p.outer)});
    for (const auto& h : p.holes) rings.push_back(ring_json(h));
    polygons.push_back(std::move(rings));
  }
  return polygons;
}

/// structure.json (written by stage 1's dump) gains the per-plane fields of stages 2–4 and the recovered planes.
void add_stage_fields_to_structure_json(const std::string& dir, const SceneStructure& structure,
                                        const VisibilityResult& visibility, const RecoveryResult& recovery,
                                        const std::vector<ConvexPolygon>& polygons) {
  const std::string path = (std::filesystem::path(dir) / "structure.json").string();
  nlohmann::json j;
  {
    std::ifstream in(path);
    if (in) j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  }
  if (j.is_discarded() || !j.is_object()) j = nlohmann::json::object();
  j["recovered_planes"] = add_hulls_fields(j["planes"], structure, visibility, recovery, polygons);
  AtomicFile out(path, "dump");
  out.stream() << j.dump(2) << '\n';
  out.commit();
}

/// DIR/scene.json: the mode, the ground, and the role of every detected plane (structure.json numbers the
/// planes the later stages use, i.e. the roof and wall planes in building mode).
void write_scene_dump(const SceneResult& scene, const std::string& path) {
  nlohmann::json j = to_json(scene);
  j["roles"] = nlohmann::json::array();
  for (PlaneRole r : scene.roles) j["roles"].push_back(plane_role_name(r));
  AtomicFile out(path, "dump");
  out.stream() << j.dump(2) << '\n';
  out.commit();
}

/// Building mode: the partition box holds the building's planes' inliers (not the ground and clutter around
/// them), the ends of the walls recovered from their outlines (RecoveredPlane::reach: the walls stand a
/// little beyond the outermost roof points, so the points' own box would cut the corners where two meet),
/// with a footprint also the footprint's corners (the building fills its footprint: a box cut short by the
/// points' extent closed its corners with closure faces), and reaches down to the ground height.
BBox building_box(const PointCloud& cloud, const SceneStructure& building, const RecoveryResult& recovery,
                  const SceneResult& scene, const Footprint& footprint) {
  BBox box;
  for (const DetectedPlane& p : building.planes)
    for (int i : p.inliers) box.extend(cloud.points[static_cast<std::size_t>(i)]);
  if (!box.valid()) return box;
  const double top = box.max.z();
  for (const RecoveredPlane& wall : recovery.recovered)
    for (const Vec3& q : wall.reach) box.extend(Vec3(q.x(), q.y(), top));
  for (const FootprintPolygon& f : footprint)
    for (const Vec2& q : f.outer) box.extend(Vec3(q.x(), q.y(), scene.ground_z));
  box.min.z() = scene.ground_z;
  box.max.z() = std::max(box.max.z(), scene.ground_z);
  return box;
}

/// Building mode: the ground is the partition box's bottom, which the box rounds down to its grid (at most
/// diagonal / 1000): the ground height becomes that value, so walls dropped to it end on the box's bottom and
/// the report gives the height the model stands on.
void snap_ground_to_box(const PointCloud& cloud, const SceneStructure& building, const RecoveryResult& recovery,
                        double margin, const Footprint& footprint, SceneResult& scene) {
  ExactPoint lo, hi;
  partition_box(building_box(cloud, building, recovery, scene, footprint), margin, lo, hi);
  scene.ground_z = lo.z.get_d();
}

}  // namespace

namespace {

/// What every stage step below shares: the run's parameters, its report, and whether to dump.
struct Run {
  const PipelineParams& params;
  nlohmann::json& report;
  bool dump;
};

/// The scene stage's outcome: the planes later stages use (building mode: ground and clutter left out).
struct SceneStage {
  SceneResult scene;
  SceneStructure structure;
};

/// Stage 1 with the small-scan rule: a scan of fewer than 10 x min_region_points points (a shed, a garage:
/// a few hundred points at survey density) where no plane of min_region_points is found is one small
/// object whose planes each hold a fair share of it: detection runs again with the smallest plane at a fifth
/// of the points, at least half of min_region_points (Vaihingen_00015: 95 points, planes of 41 and 34;
/// below 15 points nothing is fitted). Said in a warning and in the report (structure_small_scan).
SceneStructure detect_structure(const PointCloud& input, const StructureParams& params, nlohmann::json& report) {
  try {
    return run_structure(input, params);
  } catch (const Error& e) {
    const std::size_t n = input.size(), floor = static_cast<std::size_t>(params.min_region_points);
    if (e.status() != Status::NoPlanes || n >= 10 * floor) throw;
    StructureParams small = params;
    small.min_region_points = static_cast<int>(std::max((floor + 1) / 2, (n + 4) / 5));
    if (small.min_region_points >= params.min_region_points) throw;
    log::warn("[structure] no plane of " + std::to_string(floor) + " points in a scan of " + std::to_string(n) +
              ": trying planes of " + std::to_string(small.min_region_points) + " (a small scan; --min-plane-points sets it)");
    report["structure_small_scan"] = small.min_region_points;
    return run_structure(input, small);
  }
}

// Stage 1 (structure) and the scene mode (DESIGN.md §4: object, or building — ground, roofs, walls).
SceneStage structure_and_scene(const PointCloud& input, const SceneGround& ground, Run& run) {
  const PipelineParams& params = run.params;
  nlohmann::json& report = run.report;
  const SceneStructure detected = timed_stage("structure", report, [&] {
    return detect_structure(input, params.structure, report);
  });
  report["resolved"]["structure"] = detected.params;
  report["counts"]["planes"] = detected.planes.size();
  const auto on_no_plane = static_cast<std::size_t>(std::count(detected.point_plane.begin(), detected.point_plane.end(), -1));
  report["counts"]["points_on_no_plane"] = on_no_plane;
  log::info("[structure] " + std::to_string(detected.planes.size()) + " planes, spacing r = " +
            std::to_string(detected.spacing) + "; " + std::to_string(on_no_plane) + " points on no plane");

  SceneResult scene = timed_stage("scene", report, [&] { return run_scene(input, detected, params.scene, ground); });
  SceneStructure structure = building_structure(input, detected, scene, params.scene);
  report["scene"] = to_json(scene);
  if (params.ground_raster) report["scene"]["ground_raster"] = params.ground_raster->source;
  report["counts"]["building_planes"] = structure.planes.size();
  log::info("[scene] " + std::string(scene_mode_name(scene.mode)) + ": " + scene.reason);
  if (scene.is_building())
    log::info("[scene] ground at z = " + std::to_string(scene.ground_z + input.origin.z()) + " (" +
              ground_source_name(scene.ground_source) + "); " + std::to_string(scene.count(PlaneRole::Roof)) +
              " roof, " + std::to_string(scene.count(PlaneRole::Wall)) + " wall planes kept, " +
              std::to_string(scene.count(PlaneRole::Ground) + scene.count(PlaneRole::Clutter)) +
              " ground and clutter planes left out");
  if (params.artifacts) {
    params.artifacts->structure = structure;
    params.artifacts->scene = scene;
  }
  if (run.dump) {
    write_structure_dump(input, structure, params.dump_dir);
    write_scene_dump(scene, (std::filesystem::path(params.dump_dir) / "scene.json").string());
  }
  check_planes_can_enclose(structure, scene);
  return {std::move(scene), std::move(structure)};
}

// Stage 2: visibility. Its outward normal per plane decides which side of each plane is outside; every
// inlier's normal (`normals`: the structure's, turned) is flipped to agree with it, so extraction does not
// depend on how well the input (or the MST propagation of stage 1) oriented the normals. The structure's
// normals are moved into `normals` (no later stage reads them there): one copy fewer of a vector per point.
VisibilityResult visibility_stage(const PointCloud& input, SceneStage& s, std::vector<Vec3>& normals, Run& run) {
  nlohmann::json& report = run.report;
  VisibilityParams params = run.params.visibility;
  if (s.scene.is_building()) params.close_room = false;  // a building is seen from outside, never a room
  VisibilityResult visibility = timed_stage("visibility", report, [&] {
    return run_visibility(input, s.structure, params);
  });
  if (s.scene.is_building()) visibility.scanned_from_inside = false;  // aerial scans are seen from above
  report["counts"]["roofs_turned_up"] = orient_roofs_up(s.structure, s.scene, visibility.outward_normal);
  normals = std::move(s.structure.normals);
  s.structure.normals.clear();
  const std::size_t flipped = orient_inlier_normals(s.structure, visibility, normals);
  if (run.params.artifacts) {
    run.params.artifacts->visibility = visibility;
    run.params.artifacts->cloud = input;
    run.params.artifacts->cloud.normals = normals;
  }
  const auto highly = std::count(visibility.highly.begin(), visibility.highly.end(), true);
  report["counts"]["highly_visible_planes"] = highly;
  report["counts"]["closed_rays"] = visibility.closed_rays;  // a room's escapes closed (VisibilityParams::close_room)
  report["counts"]["normals_flipped"] = flipped;
  report["visibility"]["scanned_from_inside"] = visibility.scanned_from_inside;
  log::info("[visibility] " + std::to_string(highly) + " highly / " +
            std::to_string(s.structure.planes.size() - static_cast<std::size_t>(highly)) +
            " barely visible planes, " + std::to_string(flipped) +
            " inlier normals flipped to their plane's outward side");
  return visibility;
}

// Stage 3: recovery of planes the scanner missed (building mode: walls through roof outlines, where one
// segment and the vertical suffice).
RecoveryResult recovery_stage(const PointCloud& cloud, const SceneStage& s, const VisibilityResult& visibility, Run& run) {
  const PipelineParams& params = run.params;
  RecoveryParams recovery_params = params.recovery;
  if (s.scene.is_building()) {
    recovery_params.vertical = true;
    recovery_params.main_direction = s.scene.main_direction;
    recovery_params.snap_deg = params.scene.main_direction_snap_deg;
  }
  RecoveryResult recovery = timed_stage("recovery", run.report, [&] {
    return run_recovery(cloud, s.structure, recovery_params, visibility.highly);  // the enclosure: its pieces' boxes
  });
  if (params.artifacts) params.artifacts->recovery = recovery;
  run.report["counts"]["singular_segments"] = recovery.num_singular();
  run.report["counts"]["recovered_planes"] = params.hulls.recovered_planes ? recovery.recovered.size() : 0;
  run.report["counts"]["recovered_planes_covered"] = recovery.covered;  // one_plane_per_surface
  run.report["resolved"]["recovery"] = {{"distance", params.recovery.distance * s.structure.spacing},
                                        {"vertical", recovery_params.vertical},
                                        {"main_direction", recovery_params.main_direction},
                                        {"snap_deg", recovery_params.snap_deg}};
  log::info("[recovery] " + std::to_string(recovery.num_singular()) + " singular segments, " +
            std::to_string(recovery.recovered.size()) + " missing planes recovered" +
            (params.hulls.recovered_planes ? "" : " (not used: --no-recovery)"));
  return recovery;
}

// Stage 4: one convex polygon per plane, with its level and speed (building mode: walls reach the ground).
std::vector<ConvexPolygon> hulls_stage(const PointCloud& cloud, const SceneStage& s, const VisibilityResult& visibility,
                                       const RecoveryResult& recovery, Run& run) {
  const PipelineParams& params = run.params;
  HullsParams hulls_params = params.hulls;
  if (s.scene.is_building()) {
    hulls_params.walls_to_ground = true;
    hulls_params.ground_z = s.scene.ground_z;
  }
  std::vector<ConvexPolygon> polygons = timed_stage("hulls", run.report, [&] {
    return run_hulls(cloud, s.structure, visibility, recovery, hulls_params);
  });
  if (params.artifacts) params.artifacts->polygons = polygons;
  run.report["counts"]["polygons"] = polygons.size();
  run.report["resolved"]["hulls"] = {{"walls_to_ground", hulls_params.walls_to_ground},
                                     {"ground_z", hulls_params.ground_z},
                                     {"expand_reach", hulls_params.expand_reach * s.structure.spacing}};
  if (run.dump) {
    write_hulls_dump(cloud, s.structure, visibility, recovery, polygons, params.dump_dir);
    add_stage_fields_to_structure_json(params.dump_dir, s.structure, visibility, recovery, polygons);
  }
  return polygons;
}

// Building mode with a footprint (partition/footprint_prism.h): its walls, from below the partition box to
// above it, with plane ids after the detected and recovered planes'.
std::vector<ConvexPolygon> footprint_cuts(const SceneStructure& s, const RecoveryResult& recovery, const BBox& box,
                                          const Footprint& footprint) {
  const double reach = 0.1 * box.diagonal() + 1.0;
  return footprint_wall_polygons(footprint, box.min.z() - reach, box.max.z() + reach,
                                 static_cast<int>(s.planes.size() + recovery.recovered.size()));
}

// ... and the complex without the cells outside the footprint's prism (none left: the footprint misses the
// building's points).
CellComplex keep_cells_in_footprint(CellComplex cx, const Footprint& footprint, nlohmann::json& report) {
  std::size_t removed = 0;
  CellComplex kept = keep_cells_in_prism(cx, footprint, &removed);
  report["counts"]["cells_outside_footprint"] = removed;
  if (kept.cells.empty())
    throw Error(Status::DegenerateInput, "partition", "the footprint does not overlap the building's points");
  return kept;
}

// Stage 5: the partition of the (building mode: footprint) box by the polygons.
CellComplex partition_stage(const PointCloud& cloud, const SceneStage& s, const RecoveryResult& recovery,
                            const std::vector<ConvexPolygon>& polygons, Run& run) {
  const PipelineParams& params = run.params;
  PartitionInput pin;
  pin.polygons = polygons;
  pin.points_bbox = s.scene.is_building() ? building_box(cloud, s.structure, recovery, s.scene, params.footprint)
                                           : bounding_box(cloud.points);
  pin.adjacent_planes = polygon_adjacency(s.structure, recovery);
  const bool footprint = s.scene.is_building() && !params.footprint.empty();
  if (footprint) pin.cuts = footprint_cuts(s.structure, recovery, pin.points_bbox, params.footprint);
  if (run.dump) {  // the partition's whole input, for bench_partition --input
    AtomicFile out((std::filesystem::path(params.dump_dir) / "partition_input.json").string(), "dump");
    out.stream() << nlohmann::json(pin).dump() << '\n';
    out.commit();
  }
  CellComplex complex = timed_stage("partition", run.report, [&] {
    PartitionParams partition = params.partition;
    partition.exact_volumes = false;  // the extraction uses no volume
    CellComplex cx = run_partition(pin, partition);
    if (footprint) cx = keep_cells_in_footprint(std::move(cx), params.footprint, run.report);
    return cx;
  });
  if (params.artifacts) params.artifacts->complex = complex;
  run.report["counts"]["cells"] = complex.cells.size();
  run.report["counts"]["partition_facets"] = complex.facets.size();
  log::info("[partition] " + std::string(partitioner_name(params.partition.method)) + ": " +
            std::to_string(complex.cells.size()) + " cells, " + std::to_string(complex.facets.size()) + " facets");
  if (run.dump) write_partition_dump(complex, (std::filesystem::path(params.dump_dir) / "partition.ply").string());
  return complex;
}

/// A room's pieces' boxes (RecoveryParams::piece_boxes): the pieces' points on no detected plane vote on their
/// box's faces as a plane's inliers vote on its facets: each is assigned to its face (plane id planes.size() + q), its
/// normal turned to the side where the piece's inside takes the label of what lies under the room's floor
/// (the floor: scene.h room_ends, as the room rule found it; a room's model is its air, so a piece is outside).
/// `point_plane` becomes the structure's with those points assigned, and stays empty when there are none.
/// Returns how many points were assigned.
std::size_t piece_box_votes(const SceneStructure& structure, const VisibilityResult& visibility,
                              const RecoveryResult& recovery, const PipelineParams& params,
                              std::vector<int>& point_plane, std::vector<Vec3>& normals) {
  const int floor = room_ends(structure, visibility.highly, params.structure.max_distance * structure.spacing,
                              params.scene.wall_max_angle_deg).floor;
  const bool pieces = std::any_of(recovery.recovered.begin(), recovery.recovered.end(),
                                  [](const RecoveredPlane& rp) { return rp.piece >= 0; });
  if (floor < 0 || !pieces) return 0;
  // Under the floor is outside (its outward normal points down): the piece is outside, its points face in.
  const double side = visibility.outward_normal[static_cast<std::size_t>(floor)].z() < 0 ? -1.0 : 1.0;
  point_plane = structure.point_plane;
  std::size_t assigned = 0;
  for (std::size_t q = 0; q < recovery.recovered.size(); ++q) {
    const RecoveredPlane& face = recovery.recovered[q];
    if (face.piece < 0) continue;
    for (int p : face.support) {
      point_plane[static_cast<std::size_t>(p)] = static_cast<int>(structure.planes.size() + q);
      normals[static_cast<std::size_t>(p)] = side * face.plane.normal;
      ++assigned;
    }
  }
  return assigned;
}

// Stage 6: extraction of the surface by min-cut (then repair and the label clean-up).
PolygonMesh extraction_stage(const PointCloud& cloud, const std::vector<Vec3>& normals,
                             const std::vector<int>& point_plane, const SceneStage& s, const CellComplex& complex,
                             Run& run) {
  const PipelineParams& params = run.params;
  nlohmann::json& report = run.report;
  ExtractionInput ein;
  ein.complex = &complex;
  ein.cloud = &cloud;
  ein.normals = &normals;
  ein.point_plane = &point_plane;
  ein.spacing = s.structure.spacing;
  ExtractionParams extraction_params = params.extraction;
  extraction_params.building = s.scene.is_building();
  ExtractionResult extraction = timed_stage("extraction", report, [&] {
    return run_extraction(ein, extraction_params);
  });
  report["resolved"]["extraction"] = {{"building", extraction_params.building}};
  report["counts"]["forced_cells"] = extraction.forced_cells;
  if (params.artifacts) params.artifacts->inside = extraction.inside;
  report["counts"]["inside_cells"] =
      static_cast<std::size_t>(std::count(extraction.inside.begin(), extraction.inside.end(), true));
  report["counts"]["surface_facets"] = extraction.surface_facets;
  report["counts"]["voting_points"] = extraction.voting_points;
  report["counts"]["repaired_cells"] = extraction.repaired_cells;
  report["counts"]["cleanup_cells"] = extraction.cleanup_cells;
  report["counts"]["cleanup_skipped"] = extraction.cleanup_skipped;
  if (run.dump)
    write_labels_dump(complex, extraction.inside, (std::filesystem::path(params.dump_dir) / "labels.ply").string());
  return std::move(extraction.mesh);
}

// Stage 7: evaluation — the output is checked before anyone writes it; an invalid one stops the run
// unless --force.
void evaluation_stage(const PointCloud& cloud, PipelineResult& out, Run& run) {
  const PipelineParams& params = run.params;
  nlohmann::json& report = run.report;
  out.eval = timed_stage("eval", report, [&] { return run_eval(cloud, out.mesh, params.truth, params.eval); });
  const nlohmann::json ej = to_json(out.eval);
  report["validity"] = ej["validity"];
  report["accuracy"] = ej["accuracy"];
  report["face_sizes"] = ej["face_sizes"];
  report["counts"]["output_vertices"] = out.mesh.num_vertices();
  report["counts"]["output_faces"] = out.mesh.num_faces();
  for (FaceClass c : {FaceClass::Roof, FaceClass::Wall, FaceClass::Ground, FaceClass::Closure})
    report["counts"]["faces_by_class"][face_class_name(c)] =
        std::count(out.mesh.face_class.begin(), out.mesh.face_class.end(), c);
}

/// The indoor defaults a room gets (indoor_params): the parameters, and which of the two changed them.
struct IndoorChoice {
  PipelineParams params;
  bool absolute_floor = false;  ///< detection without the share floor
  bool full_detail = false;     ///< the min-cut's faces
  bool recovery = false;        ///< a room's recovery: regions split into pieces, level caps
};

/// A room's smallest plane, in points (SceneParams::indoor_min_region_points; 0: region_k + 1).
int room_min_region_points(const PipelineParams& params) {
  return params.scene.indoor_min_region_points > 0 ? params.scene.indoor_min_region_points
                                                    : params.structure.region_k + 1;
}

/// The detection a room gets (SceneParams::indoor_absolute_floor): no share floor, the room's smallest plane,
/// segments of 3 points.
void apply_absolute_floor(PipelineParams& params) {
  StructureParams& p = params.structure;
  p.min_region_fraction = 0.0;
  p.min_region_points = room_min_region_points(params);
  p.min_segment_points = std::min(p.min_segment_points, 3);
}

/// DESIGN.md §4, issue 25: a room (scene.h is_a_room) holds its furniture as structure the points support:
/// the parameters with SceneParams::indoor_absolute_floor / indoor_full_detail applied (detection with the
/// absolute floor only; the min-cut's faces), or none when neither changes anything. Said in the log.
std::optional<IndoorChoice> indoor_params(const PipelineParams& params, const PointCloud& cloud, const SceneStage& s,
                                          const VisibilityResult& visibility) {
  if (!is_a_room(cloud, s.structure, s.scene, visibility.highly, visibility.scanned_from_inside,
                 params.structure.max_distance * s.structure.spacing, params.scene.wall_max_angle_deg))
    return std::nullopt;
  IndoorChoice out{params};
  out.absolute_floor = params.scene.indoor_absolute_floor && params.structure.min_region_fraction > 0;
  if (out.absolute_floor) apply_absolute_floor(out.params);
  if (params.scene.indoor_full_detail) apply_detail(Detail::Full, out.params.extraction);
  out.full_detail = out.params.extraction.face_price != params.extraction.face_price ||
                    out.params.extraction.lambda != params.extraction.lambda;
  out.params.visibility.room = true;  // closed (VisibilityParams::close_room) whatever the normals say
  if (params.scene.indoor_near_partners) out.params.hulls.expand_reach = params.recovery.distance;
  out.recovery = params.scene.indoor_recovery && !params.recovery.vertical;
  if (out.recovery) {
    RecoveryParams& r = out.params.recovery;
    r.split_regions = r.level_caps = r.level_sides = true;
    r.piece_boxes = params.scene.indoor_piece_boxes;
    r.one_plane_per_surface = params.scene.indoor_one_plane_per_surface;
    r.min_piece_points = room_min_region_points(params);
  }
  if (!out.absolute_floor && !out.full_detail && !out.recovery) return std::nullopt;
  log::info(std::string("[scene] scanned from inside: a room, its furniture kept:") +
            (out.absolute_floor ? " planes of " + std::to_string(room_min_region_points(params)) +
                                      " points or more, whatever their share of the scene (--min-plane-share to choose);"
                                : "") +
            (out.full_detail ? " the min-cut's faces, detail full (--detail to choose);" : "") +
            (out.recovery ? " missing planes where their segments are, level tops over furniture, upright sides under its tops" +
                                std::string(out.params.recovery.piece_boxes ? ", each piece's box where no plane covers a face" : "")
                          : ""));
  return out;
}

/// A room's floor, walls and ceiling as whole planes (scene.h room_structure): the pieces of them the
/// furniture's shadows cut off join them, and (SceneParams::indoor_join_faces) so do the pieces of a piece of
/// furniture's face. Each plane keeps its visibility (a piece is gone; the plane it
/// joined keeps its label and outward side), and the pieces' inliers' normals turn to that side. Said in the
/// log and the report.
void join_room_pieces(const PointCloud& cloud, const PipelineParams& chosen, nlohmann::json& report,
                      SceneStage& scene, std::vector<Vec3>& normals, VisibilityResult& visibility) {
  RoomStructure room = room_structure(cloud, scene.structure, visibility.highly, chosen.structure.max_angle_deg,
                                      chosen.scene.indoor_join_faces ? visibility.outward_normal : std::vector<Vec3>{});
  report["counts"]["room_pieces_joined"] = room.joined - room.joined_faces;
  report["counts"]["furniture_faces_joined"] = room.joined_faces;
  if (room.joined == 0) return;
  log::info("[scene] room: " + std::to_string(room.joined - room.joined_faces) +
            " pieces of its floor, walls and ceiling and " + std::to_string(room.joined_faces) +
            " of its furniture's faces (cut off by shadows) joined their plane");
  scene.structure = std::move(room.structure);
  visibility = subset_visibility(visibility, room.from);
  orient_inlier_normals(scene.structure, visibility, normals);
  if (chosen.artifacts) {
    chosen.artifacts->structure = scene.structure;
    chosen.artifacts->visibility = visibility;
    chosen.artifacts->cloud.normals = normals;
  }
}

/// Stages 1 and 2 with the room rule (indoor_params): detection with the share floor, or at once with the
/// absolute floor when the input's normals already point into the box (normals_face_inward: a room's point at
/// its scanners); the room is decided on that pass, and detection runs again when the guess was wrong or a
/// room was found with the share floor (the first pass's seconds kept apart, `seconds.indoor_first_pass`).
/// Returns the parameters of the later stages.
PipelineParams structure_scene_and_visibility(const PointCloud& cloud, const SceneGround& ground, Run& run,
                                              SceneStage& scene, std::vector<Vec3>& normals,
                                              VisibilityResult& visibility) {
  const PipelineParams& params = run.params;
  nlohmann::json& report = run.report;
  const bool guess = params.scene.mode != SceneMode::Building && params.scene.indoor_absolute_floor &&
                     params.structure.min_region_fraction > 0 && normals_face_inward(cloud);
  PipelineParams first = params;
  if (guess) apply_absolute_floor(first);
  Run first_run{first, report, run.dump};
  scene = structure_and_scene(cloud, ground, first_run);
  visibility = visibility_stage(cloud, scene, normals, first_run);
  const std::optional<IndoorChoice> indoor = indoor_params(params, cloud, scene, visibility);
  const bool absolute_floor = indoor && indoor->absolute_floor;
  PipelineParams chosen = indoor ? indoor->params : params;
  if (guess != absolute_floor) {
    const double first_pass = report["seconds"]["structure"].get<double>() + report["seconds"]["scene"].get<double>() +
                              report["seconds"]["visibility"].get<double>();
    Run again{chosen, report, run.dump};
    scene = structure_and_scene(cloud, ground, again);
    visibility = visibility_stage(cloud, scene, normals, again);
    report["seconds"]["indoor_first_pass"] = first_pass;
  }
  if (indoor) join_room_pieces(cloud, chosen, report, scene, normals, visibility);
  if (indoor)
    report["scene"]["indoor"] = {
        {"absolute_floor", indoor->absolute_floor}, {"full_detail", indoor->full_detail},
        {"recovery", indoor->recovery}, {"piece_boxes", chosen.recovery.piece_boxes}, {"guessed_from_normals", guess},
        {"min_segment_points", chosen.structure.min_segment_points}};
  return chosen;
}

}  // namespace

PipelineResult run_pipeline(const PointCloud& input, const PipelineParams& params) {
  const BudgetScope budget_scope(params.budget);  // --max-seconds / --max-memory for the whole run
  const int threads = resolve_thread_count(params.threads);
  const ThreadLimit thread_limit(threads);
  PipelineResult out;
  nlohmann::json& report = out.report;
  report["version"] = HSR_VERSION;
  report["parameters"] = stage_params_to_json(params);
  report["origin"] = {input.origin.x(), input.origin.y(), input.origin.z()};
  report["threads"] = threads;  // 0: all cores
  report["budget"] = {{"max_seconds", params.budget.max_seconds},
                      {"max_memory_mb", params.budget.max_memory_mb},
                      {"physical_memory_mb", physical_memory_mb()}};
  report["counts"]["points"] = input.size();
  if (!input.crs.empty()) report["input_crs"] = input.crs;  // the input file's (LAS/LAZ WKT or EPSG:N)
  if (!params.footprint.empty()) report["footprint"] = footprint_to_json(params.footprint, input.origin);
  const double start = log::now_seconds(), cpu_start = log::cpu_seconds();
  Run run{params, report, !params.dump_dir.empty()};

  // A classified cloud (LAS/LAZ): ground, vegetation and noise are no building surface (scene.h,
  // split_by_class); the ground points give the building its ground. Object mode takes the points as they are.
  ClassSplit split = params.scene.mode == SceneMode::Object ? ClassSplit{} : split_by_class(input);
  if (split.applied) {
    if (split.building.empty())
      throw Error(Status::DegenerateInput, "scene",
                  "every point is classed ground, vegetation, noise or water: no building point to reconstruct");
    report["counts"]["class_ground_points"] = split.ground.size();
    report["counts"]["class_left_out_points"] = split.left_out;
    log::info("[scene] LAS classes: " + std::to_string(split.building.size()) + " points kept, " +
              std::to_string(split.ground.size()) + " ground (class 2) for the ground height, " +
              std::to_string(split.left_out) + " vegetation, noise and water left out");
  }
  const PointCloud& cloud = split.applied ? split.building : input;
  SceneGround ground;
  ground.points = std::move(split.ground);
  ground.raster = params.ground_raster;
  ground.origin = cloud.origin;
  ground.building_class_points = split.building_class_points;
  report["counts"]["reconstructed_points"] = cloud.size();

  SceneStage scene;
  std::vector<Vec3> normals;  // the structure's, turned to their planes' outward sides (stage 2)
  VisibilityResult visibility;
  const PipelineParams chosen = structure_scene_and_visibility(cloud, ground, run, scene, normals, visibility);
  Run rest{chosen, report, run.dump};  // from here on, the parameters the scene chose (indoor_params)
  const RecoveryResult recovery = recovery_stage(cloud, scene, visibility, rest);
  if (scene.scene.is_building()) {  // the box is known now (it holds the recovered walls' ends)
    snap_ground_to_box(cloud, scene.structure, recovery, params.partition.bbox_margin, params.footprint, scene.scene);
    report["scene"]["ground_z"] = scene.scene.ground_z;
    report["scene"]["ground_z_file"] = scene.scene.ground_z + cloud.origin.z();
    if (params.artifacts) params.artifacts->scene = scene.scene;
  }
  const std::vector<ConvexPolygon> polygons = hulls_stage(cloud, scene, visibility, recovery, rest);
  const CellComplex complex = partition_stage(cloud, scene, recovery, polygons, rest);
  std::vector<int> piece_point_plane;  // the structure's, with a room's pieces' points on their boxes (or empty)
  const std::size_t piece_points =
      piece_box_votes(scene.structure, visibility, recovery, chosen, piece_point_plane, normals);
  report["counts"]["piece_box_points"] = piece_points;
  out.mesh = extraction_stage(cloud, normals, piece_points ? piece_point_plane : scene.structure.point_plane, scene,
                              complex, rest);
  out.mesh.origin = cloud.origin;
  evaluation_stage(cloud, out, run);
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
