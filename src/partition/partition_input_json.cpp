// PartitionInput <-> JSON: the partition's whole input as plain data (`hsr reconstruct --dump` writes it as
// partition_input.json; bench_partition --input partitions it again), doubles written so they read back exactly.
#include "core/error.h"
#include "partition/partition.h"

#include <nlohmann/json.hpp>

namespace hsr {

namespace {

nlohmann::json vec(const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

Vec3 read_vec(const nlohmann::json& j) {
  if (!j.is_array() || j.size() != 3) throw Error(Status::BadInput, "partition", "expected [x, y, z]");
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

nlohmann::json polygons_to_json(const std::vector<ConvexPolygon>& polygons) {
  nlohmann::json polys = nlohmann::json::array();
  for (const ConvexPolygon& p : polygons) {
    nlohmann::json vs = nlohmann::json::array();
    for (const Vec3& v : p.vertices) vs.push_back(vec(v));
    polys.push_back({{"plane_id", p.plane_id},
                     {"normal", vec(p.plane.normal)},
                     {"offset", p.plane.offset},
                     {"level", p.level},
                     {"speed", p.speed},
                     {"vertices", std::move(vs)}});
  }
  return polys;
}

std::vector<ConvexPolygon> polygons_from_json(const nlohmann::json& j) {
  std::vector<ConvexPolygon> out;
  for (const nlohmann::json& p : j) {
    ConvexPolygon poly;
    poly.plane_id = p.at("plane_id").get<int>();
    poly.plane.normal = read_vec(p.at("normal"));
    poly.plane.offset = p.at("offset").get<double>();
    poly.level = p.at("level").get<int>();
    poly.speed = p.at("speed").get<double>();
    for (const nlohmann::json& v : p.at("vertices")) poly.vertices.push_back(read_vec(v));
    out.push_back(std::move(poly));
  }
  return out;
}

}  // namespace

void to_json(nlohmann::json& j, const PartitionInput& in) {
  j = nlohmann::json::object();
  j["points_bbox"] = {{"min", vec(in.points_bbox.min)}, {"max", vec(in.points_bbox.max)}};
  j["polygons"] = polygons_to_json(in.polygons);
  if (!in.cuts.empty()) j["cuts"] = polygons_to_json(in.cuts);
  nlohmann::json adj = nlohmann::json::array();
  for (const auto& [a, b] : in.adjacent_planes) adj.push_back({a, b});
  j["adjacent_planes"] = std::move(adj);
}

void from_json(const nlohmann::json& j, PartitionInput& in) {
  try {
    in = PartitionInput{};
    in.points_bbox.min = read_vec(j.at("points_bbox").at("min"));
    in.points_bbox.max = read_vec(j.at("points_bbox").at("max"));
    in.polygons = polygons_from_json(j.at("polygons"));
    if (j.contains("cuts")) in.cuts = polygons_from_json(j.at("cuts"));
    for (const nlohmann::json& a : j.at("adjacent_planes")) in.adjacent_planes.emplace_back(a.at(0).get<int>(), a.at(1).get<int>());
  } catch (const nlohmann::json::exception& e) {
    throw Error(Status::BadInput, "partition", std::string("partition input: ") + e.what());
  }
}

}  // namespace hsr
