// The runs of one scan (pipeline.cpp run_pipeline): the chain's shared state (Run, the memo of the first run's
// detection, the scene stage's result), the chain itself, and the runs decided by their result, each in its file:
// how a later run is judged against the model kept (pipeline_judge.cpp), the walls around roofs a model left out
// (pipeline_left_out_roofs.cpp, DECISIONS #159), step 0's scene kinds both ways (pipeline_scene_choice.cpp),
// steps 5, 6 and 7 (pipeline_later_runs.cpp), and the prisms when no plane or no model (pipeline_prism.cpp).
#pragma once

#include "pipeline/pipeline.h"

#include "core/error.h"

#include <cstddef>
#include <exception>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/task_group.h>

namespace hsr::pipeline_detail {

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
  /// (building_small_planes' GableHalves::Split); the other runs keep what their count needs (GableHalves::Count).
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
  std::optional<SplitInput> split_input;  ///< what step 7's count needs (GableHalves::Count; PipelineResult::split_input)
};

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
                  const std::vector<int>& walls_around_roofs = {});

// How a later run's model is judged against the model kept so far (pipeline_judge.cpp).

/// The scan's points farther than `distance` from the model, on every point's distance to it.
std::size_t farther_than(const std::vector<double>& d, double distance);

/// The scan's points farther than a distance from two models: the one kept so far and a later run's (the whole
/// scan when that run failed). keep_tighter_planes' far points.
struct FarPoints {
  std::size_t before = 0;  ///< from the model kept so far
  std::size_t after = 0;   ///< from the later run's model; the scan's size when it failed
};

/// Whether a later run's model replaces the model kept so far (keep_tighter_planes on the two evaluations).
bool later_run_explains_more(const PipelineResult& out, const PipelineResult& other, bool failed, FarPoints far,
                             const BuildingParams& b);

/// A later run's report: whether it gave a valid solid, and the figures later_run_explains_more judged.
nlohmann::json later_run_json(const PipelineResult& out, const PipelineResult& other, bool failed, FarPoints far);

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
                               double r, const BuildingParams& b);

/// The report's figures of compare_unseen_roof, in `j`.
void report_unseen_roof(const UnseenRoof& u, nlohmann::json& j);

/// Whether a second run of the same building stands on the first run's ground.
bool same_ground(const nlohmann::json& first, const nlohmann::json& second);

/// FarPoints of steps 6 and 7 at the first detection's inlier distance.
FarPoints far_points_of_runs(const PointCloud& cloud, const PipelineParams& params, const nlohmann::json& first_resolved,
                             const PipelineResult& out, const PipelineResult& other, bool failed);

/// The points farther from `out`'s model than its own detection's inlier distance (the gate of step 6's second
/// distance).
std::size_t far_points_of_model(const PointCloud& cloud, const PipelineParams& params, const PipelineResult& out);

// The walls around the roofs a model left out (pipeline_left_out_roofs.cpp, DECISIONS #159).

/// In the building's first run, after its stages 3 to 7: the second pass with walls around left-out roofs.
void walls_for_left_out_roofs(const PointCloud& cloud, const SceneResult& scene_before_box, const ScenePlan& plan,
                              Run& run, SceneStage& s, PipelineResult& out);

// Step 0: `auto` near its rule's edge, both kinds tried (pipeline_scene_choice.cpp).

/// Step 0's failures that are a kind's, not the input's: no plane, nothing to enclose.
bool made_no_model(const Error& e);

/// Step 0: the chain again with the other kind when `auto` was near its rule's edge; the run kept in `out`.
void choose_by_result(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                      const nlohmann::json& header, PipelineResult& out, const std::optional<SceneResult>& seen,
                      const std::optional<Error>& failed, DetectionMemo& memo);

/// A small scan without a footprint whose first detection made no model in either kind (`e`): the memo of its
/// detection again with the small-scan rule's smaller planes (DECISIONS #227); nothing where that does not apply.
std::optional<DetectionMemo> small_planes_after_no_model(const PointCloud& cloud, const PipelineParams& params,
                                                         const Error& e, const DetectionMemo& memo);

/// Whether small_planes_after_no_model would detect again should the run make no model: a small scan
/// (plan_small_scan) without a footprint, its memo's detection not yet the smaller planes.
bool small_planes_may_follow(const PointCloud& cloud, const PipelineParams& params, const DetectionMemo& memo);

