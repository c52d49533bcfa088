// Scene mode, ground and plane roles (see scene.h). Plain Eigen; CGAL only behind rectangle.h.
#include "scene/scene.h"

#include "core/error.h"
#include "core/log.h"
#include "core/stats.h"
#include "core/kd_tree.h"
#include "core/rectangle.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

namespace hsr {

namespace {

constexpr const char* kStage = "scene";
constexpr double kDeg = M_PI / 180.0;
constexpr int kSectors = 16;

std::vector<double> heights_of(const PointCloud& cloud, const std::vector<int>& idx) {
  std::vector<double> z;
  z.reserve(idx.size());
  for (int i : idx) z.push_back(cloud.points[static_cast<std::size_t>(i)].z());
  return z;
}

// ---------------------------------------------------------------------------------------------------------
// The auto rule.

/// Inliers of the planes with |n_z| >= min_nz (foliage planes left out when `foliage` is given).
std::size_t inliers_facing(const SceneStructure& s, double min_nz, const std::vector<bool>* foliage) {
  std::size_t on = 0;
  for (std::size_t k = 0; k < s.planes.size(); ++k)
    if ((!foliage || !(*foliage)[k]) && std::abs(s.planes[k].plane.normal.z()) >= min_nz) on += s.planes[k].inliers.size();
  return on;
}

/// Two planes meeting in a (near-)horizontal line as roofs do: a ridge (both below the line), a valley (both
/// above it) or an eave (a roof above, an upright wall below). Where one tilted plane lies above the line and
/// another tilted plane below it, the pair is the top and bottom of an object seen all round (an
/// octahedron's equator) and says nothing of "level". Sides by the planes' centroids against the line's
/// height midway between them; upright within 10 degrees.
bool meet_as_roofs(const DetectedPlane& a, const DetectedPlane& b) {
  const double s10 = std::sin(10.0 * kDeg);
  if (std::abs(a.plane.normal.z()) <= s10 || std::abs(b.plane.normal.z()) <= s10) return true;
  const Vec3 d = a.plane.normal.cross(b.plane.normal);
  Eigen::Matrix3d m;
  m.row(0) = a.plane.normal.transpose();
  m.row(1) = b.plane.normal.transpose();
  m.row(2) = d.transpose();
  const Vec3 mid = 0.5 * (a.centroid + b.centroid);
  const Vec3 on_line = m.colPivHouseholderQr().solve(Vec3(-a.plane.offset, -b.plane.offset, d.dot(mid)));
  return (a.centroid.z() - on_line.z()) * (b.centroid.z() - on_line.z()) > 0;
}

/// Rule (a)'s "level" test on the planes that are not foliage: the share of their inliers on planes within
/// 10 degrees of horizontal or vertical, and the share (weighted by the smaller plane's inliers) of adjacent
/// non-parallel pairs meeting in a line within 10 degrees of horizontal as roofs do (meet_as_roofs: ridges,
/// valleys, eaves). The larger of the two.
double levelness(const SceneStructure& s, const std::vector<bool>& foliage) {
  const double c10 = std::cos(10.0 * kDeg), s10 = std::sin(10.0 * kDeg);
  std::size_t level = 0, all = 0;
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    if (foliage[k]) continue;
    const double nz = std::abs(s.planes[k].plane.normal.z());
    all += s.planes[k].inliers.size();
    if (nz >= c10 || nz <= s10) level += s.planes[k].inliers.size();
  }
  double horizontal = 0, total = 0;
  for (std::size_t i = 0; i < s.planes.size(); ++i)
    for (int j : s.adjacency[i]) {
      if (j <= static_cast<int>(i) || foliage[i] || foliage[static_cast<std::size_t>(j)]) continue;
      const DetectedPlane& a = s.planes[i];
      const DetectedPlane& b = s.planes[static_cast<std::size_t>(j)];
      const Vec3 d = a.plane.normal.cross(b.plane.normal);
      if (d.norm() < 0.1) continue;
      const double w = static_cast<double>(std::min(a.inliers.size(), b.inliers.size()));
      total += w;
      if (std::abs(d.normalized().z()) <= s10 && meet_as_roofs(a, b)) horizontal += w;
    }
  const double plane_share = all ? static_cast<double>(level) / static_cast<double>(all) : 0.0;
  return std::max(plane_share, total > 0 ? horizontal / total : 0.0);
}

/// Rule (a): the share of all points on planes within 45 degrees of horizontal; when the scene is level
/// (levelness() >= 0.2), at least the share of the plane points (foliage left out) on planes within 60
/// degrees, so steep roofs count, and points on no plane do not count against them, but a tilted frame does
/// not pass.
double roof_share(const SceneStructure& s, std::size_t points, const std::vector<bool>& foliage) {
  const double within45 = points ? static_cast<double>(inliers_facing(s, std::cos(45.0 * kDeg), nullptr)) / static_cast<double>(points) : 0.0;
  if (levelness(s, foliage) < 0.2) return within45;
  const std::size_t on_planes = inliers_facing(s, 0.0, &foliage);
  const double within60 = on_planes ? static_cast<double>(inliers_facing(s, std::cos(60.0 * kDeg), &foliage)) / static_cast<double>(on_planes) : 0.0;
  return std::max(within45, within60);
}

/// The key of p's plan cell: xy cells of side `cell` counted from `origin`, shifted by (dx, dy) cells.
std::int64_t plan_cell(const Vec3& p, const Vec2& origin, double cell, int dx = 0, int dy = 0) {
  const auto ix = static_cast<std::int64_t>(std::floor((p.x() - origin.x()) / cell)) + dx;
  const auto iy = static_cast<std::int64_t>(std::floor((p.y() - origin.y()) / cell)) + dy;
  return ix * 0x100000000ll + iy;
}

/// Rule (b): share of the occupied xy cells (side 3 r) whose points have a height gap above
/// max(10 r, 10 % of the z extent) under a point on a surface (a plane that is not foliage): two surfaces one
/// above the other. A tree over a roof (its points on no plane, or on a foliage plane) is no second surface.
double layered_share(const PointCloud& cloud, const SceneStructure& s, const std::vector<bool>& foliage) {
  const BBox& box = s.bbox;
  const double cell = 3.0 * s.spacing, gap = std::max(10.0 * s.spacing, 0.1 * box.size().z());
  std::unordered_map<std::int64_t, std::vector<std::pair<double, bool>>> cells;  // (height, on a surface)
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const int k = s.point_plane[i];
    cells[plan_cell(cloud.points[i], box.min.head<2>(), cell)].push_back(
        {cloud.points[i].z(), k >= 0 && !foliage[static_cast<std::size_t>(k)]});
  }
  std::size_t layered = 0;
  for (auto& [key, z] : cells) {
    std::sort(z.begin(), z.end());
    for (std::size_t i = 1; i < z.size(); ++i)
      if (z[i].second && z[i].first - z[i - 1].first > gap) {
        ++layered;
        break;
      }
  }
  return cells.empty() ? 0.0 : static_cast<double>(layered) / static_cast<double>(cells.size());
}

