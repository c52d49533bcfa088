#include "core/spacing.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_3.h>

#include <cmath>

namespace hsr {

double average_spacing(const std::vector<Vec3>& points, int k, std::size_t max_samples) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Traits = CGAL::Search_traits_3<K>;
  using Search = CGAL::Orthogonal_k_neighbor_search<Traits>;
  using Tree = Search::Tree;
  if (points.size() < 2) return 0.0;
  std::vector<K::Point_3> pts;
  pts.reserve(points.size());
  for (const auto& p : points) pts.emplace_back(p.x(), p.y(), p.z());
  Tree tree(pts.begin(), pts.end());
  tree.build();
  const int kk = std::min<int>(k, static_cast<int>(points.size()) - 1);
  const std::size_t stride = std::max<std::size_t>(1, points.size() / std::max<std::size_t>(1, max_samples));
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < pts.size(); i += stride) {
    Search search(tree, pts[i], kk + 1);  // +1: the point itself
    double s = 0.0;
    int m = 0;
    bool skipped_self = false;
    for (auto it = search.begin(); it != search.end(); ++it) {
      if (!skipped_self && it->second == 0.0) { skipped_self = true; continue; }
      s += std::sqrt(it->second);
      ++m;
    }
    if (m > 0) { sum += s / m; ++n; }
  }
  return n > 0 ? sum / n : 0.0;
}

}  // namespace hsr
