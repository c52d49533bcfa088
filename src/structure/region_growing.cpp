// Stage 1, plane detection by region growing on the kNN graph (DESIGN.md "Plane detection").
//
// The algorithm of CGAL 5.5's Shape_detection::Region_growing with Least_squares_plane_fit_region and
// Least_squares_plane_fit_sorting, step for step: seeds in decreasing order of the quality of the plane fit
// to each point and its neighbours (CGAL's own fit and std::sort, so the same order), breadth-first growth
// ring by ring, a point joins when within the distance of the region's plane and its normal within the
// angle, the plane refit after every ring, regions smaller than the minimum given back. Two differences:
//  * the refit after a ring uses running sums of the region's points (its moments), so it costs the ring,
//    not the region: CGAL refits all the region's points after every ring, which made a 2 M-point plane
//    cost O(n^1.5) (8.5 s of 14 on a 3 M-point scan). The plane is the same up to rounding.
//  * the seed scores are computed in parallel (each point's own fit; the same numbers).
//  * a point that has been in StructureParams::max_seed_failures regions too small to keep (64 by default)
//    seeds no further region (it may still join one). CGAL regrows a plane smaller than the minimum from
//    every one of its points, so such a plane of s points costs s^2: on a 3 M-point scan of a house 96 M
//    point visits for 27,500 failed regions (16 of 17 s of detection); with the limit 4.8 M, the same planes
//    and the same output (and the same on the 22 shared scans; a limit of 16 already changes 4 of them).
#include "structure/structure_internal.h"

#include "core/budget.h"
#include "core/log.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/linear_least_squares_fitting_3.h>

#include <Eigen/Eigenvalues>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>

namespace hsr::structure_detail {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

/// Quality of the least-squares plane through each point and its k neighbours (CGAL's fitting quality, as
/// Least_squares_plane_fit_sorting computes it), and the seed order: decreasing quality, CGAL's std::sort.
std::vector<std::size_t> seed_order(const std::vector<Vec3>& pts, const KnnGraph& g, int k) {
  const std::size_t n = pts.size();
  std::vector<double> score(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& range) {
    std::vector<K::Point_3> local;
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      local.clear();
      const int* row = g.row(i);
      for (int j = 0; j < k; ++j) {
        const Vec3& p = pts[static_cast<std::size_t>(row[j])];
        local.emplace_back(p.x(), p.y(), p.z());
      }
      local.emplace_back(pts[i].x(), pts[i].y(), pts[i].z());
      K::Plane_3 plane;
      K::Point_3 centroid;
      score[i] = CGAL::linear_least_squares_fitting_3(local.begin(), local.end(), plane, centroid,
                                                      CGAL::Dimension_tag<0>(), K(),
                                                      CGAL::Eigen_diagonalize_traits<double, 3>());
    }
  });
  // Sorted as (score, index) records compared by score only: std::sort moves them exactly as it would move
  // bare indices compared through score[] (the same comparisons), without a cache miss per comparison.
  struct Seed {
    double score;
    std::size_t index;
  };
  std::vector<Seed> seeds(n);
  for (std::size_t i = 0; i < n; ++i) seeds[i] = {score[i], i};
  std::vector<double>().swap(score);
  std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.score > b.score; });
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = seeds[i].index;
  return order;
}

/// The plane of a growing region from its moments about the seed (running sums, so a refit costs nothing).
class RegionFit {
 public:
  void reset(const Vec3& seed, const Vec3& seed_normal) {
    origin_ = seed;
    sum_ = Vec3::Zero();
    moment_ = Eigen::Matrix3d::Zero();
    count_ = 0;
    add(seed);
    // One point: the plane through it with its own normal (as CGAL's update() for a region of size 1).
    normal_ = seed_normal.normalized();
    offset_ = -normal_.dot(seed);
  }
  void add(const Vec3& p) {
    const Vec3 d = p - origin_;
    sum_ += d;
    moment_ += d * d.transpose();
    ++count_;
  }
  /// Least-squares plane of the points added so far (smallest eigenvector of their covariance).
  void refit() {
    if (count_ < 2) return;
    const Vec3 c = sum_ / static_cast<double>(count_);
    const Eigen::Matrix3d cov = moment_ - static_cast<double>(count_) * c * c.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
    Vec3 n = es.eigenvectors().col(0);
    const double len = n.norm();
    if (!(len > 0) || !std::isfinite(len)) return;
    normal_ = n / len;
    offset_ = -normal_.dot(origin_ + c);
  }
  double distance(const Vec3& p) const { return std::abs(normal_.dot(p) + offset_); }
  const Vec3& normal() const { return normal_; }

 private:
  Vec3 origin_ = Vec3::Zero(), sum_ = Vec3::Zero();
  Eigen::Matrix3d moment_ = Eigen::Matrix3d::Zero();
  std::size_t count_ = 0;
  Vec3 normal_ = Vec3::UnitZ();
  double offset_ = 0;
};

}  // namespace