/// A roof alone: the planes (foliage left out) are all parallel, so object mode could enclose nothing, and they
/// face up (within 60 degrees of horizontal, rule (a)'s steep roofs): a lean-to, the one face of a gable the
/// scan holds, a flat roof. Whatever else the scan holds (trees, points on no plane), it is a building's roof
/// when rule (b) holds too (a top seen over a bottom everywhere is an object's, not a roof over the ground).
bool roof_alone(const SceneStructure& s, const std::vector<bool>& foliage) {
  std::vector<bool> keep(s.planes.size());
  for (std::size_t k = 0; k < s.planes.size(); ++k) keep[k] = !foliage[k];
  if (!all_parallel(s, keep)) return false;
  for (std::size_t k = 0; k < s.planes.size(); ++k)
    if (keep[k]) return std::abs(s.planes[k].plane.normal.z()) >= std::cos(60.0 * kDeg);
  return false;
}

SceneMode decide_mode(const SceneParams& params, double roof, double layered, bool alone, std::size_t building_class,
                      std::string& reason) {
  const bool one_layer = layered <= params.auto_max_layered_share;
  const bool rules_ab = roof >= params.auto_min_roof_share && one_layer;
  std::ostringstream why;
  why.precision(2);
  if (building_class > 0) {
    why << "the file classes " << building_class << " points as building (LAS class 6)";
  } else {
    why << std::fixed << roof << " of the points on planes facing up (building: >= " << params.auto_min_roof_share
        << "), " << layered << " of the xy cells with two layers (building: <= " << params.auto_max_layered_share << ")";
    if (alone && one_layer && !rules_ab) why << "; but the planes are parallel and face up: a roof alone, a building";
  }
  if (params.mode != SceneMode::Auto) {
    reason = std::string("given (") + why.str() + ")";
    return params.mode;
  }
  reason = why.str();
  if (building_class > 0) return SceneMode::Building;
  return rules_ab || (alone && one_layer) ? SceneMode::Building : SceneMode::Object;
}

// ---------------------------------------------------------------------------------------------------------
// Ground.

/// Number of the 16 angular sectors about `centre` (xy) that hold at least one of the points.
int sectors_reached(const PointCloud& cloud, const std::vector<int>& idx, const Vec2& centre) {
  std::vector<char> hit(kSectors, 0);
  for (int i : idx) {
    const Vec3& p = cloud.points[static_cast<std::size_t>(i)];
    const double a = std::atan2(p.y() - centre.y(), p.x() - centre.x());  // [-pi, pi]
    const int s = std::clamp(static_cast<int>(std::floor((a + M_PI) / (2.0 * M_PI) * kSectors)), 0, kSectors - 1);
    hit[static_cast<std::size_t>(s)] = 1;
  }
  return static_cast<int>(std::count(hit.begin(), hit.end(), 1));
}

/// Of the ground planes found, those rising `rise` (building_min_height r, what a roof rises over the ground) or
/// more above the lowest one (median heights) stand on the ground: a low roof, not a second ground. They leave
/// `candidates` (after the ground was found with them: they do not decide whether there is one).
void drop_candidates_standing_on_lower_ones(const PointCloud& cloud, const SceneStructure& s, double rise,
                                            std::vector<int>& candidates) {
  std::vector<double> height(s.planes.size(), 0.0);
  double lowest = std::numeric_limits<double>::infinity();
  for (int k : candidates) {
    const auto u = static_cast<std::size_t>(k);
    height[u] = quantile(heights_of(cloud, s.planes[u].inliers), 0.5);
    lowest = std::min(lowest, height[u]);
  }
  std::vector<int> kept;
  for (int k : candidates)
    if (height[static_cast<std::size_t>(k)] < lowest + rise) kept.push_back(k);
  candidates = std::move(kept);
}

/// The ground planes (see scene.h, source 4), or none. Fills ground_z from their inliers when found. The
/// caller checks that a roof is left once they are ground.
std::vector<int> find_ground_planes(const PointCloud& cloud, const SceneStructure& s, const SceneParams& params,
                                    const std::vector<bool>& foliage, double* ground_z) {
  const double r = s.spacing;
  std::vector<double> all_z;
  all_z.reserve(cloud.size());
  for (const Vec3& p : cloud.points) all_z.push_back(p.z());
  const double z_low = quantile(all_z, 0.01);
  const double tol = std::max(6.0 * r, 0.05 * s.bbox.size().z());
  std::vector<bool> candidate(s.planes.size(), false);
  std::vector<int> candidates;
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    const DetectedPlane& p = s.planes[k];
    if (foliage[k] || std::abs(p.plane.normal.z()) < std::cos(params.ground_max_angle_deg * kDeg)) continue;
    if (p.centroid.z() <= z_low + tol) {
      candidate[k] = true;
      candidates.push_back(static_cast<int>(k));
    }
  }
  if (candidates.empty()) return {};
  std::vector<int> ground_inliers, other_inliers;
  double top = -std::numeric_limits<double>::infinity();  // the highest median height of the planes standing on it
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    if (candidate[k]) {
      ground_inliers.insert(ground_inliers.end(), s.planes[k].inliers.begin(), s.planes[k].inliers.end());
    } else if (!foliage[k]) {  // a tree over a flat roof does not make the roof ground
      other_inliers.insert(other_inliers.end(), s.planes[k].inliers.begin(), s.planes[k].inliers.end());
      top = std::max(top, quantile(heights_of(cloud, s.planes[k].inliers), 0.5));
    }
  }
  if (other_inliers.empty()) return {};  // nothing stands on it: a flat roof alone is not ground
  const double height = quantile(heights_of(cloud, ground_inliers), 0.5);
  if (!(top >= height + params.building_min_height * r)) return {};  // something must rise clearly above it
  // It surrounds the rest (a low roof beside a taller block lies on one side only).
  Vec2 centre = Vec2::Zero();
  for (int i : other_inliers) centre += cloud.points[static_cast<std::size_t>(i)].head<2>();
  centre /= static_cast<double>(other_inliers.size());
  if (sectors_reached(cloud, ground_inliers, centre) < params.ground_min_sectors) return {};
  drop_candidates_standing_on_lower_ones(cloud, s, params.building_min_height * r, candidates);
  ground_inliers.clear();
  for (int k : candidates)
    ground_inliers.insert(ground_inliers.end(), s.planes[static_cast<std::size_t>(k)].inliers.begin(),
                          s.planes[static_cast<std::size_t>(k)].inliers.end());
  *ground_z = quantile(heights_of(cloud, ground_inliers), 0.5);
  return candidates;
}

