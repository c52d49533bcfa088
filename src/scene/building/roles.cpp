// The building's plane roles (roof, wall, ground, clutter) and its main direction (building.h).
#include "scene/building/building_internal.h"
#include "scene/scene_internal.h"

#include "core/kd_tree.h"
#include "core/log.h"
#include "core/rectangle.h"
#include "core/stats.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <optional>
#include <cmath>
#include <limits>

namespace hsr {

namespace {

using scene_detail::heights_of;
using scene_detail::kDeg;

bool is_wall(const Plane& p, const BuildingParams& params) {
  return std::abs(p.normal.z()) <= std::sin(params.wall_max_angle_deg * kDeg);
}

/// Connected groups of the planes with `member` in the adjacency graph, each sorted; group order by first plane.
std::vector<std::vector<int>> plane_groups(const SceneStructure& s, const std::vector<bool>& member) {
  std::vector<int> group(s.planes.size(), -1);
  std::vector<std::vector<int>> groups;
  for (std::size_t seed = 0; seed < s.planes.size(); ++seed) {
    if (!member[seed] || group[seed] >= 0) continue;
    std::vector<int> g{static_cast<int>(seed)};
    group[seed] = static_cast<int>(groups.size());
    for (std::size_t k = 0; k < g.size(); ++k)
      for (int nb : s.adjacency[static_cast<std::size_t>(g[k])])
        if (member[static_cast<std::size_t>(nb)] && group[static_cast<std::size_t>(nb)] < 0) {
          group[static_cast<std::size_t>(nb)] = static_cast<int>(groups.size());
          g.push_back(nb);
        }
    std::sort(g.begin(), g.end());
    groups.push_back(std::move(g));
  }
  return groups;
}

BBox xy_box(const PointCloud& cloud, const SceneStructure& s, const std::vector<int>& planes) {
  BBox b;
  for (int k : planes)
    for (int i : s.planes[static_cast<std::size_t>(k)].inliers) b.extend(cloud.points[static_cast<std::size_t>(i)]);
  return b;
}

bool xy_overlap(const BBox& a, const BBox& b, double grow) {
  return a.min.x() - grow <= b.max.x() && b.min.x() - grow <= a.max.x() && a.min.y() - grow <= b.max.y() &&
         b.min.y() - grow <= a.max.y();
}

std::size_t inliers_of(const SceneStructure& s, const std::vector<int>& planes) {
  std::size_t n = 0;
  for (int k : planes) n += s.planes[static_cast<std::size_t>(k)].inliers.size();
  return n;
}

/// Foliage, not a roof: its "plane" is a loose layer of points (RMS distance to the plane at least
/// vegetation_rms r) whose normals scatter (mean angle to the plane's normal at least vegetation_normal_deg).
bool is_vegetation(const PointCloud& cloud, const SceneStructure& s, const DetectedPlane& p, const BuildingParams& params) {
  double sq = 0, angle = 0;
  for (int i : p.inliers) {
    const double d = p.plane.signed_distance(cloud.points[static_cast<std::size_t>(i)]);
    sq += d * d;
    angle += std::acos(std::min(1.0, std::abs(s.normals[static_cast<std::size_t>(i)].dot(p.plane.normal))));
  }
  const double n = static_cast<double>(p.inliers.size());
  return std::sqrt(sq / n) >= params.vegetation_rms * s.spacing && angle / n >= params.vegetation_normal_deg * kDeg;
}

/// A low roof adjacent (SceneStructure::adjacency: inliers among each other's neighbours) to a roof that is
/// not low is a lower part of the building, a lean-to shed or a garage against its wall, not a car or a hedge
/// beside it: "low" is a height in r (building_min_height), which at survey densities of 4 points/m² is 3 m
/// (DECISIONS #53).
bool attached_to_a_tall_roof(const SceneStructure& s, std::size_t k, const std::vector<bool>& low,
                             const std::vector<bool>& foliage, const std::vector<PlaneRole>& roles) {
  for (int j : s.adjacency[k]) {
    const auto u = static_cast<std::size_t>(j);
    if (roles[u] == PlaneRole::Roof && !low[u] && !foliage[u]) return true;
  }
  return false;
}

/// Whether a low roof could be a car's (DECISIONS #77, #233): narrower than a car (its smallest-area rectangle
/// in plan under car_max_width across) and no taller than one (`rise`, its roof_height_quantile height over the
/// ground, at most car_max_height). Why the height: "low" is in r (building_min_height), so at half density it
/// takes in a storey; a 1.9 m wide flat strip 2.5 m up along a house (AHN3_16804 at half density) is no car.
bool could_be_a_car(const std::vector<Vec2>& xy, double rise, const BuildingParams& params) {
  return rise <= params.car_max_height && !(min_area_rectangle(xy).width >= params.car_max_width);
}

/// A low roof that is a wing of the building, not a car (DECISIONS #77): it rises off the ground (`height90`,
/// its roof_height_quantile height, at least wing_min_rise r above it: nearer, it cannot be told from the
/// ground, a terrain patch beside the walls), it is no car (could_be_a_car) and it touches a roof that is
/// not low in plan (one of its inliers within wing_reach r of one of `tall_roofs`, those roofs' inliers in
/// plan: the two meet along an eave). A flat
/// garage or annex against a house whose wall the scan missed has no inlier among the house's nearest
/// neighbours (attached_to_a_tall_roof): the eave lies a storey above it.
bool low_wing(const PointCloud& cloud, const SceneStructure& s, std::size_t k, double height90, double ground_z,
              const BuildingParams& params, const KdTree& tall_roofs) {
  if (height90 < ground_z + params.wing_min_rise * s.spacing || tall_roofs.size() == 0) return false;
  std::vector<Vec2> xy;
  for (int i : s.planes[k].inliers) xy.push_back(cloud.points[static_cast<std::size_t>(i)].head<2>());
  if (could_be_a_car(xy, height90 - ground_z, params)) return false;
  const double reach = params.wing_reach * s.spacing, reach2 = reach * reach;
  for (const Vec2& p : xy) {
    double d2 = 0;
    tall_roofs.nearest(Vec3(p.x(), p.y(), 0.0), &d2);
    if (d2 <= reach2) return true;
  }
  return false;
}

/// The inliers of the roofs that are neither low nor foliage, in plan (z = 0): what low_wing() looks for.
KdTree tall_roofs_in_plan(const PointCloud& cloud, const SceneStructure& s, const std::vector<bool>& low,
                          const std::vector<bool>& foliage, const std::vector<PlaneRole>& roles) {
  std::vector<Vec3> tall;
  for (std::size_t j = 0; j < s.planes.size(); ++j)
    if (roles[j] == PlaneRole::Roof && !low[j] && !foliage[j])
      for (int i : s.planes[j].inliers) {
        const Vec3& p = cloud.points[static_cast<std::size_t>(i)];
        tall.emplace_back(p.x(), p.y(), 0.0);
      }
  return tall.empty() ? KdTree() : KdTree(tall);
}

}  // namespace

std::vector<bool> foliage_planes(const PointCloud& cloud, const SceneStructure& s, const BuildingParams& params) {
  std::vector<bool> f(s.planes.size());
  for (std::size_t k = 0; k < s.planes.size(); ++k) f[k] = is_vegetation(cloud, s, s.planes[k], params);
  return f;
}

namespace building_detail {

void assign_roles(const PointCloud& cloud, const SceneStructure& s, const BuildingParams& params,
                  const std::vector<bool>& foliage, bool low_rule, SceneResult& out) {
  const double r = s.spacing;
  std::vector<bool> low(s.planes.size(), false);
  std::vector<double> height90(s.planes.size(), 0.0);
  bool tall_roof = false;
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    if (out.roles[k] == PlaneRole::Ground) continue;
    const DetectedPlane& p = s.planes[k];
    out.roles[k] = is_wall(p.plane, params) ? PlaneRole::Wall : PlaneRole::Roof;
    if (out.roles[k] != PlaneRole::Roof || foliage[k] || !low_rule) continue;
    // A roof lower than building_min_height (at its roof_height_quantile) is a car, a hedge or sloped terrain.
    height90[k] = quantile(heights_of(cloud, p.inliers), params.roof_height_quantile);
    low[k] = height90[k] < out.ground_z + params.building_min_height * r;
    tall_roof = tall_roof || !low[k];
  }
  const bool any_low = std::find(low.begin(), low.end(), true) != low.end();
  const KdTree tall_roofs = any_low && tall_roof ? tall_roofs_in_plan(cloud, s, low, foliage, out.roles) : KdTree();
  std::vector<bool> candidate(s.planes.size(), false);
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    const bool car_or_hedge = low[k] && tall_roof && !attached_to_a_tall_roof(s, k, low, foliage, out.roles) &&
                              !low_wing(cloud, s, k, height90[k], out.ground_z, params, tall_roofs);
    if (out.roles[k] == PlaneRole::Roof && (foliage[k] || car_or_hedge)) out.roles[k] = PlaneRole::Clutter;
    candidate[k] = out.roles[k] == PlaneRole::Roof || out.roles[k] == PlaneRole::Wall;
  }
  const auto groups = plane_groups(s, candidate);
  if (groups.empty()) return;
  std::size_t main = 0;
  for (std::size_t g = 1; g < groups.size(); ++g)
    if (inliers_of(s, groups[g]) > inliers_of(s, groups[main])) main = g;
  const BBox main_box = xy_box(cloud, s, groups[main]);
  const std::size_t main_inliers = inliers_of(s, groups[main]);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (g == main || xy_overlap(xy_box(cloud, s, groups[g]), main_box, params.far_group_margin * r)) continue;
    if (static_cast<double>(inliers_of(s, groups[g])) >= params.min_building_share * static_cast<double>(main_inliers))
      continue;  // another building
    for (int k : groups[g]) out.roles[static_cast<std::size_t>(k)] = PlaneRole::Clutter;
  }
}

