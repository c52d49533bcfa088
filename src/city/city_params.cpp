// CityParams <-> JSON (core/params_json.h): `hsr city`'s plan files and the Python driver's options.
#include "city/city.h"
#include "core/params_json.h"

namespace hsr {
namespace {
const auto fields = [](auto& p, auto&& f) {
  f("smrf_cell", p.smrf.cell);
  f("smrf_slope", p.smrf.slope);
  f("smrf_max_window", p.smrf.max_window);
  f("smrf_elevation_threshold", p.smrf.elevation_threshold);
  f("smrf_elevation_scalar", p.smrf.elevation_scalar);
  f("smrf_inpaint_sweeps", p.smrf.inpaint_sweeps);
  f("min_height_above_ground", p.min_height_above_ground);
  f("planar_neighbours", p.planar_neighbours);
  f("max_surface_variation", p.max_surface_variation);
  f("buffer", p.buffer);
  f("component_cell", p.component_cell);
  f("min_building_area", p.min_building_area);
  f("min_building_points", p.min_building_points);
  f("min_prism_points", p.min_prism_points);
  f("ring_inner", p.ring_inner);
  f("ring_outer", p.ring_outer);
  f("ring_max_outer", p.ring_max_outer);
  f("ring_min_points", p.ring_min_points);
  f("max_group_variation", p.max_group_variation);
  f("tile_margin", p.tile_margin);
};
}  // namespace

void to_json(nlohmann::json& j, const CityParams& p) {
  params_json::write(j, p, fields);
  j["classes"] = class_source_name(p.classes);
}

void from_json(const nlohmann::json& j, CityParams& p) {
  nlohmann::json rest = j;
  if (rest.is_object() && rest.contains("classes")) {
    if (!rest["classes"].is_string()) throw Error(Status::BadInput, "config", "parameters.city.classes must be a string");
    p.classes = parse_class_source(rest["classes"].get<std::string>());
    rest.erase("classes");
  }
  params_json::read(rest, p, "city", fields);
}

}  // namespace hsr