/// The building's footprint in plan: the xy cells (side 2 r) holding a roof or wall inlier.
class Footprint {
 public:
  Footprint(const PointCloud& cloud, const SceneStructure& s, const std::vector<PlaneRole>& roles)
      : cell_(2.0 * s.spacing), origin_(s.bbox.min.head<2>()) {
    for (std::size_t i = 0; i < cloud.size(); ++i)
      if (is_building_point(s, roles, i)) cells_.insert(plan_cell(cloud.points[i], origin_, cell_));
  }
  static bool is_building_point(const SceneStructure& s, const std::vector<PlaneRole>& roles, std::size_t i) {
    const int k = s.point_plane[i];
    return k >= 0 && (roles[static_cast<std::size_t>(k)] == PlaneRole::Roof || roles[static_cast<std::size_t>(k)] == PlaneRole::Wall);
  }
  /// Whether p's cell is within `grow` cells (Chebyshev) of a footprint cell.
  bool near(const Vec3& p, int grow) const {
    for (int dx = -grow; dx <= grow; ++dx)
      for (int dy = -grow; dy <= grow; ++dy)
        if (cells_.count(plan_cell(p, origin_, cell_, dx, dy))) return true;
    return false;
  }
  double cell() const { return cell_; }

 private:
  double cell_;
  Vec2 origin_;
  std::unordered_set<std::int64_t> cells_;
};

/// Source 5 (see scene.h): the lowest roof or wall inlier, or unassigned point on the footprint (one cell
/// around it: walls too sparse to be a plane, ground right at their foot). Terrain further out (a sloping
/// garden, a ditch) does not pull the building down. Infinity when the building has no roof or wall point.
double lowest_building_point(const PointCloud& cloud, const SceneStructure& s, const std::vector<PlaneRole>& roles) {
  const Footprint footprint(cloud, s, roles);
  double lowest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (Footprint::is_building_point(s, roles, i) || (s.point_plane[i] < 0 && footprint.near(cloud.points[i], 1)))
      lowest = std::min(lowest, cloud.points[i].z());
  return lowest;
}

/// The lowest point of the roofs that rise at least `rise` above `base` (at their 90th percentile; all roofs
/// when none does): the least height of a roof plane over one of its inliers (on the plane, so a flat roof's
/// is its height, not its noisiest point's); infinity when there is no roof. A low plane at the very bottom
/// (a terrace, a pavement by the wall) is no roof to measure "under the roofs" from.
double lowest_roof_point(const PointCloud& cloud, const SceneStructure& s, const std::vector<PlaneRole>& roles,
                         double base, double rise) {
  std::vector<bool> rises(s.planes.size(), false);
  bool any = false;
  for (std::size_t k = 0; k < s.planes.size(); ++k)
    if (roles[k] == PlaneRole::Roof) any = any || (rises[k] = quantile(heights_of(cloud, s.planes[k].inliers), 0.9) >= base + rise);
  double lowest = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    if (roles[k] != PlaneRole::Roof || (any && !rises[k])) continue;
    const Plane& pl = s.planes[k].plane;
    for (int i : s.planes[k].inliers) {
      const Vec3& p = cloud.points[static_cast<std::size_t>(i)];
      lowest = std::min(lowest, -(pl.normal.x() * p.x() + pl.normal.y() * p.y() + pl.offset) / pl.normal.z());
    }
  }
  return lowest;
}

/// Source 2: the median of the raster's heights under the roof and wall inliers (NaN when none falls on it).
double ground_from_raster(const PointCloud& cloud, const SceneStructure& s, const std::vector<PlaneRole>& roles,
                          const SceneGround& ground) {
  std::vector<double> z;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    double h;
    const Vec3 g = cloud.points[i] + ground.origin;
    if (Footprint::is_building_point(s, roles, i) && ground.raster->sample(g.x(), g.y(), h)) z.push_back(h - ground.origin.z());
  }
  return z.empty() ? std::numeric_limits<double>::quiet_NaN() : quantile(std::move(z), 0.5);
}

/// Source 3: the median height of the classified ground points in the ring around the footprint (within
/// ring r of it, not on it); NaN when fewer than 3 are there.
double ground_from_points(const PointCloud& cloud, const SceneStructure& s, const std::vector<PlaneRole>& roles,
                          const SceneGround& ground, double ring) {
  const Footprint footprint(cloud, s, roles);
  const int grow = std::max(1, static_cast<int>(std::ceil(ring * s.spacing / footprint.cell())));
  std::vector<double> z;
  for (const Vec3& p : ground.points)
    if (!footprint.near(p, 0) && footprint.near(p, grow)) z.push_back(p.z());
  return z.size() < 3 ? std::numeric_limits<double>::quiet_NaN() : quantile(std::move(z), 0.5);
}

// ---------------------------------------------------------------------------------------------------------
// Roles.

