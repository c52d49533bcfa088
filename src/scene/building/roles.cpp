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

namespace building_detail {

bool is_wall(const Plane& p, const BuildingParams& params) {
  return std::abs(p.normal.z()) <= std::sin(params.wall_max_angle_deg * scene_detail::kDeg);
}

}  // namespace building_detail

namespace {

using building_detail::is_wall;
using scene_detail::heights_of;
using scene_detail::kDeg;

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


}  // namespace

namespace building_detail {

/// A small plane that is not upright enough to be a wall (wall_max_angle_deg) is a roof only when its slope is
/// at most small_roof_max_slope_deg. Why: a few points on a chimney's or a facade's side, with noise, fit a
/// plane tilted 15-20 degrees from upright; as a roof it faces down or cuts a steep wedge through the cells
/// (AHN3_00989 with 3 cm noise: a 21-point plane 73 degrees steep, the chimney left out, p2m 0.70 -> 1.71 %).
/// A plane it rejects stays clutter.
bool small_roof_too_steep(const Plane& p, const BuildingParams& params) {
  return std::abs(p.normal.z()) < std::cos(params.small_roof_max_slope_deg * kDeg);
}

}  // namespace building_detail

namespace {

using building_detail::small_roof_too_steep;

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
                                     SplitInput* split_input, std::size_t* planes_split) {
  if (!scene.is_building() || params.small_plane_points <= 0) return detected;
  SceneStructure s = join_small_planes(cloud, detected, structure, params, scene, graphs);
  if (gable_halves == GableHalves::Off || !splits_roof_planes(params)) return s;
  SplitInput input = building_detail::split_input_of(s, detected.planes.size(), scene, params);
  if (gable_halves == GableHalves::Split)
    s = building_detail::split_roof_planes(cloud, std::move(s), input, structure, params, scene, graphs, planes_split);
  if (split_input) *split_input = std::move(input);
  return s;
}

}  // namespace hsr
