// ExtractionParams <-> JSON (core/params_json.h): the run report's parameters.extraction and --config.
#include "core/params_json.h"
#include "extraction/extraction.h"

namespace hsr {
namespace {
const auto fields = [](auto& p, auto&& f) {
  f("lambda", p.lambda);
  f("merge_coplanar", p.merge_coplanar);
  f("repair_non_manifold", p.repair_non_manifold);
  f("building", p.building);
  f("wall_area_weight", p.wall_area_weight);
  f("vouched_area_weight", p.vouched_area_weight);
  f("slab_facet_weight", p.slab_facet_weight);
  f("face_price", p.face_price);
  f("small_face_share", p.small_face_share);
  f("small_face_weight", p.small_face_weight);
  f("cleanup_max_cells", p.cleanup_max_cells);
  f("point_tolerance_spacings", p.point_tolerance_spacings);
  f("support_points", p.support_points);
  f("support_distance_spacings", p.support_distance_spacings);
};
}  // namespace

void to_json(nlohmann::json& j, const ExtractionParams& p) { params_json::write(j, p, fields); }
void from_json(const nlohmann::json& j, ExtractionParams& p) { params_json::read(j, p, "extraction", fields); }

}  // namespace hsr