bool is_wall(const Plane& p, const SceneParams& params) {
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
bool is_vegetation(const PointCloud& cloud, const SceneStructure& s, const DetectedPlane& p, const SceneParams& params) {
  double sq = 0, angle = 0;
  for (int i : p.inliers) {
    const double d = p.plane.signed_distance(cloud.points[static_cast<std::size_t>(i)]);
    sq += d * d;
    angle += std::acos(std::min(1.0, std::abs(s.normals[static_cast<std::size_t>(i)].dot(p.plane.normal))));
  }
  const double n = static_cast<double>(p.inliers.size());
  return std::sqrt(sq / n) >= params.vegetation_rms * s.spacing && angle / n >= params.vegetation_normal_deg * kDeg;
}

/// Per plane: is_vegetation().
std::vector<bool> foliage_planes(const PointCloud& cloud, const SceneStructure& s, const SceneParams& params) {
  std::vector<bool> f(s.planes.size());
  for (std::size_t k = 0; k < s.planes.size(); ++k) f[k] = is_vegetation(cloud, s, s.planes[k], params);
  return f;
}

/// A low roof adjacent (SceneStructure::adjacency: inliers among each other's neighbours) to a roof that is
/// not low is a lower part of the building, a lean-to shed or a garage against its wall, not a car or a hedge
/// beside it: "low" is a height in r (building_min_height), which at survey densities of 4 points/m² is 3 m.
bool attached_to_a_tall_roof(const SceneStructure& s, std::size_t k, const std::vector<bool>& low,
                             const std::vector<bool>& foliage, const std::vector<PlaneRole>& roles) {
  for (int j : s.adjacency[k]) {
    const auto u = static_cast<std::size_t>(j);
    if (roles[u] == PlaneRole::Roof && !low[u] && !foliage[u]) return true;
  }
  return false;
}

/// A low roof that is a wing of the building, not a car: it rises off the ground (`height90`, its 90th
/// percentile height, at least 2 r, the inlier distance, above it: nearer, it cannot be told from the ground, a
/// terrain patch beside the walls), it is wider than a car (its smallest-area rectangle in plan at least
/// car_max_width across) and it touches a roof that is not low in plan (one of its inliers within 2 r of one of
/// `tall_roofs`, those roofs' inliers in plan: the two meet along an eave). A flat garage or annex against a house
/// whose wall the scan missed has no inlier among the house's nearest neighbours (attached_to_a_tall_roof): the
/// eave lies a storey above it.
bool low_wing(const PointCloud& cloud, const SceneStructure& s, std::size_t k, double height90, double ground_z,
              double car_max_width, const KdTree& tall_roofs) {
  if (height90 < ground_z + 2.0 * s.spacing || tall_roofs.size() == 0) return false;
  std::vector<Vec2> xy;
  for (int i : s.planes[k].inliers) xy.push_back(cloud.points[static_cast<std::size_t>(i)].head<2>());
  if (!(min_area_rectangle(xy).width >= car_max_width)) return false;
  const double reach2 = 4.0 * s.spacing * s.spacing;
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

/// Roles of the non-ground planes: foliage, low ones (when `low_rule`, against out.ground_z) and far small
/// groups are clutter (see scene.h); low roofs only while a roof that is not low remains.
void assign_roles(const PointCloud& cloud, const SceneStructure& s, const SceneParams& params,
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
    // A roof lower than building_min_height (at its 90th percentile) is a car, a hedge or sloped terrain.
    height90[k] = quantile(heights_of(cloud, p.inliers), 0.9);
    low[k] = height90[k] < out.ground_z + params.building_min_height * r;
    tall_roof = tall_roof || !low[k];
  }
  const bool any_low = std::find(low.begin(), low.end(), true) != low.end();
  const KdTree tall_roofs = any_low && tall_roof ? tall_roofs_in_plan(cloud, s, low, foliage, out.roles) : KdTree();
  std::vector<bool> candidate(s.planes.size(), false);
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    const bool car_or_hedge =
        low[k] && tall_roof && !attached_to_a_tall_roof(s, k, low, foliage, out.roles) &&
        !low_wing(cloud, s, k, height90[k], out.ground_z, params.car_max_width, tall_roofs);
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
    if (g == main || xy_overlap(xy_box(cloud, s, groups[g]), main_box, 4.0 * r)) continue;
    if (static_cast<double>(inliers_of(s, groups[g])) >= params.min_building_share * static_cast<double>(main_inliers))
      continue;  // another building
    for (int k : groups[g]) out.roles[static_cast<std::size_t>(k)] = PlaneRole::Clutter;
  }
}

/// Mode of the roof outlines' directions modulo 90 degrees, length weighted (1-degree bins, +-3 smoothing,
/// then the weighted circular mean of the directions within 5 degrees of the peak). Radians in [0, pi/2).
/// Each roof's smallest-area rectangle (its inliers in plan) votes too, with its perimeter: a small roof whose
/// alpha shape gave one segment across a corner still turns its walls onto its sides.
double main_direction(const PointCloud& cloud, const SceneStructure& s, const std::vector<PlaneRole>& roles) {
  constexpr int kBins = 90;
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
  for (int b = 0; b < kBins; ++b) {
    double sum = 0;
    for (int o = -3; o <= 3; ++o) sum += hist[static_cast<std::size_t>((b + o + kBins) % kBins)];
    if (sum > best + 1e-12) {
      best = sum;
      peak = b;
    }
  }
  // Circular mean with period pi/2: average the angle times 4 on the unit circle.
  const double centre = (peak + 0.5) * kDeg;
  Vec2 acc = Vec2::Zero();
  for (const auto& [a, len] : dirs) {
    double diff = std::remainder(a - centre, M_PI / 2.0);
    if (std::abs(diff) <= 5.0 * kDeg) acc += len * Vec2(std::cos(4.0 * a), std::sin(4.0 * a));
  }
  if (!(acc.norm() > 0)) return centre;
  return std::fmod(std::atan2(acc.y(), acc.x()) / 4.0 + M_PI / 2.0, M_PI / 2.0);
}

// ---------------------------------------------------------------------------------------------------------
// The building structure.

/// A wall stands upright: horizontal normal, through its inliers' centroid, turned onto a main direction when
/// within snap_deg of one.
void stand_upright(DetectedPlane& p, double main_direction, double snap_deg) {
  Vec3 n(p.plane.normal.x(), p.plane.normal.y(), 0.0);
  n.normalize();
  double a = std::atan2(n.y(), n.x());
  const double off = std::remainder(a - main_direction, M_PI / 2.0);
  if (std::abs(off) <= snap_deg * kDeg) {
    a -= off;
    n = Vec3(std::cos(a), std::sin(a), 0.0);
  }
  p.plane.normal = n;
  p.plane.offset = -n.dot(p.centroid);
}

/// Plane b joins plane a: inliers, boundary and segments joined, a's normal through their common centroid.
/// (a's boundary_edges stay a's: they index the first slots of the joined boundary.)
void join_plane(DetectedPlane& a, const DetectedPlane& b) {
  const double wa = static_cast<double>(a.inliers.size()), wb = static_cast<double>(b.inliers.size());
  a.centroid = (wa * a.centroid + wb * b.centroid) / (wa + wb);
  a.plane.offset = -a.plane.normal.dot(a.centroid);
  a.inliers.insert(a.inliers.end(), b.inliers.begin(), b.inliers.end());
  std::sort(a.inliers.begin(), a.inliers.end());
  a.boundary.insert(a.boundary.end(), b.boundary.begin(), b.boundary.end());
  a.boundary_points.insert(a.boundary_points.end(), b.boundary_points.begin(), b.boundary_points.end());
  a.boundary_normals.insert(a.boundary_normals.end(), b.boundary_normals.begin(), b.boundary_normals.end());
  a.segments.insert(a.segments.end(), b.segments.begin(), b.segments.end());
  a.area += b.area;
}

/// After join_plane: the points and neighbours of each joined plane (head[k] >= 0 and != k: the plane it
/// joined) go to that plane.
void redirect_joined(SceneStructure& s, const std::vector<int>& head) {
  for (int& k : s.point_plane)
    if (k >= 0 && head[static_cast<std::size_t>(k)] >= 0) k = head[static_cast<std::size_t>(k)];
  for (std::size_t i = 0; i < s.planes.size(); ++i) {  // the joined planes' neighbours go to their head
    if (head[i] < 0 || head[i] == static_cast<int>(i)) continue;
    auto& into = s.adjacency[static_cast<std::size_t>(head[i])];
    into.insert(into.end(), s.adjacency[i].begin(), s.adjacency[i].end());
  }
  for (std::size_t i = 0; i < s.planes.size(); ++i) {
    auto& adj = s.adjacency[i];
    for (int& j : adj)
      if (head[static_cast<std::size_t>(j)] >= 0) j = head[static_cast<std::size_t>(j)];
    adj.erase(std::remove(adj.begin(), adj.end(), static_cast<int>(i)), adj.end());
    std::sort(adj.begin(), adj.end());
    adj.erase(std::unique(adj.begin(), adj.end()), adj.end());
  }
}

