// The walls around the roofs a building's model left out (pipeline_runs.h; BuildingParams::left_out_roof_walls,
// DECISIONS #159 and #183): the first run's stages 3 to 7 again with four walls around each such roof, kept by
// the result.
#include "pipeline/pipeline_runs.h"

#include "partition/partition.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace hsr::pipeline_detail {

namespace {

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

}  // namespace

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
                                         static_cast<std::size_t>(b.left_out_roof_min_points), b.left_out_roof_max_under,
                                         b.left_out_roof_under_unexplained);
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

}  // namespace hsr::pipeline_detail
