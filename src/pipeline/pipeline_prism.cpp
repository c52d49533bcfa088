// The prisms of run_pipeline (pipeline_runs.h): the outline prism when the chain found no plane (DECISIONS #135),
// the footprint prism when a building on a footprint made no model (#174) or had too few points for a run (#165).
#include "pipeline/pipeline_runs.h"

#include "core/log.h"
#include "core/spacing.h"
#include "pipeline/pipeline_internal.h"

#include <algorithm>
#include <cmath>

namespace hsr::pipeline_detail {

namespace {

/// Whether a scan without planes is seen from above, as `auto`'s rule (a) asks of its planes, on the points: the
/// file gives normals, and of those that lean clearly up or down (within auto_steep_roof_deg of +z or of -z) at
/// least auto_min_roof_share lean up. Why: with no plane the rule has no figures; an aerial scan's normals point
/// to the sensor, above (Vaihingen_00026: 0.90 of them within 60 degrees of +z, 0.80 at half density), an
/// object's every way (ten points of a box's side: none up). Counted among the normals that lean up or down, not
/// among all points: a steep roof's sparse points lean sideways (Vaihingen_00015 at half density, a fresh draw
/// of 35 points: 0.66 of all within 60 degrees of +z, 0.03 of -z), and they say nothing either way; normals
/// turned down (a scan seen from below) still say no. Without normals nothing tells, and `auto` makes no model.
bool normals_face_up(const PointCloud& cloud, const SceneParams& params) {
  if (cloud.normals.size() != cloud.size() || cloud.empty()) return false;
  const double cos_max = std::cos(params.auto_steep_roof_deg * M_PI / 180.0);
  std::size_t up = 0, down = 0;
  for (const Vec3& n : cloud.normals) {
    if (n.z() >= cos_max * n.norm()) ++up;
    else if (-n.z() >= cos_max * n.norm()) ++down;
  }
  return up > 0 && static_cast<double>(up) >= params.auto_min_roof_share * static_cast<double>(up + down);
}


/// Whether the run's footprint can be the prism's outline: one polygon without holes (outline_prism takes one ring).
bool footprint_is_one_ring(const PipelineParams& params) {
  return params.footprint.size() == 1 && params.footprint.front().holes.empty();
}

}  // namespace

/// Whether a run whose detection found no plane gets the outline prism (BuildingParams::outline_prism): a
/// building scan by the user's word (`--scene building`) or the file's (LAS class 6), or `auto` on a scan small
/// enough for the small-scan rule (SceneParams::small_scan_size x the smallest plane: a shed, a garage of a few
/// hundred points at survey density) whose normals face up (normals_face_up). Never in object mode: an object
/// without planes is no block.
bool outline_prism_applies(const PipelineParams& params, const SceneGround& ground, const PointCloud& cloud) {
  if (!params.scene.building.outline_prism || params.scene.mode == SceneMode::Object) return false;
  if (params.scene.mode == SceneMode::Building || ground.building_class_points > 0) return true;
  const auto small = static_cast<std::size_t>(params.scene.small_scan_size) *
                     static_cast<std::size_t>(std::max(params.structure.min_region_points, 1));
  return cloud.size() < small && normals_face_up(cloud, params.scene);
}

/// Whether a run that made no model (`e`, every run step 0 and #227 tried having failed) gets the outline prism: a
/// detection with no plane where outline_prism_applies (#135), and (DECISIONS #231) in `auto`, where it applies (a
/// small scan seen from above, or LAS class 6), planes that enclose nothing in either kind (DegenerateInput: as an
/// object, parallel planes; as a building, no roof among them). Why: Vaihingen_00015 at half density (two fresh
/// draws of 47 points) holds one steep plane, taken for a wall, and a flat part of 10 points, under any plane's
/// size: no run makes a model, and its points are an aerial building's; the prism is the model `--scene building`
/// makes of a scan with no plane, and the report says `fallback`. Not with `--scene building` (its walls' outline
/// is not the building's, #226: the user asked for that kind, and hears why it made none) nor the partition's
/// errors (an input at fault).
bool outline_prism_for_failure(const PipelineParams& params, const SceneGround& ground, const PointCloud& cloud,
                               const Error& e) {
  if (e.status() == Status::NoPlanes) return outline_prism_applies(params, ground, cloud);
  return e.status() == Status::DegenerateInput && params.scene.mode == SceneMode::Auto && e.stage() != "partition" &&
         outline_prism_applies(params, ground, cloud);
}

/// Whether a building run on a footprint that made no model (`e`) gets the footprint prism instead
/// (PipelineParams::footprint_prism_when_no_model, DECISIONS #174). Why: in a 1,000-building synthetic city a
/// shed of 147 points (0.7 per m²: only a strip along one wall in the points) held two wall planes and no roof,
/// and the whole tile exited 1; the footprint says a building stands there and its points give the roof's height.
/// Not the partition's errors: a footprint off the points (or a box of zero extent) is an input at fault, not a
/// building without a roof.
bool footprint_prism_for_failure(const PipelineParams& params, const Error& e) {
  return params.footprint_prism_when_no_model && made_no_model(e) && e.stage() != "partition" &&
         params.scene.mode != SceneMode::Object && footprint_is_one_ring(params);
}

/// The outline prism's run (scene/building/building.h outline_prism) in `out`, when the chain found no plane
/// (`why`; with `on_footprint`, when it made no model on a footprint: the footprint prism, #174): the model, its
/// evaluation, the points it leaves unexplained and the quality, which says `fallback: outline prism` or
/// `footprint prism` (report: scene.fallback). Rethrows `why` when the points make no prism.
void outline_prism_run(const PointCloud& cloud, const SceneGround& ground, const PipelineParams& params,
                       const nlohmann::json& header, const Error& why, PipelineResult& out, bool on_footprint) {
  const double r = average_spacing(cloud.points);
  on_footprint = on_footprint || (params.footprint_prism && footprint_is_one_ring(params));
  BuildingParams building = params.scene.building;
  if (!params.footprint.empty()) building.outline_prism_beyond_hull = 0.0;  // a footprint says where the walls stand (#219)
  OutlinePrism prism = outline_prism(cloud, r, building, ground, on_footprint ? &params.footprint.front().outer : nullptr);
  if (prism.mesh.faces.empty()) throw why;
  const std::string model = on_footprint ? "footprint prism" : "outline prism";
  out = PipelineResult{};
  out.report = header;
  nlohmann::json& report = out.report;
  SceneResult scene;
  scene.mode = SceneMode::Building;
  scene.reason = !on_footprint ? "no plane found: the outline prism (a block over the points' outline, BuildingParams::outline_prism)"
                 : params.footprint_prism ? "too few points for a run: the footprint prism (the footprint extruded, PipelineParams::footprint_prism)"
                                          : "the run made no model: the footprint prism (the footprint extruded, PipelineParams::footprint_prism_when_no_model)";
  scene.ground_z = prism.ground_z;
  scene.ground_source = prism.ground_source;
  scene.ground_note = prism.ground_note;
  const std::size_t roof_points = cloud.size() - prism.under_roof_points;
  log::warn(std::string("[scene] ") + why.what() + ": the model is the " + model + " of the " +
            std::to_string(roof_points) + " roof points, from the ground (" + ground_source_name(prism.ground_source) +
            ") to the " + std::to_string(params.scene.building.outline_prism_roof_quantile) +
            " quantile of their heights (scene.fallback)");
  if (!prism.ground_note.empty()) log::warn("[scene] " + prism.ground_note);
  report["scene"] = to_json(scene);
  report["scene"]["ground_z_file"] = prism.ground_z + cloud.origin.z();
  report["scene"]["fallback"] = {{"model", model},
                                 {"why", why.what()},
                                 {"spacing", r},
                                 {"roof_points", roof_points},
                                 {"under_roof_points", prism.under_roof_points},
                                 {"roof_quantile", params.scene.building.outline_prism_roof_quantile},
                                 {"roof_z", prism.roof_z},
                                 {"roof_z_file", prism.roof_z + cloud.origin.z()},
                                 {"outline_vertices", prism.mesh.faces.front().size()},
                                 {"outline_beyond_hull", prism.beyond_hull}};
  report["counts"]["planes"] = 0;
  out.mesh = std::move(prism.mesh);
  out.mesh.origin = cloud.origin;
  out.eval = timed_stage("eval", report, [&] {
    EvalResult eval = run_eval(cloud, out.mesh, params.truth, params.eval);
    pipeline_detail::report_unexplained(cloud, prism.roof, r, out.mesh, eval.point_distance, params.eval, report);
    std::vector<double>().swap(eval.point_distance);
    return eval;
  });
  pipeline_detail::report_eval(out, report);
  PointsToExplain explain;
  explain.low_points = prism.under_roof_points;  // under the roof's gap: the ground or a wall's foot, on no plane
  pipeline_detail::report_quality(scene, explain, params.scene, report);
  report["quality"].erase("scene_margin");  // no plane, no figures of the `auto` rule
  report["quality"]["fallback"] = model;
}

}  // namespace hsr::pipeline_detail
