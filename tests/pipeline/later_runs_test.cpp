// Whether a run may follow the first (pipeline_runs.h later_runs_may_follow, DECISIONS #237): decided before the
// first run's partition, it frees the memo's detection and kNN graph and measures the mesh -> points figures in the
// evaluation where no run follows (a room far from `auto`'s edge), and keeps them where one may (step 0 near the
// edge, the small planes after no model, a building's steps 5 to 7). The model and its figures do not depend on it.
#include "eval/eval.h"
#include "pipeline/pipeline.h"
#include "pipeline/pipeline_runs.h"
#include "synth/synth.h"

#include <gtest/gtest.h>

namespace hsr {
namespace {

using pipeline_detail::DetectionMemo;
using pipeline_detail::later_runs_may_follow;

/// `points` points (their count is all the rule reads of them).
PointCloud cloud_of(std::size_t points) {
  PointCloud cloud;
  cloud.points.assign(points, Vec3::Zero());
  return cloud;
}

/// The memo of a first run that detected with the defaults (the asked and the used detection the same).
DetectionMemo recorded_memo() {
  DetectionMemo memo;
  memo.record = true;
  memo.asked = memo.used = StructureParams{};
  return memo;
}

/// A scene stage's result of `mode` with `auto`'s two figures.
SceneResult scene_of(SceneMode mode, double roof_share, double layered_share) {
  SceneResult s;
  s.mode = mode;
  s.roof_share = roof_share;
  s.layered_share = layered_share;
  return s;
}

TEST(LaterRuns, NoneAfterARoomFarFromAutosEdge) {
  // The office's six rooms: 0.50 of the points facing up (building: >= 0.70), 0.80 layered (building: <= 0.50).
  const SceneResult room = scene_of(SceneMode::Object, 0.50, 0.80);
  const PipelineParams params;
  EXPECT_FALSE(later_runs_may_follow(cloud_of(72899), SceneGround{}, params, room, room, nlohmann::json::object(),
                                     recorded_memo()));
}

TEST(LaterRuns, StepZeroNearAutosEdge) {
  const SceneResult near = scene_of(SceneMode::Object, 0.65, 0.45);  // 0.05 from rule (a)'s edge
  const PipelineParams params;
  EXPECT_TRUE(later_runs_may_follow(cloud_of(72899), SceneGround{}, params, near, near, nlohmann::json::object(),
                                    recorded_memo()));
  PipelineParams object = params;  // the kind given: no step 0
  object.scene.mode = SceneMode::Object;
  EXPECT_FALSE(later_runs_may_follow(cloud_of(72899), SceneGround{}, object, near, near, nlohmann::json::object(),
                                     recorded_memo()));
}

TEST(LaterRuns, ABuildingsStepsFiveToSeven) {
  const SceneResult building = scene_of(SceneMode::Building, 0.9, 0.1);
  const SceneResult object = scene_of(SceneMode::Object, 0.9, 0.1);
  PipelineParams params;
  params.scene.mode = SceneMode::Building;
  EXPECT_TRUE(later_runs_may_follow(cloud_of(72899), SceneGround{}, params, building, building,
                                    nlohmann::json::object(), recorded_memo()));
  params.scene.mode = SceneMode::Object;  // an object's scene stage made a building by its plan
  EXPECT_TRUE(later_runs_may_follow(cloud_of(72899), SceneGround{}, params, object, building,
                                    nlohmann::json::object(), recorded_memo()));
}

TEST(LaterRuns, TheSmallPlanesAfterNoModel) {
  // 100 points: fewer than small_scan_size planes of the detection's 30, and a fifth of them (small_scan_planes)
  // fewer than 30: plan_small_scan has smaller planes, #227 may detect again.
  const PipelineParams params;
  const std::size_t small = 100;
  const SceneResult room = scene_of(SceneMode::Object, 0.50, 0.80);
  PipelineParams object = params;  // no step 0 either way
  object.scene.mode = SceneMode::Object;
  EXPECT_TRUE(later_runs_may_follow(cloud_of(small), SceneGround{}, object, room, room, nlohmann::json::object(),
                                    recorded_memo()));
  DetectionMemo smaller = recorded_memo();  // the first detection had the smaller planes already
  smaller.used.min_region_points = 3;
  EXPECT_FALSE(later_runs_may_follow(cloud_of(small), SceneGround{}, object, room, room, nlohmann::json::object(),
                                     smaller));
}

// A room's run where no run follows measures its mesh -> points figures in its evaluation: the same figures as an
// evaluation of its model at once, in the result and in the report.
TEST(LaterRuns, ARoomsFiguresAreTheSameMeasuredInItsEvaluation) {
  SynthParams p;
  p.seed = 1;
  p.office.rooms = 1;
  const SynthScan scan = run_synth("office", p);
  const PipelineParams params;
  const PipelineResult r = run_pipeline(scan.cloud, params);
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_FALSE(r.report["scene"].contains("choice"));  // no step 0: the room is far from auto's edge
  const EvalResult at_once = run_eval(scan.cloud, r.mesh, nullptr, params.eval);
  EXPECT_FALSE(r.eval.m2p_later);
  EXPECT_EQ(r.eval.accuracy.m2p_mean, at_once.accuracy.m2p_mean);
  EXPECT_EQ(r.eval.accuracy.m2p_max, at_once.accuracy.m2p_max);
  EXPECT_EQ(r.report["accuracy"]["m2p_mean"].get<double>(), at_once.accuracy.m2p_mean);
  EXPECT_TRUE(r.eval.point_distance.empty());
}

}  // namespace
}  // namespace hsr
