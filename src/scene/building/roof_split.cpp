// Step 7's split of a building's roof planes (DECISIONS #215 a gable's two halves, #223 two surfaces in one plane,
// #228 its gate, #239 counted on the kept model only): which roof planes hold two surfaces, each as its two halves'
// points (split_candidates); the structure with them split (split_roof_planes, step 7's run); what the model kept
// leaves far on them (split_gate). The roles' rules that decide which planes are roofs are in roles.cpp.
#include "scene/building/building_internal.h"
#include "scene/scene_internal.h"

#include "core/kd_tree.h"
#include "core/log.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

namespace hsr {

namespace {

using building_detail::is_wall;
using building_detail::small_roof_too_steep;
using scene_detail::kDeg;

/// A least-squares plane of points in prefix-sum form: the sums of x, y, z and their products, so that the plane
/// of any run of a sorted list and its squared residuals come in constant time.
struct Moments {
  double n = 0;
  Vec3 sum = Vec3::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  void add(const Vec3& p, double sign = 1.0) {
    n += sign;
    sum += sign * p;
    outer += sign * p * p.transpose();
  }
  /// The points' scatter about their centre (n times their covariance).
  Eigen::Matrix3d scatter() const {
    const Vec3 c = sum / n;
    return outer - n * c * c.transpose();
  }
  /// The plane through the centre along the two largest axes: its normal (turned up) and its squared residuals.
  std::pair<Vec3, double> fit() const {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter());
    Vec3 normal = eig.eigenvectors().col(0);
    if (normal.z() < 0) normal = -normal;
    return {normal, std::max(eig.eigenvalues()(0), 0.0)};
  }
  /// fit()'s squared residuals alone: the covariance's smallest eigenvalue in closed form (no eigenvectors, no
  /// iterations). Why: two_surfaces_of's scan asks it at every split place of every roof plane
  /// (DECISIONS #228: the iterative solver was most of the candidates' count).
  double residual() const {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(scatter(), Eigen::EigenvaluesOnly);
    return std::max(eig.eigenvalues()(0), 0.0);
  }
};

/// Two planes meet at a ridge, as a gable's two halves do (BuildingParams::gable_halves): each a roof (no wall,
/// not too steep) tilted more than gable_half_min_pitch_deg, and each one's uphill side (against its normal's
/// direction in plan, the normal turned up) facing the other's centre in plan. Why the last: two planes tilted
/// towards each other meet in a valley, and two tilted the same way are one roof in two pieces; neither is a
/// gable's other half.
bool ridge_pair(const Vec3& na, const Vec2& ca, const Vec3& nb, const Vec2& cb, const BuildingParams& params) {
  const double max_up = std::cos(params.gable_half_min_pitch_deg * kDeg);
  for (const Vec3& n : {na, nb}) {
    const Plane p{n, 0.0};
    if (is_wall(p, params) || small_roof_too_steep(p, params) || !(std::abs(n.z()) < max_up)) return false;
  }
  return (cb - ca).dot(na.head<2>()) < 0 && (ca - cb).dot(nb.head<2>()) < 0;
}

/// The points of a roof plane that gable_halves_of and two_surfaces_of split: its inliers and the points on no
/// plane within wing_reach r in plan of one of them, not lower than its plane's eave (its lowest height over its
/// inliers in plan) by more than gable_half_distance r, nor, with BuildingParams::split_below_ridge (off by
/// default), higher than its ridge (its highest) by more than that (DECISIONS #242: a crown over a flat roof was split off as a steep
/// "surface" and modelled, AHN3_11729 at half density; but so is a part of the building standing over the plane,
/// AHN3_00065's).
std::vector<int> split_candidates_points(const PointCloud& cloud, const SplitInput& input, const SplitInput::Roof& roof,
                                         const BuildingParams& params) {
  std::vector<int> pts = roof.inliers;
  // the plane's eave: its lowest height over its inliers in plan (not an inlier's own height: a wall's foot
  // within the inlier distance is one)
  const Plane& p = roof.fit;
  double eave = std::numeric_limits<double>::infinity(), ridge = -std::numeric_limits<double>::infinity();
  for (int i : roof.inliers) {
    const Vec3& q = cloud.points[static_cast<std::size_t>(i)];
    const double z = -(p.normal.x() * q.x() + p.normal.y() * q.y() + p.offset) / p.normal.z();
    eave = std::min(eave, z);
    ridge = std::max(ridge, z);
  }
  const double floor_z = eave - params.gable_half_distance * input.spacing;
  const double ceiling_z = params.split_below_ridge ? ridge + params.gable_half_distance * input.spacing
                                                    : std::numeric_limits<double>::infinity();
  std::vector<Vec3> xy;
  for (int i : roof.inliers) xy.emplace_back(cloud.points[static_cast<std::size_t>(i)].x(), cloud.points[static_cast<std::size_t>(i)].y(), 0.0);
  const KdTree plan(xy);
  const double reach2 = std::pow(params.wing_reach * input.spacing, 2);
  for (int i : input.free_points) {
    const Vec3& q = cloud.points[static_cast<std::size_t>(i)];
    if (q.z() < floor_z || q.z() > ceiling_z) continue;
    double d2 = 0.0;
    plan.nearest(Vec3(q.x(), q.y(), 0.0), &d2);
    if (d2 <= reach2) pts.push_back(i);
  }
  return pts;
}

/// The split of a roof plane k into a gable's two halves (BuildingParams::gable_halves, DECISIONS #215): the
/// inlier lists of the two halves, or nothing. The points: plane k's inliers and the points on no plane within
/// wing_reach r in plan of one of them, not lower than its plane's eave (its lowest height over its inliers in
/// plan) by more than gable_half_distance r (a gable's two halves span one height, eave to ridge; not a wall's
/// foot or the ground beside it). Split across each of the two axes of the inliers in plan
/// (their principal directions) at every place that leaves small_plane_points on either side, the two sides'
/// least-squares planes; the split with the least squared residuals of the two, over both axes, where the two
/// planes meet at a ridge (ridge_pair). Each half keeps its side's points within gable_half_distance r of its
/// plane (a point farther stays on no plane). Why a split, not a new detection: region growing over the same
/// points grows the larger half over the ridge again (the points' normals there lean both ways).
std::optional<std::array<std::vector<int>, 2>> gable_halves_of(const PointCloud& cloud, const SplitInput& input,
                                                               const SplitInput::Roof& roof, const BuildingParams& params) {
  const std::size_t m = static_cast<std::size_t>(params.small_plane_points);
  std::vector<int> pts = split_candidates_points(cloud, input, roof, params);
  if (pts.size() < 2 * m) return std::nullopt;
  Moments all;
  for (int i : pts) all.add(cloud.points[static_cast<std::size_t>(i)]);
  const Vec3 c = all.sum / all.n;
  Eigen::Matrix2d cov = (all.outer - all.n * c * c.transpose()).topLeftCorner<2, 2>();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> axes(cov);
  double best = std::numeric_limits<double>::infinity();
  std::optional<std::array<std::vector<int>, 2>> out;
  for (int axis = 0; axis < 2; ++axis) {
    const Vec2 d = axes.eigenvectors().col(axis);
    std::vector<std::pair<double, int>> order;
    for (int i : pts) order.emplace_back(cloud.points[static_cast<std::size_t>(i)].head<2>().dot(d), i);
    std::sort(order.begin(), order.end());
    Moments low;
    for (std::size_t j = 0; j + m < order.size(); ++j) {
      low.add(cloud.points[static_cast<std::size_t>(order[j].second)]);
      if (j + 1 < m || order[j].first == order[j + 1].first) continue;  // a split between two distinct places
      Moments high;
      high.n = all.n - low.n;
      high.sum = all.sum - low.sum;
      high.outer = all.outer - low.outer;
      const auto [na, ra] = low.fit();
      const auto [nb, rb] = high.fit();
      if (!(ra + rb < best)) continue;
      const Vec2 ca = (low.sum / low.n).head<2>(), cb = (high.sum / high.n).head<2>();
      if (!ridge_pair(na, ca, nb, cb, params)) continue;
      const Vec3 pa = low.sum / low.n, pb = high.sum / high.n;
      const double near = params.gable_half_distance * input.spacing;
      std::array<std::vector<int>, 2> halves;
      for (std::size_t q = 0; q < order.size(); ++q) {
        const bool first = q <= j;
        const Vec3& p = cloud.points[static_cast<std::size_t>(order[q].second)];
        if (std::abs((p - (first ? pa : pb)).dot(first ? na : nb)) <= near) halves[first ? 0 : 1].push_back(order[q].second);
      }
      if (halves[0].size() < 3 || halves[1].size() < 3) continue;
      best = ra + rb;
      out = std::move(halves);
    }
  }
  return out;
}

/// Whether two planes could hold small_plane_points (`m`) more of a roof plane's `points` within
/// gable_half_distance r than the plane itself holds (`near_one`): each half keeps only points of the `points`,
/// so the gain is at most the points the plane leaves farther than that. Why: two_surfaces_of asks it before its
/// scan over every split place, which is most of the candidates' count; on the AHN3
/// tile 263 of 450 roof planes end here (DECISIONS #232). The same candidates as without it.
bool may_gain_a_plane(std::size_t points, std::size_t near_one, std::size_t m) { return points >= near_one + m; }

/// The split of a roof plane k whose points lie on two surfaces (BuildingParams::two_surface_planes, DECISIONS
/// #223): the inlier lists of the two, or nothing. The points as gable_halves_of gathers them
/// (split_candidates_points); the least-squares split across either axis in plan (any two planes, no ridge asked);
/// then each point taken to the nearer of the two planes and both fitted again, until no point changes side (at
/// most kMaxRounds rounds; each side keeping small_plane_points). A candidate when the two planes hold at least
/// small_plane_points more of the points within gable_half_distance r than plane k does. Each keeps its points
/// within gable_half_distance r. Why the rounds: two surfaces meet where their planes cross, which runs at any
/// angle to the axes in plan (a hip beside a slope); the nearer plane puts each point on its side of that line.
std::optional<std::array<std::vector<int>, 2>> two_surfaces_of(const PointCloud& cloud, const SplitInput& input,
                                                               const SplitInput::Roof& roof, const BuildingParams& params) {
  constexpr int kMaxRounds = 20;  // the rounds settle in a few; a bound keeps a flip-flopping point from looping
  const std::size_t m = static_cast<std::size_t>(params.small_plane_points);
  const std::vector<int> pts = split_candidates_points(cloud, input, roof, params);
  if (pts.size() < 2 * m) return std::nullopt;
  const auto at = [&](int i) -> const Vec3& { return cloud.points[static_cast<std::size_t>(i)]; };
  const double near = params.gable_half_distance * input.spacing;
  const Plane& one = roof.fit;
  std::size_t near_one = 0;
  for (int i : pts) near_one += std::abs(one.normal.dot(at(i)) + one.offset) <= near;
  if (!may_gain_a_plane(pts.size(), near_one, m)) return std::nullopt;
  Moments all;
  for (int i : pts) all.add(at(i));
  const Vec3 c = all.sum / all.n;
  Eigen::Matrix2d cov = (all.outer - all.n * c * c.transpose()).topLeftCorner<2, 2>();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> axes(cov);
  // the least-squares split across an axis: each point's side (true: the low side)
  double best = std::numeric_limits<double>::infinity();
  std::vector<char> side;
  for (int axis = 0; axis < 2; ++axis) {
    const Vec2 d = axes.eigenvectors().col(axis);
    std::vector<std::pair<double, std::size_t>> order;
    for (std::size_t q = 0; q < pts.size(); ++q) order.emplace_back(at(pts[q]).head<2>().dot(d), q);
    std::sort(order.begin(), order.end());
    Moments low;
    for (std::size_t j = 0; j + m < order.size(); ++j) {
      low.add(at(pts[order[j].second]));
      if (j + 1 < m || order[j].first == order[j + 1].first) continue;  // a split between two distinct places
      Moments high;
      high.n = all.n - low.n;
      high.sum = all.sum - low.sum;
      high.outer = all.outer - low.outer;
      const double residuals = low.residual() + high.residual();
      if (!(residuals < best)) continue;
      best = residuals;
      side.assign(pts.size(), 0);
      for (std::size_t q = 0; q <= j; ++q) side[order[q].second] = 1;
    }
  }
  if (side.empty()) return std::nullopt;
  // the two planes, each point to the nearer, until no point changes side
  Vec3 n[2], centre[2];
  const auto fit_sides = [&] {
    Moments mo[2];
    for (std::size_t q = 0; q < pts.size(); ++q) mo[side[q] ? 0 : 1].add(at(pts[q]));
    if (mo[0].n < static_cast<double>(m) || mo[1].n < static_cast<double>(m)) return false;
    for (int h = 0; h < 2; ++h) {
      n[h] = mo[h].fit().first;
      centre[h] = mo[h].sum / mo[h].n;
    }
    return true;
  };
  if (!fit_sides()) return std::nullopt;
  for (int round = 0; round < kMaxRounds; ++round) {
    std::vector<char> next(pts.size());
    for (std::size_t q = 0; q < pts.size(); ++q)
      next[q] = std::abs((at(pts[q]) - centre[0]).dot(n[0])) <= std::abs((at(pts[q]) - centre[1]).dot(n[1]));
    if (next == side) break;
    const std::vector<char> before = std::move(side);
    side = std::move(next);
    if (!fit_sides()) {  // a side fell under small_plane_points: the split before stands
      side = before;
      fit_sides();
      break;
    }
  }
  // what one plane leaves far and two explain
  std::array<std::vector<int>, 2> halves;
  for (std::size_t q = 0; q < pts.size(); ++q) {
    const Vec3& p = at(pts[q]);
    const int h = side[q] ? 0 : 1;
    if (std::abs((p - centre[h]).dot(n[h])) <= near) halves[h].push_back(pts[q]);
  }
  if (halves[0].size() < m || halves[1].size() < m || halves[0].size() + halves[1].size() < near_one + m)
    return std::nullopt;
  for (auto& h : halves) std::sort(h.begin(), h.end());
  return halves;
}

}  // namespace