/// Walls that became one plane (the same upright normal, either way, offsets within `tol`:
/// region growing split a sparse facade into pieces) are merged into the first of them (join_plane); the
/// others are no longer kept.
void merge_coplanar_walls(SceneStructure& s, const std::vector<PlaneRole>& roles, double tol, std::vector<bool>& keep) {
  std::vector<int> head(s.planes.size(), -1);
  for (std::size_t i = 0; i < s.planes.size(); ++i) {
    if (!keep[i] || roles[i] != PlaneRole::Wall || head[i] >= 0) continue;
    head[i] = static_cast<int>(i);
    DetectedPlane& a = s.planes[i];
    for (std::size_t j = i + 1; j < s.planes.size(); ++j) {
      if (!keep[j] || roles[j] != PlaneRole::Wall || head[j] >= 0) continue;
      const DetectedPlane& b = s.planes[j];
      const double dot = a.plane.normal.dot(b.plane.normal);
      if (std::abs(dot) < 1.0 - 1e-9 || std::abs(a.plane.offset - (dot > 0 ? 1 : -1) * b.plane.offset) > tol) continue;
      head[j] = static_cast<int>(i);
      keep[j] = false;
      join_plane(a, b);
    }
  }
  redirect_joined(s, head);
}

/// A roof part's outline along the building's main directions: each side of the roof's inliers' rectangle
/// in the main frame that its points line (at least 6 within 1.5 r of it, spanning half its length) but no
/// boundary segment follows (the alpha shape's segment fitting misses sides with stray points) gets a
/// segment: along the side, through its points, facing out. Stage 3 then treats it like any other.
void complete_outline(const PointCloud& cloud, double r, double main_direction, DetectedPlane& roof) {
  const Vec2 e0(std::cos(main_direction), std::sin(main_direction)), e1(-e0.y(), e0.x());
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (int i : roof.inliers) {
    const Vec2 p = cloud.points[static_cast<std::size_t>(i)].head<2>();
    const Vec2 q(p.dot(e0), p.dot(e1));
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  for (int axis = 0; axis < 2; ++axis)
    for (int side = 0; side < 2; ++side) {
      const double at = side ? hi[axis] : lo[axis];
      const Vec2 out = (side ? 1.0 : -1.0) * (axis ? e1 : e0), along = axis ? e0 : e1;
      const double length = hi[1 - axis] - lo[1 - axis];
      // Already followed by a segment (parallel, facing the same way, near the side)?
      bool covered = false;
      for (const BoundarySegment& seg : roof.segments) {
        const Vec2 d = (seg.b - seg.a).head<2>();
        const Vec2 mid = 0.5 * (seg.a + seg.b).head<2>();
        const double coord = axis ? mid.dot(e1) : mid.dot(e0);
        if (d.norm() > 0 && std::abs(d.normalized().dot(along)) > std::cos(10.0 * kDeg) &&
            seg.normal.head<2>().dot(out) > 0 && std::abs(coord - at) < 5.0 * r)
          covered = true;
      }
      if (covered || !(length > 0)) continue;
      BoundarySegment seg;
      double smin = std::numeric_limits<double>::infinity(), smax = -smin;
      for (int i : roof.inliers) {
        const Vec2 p = cloud.points[static_cast<std::size_t>(i)].head<2>();
        if (std::abs((axis ? p.dot(e1) : p.dot(e0)) - at) > 1.5 * r) continue;
        seg.support.push_back(i);
        smin = std::min(smin, p.dot(along));
        smax = std::max(smax, p.dot(along));
      }
      if (seg.support.size() < 6 || smax - smin < 0.5 * length) continue;
      // The side's ends, lifted onto the roof plane.
      auto lift = [&](double t) {
        const Vec2 xy = at * (axis ? e1 : e0) + t * along;
        const Plane& pl = roof.plane;
        const double z = -(pl.normal.x() * xy.x() + pl.normal.y() * xy.y() + pl.offset) / pl.normal.z();
        return Vec3(xy.x(), xy.y(), z);
      };
      seg.a = lift(smin);
      seg.b = lift(smax);
      const Vec3 n = roof.plane.normal;
      Vec3 o(out.x(), out.y(), 0.0);
      seg.normal = (o - o.dot(n) * n).normalized();  // in the roof's plane, facing out
      seg.plane = roof.segments.empty() ? -1 : roof.segments.front().plane;
      roof.segments.push_back(std::move(seg));
    }
}

}  // namespace

const char* scene_mode_name(SceneMode m) {
  switch (m) {
    case SceneMode::Object: return "object";
    case SceneMode::Building: return "building";
    case SceneMode::Auto: break;
  }
  return "auto";
}

SceneMode parse_scene_mode(const std::string& name) {
  for (SceneMode m : {SceneMode::Auto, SceneMode::Object, SceneMode::Building})
    if (name == scene_mode_name(m)) return m;
  throw Error(Status::BadInput, "cli", "unknown scene mode '" + name + "' (auto | object | building)");
}

const char* plane_role_name(PlaneRole r) {
  switch (r) {
    case PlaneRole::Roof: return "roof";
    case PlaneRole::Wall: return "wall";
    case PlaneRole::Ground: return "ground";
    case PlaneRole::Clutter: return "clutter";
    case PlaneRole::Object: break;
  }
  return "object";
}

const char* ground_source_name(GroundSource g) {
  switch (g) {
    case GroundSource::Plane: return "plane";
    case GroundSource::Given: return "given";
    case GroundSource::LowestPoints: return "lowest building point";
    case GroundSource::Raster: return "raster";
    case GroundSource::ClassifiedPoints: return "classified ground points";
    case GroundSource::Assumed: return "assumed storey";
    case GroundSource::None: break;
  }
  return "none";
}

std::size_t SceneResult::count(PlaneRole r) const {
  return static_cast<std::size_t>(std::count(roles.begin(), roles.end(), r));
}

