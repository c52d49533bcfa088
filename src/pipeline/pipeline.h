// The whole method, stage after stage (DESIGN.md §1): structure → scene → visibility → recovery → hulls →
// partition → extraction → eval, each with the parameters the scene plan (scene/plan.h) resolved. Records
// per-stage wall time, counts and peak memory into a JSON report. This is what the CLI, the drivers, the
// tests and the Python module call.
#pragma once

#include "core/budget.h"
#include "core/footprint.h"
#include "core/types.h"
#include "eval/eval.h"
#include "extraction/extraction.h"
#include "hulls/hulls.h"
#include "partition/partition.h"
#include "recovery/recovery.h"
#include "scene/plan.h"
#include "scene/scene.h"
#include "structure/structure.h"
#include "visibility/visibility.h"

#include <nlohmann/json.hpp>

#include <functional>
#include <optional>
#include <string>

namespace hsr {

/// What the stages produced, for the visual report (src/report) and the Python module. Filled by
/// run_pipeline when PipelineParams::artifacts is set, stage by stage (a run that fails keeps what it got).
/// `cloud` is the input with the normals the extraction used (each inlier's flipped to its plane's
/// outward side); the other members are the stages' results as returned.
struct PipelineArtifacts {
  PointCloud cloud;
  SceneStructure structure;  ///< the structure the later stages used (building mode: the building's planes)
  SceneResult scene;
  VisibilityResult visibility;
  RecoveryResult recovery;
  std::vector<ConvexPolygon> polygons;
  CellComplex complex;
  std::vector<bool> inside;  ///< per cell of `complex`: labelled inside by the extraction
};

/// The stages' parameters as the user set them (StageParams, scene/plan.h: the scene plan resolves from them
/// the parameters each stage runs with), and what the run does around them.
struct PipelineParams : StageParams {
  EvalParams eval;
  /// Which of the parameters the user chose (the CLI's flags given, Python's keywords): a scene kind's
  /// defaults never override them (scene/plan.h).
  UserChoices user;
  /// Write the mesh even when it fails the validity checks (the report flags it). Default: fail instead.
  bool force = false;
  /// If non-empty: folder for the per-stage dumps (planes.ply, boundaries.obj, partition.ply, labels.ply...).
  std::string dump_dir;
  /// Optional ground truth for the report's accuracy section (null: none).
  const PolygonMesh* truth = nullptr;
  /// Optional terrain model under the scene (`--ground DTM.tif`, io/raster.h): building mode's ground when no
  /// height is given (scene/building/building.h, ground source 2). Null: none.
  const Raster* ground_raster = nullptr;
  /// Time / memory limits of the run (default none): checked between stages and in long loops; a run over
  /// budget throws Error(BudgetExceeded) naming the stage. Out of memory (std::bad_alloc) is BudgetExceeded too.
  Budget budget;
  /// Optional: receives every stage's result (null: nothing kept).
  PipelineArtifacts* artifacts = nullptr;
  /// Building mode: the building's footprint (local x, y; e.g. `hsr reconstruct --footprint`, `hsr city`): the
  /// solid stays inside the vertical prism over it (partition/footprint_prism.h: its edges are walls of the
  /// partition, cells outside are removed). Empty (default): no bound. Ignored in object mode. Written to
  /// the report as `footprint` (not among the stages' `parameters`).
  Footprint footprint;
  /// Building mode with a footprint of one polygon: no plane detection, the model is the footprint's prism, the
  /// outline prism (scene/building/building.h outline_prism, DECISIONS #135) over the footprint's outline instead of
  /// the points' hull, reported as `quality.fallback: footprint prism` (`hsr reconstruct --footprint-prism`).
  /// `hsr city` sets it for a footprint holding fewer building points than CityParams::min_building_points
  /// (DECISIONS #165: a few tens of points, a garden shed, still get a model, as roofer extrudes every footprint).
  /// Not among the stages' `parameters`.
  bool footprint_prism = false;
  /// Building mode with a footprint of one polygon: a run that makes no model (no plane, or no plane left to be a
  /// roof: Status NoPlanes or DegenerateInput) gets the footprint prism above instead of failing, reported as
  /// `quality.fallback: footprint prism` with the run's error as `scene.fallback.why` (DECISIONS #174). Why: the
  /// footprint says a building stands there and its points give the roof's height; a city user expects every
  /// footprint with points modelled (roofer extrudes every footprint). False: the run's error stands. Not among the
  /// stages' `parameters`.
  bool footprint_prism_when_no_model = true;
  /// Worker threads of the run; 0: the environment variable HSR_THREADS if set, else all cores. The output
  /// does not depend on it (every parallel loop is deterministic).
  int threads = 0;
  /// Called once when the building's first run and step 0 are done, before steps 5 to 7 and the kept model's mesh
  /// -> points figures, which then run on the idle core (core/threads.h run_on_idle_core): `hsr reconstruct --turn`
  /// gives hsr city's turn up there (driver.h Turn, DECISIONS #235; steps 5 and 6 after it since #249). Empty: nothing, and they run as before. The
  /// output does not depend on it. Not among the stages' `parameters`.
  std::function<void()> turn_over;
};

/// Calls f(name, params) for every stage's parameters in `pp` (a PipelineParams, const or not), in pipeline
/// order. The run report's `parameters.<name>` and `hsr reconstruct --config` (stage_params_to_json /
/// _from_json) both go through this list: a stage's parameters are in both once listed here, with to_json /
/// from_json next to its Params struct (core/params_json.h).
template <class P, class F>
void for_each_stage_params(P& pp, F&& f) {
  f("structure", pp.structure);
  f("scene", pp.scene);
  f("visibility", pp.visibility);
  f("recovery", pp.recovery);
  f("hulls", pp.hulls);
  f("partition", pp.partition);
  f("extraction", pp.extraction);
  f("eval", pp.eval);
  f("user_choices", pp.user);  // not a stage: which of the above the user chose (scene/plan.h)
}

/// {"structure": {...}, "visibility": {...}, ...}: every field of every stage's parameters, as given.
nlohmann::json stage_params_to_json(const PipelineParams& pp);
/// The inverse: reads each stage `parameters` holds into `pp` (stages and fields it lacks keep their
/// values). An unknown stage or field, or a value of the wrong type, is Error(BadInput, "config").
void stage_params_from_json(const nlohmann::json& parameters, PipelineParams& pp);

/// Parameters given in the input's (file) coordinates made local to a cloud shifted by `origin` (io.h
/// local_origin): the scanner positions, and the given ground height unless `ground_z_is_local` (a --config
/// replay's, which the report holds local). The CLI and the Python module call it once the points are read.
void params_to_local(PipelineParams& params, const Vec3& origin, bool ground_z_is_local = false);

struct PipelineResult {
  PolygonMesh mesh;
  EvalResult eval;
  /// parameters (every stage's, as given: stage_params_to_json), resolved (absolute values the stages
  /// derived from them), origin (local-to-global shift), per-stage seconds, peak memory, counts,
  /// validity, accuracy
  nlohmann::json report;
  /// What step 7's count needs of the run that made this model (scene/building SplitInput), where step 7 may run
  /// (a building scan the memo records, gable_halves or two_surface_planes on); run_pipeline counts the candidates
  /// on the kept model's only, after step 6 (try_gable_halves), and empties it (DECISIONS #239).
  std::optional<SplitInput> split_input;
};

/// Runs every stage on `cloud`. The report has per stage: "seconds" (wall), "cpu_seconds" (all threads) and
/// "peak_memory_mb_after" (the process's peak resident memory when the stage ended). Throws hsr::Error with the failing stage's name on failure; when the output
/// fails validation and !params.force, throws Status::InvalidOutput (the report is attached to the message);
/// over params.budget, throws Status::BudgetExceeded naming the stage that was running.
PipelineResult run_pipeline(const PointCloud& cloud, const PipelineParams& params);

}  // namespace hsr