SplitCandidates split_candidates(const PointCloud& cloud, const SplitInput& input, const BuildingParams& params,
                                 std::vector<std::size_t>* planes) {
  SplitCandidates halves;
  if (planes) planes->clear();
  for (const SplitInput::Roof& roof : input.roofs) {
    std::optional<std::array<std::vector<int>, 2>> h;
    if (params.gable_halves) h = gable_halves_of(cloud, input, roof, params);
    if (!h && params.two_surface_planes) h = two_surfaces_of(cloud, input, roof, params);
    if (!h) continue;
    if (planes) planes->push_back(roof.plane);
    halves.push_back(std::move(*h));
  }
  return halves;
}

namespace building_detail {

SplitInput split_input_of(const SceneStructure& s, std::size_t first_size, const SceneResult& scene,
                          const BuildingParams& params) {
  SplitInput input;
  input.spacing = s.spacing;
  for (std::size_t k = 0; k < first_size && k < s.planes.size(); ++k) {
    if (scene.roles[k] != PlaneRole::Roof || is_wall(s.planes[k].plane, params)) continue;
    input.roofs.push_back({k, s.planes[k].plane, s.planes[k].inliers});
  }
  for (std::size_t i = 0; i < s.point_plane.size(); ++i)
    if (s.point_plane[i] < 0) input.free_points.push_back(static_cast<int>(i));
  return input;
}

SceneStructure split_roof_planes(const PointCloud& cloud, SceneStructure s, const SplitInput& input,
                                 const StructureParams& structure, const BuildingParams& params, SceneResult& scene,
                                 KnnGraphCache* graphs, std::size_t* planes_split) {
  std::vector<std::size_t> found;
  const SplitCandidates halves = split_candidates(cloud, input, params, &found);
  if (planes_split) *planes_split = found.size();
  if (found.empty()) return s;
  // Every such plane left out, its points and the free points its halves take unassigned, the halves appended.
  std::vector<bool> keep(s.planes.size(), true);
  for (std::size_t k : found) keep[k] = false;
  SceneStructure without = subset_planes(s, keep, structure.min_line_angle_deg);
  std::vector<std::vector<int>> lists;
  std::vector<char> used(cloud.size(), 0);
  for (const auto& h : halves)
    for (const std::vector<int>& half : h) {
      std::vector<int> list;
      for (int i : half)
        if (without.point_plane[static_cast<std::size_t>(i)] < 0 && !used[static_cast<std::size_t>(i)]) {
          used[static_cast<std::size_t>(i)] = 1;
          list.push_back(i);
        }
      lists.push_back(std::move(list));
    }
  std::vector<PlaneRole> roles;
  for (std::size_t k = 0; k < s.planes.size(); ++k)
    if (keep[k]) roles.push_back(scene.roles[k]);
  SceneStructure with = add_planes(cloud, without, std::move(lists), structure, graphs);
  for (std::size_t j = without.planes.size(); j < with.planes.size(); ++j) {
    const Plane& p = with.planes[j].plane;
    roles.push_back(is_wall(p, params) || small_roof_too_steep(p, params) ? PlaneRole::Clutter : PlaneRole::Roof);
  }
  scene.roles = std::move(roles);
  std::string sizes;
  for (std::size_t j = without.planes.size(); j < with.planes.size(); ++j)
    sizes += (sizes.empty() ? "" : ", ") + std::to_string(with.planes[j].inliers.size());
  log::verbose("scene: " + std::to_string(found.size()) + " roof plane(s) holding a gable's two halves split: planes of " +
               sizes + " points");
  return with;
}

}  // namespace building_detail

