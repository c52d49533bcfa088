// core/kd_tree: exact k-nearest neighbours against brute force (ties by index included), the all-points
// rows, thread independence, and average_spacing bit for bit equal to the CGAL kd-tree it replaced.
#include "core/kd_tree.h"
#include "core/error.h"
#include "core/spacing.h"
#include "core/threads.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_3.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace hsr {
namespace {

double sq(const Vec3& q, const Vec3& p) {  // the documented formula: x, y, z summed in this order
  const double dx = q.x() - p.x(), dy = q.y() - p.y(), dz = q.z() - p.z();
  double d = dx * dx;
  d += dy * dy;
  d += dz * dz;
  return d;
}

/// Brute force: the k smallest (squared distance, index).
std::vector<std::pair<double, int>> brute(const std::vector<Vec3>& pts, const Vec3& q, int k) {
  std::vector<std::pair<double, int>> all;
  for (std::size_t i = 0; i < pts.size(); ++i) all.emplace_back(sq(q, pts[i]), static_cast<int>(i));
  std::sort(all.begin(), all.end());
  all.resize(std::min<std::size_t>(all.size(), static_cast<std::size_t>(k)));
  return all;
}

/// Points on three planes (as scans are), coordinates rounded to a 1/64 grid (many exact distance ties)
/// and every 10th point repeated.
std::vector<Vec3> tied_points(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 4.0);
  std::vector<Vec3> pts;
  for (std::size_t i = 0; i < n; ++i) {
    Vec3 p(u(rng), u(rng), u(rng));
    p[static_cast<int>(i % 3)] = static_cast<double>(i % 2);
    for (int d = 0; d < 3; ++d) p[d] = std::round(p[d] * 64) / 64;
    pts.push_back(p);
    if (i % 10 == 0) pts.push_back(p);
  }
  return pts;
}

std::vector<Vec3> random_points(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  std::vector<Vec3> pts(n);
  for (auto& p : pts) p = Vec3(u(rng), u(rng), 0.01 * u(rng));
  return pts;
}

TEST(KdTree, NearestKIsTheBruteForceAnswerWithTiesToTheSmallerIndex) {
  for (const auto& pts : {tied_points(6000, 1), random_points(6000, 2)}) {
    const KdTree tree(pts);
    ASSERT_EQ(tree.size(), pts.size());
    std::mt19937_64 rng(3);
    for (int trial = 0; trial < 300; ++trial) {
      const Vec3 q = trial % 2 ? pts[rng() % pts.size()] : Vec3(std::round(4.0 * (rng() % 1000) / 1000 * 64) / 64, 0.5, 1.0);
      for (int k : {1, 6, 13, 40}) {
        std::vector<int> idx(static_cast<std::size_t>(k));
        std::vector<double> d2(idx.size());
        ASSERT_EQ(tree.nearest_k(q, k, idx.data(), d2.data()), k);
        const auto want = brute(pts, q, k);
        for (int j = 0; j < k; ++j) {
          EXPECT_EQ(idx[static_cast<std::size_t>(j)], want[static_cast<std::size_t>(j)].second) << "k " << k << " rank " << j;
          EXPECT_EQ(d2[static_cast<std::size_t>(j)], want[static_cast<std::size_t>(j)].first);
        }
      }
      double d = -1;
      EXPECT_EQ(tree.nearest(q, &d), brute(pts, q, 1)[0].second);
      EXPECT_EQ(d, brute(pts, q, 1)[0].first);
    }
  }
}

TEST(KdTree, FewerPointsThanAskedAndEmpty) {
  const std::vector<Vec3> pts = {{0, 0, 0}, {1, 0, 0}, {0, 2, 0}};
  const KdTree tree(pts);
  int idx[5];
  EXPECT_EQ(tree.nearest_k(Vec3(0.9, 0, 0), 5, idx), 3);
  EXPECT_EQ(idx[0], 1);
  EXPECT_EQ(idx[1], 0);
  EXPECT_EQ(idx[2], 2);
  const KdTree empty(std::vector<Vec3>{});
  EXPECT_EQ(empty.nearest_k(Vec3::Zero(), 3, idx), 0);
}

