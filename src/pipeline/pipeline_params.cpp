// Every stage's parameters <-> the run report's `parameters` object (pipeline.h, for_each_stage_params).
#include "pipeline/pipeline.h"

#include "core/error.h"

#include <cmath>
#include <set>
#include <string>

namespace hsr {

nlohmann::json stage_params_to_json(const PipelineParams& pp) {
  nlohmann::json j = nlohmann::json::object();
  for_each_stage_params(pp, [&](const char* name, const auto& params) { j[name] = params; });
  return j;
}

void stage_params_from_json(const nlohmann::json& parameters, PipelineParams& pp) {
  if (!parameters.is_object()) throw Error(Status::BadInput, "config", "parameters is not a JSON object");
  std::set<std::string> stages;
  for_each_stage_params(pp, [&](const char* name, auto& params) {
    stages.insert(name);
    if (const auto it = parameters.find(name); it != parameters.end()) from_json(*it, params);
  });
  for (const auto& [name, value] : parameters.items())
    if (!stages.count(name)) throw Error(Status::BadInput, "config", "parameters." + name + " is not a stage of hsr");
}

void params_to_local(PipelineParams& params, const Vec3& origin, bool ground_z_is_local) {
  for (Vec3& s : params.structure.scanners) s -= origin;
  double& ground_z = params.scene.building.ground_z;
  if (!std::isnan(ground_z) && !ground_z_is_local) ground_z -= origin.z();
}

}  // namespace hsr
