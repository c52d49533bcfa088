// Step 0 of run_pipeline (pipeline_runs.h; scene/plan.h plan_scene_choice, issue 42 item 2): when `auto` was
// near its rule's edge, the chain again with the other kind, and the valid solid that explains more of the
// points kept.
#include "pipeline/pipeline_runs.h"

#include "core/log.h"
#include "scene/plan.h"

namespace hsr::pipeline_detail {

/// Step 0's failures that are a kind's, not the input's: no plane, nothing to enclose (the other kind may
/// make a model where this one made none).
bool made_no_model(const Error& e) { return e.status() == Status::NoPlanes || e.status() == Status::DegenerateInput; }

namespace {

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


}  // namespace

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

/// DECISIONS #227. A small scan (plan_small_scan) without a footprint whose first detection made no model in either
/// kind (`e`: step 0 tried the other where it could) is detected again with the small-scan rule's smaller planes, as
/// when its first detection holds no plane (#136): the memo the chain and steps 0 to 7 then run on, its detection
/// that one (asked: the first's parameters; used: the smaller planes, so the report says `structure_small_scan`).
/// Nothing when the first detection had the smaller planes already, or the scan is no small one. Why: a noisy
/// sparse scan (Vaihingen_00015 with 3 cm of noise, 95 points, a fresh draw) held one plane of 30 points, a wall,
/// so the rule's smaller planes were never tried; `auto` said object and one plane encloses nothing. Decided by
/// the result (no model), not by one more figure of the first planes.
std::optional<DetectionMemo> small_planes_after_no_model(const PointCloud& cloud, const PipelineParams& params,
                                                         const Error& e, const DetectionMemo& memo) {
  if (!made_no_model(e) || !memo.detected || !small_planes_may_follow(cloud, params, memo)) return std::nullopt;
  const std::optional<StructureParams> small = plan_small_scan(cloud.size(), memo.asked, params.scene);
  log::warn("[structure] " + std::string(e.what()) + ": a small scan (" + std::to_string(cloud.size()) +
            " points) detected again with planes of " + std::to_string(small->min_region_points) + " points (#227)");
  DetectionMemo again;
  again.record = true;
  again.asked = memo.asked;
  again.used = *small;
  again.graph = memo.graph;
  again.detected = run_structure(cloud, *small, &again.graph);
  return again;
}

bool small_planes_may_follow(const PointCloud& cloud, const PipelineParams& params, const DetectionMemo& memo) {
  if (!params.footprint.empty() || !memo.record) return false;
  if (!same_detection(memo.asked, memo.used)) return false;  // the smaller planes already (structure_stage)
  return plan_small_scan(cloud.size(), memo.asked, params.scene).has_value();
}

bool later_runs_may_follow(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                          const SceneResult& seen, const SceneResult& scene, const nlohmann::json& report,
                          const DetectionMemo& memo) {
  if (seen.is_building() || scene.is_building()) return true;  // steps 5 to 7, step 6's run beside the first
  const bool small_scan = report.contains("structure_small_scan");  // as choose_by_result asks it
  if (plan_scene_choice(params.scene, seen, cloud.size(), ground.building_class_points, small_scan)) return true;
  return small_planes_may_follow(cloud, params, memo);
}

}  // namespace hsr::pipeline_detail
