#include "core/spacing.h"

#include <cmath>

namespace hsr {

double average_spacing(const std::vector<Vec3>& points, int k, std::size_t max_samples) {
  if (points.size() < 2) return 0.0;
  return average_spacing(points, KdTree(points), k, max_samples);
}

double average_spacing(const std::vector<Vec3>& points, const KdTree& tree, int k, std::size_t max_samples) {
  if (points.size() < 2) return 0.0;
  const int kk = std::min<int>(k, static_cast<int>(points.size()) - 1);
  const std::size_t stride = std::max<std::size_t>(1, points.size() / std::max<std::size_t>(1, max_samples));
  std::vector<int> index(static_cast<std::size_t>(kk) + 1);
  std::vector<double> d2(index.size());
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < points.size(); i += stride) {
    const int found = tree.nearest_k(points[i], kk + 1, index.data(), d2.data());  // +1: the point itself
    double s = 0.0;
    int m = 0;
    bool skipped_self = false;
    for (int j = 0; j < found; ++j) {
      if (!skipped_self && d2[static_cast<std::size_t>(j)] == 0.0) { skipped_self = true; continue; }
      s += std::sqrt(d2[static_cast<std::size_t>(j)]);
      ++m;
    }
    if (m > 0) { sum += s / m; ++n; }
  }
  return n > 0 ? sum / n : 0.0;
}

}  // namespace hsr