/// building_internal.h. Why: the smallest rectangle around points on a raster's rows follows the rows whatever the
/// building's direction (Vaihingen's scans lie on a 0.5 m grid; Vaihingen_00034 at half density, 2.3 degrees off
/// the grid, got 0).
bool sides_on_raster_rows(const std::vector<Vec2>& xy, double angle, double tolerance) {
  const Vec2 e0(std::cos(angle), std::sin(angle)), e1(-e0.y(), e0.x());
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec2& p : xy) {
    const Vec2 q(p.dot(e0), p.dot(e1));
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  std::array<int, 4> on{0, 0, 0, 0};
  for (const Vec2& p : xy) {
    const Vec2 q(p.dot(e0), p.dot(e1));
    on[0] += q.x() - lo.x() <= tolerance;
    on[1] += hi.x() - q.x() <= tolerance;
    on[2] += q.y() - lo.y() <= tolerance;
    on[3] += hi.y() - q.y() <= tolerance;
  }
  return *std::max_element(on.begin(), on.end()) >= 3;
}

/// The side of the smallest-area rectangle around every roof's and wall's inliers in plan, when it lies within
/// main_direction_window_deg of `outlines` (the direction the outlines give), its sides are not on a raster's
/// rows (sides_on_raster_rows, BuildingParams::main_direction_raster_tolerance) and the roofs fill it
/// (BuildingParams::main_direction_min_fill: their alpha shapes' area in plan against its area); else `outlines`.
/// Why: a roof part's outline segments and its rectangle span a few metres, and at the spacing of a sparse scan
/// (half a metre) their directions scatter by degrees; the sides of the rectangle around all the roofs and walls
/// span the whole building, so its direction is the better one where it agrees with the outlines (DECISIONS #195: hsr's walls stood
/// a median 1.08 degrees off City3D's at half density, the rectangle around all the scan's points 0.43). An L,
/// a bent building or a courtyard, whose rectangle need not follow its sides, does not fill it and keeps the
/// outlines' direction.
double rectangle_direction(const PointCloud& cloud, const SceneStructure& s, const std::vector<PlaneRole>& roles,
                           double outlines, const BuildingParams& params) {
  std::vector<Vec2> xy;
  double roofs_area = 0;  // in plan
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    if (roles[k] != PlaneRole::Roof && roles[k] != PlaneRole::Wall) continue;
    for (int i : s.planes[k].inliers) xy.push_back(cloud.points[static_cast<std::size_t>(i)].head<2>());
    if (roles[k] == PlaneRole::Roof) roofs_area += s.planes[k].area * std::abs(s.planes[k].plane.normal.z());
  }
  const RectangleDirection rect = min_area_rectangle(xy);
  if (!(rect.perimeter > 0)) return outlines;
  if (roofs_area < params.main_direction_min_fill * rect.width * (0.5 * rect.perimeter - rect.width)) return outlines;
  const double off = std::remainder(rect.angle - outlines, M_PI / 2.0);
  if (!(std::abs(off) <= params.main_direction_window_deg * kDeg)) return outlines;
  const double r = s.spacing > 0 ? s.spacing : 1.0;
  const double tolerance = params.main_direction_raster_tolerance * r;
  return tolerance >= 0 && sides_on_raster_rows(xy, rect.angle, tolerance) ? outlines : rect.angle;
}