TEST(KdTree, NeighbourRowsAreEachPointsNearestWithItselfLeftOut) {
  const std::vector<Vec3> pts = tied_points(3000, 4);
  const KdTree tree(pts);
  const int k = 12;
  const std::vector<int> rows = tree.neighbour_rows(k);
  ASSERT_EQ(rows.size(), pts.size() * k);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    std::vector<int> want;
    for (const auto& [d, j] : brute(pts, pts[i], k + 1))
      if (j != static_cast<int>(i)) want.push_back(j);
    want.resize(k);
    for (int a = 0; a < k; ++a) ASSERT_EQ(rows[i * k + a], want[static_cast<std::size_t>(a)]) << "point " << i;
  }
}

TEST(KdTree, SameAnswersWithOneThreadOrMany) {
  const std::vector<Vec3> pts = random_points(200000, 5);  // large enough for the parallel build and rows
  std::vector<int> one, many;
  std::vector<int> order_one, order_many;
  {
    const ThreadLimit limit(1);
    const KdTree tree(pts);
    one = tree.neighbour_rows(10);
    order_one = tree.leaf_order();
  }
  {
    const KdTree tree(pts);
    many = tree.neighbour_rows(10);
    order_many = tree.leaf_order();
  }
  EXPECT_EQ(one, many);
  EXPECT_EQ(order_one, order_many);
}

/// The CGAL kd-tree implementation average_spacing had before core/kd_tree (the reference).
double cgal_average_spacing(const std::vector<Vec3>& points, int k, std::size_t max_samples) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Traits = CGAL::Search_traits_3<K>;
  using Search = CGAL::Orthogonal_k_neighbor_search<Traits>;
  std::vector<K::Point_3> pts;
  for (const auto& p : points) pts.emplace_back(p.x(), p.y(), p.z());
  Search::Tree tree(pts.begin(), pts.end());
  tree.build();
  const int kk = std::min<int>(k, static_cast<int>(points.size()) - 1);
  const std::size_t stride = std::max<std::size_t>(1, points.size() / std::max<std::size_t>(1, max_samples));
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < pts.size(); i += stride) {
    Search search(tree, pts[i], kk + 1);
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

TEST(KdTree, AverageSpacingIsBitForBitTheCgalOne) {
  for (const auto& pts : {tied_points(30000, 6), random_points(50000, 7)}) {
    EXPECT_EQ(average_spacing(pts), cgal_average_spacing(pts, 6, 20000));
    EXPECT_EQ(average_spacing(pts, 3, 1000), cgal_average_spacing(pts, 3, 1000));
  }
}

/// The spacing read off the detection's kNN graph is the queries' spacing to the last bit, duplicates, exact
/// ties and a handful of points (fewer than k + 1) included.
TEST(KdTree, AverageSpacingOfTheGraphRowsIsBitForBitTheQueriesOne) {
  std::vector<Vec3> few = random_points(5, 9);
  few.push_back(few[2]);
  for (const auto& pts : {tied_points(30000, 6), random_points(50000, 7), few}) {
    const KdTree tree(pts);
    for (const int row_k : {6, 12}) {
      const int k = std::min<int>(row_k, static_cast<int>(pts.size()) - 1);
      const std::vector<int> rows = tree.neighbour_rows(k);
      EXPECT_EQ(average_spacing_of_rows(pts, rows, k), average_spacing(pts, tree)) << pts.size() << " points, rows of " << k;
      EXPECT_EQ(average_spacing_of_rows(pts, rows, k, 3, 1000), average_spacing(pts, tree, 3, 1000));
    }
  }
  EXPECT_THROW(average_spacing_of_rows(few, KdTree(few).neighbour_rows(2), 2), Error);
}

}  // namespace
}  // namespace hsr
