// Every stage's parameters <-> JSON (core/params_json.h, pipeline.h for_each_stage_params): the run
// report's `parameters` and `hsr reconstruct --config` (issue 15). A field missing from a stage's list,
// a field written but not read back, or a stage missing from the registry fails here.
#include "core/error.h"
#include "pipeline/pipeline.h"
#include "synth/synth.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

using namespace hsr;

namespace {

/// Number of members of an aggregate (every stage's Params is one): the largest N for which T{x1..xN}
/// compiles, x converting to anything.
struct AnyField {
  template <class T>
  operator T() const;
};
template <class T, class... A>
constexpr std::size_t field_count() {
  if constexpr (requires { T{A{}..., AnyField{}}; }) return field_count<T, A..., AnyField>();
  else return sizeof...(A);
}

/// A value of the same JSON type that differs from `v` and that the stage accepts.
nlohmann::json changed(const std::string& key, const nlohmann::json& v) {
  if (v.is_boolean()) return !v.get<bool>();
  if (v.is_number_unsigned()) return v.get<std::uint64_t>() + 3;
  if (v.is_number_integer()) return v.get<std::int64_t>() + 3;
  if (v.is_number_float()) return v.get<double>() * 0.75 + 0.125;
  if (v.is_null()) return 1.5;  // a double that is NaN ("none given"): scene.ground_z
  if (key == "method") return v == "bsp" ? "kinetic" : "bsp";
  if (key == "mode") return v == "auto" ? "building" : "auto";
  if (key == "detector") return v == "ransac" ? "region-growing" : "ransac";
  if (key == "scanners") return nlohmann::json::array({{1.5, -2.0, 3.25}});
  ADD_FAILURE() << "no change known for " << key << " = " << v;
  return v;
}

}  // namespace

TEST(ParamsJson, EveryFieldOfEveryStageIsWritten) {
  std::size_t stages = 0;
  const PipelineParams defaults_all;
  for_each_stage_params(defaults_all, [&](const char* name, const auto& params) {
    using P = std::decay_t<decltype(params)>;
    const nlohmann::json j = params;
    EXPECT_EQ(j.size(), field_count<P>()) << name << ": a field of the struct is not in its JSON list";
    ++stages;
  });
  EXPECT_EQ(stage_params_to_json(PipelineParams{}).size(), stages);
  // The scene's kinds are objects of their own inside parameters.scene.
  const nlohmann::json scene = SceneParams{};
  EXPECT_EQ(scene["building"].size(), field_count<BuildingParams>()) << "scene.building: a field is not in its list";
  EXPECT_EQ(scene["room"].size(), field_count<RoomParams>()) << "scene.room: a field is not in its list";
}

TEST(ParamsJson, EveryWrittenFieldIsReadBack) {
  const PipelineParams defaults_all;
  for_each_stage_params(defaults_all, [&](const char* name, const auto& defaults) {
    using P = std::decay_t<decltype(defaults)>;
    const nlohmann::json base = defaults;
    for (const auto& [key, value] : base.items()) {
      // A field that is an object of its own (scene.building, scene.room): each of its fields in turn.
      std::vector<std::pair<std::string, nlohmann::json>> variants;
      if (value.is_object()) {
        for (const auto& [inner, v] : value.items()) {
          nlohmann::json o = value;
          o[inner] = changed(inner, v);
          variants.emplace_back(key + "." + inner, o);
        }
      } else {
        variants.emplace_back(key, changed(key, value));
      }
      for (const auto& [what, v] : variants) {
        nlohmann::json j = base;
        j[key] = v;
        P p = defaults;
        from_json(j, p);
        EXPECT_EQ(nlohmann::json(p), j) << name << "." << what << " is written but not read";
      }
    }
  });
}