/// Length weighted, 1-degree bins, smoothed over ± main_direction_smoothing_deg, then the weighted circular
/// mean of the directions within main_direction_window_deg of the peak. Each roof's smallest-area rectangle
/// (its inliers in plan) votes too, with its perimeter: a small roof whose alpha shape gave one segment across
/// a corner still turns its walls onto its sides. Then the direction of the rectangle around all the roofs and
/// walls when it agrees (rectangle_direction, BuildingParams::main_direction_from_rectangle).
double main_direction(const PointCloud& cloud, const SceneStructure& s, const std::vector<PlaneRole>& roles,
                      const BuildingParams& params) {
  constexpr int kBins = 90;  // one per degree of a quarter turn
  std::vector<double> hist(kBins, 0.0);
  std::vector<std::pair<double, double>> dirs;  // (angle mod 90 deg, length)
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    if (roles[k] != PlaneRole::Roof && roles[k] != PlaneRole::Wall) continue;
    for (const BoundarySegment& seg : s.planes[k].segments) {
      const Vec3 d = seg.b - seg.a;
      const double len = d.head<2>().norm();
      if (!(len > 0)) continue;
      double a = std::fmod(std::atan2(d.y(), d.x()) + 2.0 * M_PI, M_PI / 2.0);
      dirs.push_back({a, len});
      hist[static_cast<std::size_t>(std::min(kBins - 1, static_cast<int>(a / kDeg)))] += len;
    }
    if (roles[k] != PlaneRole::Roof) continue;
    std::vector<Vec2> xy;
    xy.reserve(s.planes[k].inliers.size());
    for (int i : s.planes[k].inliers) xy.push_back(cloud.points[static_cast<std::size_t>(i)].head<2>());
    const RectangleDirection rect = min_area_rectangle(xy);
    if (rect.perimeter > 0) {
      dirs.push_back({rect.angle, rect.perimeter});
      hist[static_cast<std::size_t>(std::min(kBins - 1, static_cast<int>(rect.angle / kDeg)))] += rect.perimeter;
    }
  }
  if (dirs.empty()) return 0.0;
  int peak = 0;
  double best = -1;
  const int smooth = params.main_direction_smoothing_deg;
  for (int b = 0; b < kBins; ++b) {
    double sum = 0;
    for (int o = -smooth; o <= smooth; ++o) sum += hist[static_cast<std::size_t>((b + o + kBins) % kBins)];
    if (sum > best + 1e-12) {  // strictly larger: the first of equal peaks
      best = sum;
      peak = b;
    }
  }
  // Circular mean with period pi/2: average the angle times 4 on the unit circle.
  const double centre = (peak + 0.5) * kDeg;
  Vec2 acc = Vec2::Zero();
  for (const auto& [a, len] : dirs) {
    double diff = std::remainder(a - centre, M_PI / 2.0);
    if (std::abs(diff) <= params.main_direction_window_deg * kDeg) acc += len * Vec2(std::cos(4.0 * a), std::sin(4.0 * a));
  }
  const double outlines = acc.norm() > 0 ? std::fmod(std::atan2(acc.y(), acc.x()) / 4.0 + M_PI / 2.0, M_PI / 2.0) : centre;
  return params.main_direction_from_rectangle ? rectangle_direction(cloud, s, roles, outlines, params) : outlines;
}

}  // namespace building_detail

}  // namespace hsr

