// VisibilityParams <-> JSON (core/params_json.h): the run report's parameters.visibility and --config.
#include "core/params_json.h"
#include "visibility/visibility.h"

namespace hsr {
namespace {
const auto fields = [](auto& p, auto&& f) {
  f("keypoints", p.keypoints);
  f("directions", p.directions);
  f("smoothness", p.smoothness);
  f("max_iterations", p.max_iterations);
  f("alpha_radius", p.alpha_radius);
  f("threshold", p.threshold);
  f("one_sided", p.one_sided);
  f("normalize_smoothness", p.normalize_smoothness);
  f("close_room", p.close_room);
  f("room", p.room);
};
}  // namespace

void to_json(nlohmann::json& j, const VisibilityParams& p) { params_json::write(j, p, fields); }
void from_json(const nlohmann::json& j, VisibilityParams& p) { params_json::read(j, p, "visibility", fields); }

}  // namespace hsr