TEST(ParamsJson, NamesAreReadableAndRoundTripExactly) {
  PipelineParams pp;
  pp.partition.method = Partitioner::Bsp;
  pp.structure.detector = PlaneDetector::Ransac;
  pp.extraction.lambda = 0.1 + 0.2;  // not a short decimal
  pp.structure.scanners = {{1.0 / 3, 2e-17, -5e6}};
  const nlohmann::json j = stage_params_to_json(pp);
  EXPECT_EQ(j["partition"]["method"], "bsp");
  EXPECT_EQ(j["structure"]["detector"], "ransac");
  PipelineParams back;
  stage_params_from_json(nlohmann::json::parse(j.dump()), back);  // through text, as a report file
  EXPECT_EQ(back.extraction.lambda, pp.extraction.lambda);
  EXPECT_EQ(back.structure.scanners, pp.structure.scanners);
  EXPECT_EQ(stage_params_to_json(back), j);
}

TEST(ParamsJson, UnknownOrMistypedParametersAreErrors) {
  auto status = [](const nlohmann::json& parameters) {
    PipelineParams pp;
    try {
      stage_params_from_json(parameters, pp);
    } catch (const Error& e) {
      EXPECT_EQ(e.stage(), "config");
      return e.status();
    }
    return Status::Ok;
  };
  EXPECT_EQ(status({{"extraction", {{"lambda", 0.3}}}}), Status::Ok) << "missing fields keep their value";
  EXPECT_EQ(status({{"extraction", {{"lamda", 0.3}}}}), Status::BadInput);
  EXPECT_EQ(status({{"extraktion", nlohmann::json::object()}}), Status::BadInput);
  EXPECT_EQ(status({{"extraction", {{"lambda", "big"}}}}), Status::BadInput);
  EXPECT_EQ(status({{"partition", {{"kinetic_k", 1.5}}}}), Status::BadInput) << "no silent truncation";
  EXPECT_EQ(status({{"eval", {{"mesh_samples", -1}}}}), Status::BadInput) << "no silent wrap";
  EXPECT_EQ(status({{"partition", {{"method", "voronoi"}}}}), Status::BadInput);
  EXPECT_EQ(status({{"structure", {{"scanners", {1, 2, 3}}}}}), Status::BadInput);
  EXPECT_EQ(status(nlohmann::json::array()), Status::BadInput);
}

TEST(ParamsJson, ReportHoldsTheParametersAndAReplayGivesTheSameMesh) {
  SynthParams sp;
  sp.seed = 3;
  const SynthScan scan = run_synth("dormer_house", sp);
  PipelineParams pp;
  pp.partition.method = Partitioner::Kinetic;
  pp.partition.kinetic_k = 2;
  pp.extraction.lambda = 0.6;
  pp.visibility.smoothness = 0.3;
  pp.recovery.angle_deg = 12;
  pp.structure.alpha_radius = 2.5;
  pp.eval.mesh_samples = 5000;
  const PipelineResult a = run_pipeline(scan.cloud, pp);
  EXPECT_EQ(a.report["parameters"], stage_params_to_json(pp));
  for_each_stage_params(pp, [&](const char* name, const auto&) {
    EXPECT_TRUE(a.report["parameters"].contains(name)) << name;
  });
  PipelineParams replay;
  stage_params_from_json(nlohmann::json::parse(a.report.dump())["parameters"], replay);
  const PipelineResult b = run_pipeline(scan.cloud, replay);
  EXPECT_EQ(a.mesh.vertices, b.mesh.vertices);
  EXPECT_EQ(a.mesh.faces, b.mesh.faces);
  EXPECT_EQ(a.report["counts"], b.report["counts"]);
  const PipelineResult defaults = run_pipeline(scan.cloud, PipelineParams{});
  EXPECT_NE(a.report["counts"], defaults.report["counts"]) << "the parameters changed nothing: a weak test";
}

// Visibility's occluders use the structure stage's alpha radius whether or not the structure carries its
// resolved parameters (it used to fall back to 2.5 r against the structure's default 3 r).
TEST(ParamsJson, VisibilityUsesTheStructureAlphaRadius) {
  SynthParams sp;
  sp.seed = 5;
  const SynthScan scan = run_synth("room", sp);
  SceneStructure s = run_structure(scan.cloud);
  const VisibilityResult with = run_visibility(scan.cloud, s);
  s.params = nlohmann::json::object();  // as a structure made by hand
  const VisibilityResult without = run_visibility(scan.cloud, s);
  EXPECT_EQ(with.ratio, without.ratio);
  EXPECT_EQ(with.highly, without.highly);
}