namespace {

/// The ground height from the first source of scene.h's list that has one; sets out.ground_z and
/// out.ground_source (and out.ground_note when it had to assume). Roles must be set (roof and wall planes
/// define the footprint); the ground planes are those find_ground_planes() returned.
void choose_ground(const PointCloud& cloud, const SceneStructure& s, const SceneParams& params,
                   const SceneGround& ground, double plane_height, SceneResult& out) {
  const auto use = [&](GroundSource src, double z) {
    out.ground_source = src;
    out.ground_z = z;
  };
  if (!std::isnan(params.ground_z)) return use(GroundSource::Given, params.ground_z);
  if (ground.raster) {
    const double z = ground_from_raster(cloud, s, out.roles, ground);
    if (std::isfinite(z)) return use(GroundSource::Raster, z);
    log::warn("[scene] the ground raster '" + ground.raster->source + "' has no height under the building; looking further");
  }
  if (!ground.points.empty()) {
    const double z = ground_from_points(cloud, s, out.roles, ground, params.ground_ring);
    if (std::isfinite(z)) return use(GroundSource::ClassifiedPoints, z);
  }
  if (!out.ground_planes.empty()) return use(GroundSource::Plane, plane_height);
  const double lowest = lowest_building_point(cloud, s, out.roles);
  const double roof_low = lowest_roof_point(cloud, s, out.roles, lowest, params.building_min_height * s.spacing);
  if (lowest <= roof_low - 2.0 * s.spacing || !std::isfinite(roof_low))
    return use(GroundSource::LowestPoints, std::isfinite(lowest) ? lowest : s.bbox.min.z());
  use(GroundSource::Assumed, std::min(lowest, roof_low) - params.assumed_wall_height);
  std::ostringstream note;
  note << "nothing in the scan lies under its roofs and no ground is known: the walls are assumed "
       << params.assumed_wall_height << " tall (one storey); give the ground with --ground-z Z or --ground DTM.tif";
  out.ground_note = note.str();
}

bool any_roof(const std::vector<PlaneRole>& roles) {
  return std::find(roles.begin(), roles.end(), PlaneRole::Roof) != roles.end();
}

}  // namespace

ClassSplit split_by_class(const PointCloud& cloud) {
  ClassSplit out;
  const auto& cls = cloud.attributes.classification;
  if (cls.size() != cloud.size()) return out;
  const auto is_ground = [](std::uint8_t c) { return c == 2; };
  const auto left_out = [](std::uint8_t c) { return c == 3 || c == 4 || c == 5 || c == 7 || c == 9 || c == 18; };
  std::vector<std::size_t> keep;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (is_ground(cls[i])) out.ground.push_back(cloud.points[i]);
    else if (left_out(cls[i])) ++out.left_out;
    else keep.push_back(i);
    if (cls[i] == 6) ++out.building_class_points;
  }
  if (out.ground.empty() && out.left_out == 0) {  // nothing to split off: the cloud as it is
    out.ground.clear();
    return out;
  }
  out.applied = true;
  PointCloud& b = out.building;
  b.origin = cloud.origin;
  b.source = cloud.source;
  b.crs = cloud.crs;
  const PointAttributes& a = cloud.attributes;
  const auto pick = [&](const auto& from, auto& to) {
    if (from.size() != cloud.size()) return;
    to.reserve(keep.size());
    for (std::size_t i : keep) to.push_back(from[i]);
  };
  pick(cloud.points, b.points);
  pick(cloud.normals, b.normals);
  pick(a.classification, b.attributes.classification);
  pick(a.return_number, b.attributes.return_number);
  pick(a.number_of_returns, b.attributes.number_of_returns);
  pick(a.intensity, b.attributes.intensity);
  pick(a.gps_time, b.attributes.gps_time);
  pick(a.rgb, b.attributes.rgb);
  return out;
}

SceneResult run_scene(const PointCloud& cloud, const SceneStructure& structure, const SceneParams& params,
                      const SceneGround& ground) {
  if (!(params.auto_min_roof_share >= 0 && params.auto_min_roof_share <= 1) ||
      !(params.auto_max_layered_share >= 0 && params.auto_max_layered_share <= 1) ||
      !(params.ground_max_angle_deg > 0 && params.ground_max_angle_deg < 90) ||
      !(params.wall_max_angle_deg > 0 && params.wall_max_angle_deg < 45) || params.ground_min_sectors < 0 ||
      params.ground_min_sectors > kSectors || !(params.building_min_height >= 0) || !(params.car_max_width >= 0) ||
      !(params.main_direction_snap_deg >= 0 && params.main_direction_snap_deg < 45) || !(params.ground_ring > 0) ||
      !(params.assumed_wall_height > 0) || !std::isfinite(params.assumed_wall_height) ||
      (!std::isnan(params.ground_z) && !std::isfinite(params.ground_z)))
    throw Error(Status::BadInput, kStage, "parameters out of range (see scene.h)");
  SceneResult out;
  const std::vector<bool> foliage = foliage_planes(cloud, structure, params);
  out.roof_share = roof_share(structure, cloud.size(), foliage);
  out.layered_share = layered_share(cloud, structure, foliage);
  out.mode = decide_mode(params, out.roof_share, out.layered_share, roof_alone(structure, foliage),
                         ground.building_class_points, out.reason);
  out.roles.assign(structure.planes.size(), PlaneRole::Object);
  if (!out.is_building()) return out;

  double plane_height = 0.0;
  if (!(params.given_ground_wins && !std::isnan(params.ground_z)))
    out.ground_planes = find_ground_planes(cloud, structure, params, foliage, &plane_height);
  for (int k : out.ground_planes) out.roles[static_cast<std::size_t>(k)] = PlaneRole::Ground;
  // Roles first without the low rule ("low" needs a ground; a roof-only scan's lowest roof is no car)...
  assign_roles(cloud, structure, params, foliage, false, out);
  if (!out.ground_planes.empty() && !any_roof(out.roles)) {
    // Nothing stands on the "ground" but foliage and far small things: it is the (flat) roof of the scan.
    out.ground_planes.clear();
    std::fill(out.roles.begin(), out.roles.end(), PlaneRole::Object);
    assign_roles(cloud, structure, params, foliage, false, out);
  }
  if (!any_roof(out.roles))
    throw Error(Status::DegenerateInput, kStage,
                "building mode: no plane is left to be a roof (" + std::to_string(out.count(PlaneRole::Clutter)) +
                    " foliage or clutter, " + std::to_string(out.count(PlaneRole::Wall)) + " wall planes); try --scene object");
  // ...then the ground from its sources, and the roles against it: cars, hedges and terrain are low (not
  // against an assumed ground: nothing lies under the roofs, a low roof is a low part of the building).
  choose_ground(cloud, structure, params, ground, plane_height, out);
  if (out.ground_source != GroundSource::Assumed) {
    for (PlaneRole& r : out.roles)
      if (r != PlaneRole::Ground) r = PlaneRole::Object;
    assign_roles(cloud, structure, params, foliage, true, out);
  }
  out.main_direction = main_direction(cloud, structure, out.roles);
  if (!out.ground_note.empty()) log::warn("[scene] " + out.ground_note);
  std::ostringstream msg;
  msg << "[scene] building: ground at z = " << out.ground_z << " (" << ground_source_name(out.ground_source) << "), "
      << out.count(PlaneRole::Roof) << " roof, " << out.count(PlaneRole::Wall) << " wall, "
      << out.count(PlaneRole::Ground) << " ground, " << out.count(PlaneRole::Clutter) << " clutter planes; main direction "
      << out.main_direction / kDeg << " deg";
  log::verbose(msg.str());
  return out;
}

