// PartitionParams <-> JSON (core/params_json.h): the run report's parameters.partition and --config.
#include "core/params_json.h"
#include "partition/partition.h"

namespace hsr {

void to_json(nlohmann::json& j, Partitioner p) { j = partitioner_name(p); }
void from_json(const nlohmann::json& j, Partitioner& p) {
  try {
    p = parse_partitioner(j.get<std::string>());
  } catch (const Error& e) {
    throw Error(Status::BadInput, "config", e.what());
  }
}

namespace {
const auto fields = [](auto& p, auto&& f) {
  f("method", p.method);
  f("bbox_margin", p.bbox_margin);
  f("bsp_extend", p.bsp_extend);
  f("kinetic_k", p.kinetic_k);
  f("max_polygons_per_domain", p.max_polygons_per_domain);
  f("max_crossings", p.max_crossings);
  f("cross_to_bounds", p.cross_to_bounds);
  f("meet_at_point", p.meet_at_point);
  f("wait_at_bounds", p.wait_at_bounds);
  f("trim", p.trim);
  f("threads", p.threads);
  f("footprint_wall_offset", p.footprint_wall_offset);
  f("footprint_wall_angle_deg", p.footprint_wall_angle_deg);
  f("footprint_wall_band", p.footprint_wall_band);
  f("exact_volumes", p.exact_volumes);
};
}  // namespace

void to_json(nlohmann::json& j, const PartitionParams& p) { params_json::write(j, p, fields); }
void from_json(const nlohmann::json& j, PartitionParams& p) { params_json::read(j, p, "partition", fields); }

}  // namespace hsr
