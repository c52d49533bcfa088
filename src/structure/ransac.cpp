// Stage 1 option: planes by CGAL efficient RANSAC (Schnabel et al. 2007), made deterministic by reseeding
// CGAL's default random generator (which Efficient_RANSAC draws from) with params.seed.
#include "structure/structure_internal.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Random.h>
#include <CGAL/Shape_detection/Efficient_RANSAC.h>
#include <CGAL/property_map.h>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace hsr::structure_detail {

std::vector<std::vector<int>> detect_planes_ransac(const std::vector<Vec3>& points, const std::vector<Vec3>& normals,
                                                   const StructureParams& params, double r,
                                                   std::size_t min_points) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  // Efficient_RANSAC reorders its input range (octree), so each item carries its original index.
  using Item = std::tuple<K::Point_3, K::Vector_3, int>;
  using Range = std::vector<Item>;
  using Traits = CGAL::Shape_detection::Efficient_RANSAC_traits<K, Range, CGAL::Nth_of_tuple_property_map<0, Item>,
                                                                CGAL::Nth_of_tuple_property_map<1, Item>>;
  using Ransac = CGAL::Shape_detection::Efficient_RANSAC<Traits>;
  using PlaneShape = CGAL::Shape_detection::Plane<Traits>;

  Range items;
  items.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    items.emplace_back(K::Point_3(points[i].x(), points[i].y(), points[i].z()),
                       K::Vector_3(normals[i].x(), normals[i].y(), normals[i].z()), static_cast<int>(i));
  CGAL::get_default_random() = CGAL::Random(static_cast<unsigned int>(params.seed ^ (params.seed >> 32)));
  Ransac ransac;
  ransac.set_input(items);
  ransac.add_shape_factory<PlaneShape>();
  Ransac::Parameters p;
  p.probability = params.ransac_probability;
  p.min_points = min_points;
  p.epsilon = params.max_distance * r;
  p.cluster_epsilon = params.ransac_cluster_epsilon * r;
  p.normal_threshold = std::cos(params.max_angle_deg * 3.14159265358979323846 / 180.0);
  ransac.detect(p);
  std::vector<std::vector<int>> out;
  for (const auto& shape : ransac.shapes()) {
    std::vector<int> v;
    for (std::size_t idx : shape->indices_of_assigned_points()) v.push_back(std::get<2>(items[idx]));
    std::sort(v.begin(), v.end());
    if (!v.empty()) out.push_back(std::move(v));
  }
  return out;
}

}  // namespace hsr::structure_detail