SceneStructure building_structure(const PointCloud& cloud, const SceneStructure& structure, const SceneResult& scene,
                                  const SceneParams& params) {
  if (!scene.is_building()) return structure;
  if (scene.roles.size() != structure.planes.size())
    throw Error(Status::Internal, kStage, "scene roles do not match the structure's planes");
  SceneStructure s = structure;
  std::vector<bool> keep(s.planes.size(), false);
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    keep[k] = scene.roles[k] == PlaneRole::Roof || scene.roles[k] == PlaneRole::Wall;
    if (scene.roles[k] == PlaneRole::Wall) stand_upright(s.planes[k], scene.main_direction, params.main_direction_snap_deg);
  }
  merge_coplanar_walls(s, scene.roles, params.wall_merge_distance * s.spacing, keep);
  for (std::size_t k = 0; k < s.planes.size(); ++k)
    if (keep[k] && scene.roles[k] == PlaneRole::Roof) complete_outline(cloud, s.spacing, scene.main_direction, s.planes[k]);
  return subset_planes(s, keep);
}

/// Whether plane `b` lies on plane `a`: its inliers within `r` of a on average, the normals within
/// `max_angle_deg` (either way).
bool lies_on(const PointCloud& cloud, const Plane& a, const DetectedPlane& b, double r, double max_angle_deg) {
  if (std::abs(a.normal.dot(b.plane.normal)) < std::cos(max_angle_deg * kDeg)) return false;
  double sum = 0;
  for (int i : b.inliers) sum += std::abs(a.signed_distance(cloud.points[static_cast<std::size_t>(i)]));
  return sum <= r * static_cast<double>(b.inliers.size());
}

/// room_structure's furniture rule: within each piece of furniture (points off the enclosure linked within the
/// alpha radius), a plane that lies on a larger one of the piece and faces the same way (outward normals within
/// max_angle_deg) joins it, largest first. Updates head, keep and s as room_structure's enclosure rule does;
/// returns how many joined.
std::size_t join_faces_of_pieces(const PointCloud& cloud, SceneStructure& s, const std::vector<bool>& enclosure,
                                 const std::vector<Vec3>& outward, double max_angle_deg, std::vector<int>& head,
                                 std::vector<bool>& keep) {
  const auto plane_of = [&](std::size_t i) {  // a point's plane, after the joins so far
    const int k = s.point_plane[i];
    return k >= 0 && head[static_cast<std::size_t>(k)] >= 0 ? head[static_cast<std::size_t>(k)] : k;
  };
  std::vector<int> off;  // the points on no enclosing plane
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const int k = plane_of(i);
    if (k < 0 || !enclosure[static_cast<std::size_t>(k)]) off.push_back(static_cast<int>(i));
  }
  const double link = s.alpha_radius > 0 ? s.alpha_radius : 3.0 * s.spacing;
  std::size_t joined = 0;
  for (const std::vector<int>& piece : linked_groups(cloud.points, off, link)) {
    std::vector<int> planes;
    for (int p : piece)
      if (plane_of(static_cast<std::size_t>(p)) >= 0) planes.push_back(plane_of(static_cast<std::size_t>(p)));
    std::sort(planes.begin(), planes.end());
    planes.erase(std::unique(planes.begin(), planes.end()), planes.end());
    std::stable_sort(planes.begin(), planes.end(), [&](int x, int y) {
      return s.planes[static_cast<std::size_t>(x)].inliers.size() > s.planes[static_cast<std::size_t>(y)].inliers.size();
    });
    for (std::size_t i = 0; i < planes.size(); ++i) {
      const std::size_t a = static_cast<std::size_t>(planes[i]);
      if (head[a] >= 0 && head[a] != static_cast<int>(a)) continue;  // joined another already
      const Plane plane = s.planes[a].plane;  // the test is against a's own plane and size, as for the enclosure
      const std::size_t size = s.planes[a].inliers.size();
      for (std::size_t j = i + 1; j < planes.size(); ++j) {
        const std::size_t b = static_cast<std::size_t>(planes[j]);
        if (head[b] >= 0 || s.planes[b].inliers.size() >= size) continue;
        if (outward[a].dot(outward[b]) < std::cos(max_angle_deg * kDeg)) continue;  // a thin panel's two faces
        if (!lies_on(cloud, plane, s.planes[b], s.spacing, max_angle_deg)) continue;
        head[a] = static_cast<int>(a);
        head[b] = static_cast<int>(a);
        keep[b] = false;
        join_plane(s.planes[a], s.planes[b]);
        ++joined;
      }
    }
  }
  return joined;
}

RoomStructure room_structure(const PointCloud& cloud, const SceneStructure& structure,
                             const std::vector<bool>& enclosure, double max_angle_deg,
                             const std::vector<Vec3>& outward) {
  if (enclosure.size() != structure.planes.size() || !(outward.empty() || outward.size() == structure.planes.size()))
    throw Error(Status::Internal, kStage, "room_structure: one enclosure flag (and outward normal) per plane expected");
  RoomStructure out;
  SceneStructure s = structure;
  std::vector<int> head(s.planes.size(), -1);
  std::vector<bool> keep(s.planes.size(), true);
  // Largest enclosing planes first: a piece joins the largest plane it lies on.
  std::vector<std::size_t> order;
  for (std::size_t a = 0; a < s.planes.size(); ++a)
    if (enclosure[a]) order.push_back(a);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
    return s.planes[x].inliers.size() > s.planes[y].inliers.size();
  });
  for (std::size_t a : order) {
    if (head[a] >= 0) continue;
    // The test is against a's own plane and size, not as the pieces joined move them.
    const Plane plane = s.planes[a].plane;
    const std::size_t size = s.planes[a].inliers.size();
    for (std::size_t b = 0; b < s.planes.size(); ++b) {
      if (b == a || head[b] >= 0 || s.planes[b].inliers.size() >= size) continue;
      if (!lies_on(cloud, plane, s.planes[b], s.spacing, max_angle_deg)) continue;
      head[a] = static_cast<int>(a);
      head[b] = static_cast<int>(a);
      keep[b] = false;
      join_plane(s.planes[a], s.planes[b]);
      ++out.joined;
    }
  }
  if (!outward.empty()) {
    out.joined_faces = join_faces_of_pieces(cloud, s, enclosure, outward, max_angle_deg, head, keep);
    out.joined += out.joined_faces;
  }
  for (std::size_t k = 0; k < keep.size(); ++k)
    if (keep[k]) out.from.push_back(static_cast<int>(k));
  if (out.joined == 0) {
    out.structure = structure;
    return out;
  }
  redirect_joined(s, head);
  out.structure = subset_planes(s, keep);
  return out;
}

