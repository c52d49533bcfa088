// StructureParams <-> JSON (core/params_json.h): the run report's parameters.structure and --config.
#include "core/params_json.h"
#include "structure/structure.h"

namespace hsr {

void to_json(nlohmann::json& j, PlaneDetector d) { j = d == PlaneDetector::Ransac ? "ransac" : "region-growing"; }

void from_json(const nlohmann::json& j, PlaneDetector& d) {
  const std::string name = j.get<std::string>();
  if (name == "ransac") d = PlaneDetector::Ransac;
  else if (name == "region-growing" || name == "region_growing") d = PlaneDetector::RegionGrowing;
  else throw Error(Status::BadInput, "config", "unknown plane detector '" + name + "' (region-growing | ransac)");
}

namespace {
const auto fields = [](auto& p, auto&& f) {
  f("spacing", p.spacing);
  f("normal_k", p.normal_k);
  f("scanners", p.scanners);
  f("detector", p.detector);
  f("region_k", p.region_k);
  f("max_distance", p.max_distance);
  f("max_angle_deg", p.max_angle_deg);
  f("signed_normals", p.signed_normals);
  f("min_region_points", p.min_region_points);
  f("min_region_fraction", p.min_region_fraction);
  f("leftover_rounds", p.leftover_rounds);
  f("leftover_max_angle_deg", p.leftover_max_angle_deg);
  f("ransac_probability", p.ransac_probability);
  f("ransac_cluster_epsilon", p.ransac_cluster_epsilon);
  f("seed", p.seed);
  f("regularize", p.regularize);
  f("regularize_angle_deg", p.regularize_angle_deg);
  f("alpha_radius", p.alpha_radius);
  f("boundary_normal_k", p.boundary_normal_k);
  f("segment_max_distance", p.segment_max_distance);
  f("segment_max_angle_deg", p.segment_max_angle_deg);
  f("min_segment_points", p.min_segment_points);
  f("regularize_segments", p.regularize_segments);
  f("segment_angle_tolerance_deg", p.segment_angle_tolerance_deg);
  f("segment_collinear_tolerance", p.segment_collinear_tolerance);
  f("adjacency_k", p.adjacency_k);
  f("min_adjacent_pairs", p.min_adjacent_pairs);
  f("min_line_angle_deg", p.min_line_angle_deg);
  f("max_seed_failures", p.max_seed_failures);
  f("min_region_width", p.min_region_width);
  f("min_region_distinct", p.min_region_distinct);
  f("share_coincident_planes", p.share_coincident_planes);
};
}  // namespace

void to_json(nlohmann::json& j, const StructureParams& p) { params_json::write(j, p, fields); }
void from_json(const nlohmann::json& j, StructureParams& p) { params_json::read(j, p, "structure", fields); }


StructureParams with_segment_fields(StructureParams detection, const StructureParams& segments) {
  detection.segment_max_distance = segments.segment_max_distance;
  detection.segment_max_angle_deg = segments.segment_max_angle_deg;
  detection.min_segment_points = segments.min_segment_points;
  detection.regularize_segments = segments.regularize_segments;
  detection.segment_angle_tolerance_deg = segments.segment_angle_tolerance_deg;
  detection.segment_collinear_tolerance = segments.segment_collinear_tolerance;
  return detection;
}

bool same_detection(const StructureParams& a, const StructureParams& b) {
  // Every field through the one field list (to_json), so a field added later is compared too.
  return nlohmann::json(with_segment_fields(a, b)) == nlohmann::json(b);
}

}  // namespace hsr
