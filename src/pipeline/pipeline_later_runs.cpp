// Steps 5, 6 and 7 of run_pipeline (pipeline_runs.h): a building scan small enough is reconstructed again with
// finer outline segments (step 5, DECISIONS #116), with tighter planes (step 6, #137; its run may begin beside the
// first, #201) and with a gable's two halves split (step 7, #215, off by default); each later model is kept only
// when it explains the points better (pipeline_judge.cpp).
#include "pipeline/pipeline_runs.h"

#include "core/log.h"
#include "core/spacing.h"

#include <algorithm>

namespace hsr::pipeline_detail {

namespace {

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

}  // namespace

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
  if (!small_enough_to_run_again(cloud.size(), params.scene)) return;
  if (out.report["quality"].value("scene", "") != "building" || !out.report["counts"].contains("outline_segments"))
    return;
  if (out.report["scene"].contains("own_frame_turn_deg")) return;  // the own frame's run: not tried (#94, off)
  if (one_second_run(params)) return;  // step 6's run takes step 5's finer outline
  const nlohmann::json first_scene = out.report["scene"], first_choice = out.report["quality"]["scene_choice"];
  const nlohmann::json first_far = out.report["counts"].value("gable_half_candidates_far", nlohmann::json());
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

/// Whether step 6 (try_tighter_planes) runs on the model `report` is of: a building scan, small enough
/// (SceneParams::auto_choice_max_points), not the outline prism (no planes), not the own frame's run (#94, off),
/// and the tighter distance tighter than the detection's.
bool tighter_planes_apply(const PointCloud& cloud, const PipelineParams& params, const nlohmann::json& report) {
  const BuildingParams& b = params.scene.building;
  if (!(b.tighter_planes_distance > 0.0 && b.tighter_planes_distance < params.structure.max_distance)) return false;
  if (!small_enough_to_run_again(cloud.size(), params.scene)) return false;
  if (report["quality"].value("scene", "") != "building" || !report["counts"].contains("outline_segments"))
    return false;
  return !report["scene"].contains("own_frame_turn_deg") && !report["quality"].contains("fallback");
}

/// Step 6's run on the model whose scene report is `scene` (step 0's choice kept: building mode), with outline
/// segments of `segment_points` points. `memo` is read only (the first run's kNN graph, #150).
TighterPlanesRun run_tighter_planes(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                                    const nlohmann::json& header, const nlohmann::json& scene, int segment_points,
                                    double distance, DetectionMemo& memo) {
  TighterPlanesRun run;
  run.segment_points = segment_points;
  PipelineParams again = params;
  if (scene.contains("choice")) again.scene.mode = SceneMode::Building;  // step 0 kept the building
  again.structure.min_segment_points = segment_points;
  again.structure.max_distance = distance;
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

namespace {

/// The outline segments' count of boundary points of step 6's run: step 5's finest with one second run
/// (one_second_run), else the count step 5 kept (`scene`: the kept model's scene report).
int step6_segment_points(const PipelineParams& params, const nlohmann::json& scene) {
  if (one_second_run(params)) return params.scene.building.finer_outline_points;
  return scene.contains("finer_outline")
             ? scene["finer_outline"].value("kept_segment_points", params.structure.min_segment_points)
             : params.structure.min_segment_points;
}

/// Step 6's judgement of its run `run` (made with the planes' inliers within `distance` r) against the model kept
/// so far in `out`: keep_tighter_planes (valid; p2m lower by finer_outline_min_gain; no more slivers unless fewer
/// points are far; the same ground) and no more roof that no point sees (no_more_unseen_roof). When kept, `out` is
/// the run's model with the scene report's earlier steps' entries. Returns the report's entry.
nlohmann::json keep_tighter_run(const PointCloud& cloud, const PipelineParams& params, TighterPlanesRun& run,
                                double distance, PipelineResult& out) {
  const BuildingParams& b = params.scene.building;
  const nlohmann::json first_scene = out.report["scene"], first_choice = out.report["quality"]["scene_choice"];
  const nlohmann::json first_seconds = out.report["seconds"], first_resolved = out.report["resolved"];
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
  t["distance"] = distance;
  t["kept"] = keep;
  if (!failed) t["same_ground"] = same_ground(out.report, other.report);
  if (by_p2m && out.eval.validity.valid() && b.unseen_roof_distance > 0) {
    report_unseen_roof(unseen, t);
  }
  if (keep) {
    log::info("[scene] building: planes' inliers within " + std::to_string(distance) + " r: p2m " +
              std::to_string(out.eval.accuracy.p2m_mean) + " -> " + std::to_string(other.eval.accuracy.p2m_mean) +
              ", kept");
    out = std::move(other);
    if (params.artifacts) *params.artifacts = std::move(run.artifacts);
    for (const char* key : {"choice", "finer_outline", "left_out_roofs", "tighter_planes"})
      if (first_scene.contains(key)) out.report["scene"][key] = first_scene[key];
    if (first_seconds.contains("finer_outline")) out.report["seconds"]["finer_outline"] = first_seconds["finer_outline"];
    if (first_seconds.contains("tighter_planes")) out.report["seconds"]["tighter_planes"] = first_seconds["tighter_planes"];
    out.report["quality"]["scene_choice"] = first_choice;
  }
  return t;
}

}  // namespace

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
  const nlohmann::json first_scene = out.report["scene"];
  // the outline segments' count of points of step 6's run (step 5's kept one, or its finest with one second run)
  const int segment_points = step6_segment_points(params, first_scene);
  const double t0 = log::now_seconds();
  TighterPlanesRun run = early && early->segment_points == segment_points
                             ? std::move(*early)
                             : run_tighter_planes(cloud, ground, params, header, first_scene, segment_points,
                                                  b.tighter_planes_distance, memo);
  early.reset();
  if (run.budget) std::rethrow_exception(run.budget);  // the run's budget holds for every run
  nlohmann::json t = keep_tighter_run(cloud, params, run, b.tighter_planes_distance, out);
  if (one_second_run(params)) t["outline_segment_points"] = segment_points;  // step 5's with it (#189)
  if (!run.beside.empty()) t["beside"] = run.beside;
  out.report["scene"]["tighter_planes"] = t;
  out.report["seconds"]["tighter_planes"] = log::now_seconds() - t0;
}

namespace {

/// Whether step 6's second distance runs on the kept model `out` (BuildingParams::tighter_planes_second_distance):
/// step 6 ran and its model was not kept, the second distance is tighter than step 6's, the scan holds at most
/// tighter_planes_second_max_points points, and the kept model leaves at least the detection's smallest plane
/// (StructureParams::min_region_points as resolved) of points farther than its detection's inlier distance. Why:
/// a tighter detection can only gain where the model leaves points unexplained, and a plane's worth of them is what
/// a plane of its own would take; where step 6's distance gained, the model has its tighter planes already.
bool tighter_planes_second_applies(const PointCloud& cloud, const PipelineParams& params, const PipelineResult& out) {
  const BuildingParams& b = params.scene.building;
  if (!(b.tighter_planes_second_distance > 0.0) || !tighter_planes_apply(cloud, params, out.report)) return false;
  const nlohmann::json step6 = out.report["scene"].value("tighter_planes", nlohmann::json::object());
  if (step6.empty() || step6.value("kept", false)) return false;  // a second chance where step 6 gained nothing
  if (!(b.tighter_planes_second_distance < b.tighter_planes_distance)) return false;
  if (b.tighter_planes_second_max_points > 0 && cloud.size() > static_cast<std::size_t>(b.tighter_planes_second_max_points))
    return false;
  const nlohmann::json structure = out.report.value("resolved", nlohmann::json::object())
                                       .value("structure", nlohmann::json::object());
  const std::size_t smallest_plane =
      structure.value("min_region_points", static_cast<std::size_t>(params.structure.min_region_points));
  return out.eval.point_distance.size() == cloud.size() && far_points_of_model(cloud, params, out) >= smallest_plane;
}

}  // namespace

/// Step 6's second distance (BuildingParams::tighter_planes_second_distance, DECISIONS #246): where the kept model
/// leaves a plane's worth of points far (tighter_planes_second_applies), the building is reconstructed once more
/// with its planes' inliers within the second distance, with step 6's outline segments, and judged as step 6's run
/// (keep_tighter_run). Report: scene.tighter_planes_second. Why: see BuildingParams::tighter_planes_second_distance.
void try_tighter_planes_second(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                               const nlohmann::json& header, PipelineResult& out, DetectionMemo& memo) {
  const BuildingParams& b = params.scene.building;
  if (!tighter_planes_second_applies(cloud, params, out)) return;
  const double t0 = log::now_seconds();
  const nlohmann::json scene = out.report["scene"];
  TighterPlanesRun run = run_tighter_planes(cloud, ground, params, header, scene, step6_segment_points(params, scene),
                                            b.tighter_planes_second_distance, memo);
  if (run.budget) std::rethrow_exception(run.budget);  // the run's budget holds for every run
  nlohmann::json t = keep_tighter_run(cloud, params, run, b.tighter_planes_second_distance, out);
  out.report["scene"]["tighter_planes_second"] = t;
  out.report["seconds"]["tighter_planes_second"] = log::now_seconds() - t0;
}

namespace {

/// Step 7's count and gate, on the kept model only (DECISIONS #239; until then every run of the chain counted its
/// own candidates, though only the kept model's were read): the candidates (split_candidates on the run's
/// SplitInput; report counts.gable_half_candidates) and, where the model's distances are kept, #228's gate
/// (split_gate; report counts.gable_half_candidates_far, scene.split_gate). Whether step 7's run is to be made: a
/// candidate, and with split_where_left_far the gate's yes. Why here: at `-j 1` by turns this runs beside the
/// next building's first runs (DECISIONS #235), not in every run's first.
bool split_run_asked(const PointCloud& cloud, const BuildingParams& b, PipelineResult& out) {
  const double t0 = log::now_seconds();
  const SplitInput& input = *out.split_input;
  const SplitCandidates candidates = split_candidates(cloud, input, b);
  out.report["counts"]["gable_half_candidates"] = candidates.size();
  bool gate_run = false;
  if (!candidates.empty() && out.eval.point_distance.size() == cloud.size()) {
    const SplitGate g = split_gate(cloud, candidates, out.eval.point_distance, input.spacing, input.min_region_points, b);
    gate_run = g.may_gain(b) || !out.eval.validity.valid();
    out.report["counts"]["gable_half_candidates_far"] = g.far_candidates;
    out.report["scene"]["split_gate"] = {{"far_candidates", g.far_candidates},
                                         {"gain_share", g.distance_sum > 0 ? g.gain / g.distance_sum : 0.0},
                                         {"run", gate_run}};
  }
  out.report["seconds"]["split_count"] = log::now_seconds() - t0;
  return !candidates.empty() && (!b.split_where_left_far || gate_run);
}

}  // namespace

/// Step 7 (BuildingParams::gable_halves, DECISIONS #215; two_surface_planes, #223): a building scan whose kept
/// model has a roof plane holding a gable's two halves or two surfaces (split_run_asked: counted on the kept model,
/// gated where split_where_left_far asks) is reconstructed once more with those planes split
/// (DetectionMemo::split_gables), with the kept model's detection and outline segments, and keep_tighter_planes
/// decides by the result as in step 6 (valid; p2m lower by finer_outline_min_gain of it; no more slivers unless
/// fewer points are far; the same ground). Report: scene.gable_halves. Why: see BuildingParams::gable_halves.
void try_gable_halves(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                      const nlohmann::json& header, PipelineResult& out, DetectionMemo& memo) {
  const BuildingParams& b = params.scene.building;
  if (!splits_roof_planes(b) || b.small_plane_points <= 0 || !memo.record || !out.split_input) return;
  if (out.report["quality"].value("scene", "") != "building" || out.report["quality"].contains("fallback") ||
      out.report["scene"].contains("own_frame_turn_deg"))
    return;
  if (!split_run_asked(cloud, b, out)) return;
  const double t0 = log::now_seconds();
  const nlohmann::json first_scene = out.report["scene"], first_choice = out.report["quality"]["scene_choice"];
  const nlohmann::json first_far = out.report["counts"].value("gable_half_candidates_far", nlohmann::json());
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
    for (const char* key : {"choice", "finer_outline", "left_out_roofs", "tighter_planes", "split_gate"})
      if (first_scene.contains(key)) out.report["scene"][key] = first_scene[key];
    if (first_far.is_number()) out.report["counts"]["gable_half_candidates_far"] = first_far;
    for (const char* key : {"finer_outline", "tighter_planes"})
      if (first_seconds.contains(key)) out.report["seconds"][key] = first_seconds[key];
    out.report["quality"]["scene_choice"] = first_choice;
  }
  out.report["scene"]["gable_halves"] = t;
  out.report["seconds"]["gable_halves"] = log::now_seconds() - t0;
}

}  // namespace hsr::pipeline_detail
