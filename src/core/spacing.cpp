#include "core/spacing.h"

#include "core/error.h"
#include "core/footprint.h"
#include "core/hull2d.h"

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

double average_spacing_of_rows(const std::vector<Vec3>& points, const std::vector<int>& rows, int row_k, int k,
                               std::size_t max_samples) {
  if (points.size() < 2) return 0.0;
  const int kk = std::min<int>(k, static_cast<int>(points.size()) - 1);
  if (row_k < kk || rows.size() != points.size() * static_cast<std::size_t>(row_k))
    throw Error(Status::Internal, "spacing", "the kNN graph's rows are shorter than the spacing's k");
  const std::size_t stride = std::max<std::size_t>(1, points.size() / std::max<std::size_t>(1, max_samples));
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < points.size(); i += stride) {
    const int* row = rows.data() + i * static_cast<std::size_t>(row_k);
    double s = 0.0;
    for (int j = 0; j < kk; ++j) {
      // (qx-px)^2 + (qy-py)^2 + (qz-pz)^2 in this order, as the kd-tree's queries compute it
      const Vec3& q = points[i];
      const Vec3& p = points[static_cast<std::size_t>(row[j])];
      const double dx = q.x() - p.x(), dy = q.y() - p.y(), dz = q.z() - p.z();
      double d2 = dx * dx;
      d2 += dy * dy;
      d2 += dz * dz;
      s += std::sqrt(d2);
    }
    if (kk > 0) { sum += s / kk; ++n; }
  }
  return n > 0 ? sum / n : 0.0;
}

double plan_spacing(const std::vector<Vec2>& xy) {
  if (xy.size() < 3) return 0.0;
  const std::vector<Vec2> hull = convex_hull_2d(xy);
  if (hull.size() < 3) return 0.0;
  return std::sqrt(0.5 * std::abs(twice_ring_area(hull)) / static_cast<double>(xy.size()));
}

double edge_beyond_outermost_points(double spacing, double factor) {
  return factor > 0 && spacing > 0 ? factor * spacing : 0.0;
}

}  // namespace hsr
