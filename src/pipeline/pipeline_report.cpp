// run_pipeline's report fields and dumps that are not a stage's own (pipeline_internal.h).
#include "pipeline/pipeline_internal.h"

#include "core/atomic_file.h"
#include "core/face_class.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

namespace hsr::pipeline_detail {

namespace {

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

}  // namespace

std::string fmt_seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f s", s);
  return buf;
}

void report_header(const PointCloud& input, const PipelineParams& params, int threads, nlohmann::json& report) {
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
}

void report_class_split(const ClassSplit& split, nlohmann::json& report) {
  if (!split.applied) return;
  report["counts"]["class_ground_points"] = split.ground.size();
  report["counts"]["class_left_out_points"] = split.left_out;
  log::info("[scene] LAS classes: " + std::to_string(split.building.size()) + " points kept, " +
            std::to_string(split.ground.size()) + " ground (class 2) for the ground height, " +
            std::to_string(split.left_out) + " vegetation, noise and water left out");
}

void report_scene(const PointCloud& cloud, const SceneResult& scene, const SceneStructure& structure,
                  const Raster* ground_raster, nlohmann::json& report) {
  report["scene"] = to_json(scene);
  if (ground_raster) report["scene"]["ground_raster"] = ground_raster->source;
  report["counts"]["building_planes"] = structure.planes.size();
  log::info("[scene] " + std::string(scene_mode_name(scene.mode)) + ": " + scene.reason);
  if (scene.is_building())
    log::info("[scene] ground at z = " + std::to_string(scene.ground_z + cloud.origin.z()) + " (" +
              ground_source_name(scene.ground_source) + "); " + std::to_string(scene.count(PlaneRole::Roof)) +
              " roof, " + std::to_string(scene.count(PlaneRole::Wall)) + " wall planes kept, " +
              std::to_string(scene.count(PlaneRole::Ground) + scene.count(PlaneRole::Clutter)) +
              " ground and clutter planes left out");
}

void report_eval(const PipelineResult& out, nlohmann::json& report) {
  const nlohmann::json ej = to_json(out.eval);
  report["validity"] = ej["validity"];
  report["accuracy"] = ej["accuracy"];
  report["accuracy"]["mesh_samples"] = out.eval.mesh_samples;  // the samples the m2p figures rest on
  report["face_sizes"] = ej["face_sizes"];
  report["counts"]["output_vertices"] = out.mesh.num_vertices();
  report["counts"]["output_faces"] = out.mesh.num_faces();
  for (FaceClass c : {FaceClass::Roof, FaceClass::Wall, FaceClass::Ground, FaceClass::Closure})
    report["counts"]["faces_by_class"][face_class_name(c)] =
        std::count(out.mesh.face_class.begin(), out.mesh.face_class.end(), c);
}

void report_unexplained(const PointCloud& cloud, const std::vector<bool>& explain, double spacing,
                        const PolygonMesh& mesh, const std::vector<double>& point_distance, const EvalParams& params,
                        nlohmann::json& report) {
  std::vector<Vec3> points;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (explain[i]) points.push_back(cloud.points[i]);
  const double distance = params.unexplained_distance * spacing;
  std::size_t unexplained = 0;
  if (point_distance.size() == cloud.size()) {  // the evaluation's distances: no second pass over the points
    for (std::size_t i = 0; i < cloud.size(); ++i) unexplained += explain[i] && point_distance[i] > distance;
  } else {
    unexplained = count_farther(points, mesh, distance);
  }
  const double share = points.empty() ? 0.0 : static_cast<double>(unexplained) / static_cast<double>(points.size());
  report["counts"]["points_to_explain"] = points.size();
  report["counts"]["points_left_out"] = cloud.size() - points.size();
  report["counts"]["points_unexplained"] = unexplained;
  report["quality"]["points_unexplained_share"] = share;
  report["quality"]["unexplained_distance"] = distance;
  if (share <= params.unexplained_warn_share) return;
  char pct[32];
  std::snprintf(pct, sizeof pct, "%.1f %%", 100.0 * share);
  log::warn("[eval] " + std::to_string(unexplained) + " of the " + std::to_string(points.size()) +
            " points to explain (" + pct + ") lie farther than " + std::to_string(distance) +
            " from the model: a part of the building (or of the object), a tree or a neighbour is not modelled (counts.points_unexplained)");
}

void report_quality(const SceneResult& scene, const PointsToExplain& explain, const SceneParams& params,
                    nlohmann::json& report) {
  nlohmann::json& q = report["quality"];
  q["points_explained_share"] = 1.0 - q.value("points_unexplained_share", 0.0);
  q["p2m_mean"] = report["accuracy"].value("p2m_mean", 0.0);
  q["scene"] = scene_mode_name(scene.mode);
  q["scene_choice"] = params.mode == SceneMode::Auto ? "auto" : "given";
  q["scene_margin"] = scene_margin(scene, params);
  q["ground_source"] = ground_source_name(scene.ground_source);
  nlohmann::json removed = nlohmann::json::object();
  std::size_t total = 0;
  const auto add = [&](const char* rule, std::size_t n) {
    if (n == 0) return;
    removed[rule] = n;
    total += n;
  };
  const nlohmann::json& counts = report["counts"];
  add("las_class_ground", counts.value("class_ground_points", std::size_t{0}));
  add("las_class_vegetation_noise_water", counts.value("class_left_out_points", std::size_t{0}));
  add("ground_planes", explain.ground_plane_points);
  add("clutter_planes", explain.clutter_plane_points);
  add("low_points_on_no_plane", explain.low_points);
  q["removed_points"] = removed;
  q["removed_points_total"] = total;
}

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

void write_scene_dump(const SceneResult& scene, const std::string& path) {
  nlohmann::json j = to_json(scene);
  j["roles"] = nlohmann::json::array();
  for (PlaneRole r : scene.roles) j["roles"].push_back(plane_role_name(r));
  AtomicFile out(path, "dump");
  out.stream() << j.dump(2) << '\n';
  out.commit();
}

void write_partition_input_dump(const PartitionInput& pin, const std::string& dir) {
  AtomicFile out((std::filesystem::path(dir) / "partition_input.json").string(), "dump");
  out.stream() << nlohmann::json(pin).dump() << '\n';
  out.commit();
}

}  // namespace hsr::pipeline_detail
