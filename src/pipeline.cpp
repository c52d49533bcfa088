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
  const Vec3& n0 = s.planes.front().plane.normal;
  for (const auto& p : s.planes)
    if (std::abs(p.plane.normal.dot(n0)) < std::cos(5.0 * M_PI / 180.0)) return;
  throw Error(Status::DegenerateInput, "structure",
              std::to_string(s.planes.size()) + " plane(s) found, all parallel (points on one plane?): "
              "no volume can be enclosed");
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
/// them) and reaches down to the ground height.
BBox building_box(const PointCloud& cloud, const SceneStructure& building, const SceneResult& scene) {
  BBox box;
  for (const DetectedPlane& p : building.planes)
    for (int i : p.inliers) box.extend(cloud.points[static_cast<std::size_t>(i)]);
  box.min.z() = scene.ground_z;
  box.max.z() = std::max(box.max.z(), scene.ground_z);
  return box;
}

/// Building mode: the ground is the partition box's bottom, which the box rounds down to its grid (at most
/// diagonal / 1000): the ground height becomes that value, so walls dropped to it end on the box's bottom and
/// the report gives the height the model stands on.
void snap_ground_to_box(const PointCloud& cloud, const SceneStructure& building, double margin, SceneResult& scene) {
  ExactPoint lo, hi;
  partition_box(building_box(cloud, building, scene), margin, lo, hi);
  scene.ground_z = lo.z.get_d();
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
  report["counts"]["points"] = input.size();
  const double start = log::now_seconds(), cpu_start = log::cpu_seconds();
  const bool dump = !params.dump_dir.empty();

  // Stage 1: structure.
  const SceneStructure detected = timed_stage("structure", report, [&] {
    return run_structure(input, params.structure);
  });
  report["resolved"]["structure"] = detected.params;
  report["counts"]["planes"] = detected.planes.size();
  log::info("[structure] " + std::to_string(detected.planes.size()) + " planes, spacing r = " +
            std::to_string(detected.spacing));

  // Scene mode (DESIGN.md §4): object, or building (ground, roofs, walls; clutter left out).
  SceneResult scene = timed_stage("scene", report, [&] { return run_scene(input, detected, params.scene); });
  const SceneStructure structure = building_structure(input, detected, scene, params.scene);
  if (scene.is_building()) snap_ground_to_box(input, structure, params.partition.bbox_margin, scene);
  report["scene"] = to_json(scene);
  if (scene.is_building()) report["scene"]["ground_z_file"] = scene.ground_z + input.origin.z();
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
  if (dump) {  // the planes the later stages use (building mode: without ground and clutter), and the scene
    write_structure_dump(input, structure, params.dump_dir);
    write_scene_dump(scene, (std::filesystem::path(params.dump_dir) / "scene.json").string());
  }
  check_planes_can_enclose(structure, scene);

  // Stage 2: visibility. Its outward normal per plane decides which side of each plane is outside; every
  // inlier's normal is flipped to agree with it, so extraction does not depend on how well the input (or
  // the MST propagation of stage 1) oriented the normals.
  VisibilityResult visibility = timed_stage("visibility", report, [&] {
    return run_visibility(input, structure, params.visibility);
  });
  report["counts"]["roofs_turned_up"] = orient_roofs_up(structure, scene, visibility.outward_normal);
  PointCloud cloud = input;
  cloud.normals = structure.normals;
  const std::size_t flipped = orient_inlier_normals(structure, visibility, cloud.normals);
  if (params.artifacts) {
    params.artifacts->visibility = visibility;
    params.artifacts->cloud = cloud;
  }
  const auto highly = std::count(visibility.highly.begin(), visibility.highly.end(), true);
  report["counts"]["highly_visible_planes"] = highly;
  report["counts"]["normals_flipped"] = flipped;
  log::info("[visibility] " + std::to_string(highly) + " highly / " +
            std::to_string(structure.planes.size() - static_cast<std::size_t>(highly)) + " barely visible planes, " +
            std::to_string(flipped) + " inlier normals flipped to their plane's outward side");

  // Stage 3: recovery of planes the scanner missed.
  RecoveryParams recovery_params = params.recovery;
  if (scene.is_building()) {  // walls through roof outlines: one segment and the vertical suffice
    recovery_params.vertical = true;
    recovery_params.main_direction = scene.main_direction;
    recovery_params.snap_deg = params.scene.main_direction_snap_deg;
  }
  const RecoveryResult recovery = timed_stage("recovery", report, [&] {
    return run_recovery(cloud, structure, recovery_params);
  });
  if (params.artifacts) params.artifacts->recovery = recovery;
  report["counts"]["singular_segments"] = recovery.num_singular();
  report["counts"]["recovered_planes"] = params.hulls.recovered_planes ? recovery.recovered.size() : 0;
  log::info("[recovery] " + std::to_string(recovery.num_singular()) + " singular segments, " +
            std::to_string(recovery.recovered.size()) + " missing planes recovered" +
            (params.hulls.recovered_planes ? "" : " (not used: --no-recovery)"));

  // Stage 4: one convex polygon per plane, with its level and speed.
  HullsParams hulls_params = params.hulls;
  if (scene.is_building()) {  // walls stand on the ground
    hulls_params.walls_to_ground = true;
    hulls_params.ground_z = scene.ground_z;
  }
  const std::vector<ConvexPolygon> polygons = timed_stage("hulls", report, [&] {
    return run_hulls(cloud, structure, visibility, recovery, hulls_params);
  });
  if (params.artifacts) params.artifacts->polygons = polygons;
  report["counts"]["polygons"] = polygons.size();
  report["resolved"]["recovery"] = {{"distance", params.recovery.distance * structure.spacing},
                                    {"vertical", recovery_params.vertical},
                                    {"main_direction", recovery_params.main_direction},
                                    {"snap_deg", recovery_params.snap_deg}};
  report["resolved"]["hulls"] = {{"walls_to_ground", hulls_params.walls_to_ground},
                                 {"ground_z", hulls_params.ground_z}};
  if (dump) {
    write_hulls_dump(cloud, structure, visibility, recovery, polygons, params.dump_dir);
    add_stage_fields_to_structure_json(params.dump_dir, structure, visibility, recovery, polygons);
  }

  // Stage 5: partition.
  PartitionInput pin;
  pin.polygons = polygons;
  pin.points_bbox = scene.is_building() ? building_box(cloud, structure, scene) : bounding_box(cloud.points);
  pin.adjacent_planes = polygon_adjacency(structure, recovery);
  const CellComplex complex = timed_stage("partition", report, [&] {
    PartitionParams partition = params.partition;
    partition.exact_volumes = false;  // the extraction uses no volume
    return run_partition(pin, partition);
  });
  if (params.artifacts) params.artifacts->complex = complex;
  report["counts"]["cells"] = complex.cells.size();
  report["counts"]["partition_facets"] = complex.facets.size();
  log::info("[partition] " + std::string(partitioner_name(params.partition.method)) + ": " +
            std::to_string(complex.cells.size()) + " cells, " + std::to_string(complex.facets.size()) + " facets");
  if (dump) write_partition_dump(complex, (std::filesystem::path(params.dump_dir) / "partition.ply").string());

  // Stage 6: extraction.
  ExtractionInput ein;
  ein.complex = &complex;
  ein.cloud = &cloud;
  ein.point_plane = &structure.point_plane;
  ein.spacing = structure.spacing;
  ExtractionParams extraction_params = params.extraction;
  extraction_params.building = scene.is_building();
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
  if (dump)
    write_labels_dump(complex, extraction.inside, (std::filesystem::path(params.dump_dir) / "labels.ply").string());
  out.mesh = std::move(extraction.mesh);
  out.mesh.origin = input.origin;

  // Stage 7: evaluation — the output is checked before anyone writes it.
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