/// Whether a run may follow the first (and read the memo's detection and kNN graph, its evaluation's distances or
/// its model's mesh -> points figures), decided before the first run's partition from its scene stage's result
/// `seen` (what step 0 decides on) and its final scene `scene`: step 0 (plan_scene_choice), the small planes after
/// no model (#227), or a building's steps 5 to 7 and step 6's run begun beside the first (all on a building only,
/// and only step 0 makes a run a building after its scene stage).
bool later_runs_may_follow(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                          const SceneResult& seen, const SceneResult& scene, const nlohmann::json& report,
                          const DetectionMemo& memo);

// Steps 5, 6 and 7 of a building scan (pipeline_later_runs.cpp).

/// Step 5: finer outline segments, kept by the result.
void try_finer_outline(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                       const nlohmann::json& header, PipelineResult& out, DetectionMemo& memo,
                       const std::function<void()>& beside);

/// Whether steps 5 and 6 are one run (a building given its footprint, both steps on; DECISIONS #189).
bool one_second_run(const PipelineParams& params);

/// Whether step 6 runs on the model `report` is of.
bool tighter_planes_apply(const PointCloud& cloud, const PipelineParams& params, const nlohmann::json& report);

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

/// Step 6's run on the model whose scene report is `scene`, with outline segments of `segment_points` points and
/// the planes' inliers within `distance` r (BuildingParams::tighter_planes_distance, or its second distance).
TighterPlanesRun run_tighter_planes(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                                    const nlohmann::json& header, const nlohmann::json& scene, int segment_points,
                                    double distance, DetectionMemo& memo);

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
  /// a scan too large for step 6, or object mode) or by turns (begins_after_the_turn).
  std::function<void(const DetectionMemo&)> hook() {
    const std::size_t threads = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
    if (threads <= 1 || !one_second_run(params_) || params_.scene.mode == SceneMode::Object) return {};
    if (begins_after_the_turn()) return {};
    if (!small_enough_to_run_again(cloud_.size(), params_.scene)) return {};
    return [this](const DetectionMemo& memo) {
      if (memo_) return;  // begun already
      memo_ = memo;
      group_.run([this] {
        run_ = run_tighter_planes(cloud_, ground_, params_, header_, nlohmann::json::object(),
                                  params_.scene.building.finer_outline_points,
                                  params_.scene.building.tighter_planes_distance, *memo_);
        run_->beside = "first run";
      });
    };
  }

  /// By turns (PipelineParams::turn_over: hsr city at `-j 1`) step 6's run is made after the turn, beside the next
  /// building's first runs, not beside this one's first run. Why (DECISIONS #250): begun beside the first run it
  /// held the turn until it was done, and the core it took was the one the previous building's steps 5 to 7 were
  /// using; after the turn the same run fills the core the next building leaves idle (the same model either way).
  bool begins_after_the_turn() const { return static_cast<bool>(params_.turn_over); }

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

/// Step 6: the planes' inliers within tighter_planes_distance r, kept by the result (`early`: a run made beside).
void try_tighter_planes(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                        const nlohmann::json& header, PipelineResult& out, DetectionMemo& memo,
                        std::optional<TighterPlanesRun>& early);

/// Step 6's second distance: where step 6's run was not kept and the model still leaves a plane's worth of points
/// far (a scan of at most tighter_planes_second_max_points points), the planes' inliers within
/// tighter_planes_second_distance r, kept by the result.
void try_tighter_planes_second(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                               const nlohmann::json& header, PipelineResult& out, DetectionMemo& memo);

/// Step 7: a gable's two halves split, kept by the result.
void try_gable_halves(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                      const nlohmann::json& header, PipelineResult& out, DetectionMemo& memo);

// The prisms when the chain found no plane or made no model (pipeline_prism.cpp).

/// Whether a run whose detection found no plane gets the outline prism.
bool outline_prism_applies(const PipelineParams& params, const SceneGround& ground, const PointCloud& cloud);

/// Whether a run that made no model (`e`) gets the outline prism: no plane found where outline_prism_applies, or
/// (#231) `auto`'s planes enclosing nothing in either kind.
bool outline_prism_for_failure(const PipelineParams& params, const SceneGround& ground, const PointCloud& cloud,
                               const Error& e);

/// Whether a building run on a footprint that made no model (`e`) gets the footprint prism instead.
bool footprint_prism_for_failure(const PipelineParams& params, const Error& e);

/// The outline prism's (or, `on_footprint`, the footprint prism's) run in `out`; rethrows `why` when the points
/// make no prism.
void outline_prism_run(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                       const nlohmann::json& header, const Error& why, PipelineResult& out, bool on_footprint = false);

}  // namespace hsr::pipeline_detail
