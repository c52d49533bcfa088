// HullsParams <-> JSON (core/params_json.h): the run report's parameters.hulls and --config.
#include "core/params_json.h"
#include "hulls/hulls.h"

namespace hsr {
namespace {
const auto fields = [](auto& p, auto&& f) {
  f("min_area_fraction", p.min_area_fraction);
  f("expand", p.expand);
  f("expand_reach", p.expand_reach);
  f("recovered_planes", p.recovered_planes);
  f("min_speed", p.min_speed);
  f("walls_to_ground", p.walls_to_ground);
  f("ground_z", p.ground_z);
};
}  // namespace

void to_json(nlohmann::json& j, const HullsParams& p) { params_json::write(j, p, fields); }
void from_json(const nlohmann::json& j, HullsParams& p) { params_json::read(j, p, "hulls", fields); }

}  // namespace hsr