double projected_width(const std::vector<Vec3>& points, const std::vector<int>& region, const Vec3& n) {
  if (region.size() < 2) return 0.0;
  const Vec3 u = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized(), v = n.cross(u);
  const Vec3& o = points[static_cast<std::size_t>(region[0])];
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  Eigen::Matrix2d moment = Eigen::Matrix2d::Zero();
  for (const int i : region) {
    const Vec3 d = points[static_cast<std::size_t>(i)] - o;
    const Eigen::Vector2d q(d.dot(u), d.dot(v));
    mean += q;
    moment += q * q.transpose();
  }
  const double count = static_cast<double>(region.size());
  mean /= count;
  const Eigen::Matrix2d cov = moment / count - mean * mean.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov, Eigen::EigenvaluesOnly);
  return std::sqrt(12.0 * std::max(0.0, es.eigenvalues()(0)));
}

/// Distinct positions among the points `region` (a duplicated point, as merged scans have, counts once).
std::size_t distinct_positions(const std::vector<Vec3>& points, const std::vector<int>& region) {
  std::vector<std::array<double, 3>> p;
  p.reserve(region.size());
  for (const int i : region) p.push_back({points[i].x(), points[i].y(), points[i].z()});
  std::sort(p.begin(), p.end());
  return static_cast<std::size_t>(std::unique(p.begin(), p.end()) - p.begin());
}

bool is_large_enough(const std::vector<Vec3>& points, const std::vector<int>& region, const Vec3& n,
                     const MinimumPlane& min) {
  if (region.size() < min.points) return false;
  // Near the minimum, duplicates must not make a plane: count distinct positions (far above it, no need).
  if (min.distinct && region.size() < 4 * min.points && distinct_positions(points, region) < min.points) return false;
  return !(min.width > 0) || projected_width(points, region, n) >= min.width;
}

std::vector<std::vector<int>> detect_planes_region_growing(const std::vector<Vec3>& pts,
                                                           const std::vector<Vec3>& normals, const KnnGraph& g,
                                                           const StructureParams& params, double r,
                                                           const MinimumPlane& min, const std::vector<char>& taken) {
  const std::size_t n = pts.size();
  const int k = std::min(params.region_k, g.k);
  const double max_distance = params.max_distance * r;
  const double min_cos = std::cos(params.max_angle_deg * CGAL_PI / 180.0);
  const std::vector<std::size_t> order = seed_order(pts, g, k);
  check_budget("structure");

  std::vector<char> visited = taken.empty() ? std::vector<char>(n, 0) : taken;
  std::vector<std::uint8_t> failures(n, 0);  // regions too small a point was part of (saturating)
  const int max_failures = params.max_seed_failures;
  std::size_t failed = 0, failed_points = 0;
  std::vector<int> region, ring, next;
  std::vector<std::vector<int>> out;
  RegionFit fit;
  for (std::size_t s = 0; s < n; ++s) {
    const int seed = static_cast<int>(order[s]);
    if (visited[static_cast<std::size_t>(seed)]) continue;
    if (max_failures > 0 && failures[static_cast<std::size_t>(seed)] >= max_failures) continue;
    if ((s & 0xffff) == 0) check_budget("structure");
    // Breadth-first, ring by ring; the plane is refit when a ring is done (CGAL's two running queues).
    region.assign(1, seed);
    visited[static_cast<std::size_t>(seed)] = 1;
    fit.reset(pts[static_cast<std::size_t>(seed)], normals[static_cast<std::size_t>(seed)]);
    ring.assign(1, seed);
    while (!ring.empty()) {
      next.clear();
      for (const int item : ring) {
        const int* row = g.row(static_cast<std::size_t>(item));
        for (int j = 0; j < k; ++j) {
          const int q = row[j];
          if (visited[static_cast<std::size_t>(q)]) continue;
          const Vec3& nq = normals[static_cast<std::size_t>(q)];
          if (params.signed_normals && nq.dot(normals[static_cast<std::size_t>(seed)]) <= 0) continue;
          const double len = nq.norm();
          if (!(fit.distance(pts[static_cast<std::size_t>(q)]) <= max_distance &&
                std::abs((nq / len).dot(fit.normal())) >= min_cos))
            continue;
          visited[static_cast<std::size_t>(q)] = 1;
          next.push_back(q);
          region.push_back(q);
          fit.add(pts[static_cast<std::size_t>(q)]);
        }
      }
      fit.refit();
      ring.swap(next);
    }
    if (is_large_enough(pts, region, fit.normal(), min)) {
      std::sort(region.begin(), region.end());
      out.push_back(region);
    } else {
      for (const int i : region) {
        visited[static_cast<std::size_t>(i)] = 0;
        if (failures[static_cast<std::size_t>(i)] < 255) ++failures[static_cast<std::size_t>(i)];
      }
      ++failed;
      failed_points += region.size();
    }
  }
  log::verbose("structure: region growing: " + std::to_string(out.size()) + " regions, " + std::to_string(failed) +
               " too small (" + std::to_string(failed_points) + " points visited by them)");
  return out;
}

}  // namespace hsr::structure_detail