std::size_t orient_roofs_up(const SceneStructure& building, const SceneResult& scene, std::vector<Vec3>& outward) {
  if (!scene.is_building()) return 0;
  if (outward.size() != building.planes.size())
    throw Error(Status::Internal, kStage, "orient_roofs_up: one outward normal per plane expected");
  std::size_t turned = 0;
  for (std::size_t k = 0; k < outward.size(); ++k)
    if (building.planes[k].plane.normal.z() != 0.0 && outward[k].z() < 0) {
      outward[k] = -outward[k];
      ++turned;
    }
  return turned;
}

nlohmann::json to_json(const SceneResult& scene) {
  nlohmann::json j = {{"mode", scene_mode_name(scene.mode)},
                      {"reason", scene.reason},
                      {"roof_share", scene.roof_share},
                      {"layered_share", scene.layered_share}};
  if (scene.is_building()) {
    j["ground_z"] = scene.ground_z;
    j["ground_source"] = ground_source_name(scene.ground_source);
    if (!scene.ground_note.empty()) j["ground_note"] = scene.ground_note;
    j["ground_planes"] = scene.ground_planes;
    j["main_direction_deg"] = scene.main_direction / kDeg;
    for (PlaneRole r : {PlaneRole::Roof, PlaneRole::Wall, PlaneRole::Ground, PlaneRole::Clutter})
      j["planes"][plane_role_name(r)] = scene.count(r);
  }
  return j;
}

bool normals_face_inward(const PointCloud& cloud) {
  if (!cloud.has_normals() || cloud.empty()) return false;
  const BBox box = bounding_box(cloud.points);
  const double slab = 0.01 * (box.max - box.min).maxCoeff();
  constexpr double kCos60 = 0.5;
  // Votes per side: 0..3 the lateral sides (x-, x+, y-, y+), 4 the top. The bottom is left out: the
  // ground under a building scanned from outside faces up, into the box.
  std::array<long, 5> inward{}, outward{};
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3& p = cloud.points[i];
    const Vec3& n = cloud.normals[i];
    for (int s = 0; s < 5; ++s) {
      const int axis = s < 4 ? s / 2 : 2;
      const bool high = s == 4 || s % 2 == 1;
      const double d = high ? box.max[axis] - p[axis] : p[axis] - box.min[axis];
      const double along = high ? n[axis] : -n[axis];  // the normal along the side's outward axis
      if (d > slab || std::abs(along) < kCos60 * n.norm()) continue;
      (along < 0 ? inward : outward)[static_cast<std::size_t>(s)] += 1;
    }
  }
  const double lined = 0.005 * static_cast<double>(cloud.size());
  auto faces_in = [&](int s) {
    const auto k = static_cast<std::size_t>(s);
    return static_cast<double>(inward[k] + outward[k]) >= lined && inward[k] >= 3 * outward[k];
  };
  int sides = 0;
  for (int s = 0; s < 4; ++s) sides += faces_in(s);
  return faces_in(4) && sides >= 3;
}

RoomEnds room_ends(const SceneStructure& structure, const std::vector<bool>& enclosing, double tolerance,
                   double level_deg) {
  RoomEnds ends;
  const double zmin = structure.bbox.min.z(), zmax = structure.bbox.max.z();
  for (std::size_t i = 0; i < structure.planes.size() && i < enclosing.size(); ++i) {
    const DetectedPlane& plane = structure.planes[i];
    if (!enclosing[i] || std::abs(plane.plane.normal.z()) < std::cos(level_deg * kDeg)) continue;
    const bool top = plane.centroid.z() >= zmax - tolerance, bottom = plane.centroid.z() <= zmin + tolerance;
    int* slot = top ? &ends.ceiling : bottom ? &ends.floor : nullptr;
    if (slot && (*slot < 0 || structure.planes[*slot].inliers.size() < plane.inliers.size())) *slot = static_cast<int>(i);
  }
  return ends;
}

RoomEvidence room_evidence(const PointCloud& cloud, const SceneStructure& structure, const std::vector<bool>& enclosing,
                           double tolerance, double level_deg) {
  RoomEvidence out;
  const auto [floor, ceiling] = room_ends(structure, enclosing, tolerance, level_deg);
  if (ceiling < 0 || floor < 0 || ceiling == floor) return out;
  const double cell = 3.0 * structure.spacing;
  const Vec2 origin = structure.bbox.min.head<2>();
  std::unordered_set<std::int64_t> floor_cells, ceiling_cells;
  for (int k : structure.planes[floor].inliers) floor_cells.insert(plan_cell(cloud.points[k], origin, cell));
  for (int k : structure.planes[ceiling].inliers) ceiling_cells.insert(plan_cell(cloud.points[k], origin, cell));
  std::size_t over = 0;
  for (std::int64_t c : ceiling_cells) over += floor_cells.count(c);
  const double top = structure.planes[ceiling].centroid.z(), bottom = structure.planes[floor].centroid.z();
  std::vector<const Plane*> enclosure;  // a hall has six among hundreds of planes: not looked up per point
  for (std::size_t i = 0; i < structure.planes.size(); ++i)
    if (enclosing[i]) enclosure.push_back(&structure.planes[i].plane);
  std::size_t beyond = 0, content = 0;
  for (const Vec3& p : cloud.points) {
    if (p.z() > top + tolerance || p.z() < bottom - tolerance) {
      ++beyond;
      continue;
    }
    content += std::none_of(enclosure.begin(), enclosure.end(),
                            [&](const Plane* e) { return std::abs(e->signed_distance(p)) <= tolerance; });
  }
  const double n = static_cast<double>(cloud.size());
  out.ceiling_over_floor = 2 * over >= ceiling_cells.size() && static_cast<double>(beyond) < 0.01 * n;
  out.content_share = static_cast<double>(content) / n;
  return out;
}

bool is_a_room(const PointCloud& cloud, const SceneStructure& structure, const SceneResult& scene,
               const std::vector<bool>& enclosing, bool scanned_from_inside, double tolerance, double level_deg) {
  if (scene.is_building()) return false;
  if (cloud.has_normals() && !scanned_from_inside) return false;
  const RoomEvidence room = room_evidence(cloud, structure, enclosing, tolerance, level_deg);
  return room.ceiling_over_floor && (cloud.has_normals() || room.content_share > 0.01);
}

}  // namespace hsr