// The gate of step 7 (building.h): the candidates whose halves' points the model leaves far, a plane's worth, and
// what bringing those points to their halves' planes would take off the model's distances.
SplitGate split_gate(const PointCloud& cloud, const SplitCandidates& candidates, const std::vector<double>& point_distance,
                     double spacing, std::size_t min_points, const BuildingParams& params) {
  SplitGate gate;
  if (point_distance.size() != cloud.size()) return gate;
  const double far = params.gable_half_distance * spacing;
  for (double d : point_distance) gate.distance_sum += d;
  for (const auto& halves : candidates) {
    std::size_t left = 0;
    double gain = 0.0;
    for (const std::vector<int>& half : halves) {
      Moments mo;
      for (int i : half) mo.add(cloud.points[static_cast<std::size_t>(i)]);
      const Vec3 n = mo.fit().first, c = mo.sum / mo.n;
      for (int i : half) {
        const double d = point_distance[static_cast<std::size_t>(i)];
        if (!(d > far)) continue;
        ++left;
        gain += std::max(0.0, d - std::abs((cloud.points[static_cast<std::size_t>(i)] - c).dot(n)));
      }
    }
    if (left < min_points) continue;
    ++gate.far_candidates;
    gate.gain += gain;
  }
  return gate;
}

}  // namespace hsr
