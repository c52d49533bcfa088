// What run_pipeline (pipeline.cpp) uses around the stages: timing a stage into the report, and the per-stage
// dumps and report fields that are not a stage's own (pipeline_report.cpp).
#pragma once

#include "pipeline/pipeline.h"

#include "core/error.h"
#include "core/log.h"

#include <new>
#include <string>

namespace hsr::pipeline_detail {

std::string fmt_seconds(double s);

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

/// The report's header: version, every stage's parameters as given, origin, threads, budget, input counts.
void report_header(const PointCloud& input, const PipelineParams& params, int threads, nlohmann::json& report);

/// The report's counts and log line of the LAS class split (scene.h split_by_class), when it applied.
void report_class_split(const ClassSplit& split, nlohmann::json& report);

/// The report's and log's lines on the scene stage's result.
void report_scene(const PointCloud& cloud, const SceneResult& scene, const SceneStructure& structure,
                  const Raster* ground_raster, nlohmann::json& report);

/// The report's validity, accuracy, face sizes and output counts from the evaluation.
void report_eval(const PipelineResult& out, nlohmann::json& report);

/// The points the model must explain (`explain`, scene.h points_to_explain) farther than
/// EvalParams::unexplained_distance r from `mesh` (issue 42): counts.points_to_explain, points_left_out (the
/// rest), points_unexplained, and quality.points_unexplained_share and unexplained_distance (absolute); a
/// warning above EvalParams::unexplained_warn_share. `point_distance`: every point's distance to `mesh` as the
/// evaluation measured it (EvalResult::point_distance), or empty: then they are measured here.
void report_unexplained(const PointCloud& cloud, const std::vector<bool>& explain, double spacing,
                        const PolygonMesh& mesh, const std::vector<double>& point_distance, const EvalParams& params,
                        nlohmann::json& report);

/// The report's `quality` (issue 42 item 4), after report_unexplained and report_eval: the share of the points
/// explained, p2m, the scene and how it was chosen (auto or given) with auto's margin (scene.h scene_margin), the
/// ground's source, and every rule that removed points with how many (removed_points; LAS classes, ground
/// planes, clutter planes, low points on no plane; rules that removed none are left out).
void report_quality(const SceneResult& scene, const PointsToExplain& explain, const SceneParams& params,
                    nlohmann::json& report);

/// structure.json (written by stage 1's dump) gains the per-plane fields of stages 2–4 and the recovered planes.
void add_stage_fields_to_structure_json(const std::string& dir, const SceneStructure& structure,
                                        const VisibilityResult& visibility, const RecoveryResult& recovery,
                                        const std::vector<ConvexPolygon>& polygons);

/// DIR/scene.json: the mode, the ground, and the role of every detected plane (structure.json numbers the
/// planes the later stages use, i.e. the roof and wall planes in building mode).
void write_scene_dump(const SceneResult& scene, const std::string& path);

/// DIR/partition_input.json: the partition's whole input, for bench_partition --input.
void write_partition_input_dump(const PartitionInput& pin, const std::string& dir);

/// A building's own frame (BuildingParams::own_frame): the turn about z, in radians, that puts its main
/// direction (SceneResult::main_direction, in [0, 90) degrees, a direction modulo 90) along an axis, the
/// smaller of the turns onto x and onto y; 0 for a building already on the axes.
double own_frame_turn(double main_direction);

/// What the chain is given, turned about z by `angle` radians about the local origin: points and normals, the
/// classified ground points, the footprint, the scanners of normal orientation and the truth mesh (`truth` is
/// filled and params.truth points at it when a truth is given).
PointCloud turned_cloud(const PointCloud& cloud, double angle);
std::vector<Vec3> turned_points(const std::vector<Vec3>& points, double angle);
PipelineParams turned_params(const PipelineParams& params, double angle, PolygonMesh& truth);

/// The mesh's vertices turned about z by `angle` radians about the local origin.
void turn_mesh(PolygonMesh& mesh, double angle);

}  // namespace hsr::pipeline_detail