namespace hsr {

namespace {

/// How far the roofs reach over a small upright plane on the side where they reach the least, in the
/// plane's units: the roof inliers (planes with role Roof, `roles`) whose position along the wall lies within
/// its inliers' extent (one spacing `r` more each end) and that stand no lower than a spacing under the wall's
/// highest inlier, by signed distance in plan to the wall's line through its centroid; the smaller of the
/// largest distance on either side, 0 when one side has none. A wall under an eave has the roof on both sides
/// of it (the eave's overhang on the outer one); an outer wall whose top is the eave, or a step wall between a
/// roof and a lower one, has the roofs above its top on one side only.
double roof_overhang(const PointCloud& cloud, const SceneStructure& s, const std::vector<PlaneRole>& roles,
                     const DetectedPlane& wall, double r) {
  Vec2 n = wall.plane.normal.head<2>();
  if (!(n.norm() > 0) || wall.inliers.empty()) return 0.0;
  n.normalize();
  const Vec2 along(-n.y(), n.x());
  const Vec2 c = wall.centroid.head<2>();
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, top = -lo;
  for (int i : wall.inliers) {
    const Vec3& p = cloud.points[static_cast<std::size_t>(i)];
    const double t = along.dot(p.head<2>());
    lo = std::min(lo, t);
    hi = std::max(hi, t);
    top = std::max(top, p.z());
  }
  double out = 0.0, in = 0.0;
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    if (roles[k] != PlaneRole::Roof) continue;
    for (int i : s.planes[k].inliers) {
      const Vec3& p = cloud.points[static_cast<std::size_t>(i)];
      const double t = along.dot(p.head<2>());
      if (t < lo - r || t > hi + r || p.z() < top - r) continue;
      const double d = n.dot(p.head<2>() - c);
      out = std::max(out, d);
      in = std::max(in, -d);
    }
  }
  return std::min(out, in);
}

/// A small upright plane is no wall of the building when the roofs above it reach more than
/// small_wall_max_overhang spacings beyond it on both sides (roof_overhang), or when small planes may be
/// roofs only (small_plane_walls false). Why: a scanned wall under an eave becomes the model's wall there, and
/// the roof outline's wall, at the eave, is no longer recovered (a detected wall explains the roof's side,
/// recovery's wall_join_distance): the model's wall moves inside the eave line that City3D's model and the
/// first planes' recovered walls follow (AHN3_01218: a 16-point wall 0.8 r inside the eave, City3D -> hsr on
/// City3D's ground 0.66 -> 1.23 %). A plane it rejects stays clutter.
bool small_wall_under_an_eave(const PointCloud& cloud, const SceneStructure& s, const std::vector<PlaneRole>& roles,
                              const DetectedPlane& wall, const BuildingParams& params) {
  if (!params.small_plane_walls) return true;
  if (params.small_wall_max_overhang < 0) return false;
  const double overhang = roof_overhang(cloud, s, roles, wall, s.spacing) / s.spacing;
  const bool under = overhang > params.small_wall_max_overhang;
  log::verbose("scene: a small upright plane of " + std::to_string(wall.inliers.size()) + " points, the roofs " +
               std::to_string(overhang) + " r over it on both sides: " + (under ? "under an eave, no wall" : "a wall"));
  return under;
}

/// A small plane that is not upright enough to be a wall (wall_max_angle_deg) is a roof only when its slope is
/// at most small_roof_max_slope_deg. Why: a few points on a chimney's or a facade's side, with noise, fit a
/// plane tilted 15-20 degrees from upright; as a roof it faces down or cuts a steep wedge through the cells
/// (AHN3_00989 with 3 cm noise: a 21-point plane 73 degrees steep, the chimney left out, p2m 0.70 -> 1.71 %).
/// A plane it rejects stays clutter.
bool small_roof_too_steep(const Plane& p, const BuildingParams& params) {
  return std::abs(p.normal.z()) < std::cos(params.small_roof_max_slope_deg * kDeg);
}

/// The inliers of the building's roofs that are neither low nor foliage: in plan (z = 0) for the search and
/// with their heights, for small_roof_under_an_eave().
struct RoofsInPlan {
  KdTree plan;
  std::vector<double> z;
};

RoofsInPlan roofs_in_plan(const PointCloud& cloud, const SceneStructure& s, const std::vector<bool>& low,
                          const std::vector<bool>& foliage, const std::vector<PlaneRole>& roles) {
  std::vector<Vec3> xy;
  RoofsInPlan r;
  for (std::size_t j = 0; j < s.planes.size(); ++j)
    if (roles[j] == PlaneRole::Roof && !low[j] && !foliage[j])
      for (int i : s.planes[j].inliers) {
        const Vec3& p = cloud.points[static_cast<std::size_t>(i)];
        xy.emplace_back(p.x(), p.y(), 0.0);
        r.z.push_back(p.z());
      }
  if (!xy.empty()) r.plan = KdTree(xy);
  return r;
}

/// A small roof plane that is not low lies under the eave of a roof of the building: one of its inliers has,
/// within wing_reach r of it in plan, an inlier of one of `roofs` higher than itself by more than
/// small_roof_eave_drop r. Why: a first-size roof that is not low is a roof of the building wherever it lies
/// (assign_roles), while a small one joins only a plane it touches (SceneStructure::adjacency: inliers among each
/// other's nearest neighbours). A lower part whose eave lies a storey under the main roof's, its wall unscanned,
/// has no such neighbour, and at half density such a part falls under the smallest plane: AHN3_03746's annex roof
/// (46 points, a roof at full density; 24 at half density) was left out as clutter. The same in-plan reach as a
/// low wing's (#77): the two roofs meet along an eave. Under it, not over it: a tree's crown over a flat roof
/// meets the roof in plan too, above it (AHN3_15708 at half density: its crown's small planes would be roofs,
/// the tree modelled). Under by more than the inlier distance: a noisy patch at the roof's own height is not
/// under it (#176).
bool small_roof_under_an_eave(const PointCloud& cloud, const DetectedPlane& small, const RoofsInPlan& roofs,
                              double spacing, const BuildingParams& params) {
  if (!params.small_roof_meets_in_plan || roofs.plan.size() == 0) return false;
  const double reach = params.wing_reach * spacing, reach2 = reach * reach;
  const double drop = params.small_roof_eave_drop * spacing;
  constexpr int kNear = 8;
  int idx[kNear];
  double d2[kNear];
  for (int i : small.inliers) {
    const Vec3& p = cloud.points[static_cast<std::size_t>(i)];
    const int n = roofs.plan.nearest_k(Vec3(p.x(), p.y(), 0.0), kNear, idx, d2);
    for (int k = 0; k < n; ++k)
      if (d2[k] <= reach2 && roofs.z[static_cast<std::size_t>(idx[k])] > p.z() + drop) return true;
  }
  return false;
}

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
  /// iterations). Why: two_surfaces_of's scan asks it at every split place of every roof plane in every run
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

/// The points of roof plane k that gable_halves_of and two_surfaces_of split: its inliers and the points on no
/// plane within wing_reach r in plan of one of them, not lower than its plane's eave (its lowest height over its
/// inliers in plan) by more than gable_half_distance r.
std::vector<int> split_candidates_points(const PointCloud& cloud, const SceneStructure& s, std::size_t k,
                                         const BuildingParams& params) {
  const DetectedPlane& roof = s.planes[k];
  std::vector<int> pts = roof.inliers;
  // the plane's eave: its lowest height over its inliers in plan (not an inlier's own height: a wall's foot
  // within the inlier distance is one)
  const Plane& p = roof.plane;
  double eave = std::numeric_limits<double>::infinity();
  for (int i : roof.inliers) {
    const Vec3& q = cloud.points[static_cast<std::size_t>(i)];
    eave = std::min(eave, -(p.normal.x() * q.x() + p.normal.y() * q.y() + p.offset) / p.normal.z());
  }
  const double floor_z = eave - params.gable_half_distance * s.spacing;
  std::vector<Vec3> xy;
  for (int i : roof.inliers) xy.emplace_back(cloud.points[static_cast<std::size_t>(i)].x(), cloud.points[static_cast<std::size_t>(i)].y(), 0.0);
  const KdTree plan(xy);
  const double reach2 = std::pow(params.wing_reach * s.spacing, 2);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (s.point_plane[i] >= 0 || cloud.points[i].z() < floor_z) continue;
    double d2 = 0.0;
    plan.nearest(Vec3(cloud.points[i].x(), cloud.points[i].y(), 0.0), &d2);
    if (d2 <= reach2) pts.push_back(static_cast<int>(i));
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
std::optional<std::array<std::vector<int>, 2>> gable_halves_of(const PointCloud& cloud, const SceneStructure& s,
                                                               std::size_t k, const BuildingParams& params) {
  const std::size_t m = static_cast<std::size_t>(params.small_plane_points);
  std::vector<int> pts = split_candidates_points(cloud, s, k, params);
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
      const double near = params.gable_half_distance * s.spacing;
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
/// scan over every split place, which is most of the candidates' count in every run of a building; on the AHN3
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
std::optional<std::array<std::vector<int>, 2>> two_surfaces_of(const PointCloud& cloud, const SceneStructure& s,
                                                               std::size_t k, const BuildingParams& params) {
  constexpr int kMaxRounds = 20;  // the rounds settle in a few; a bound keeps a flip-flopping point from looping
  const std::size_t m = static_cast<std::size_t>(params.small_plane_points);
  const std::vector<int> pts = split_candidates_points(cloud, s, k, params);
  if (pts.size() < 2 * m) return std::nullopt;
  const auto at = [&](int i) -> const Vec3& { return cloud.points[static_cast<std::size_t>(i)]; };
  const double near = params.gable_half_distance * s.spacing;
  const Plane& one = s.planes[k].plane;
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

/// The building's roof planes of the detection's size (index under `first_size`) that hold a gable's two halves
/// (gable_halves_of, when BuildingParams::gable_halves) or else two surfaces (two_surfaces_of, when
/// two_surface_planes), listed in `*candidates` (each as its two halves); with `split`, each replaced by its halves (roles Roof; a plane
/// that is a wall or too steep, clutter).
SceneStructure split_gables(const PointCloud& cloud, SceneStructure s, std::size_t first_size,
                            const StructureParams& structure, const BuildingParams& params, SceneResult& scene,
                            bool split, SplitCandidates* candidates, KnnGraphCache* graphs) {
  std::vector<std::size_t> found;
  std::vector<std::array<std::vector<int>, 2>> halves;
  for (std::size_t k = 0; k < first_size && k < s.planes.size(); ++k) {
    if (scene.roles[k] != PlaneRole::Roof || is_wall(s.planes[k].plane, params)) continue;
    std::optional<std::array<std::vector<int>, 2>> h;
    if (params.gable_halves) h = gable_halves_of(cloud, s, k, params);
    if (!h && params.two_surface_planes) h = two_surfaces_of(cloud, s, k, params);
    if (h) {
      found.push_back(k);
      halves.push_back(std::move(*h));
    }
  }
  if (candidates) *candidates = halves;
  if (!split || found.empty()) return s;
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

}  // namespace

namespace {

/// The small planes found among the points on no plane and the roles of those that join the building
/// (building_small_planes before the gable halves).
SceneStructure join_small_planes(const PointCloud& cloud, const SceneStructure& detected,
                                 const StructureParams& structure, const BuildingParams& params,
                                 SceneResult& scene, KnnGraphCache* graphs) {
  SceneStructure s = add_small_planes(cloud, detected, std::vector<bool>(cloud.size(), true), structure,
                                      static_cast<std::size_t>(params.small_plane_points),
                                      params.small_plane_width * detected.spacing, graphs);
  const std::size_t first = detected.planes.size();
  if (s.planes.size() == first) return detected;
  // Low: under the low rule's height (building_min_height r over the ground; not against an assumed ground).
  const bool low_rule = scene.ground_source != GroundSource::Assumed;
  const double low_z = scene.ground_z + params.building_min_height * s.spacing;
  std::vector<bool> foliage(s.planes.size(), false), low(s.planes.size(), false);
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    if (k >= first) {
      foliage[k] = is_vegetation(cloud, s, s.planes[k], params);
      scene.roles.push_back(PlaneRole::Clutter);
    }
    low[k] = low_rule && quantile(heights_of(cloud, s.planes[k].inliers), params.roof_height_quantile) < low_z;
  }
  // A small plane is a part of the building when it touches one (a low one: a roof that is not low, as a low
  // roof of the first planes must, #53): in order, until none joins.
  for (bool joined = true; joined;) {
    joined = false;
    // The roofs as the pass began, built when a small roof first needs them (most passes test none).
    const std::vector<PlaneRole> pass_roles = scene.roles;
    std::optional<RoofsInPlan> roofs;
    for (std::size_t k = first; k < s.planes.size(); ++k) {
      if (foliage[k] || scene.roles[k] != PlaneRole::Clutter) continue;
      const bool wall = is_wall(s.planes[k].plane, params);
      const bool touches = std::any_of(s.adjacency[k].begin(), s.adjacency[k].end(), [&](int j) {
        const PlaneRole r = scene.roles[static_cast<std::size_t>(j)];
        return low[k] ? r == PlaneRole::Roof && !low[static_cast<std::size_t>(j)] : r == PlaneRole::Roof || r == PlaneRole::Wall;
      });
      const bool candidate = !touches && !wall && !low[k] && params.small_roof_meets_in_plan;
      if (candidate && !roofs) roofs = roofs_in_plan(cloud, s, low, foliage, pass_roles);
      const bool meets = candidate && small_roof_under_an_eave(cloud, s.planes[k], *roofs, s.spacing, params);
      if (!touches && !meets) continue;
      if (meets)
        log::verbose("scene: a small roof plane of " + std::to_string(s.planes[k].inliers.size()) +
                     " points lies under the eave of a roof of the building in plan, no adjacency: a roof of it");
      if (wall && small_wall_under_an_eave(cloud, s, scene.roles, s.planes[k], params)) continue;
      if (!wall && small_roof_too_steep(s.planes[k].plane, params)) continue;
      scene.roles[k] = wall ? PlaneRole::Wall : PlaneRole::Roof;
      joined = true;
    }
  }
  return s;
}

}  // namespace

SceneStructure building_small_planes(const PointCloud& cloud, const SceneStructure& detected,
                                     const StructureParams& structure, const BuildingParams& params,
                                     SceneResult& scene, KnnGraphCache* graphs, GableHalves gable_halves,
                                     SplitCandidates* gable_candidates) {
  if (gable_candidates) gable_candidates->clear();
  if (!scene.is_building() || params.small_plane_points <= 0) return detected;
  SceneStructure s = join_small_planes(cloud, detected, structure, params, scene, graphs);
  if (gable_halves == GableHalves::Off || !splits_roof_planes(params)) return s;
  return split_gables(cloud, std::move(s), detected.planes.size(), structure, params, scene,
                      gable_halves == GableHalves::Split, gable_candidates, graphs);
}

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
