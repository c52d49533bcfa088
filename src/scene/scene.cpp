// Scene mode, ground and plane roles (see scene.h). Plain Eigen, no CGAL.
#include "scene/scene.h"

#include "core/error.h"
#include "core/log.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <unordered_map>

namespace hsr {

namespace {

constexpr const char* kStage = "scene";
constexpr double kDeg = M_PI / 180.0;
constexpr int kSectors = 16;

/// q-quantile (0 <= q <= 1) of `values` (copied; nearest rank).
double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const std::size_t k = std::min(values.size() - 1, static_cast<std::size_t>(q * static_cast<double>(values.size())));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

std::vector<double> heights_of(const PointCloud& cloud, const std::vector<int>& idx) {
  std::vector<double> z;
  z.reserve(idx.size());
  for (int i : idx) z.push_back(cloud.points[static_cast<std::size_t>(i)].z());
  return z;
}

// ---------------------------------------------------------------------------------------------------------
// The auto rule.

/// Share of all points that are inliers of planes with |n_z| >= min_nz.
double share_on_planes(const SceneStructure& s, std::size_t points, double min_nz) {
  std::size_t on = 0;
  for (const DetectedPlane& p : s.planes)
    if (std::abs(p.plane.normal.z()) >= min_nz) on += p.inliers.size();
  return points ? static_cast<double>(on) / static_cast<double>(points) : 0.0;
}

/// Rule (a)'s "level" test: the share of the points on planes within 10 degrees of horizontal or vertical,
/// and the share (weighted by the smaller plane's inliers) of adjacent non-parallel pairs meeting in a line
/// within 10 degrees of horizontal (ridges, eaves). The larger of the two.
double levelness(const SceneStructure& s, std::size_t points) {
  const double c10 = std::cos(10.0 * kDeg), s10 = std::sin(10.0 * kDeg);
  std::size_t level = 0;
  for (const DetectedPlane& p : s.planes)
    if (std::abs(p.plane.normal.z()) >= c10 || std::abs(p.plane.normal.z()) <= s10) level += p.inliers.size();
  double horizontal = 0, total = 0;
  for (std::size_t i = 0; i < s.planes.size(); ++i)
    for (int j : s.adjacency[i]) {
      if (j <= static_cast<int>(i)) continue;
      const Vec3 d = s.planes[i].plane.normal.cross(s.planes[static_cast<std::size_t>(j)].plane.normal);
      if (d.norm() < 0.1) continue;
      const double w = static_cast<double>(std::min(s.planes[i].inliers.size(), s.planes[static_cast<std::size_t>(j)].inliers.size()));
      total += w;
      if (std::abs(d.normalized().z()) <= s10) horizontal += w;
    }
  const double plane_share = points ? static_cast<double>(level) / static_cast<double>(points) : 0.0;
  return std::max(plane_share, total > 0 ? horizontal / total : 0.0);
}

/// Rule (a): the share of the points on planes facing up: within 45 degrees of horizontal, or within 60
/// degrees when the scene is level (levelness() >= 0.2), so steep roofs count but a tilted frame does not.
double roof_share(const SceneStructure& s, std::size_t points) {
  const double within45 = share_on_planes(s, points, std::cos(45.0 * kDeg));
  if (levelness(s, points) < 0.2) return within45;
  return std::max(within45, share_on_planes(s, points, std::cos(60.0 * kDeg)));
}

/// Rule (b): share of the occupied xy cells (side 3 r) whose points have a height gap above
/// max(10 r, 10 % of the z extent): two surfaces one above the other.
double layered_share(const PointCloud& cloud, double r, const BBox& box) {
  const double cell = 3.0 * r, gap = std::max(10.0 * r, 0.1 * box.size().z());
  std::unordered_map<std::int64_t, std::vector<double>> cells;
  const std::int64_t stride = 1 + static_cast<std::int64_t>(std::ceil(box.size().y() / cell));
  for (const Vec3& p : cloud.points) {
    const auto ix = static_cast<std::int64_t>(std::floor((p.x() - box.min.x()) / cell));
    const auto iy = static_cast<std::int64_t>(std::floor((p.y() - box.min.y()) / cell));
    cells[ix * stride + iy].push_back(p.z());
  }
  std::size_t layered = 0;
  for (auto& [key, z] : cells) {
    std::sort(z.begin(), z.end());
    for (std::size_t i = 1; i < z.size(); ++i)
      if (z[i] - z[i - 1] > gap) {
        ++layered;
        break;
      }
  }
  return cells.empty() ? 0.0 : static_cast<double>(layered) / static_cast<double>(cells.size());
}

SceneMode decide_mode(const SceneParams& params, double roof, double layered, bool rises, std::string& reason) {
  std::ostringstream why;
  why.precision(2);
  why << std::fixed << roof << " of the points on planes facing up (building: >= "
      << params.auto_min_roof_share << "), " << layered << " of the xy cells with two layers (building: <= "
      << params.auto_max_layered_share << ")";
  if (params.mode != SceneMode::Auto) {
    reason = std::string("given (") + why.str() + ")";
    return params.mode;
  }
  const bool building = roof >= params.auto_min_roof_share && layered <= params.auto_max_layered_share && rises;
  reason = why.str() + (rises ? "" : ", and nothing rises above the lowest points (building: a height of 4 r)");
  return building ? SceneMode::Building : SceneMode::Object;
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

/// The ground planes (see scene.h), or none. Fills ground_z from their inliers when found.
std::vector<int> find_ground_planes(const PointCloud& cloud, const SceneStructure& s, const SceneParams& params,
                                    double* ground_z) {
  const double r = s.spacing;
  std::vector<double> all_z;
  all_z.reserve(cloud.size());
  for (const Vec3& p : cloud.points) all_z.push_back(p.z());
  const double z_low = quantile(all_z, 0.01);
  const double tol = std::max(6.0 * r, 0.05 * s.bbox.size().z());
  std::vector<int> candidates;
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    const DetectedPlane& p = s.planes[k];
    if (std::abs(p.plane.normal.z()) < std::cos(params.ground_max_angle_deg * kDeg)) continue;
    if (p.centroid.z() <= z_low + tol) candidates.push_back(static_cast<int>(k));
  }
  if (candidates.empty()) return {};
  std::vector<int> ground_inliers, other_inliers;
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    const bool cand = std::find(candidates.begin(), candidates.end(), static_cast<int>(k)) != candidates.end();
    auto& dst = cand ? ground_inliers : other_inliers;
    dst.insert(dst.end(), s.planes[k].inliers.begin(), s.planes[k].inliers.end());
  }
  if (other_inliers.empty()) return {};  // nothing stands on it: a flat roof alone is not ground
  const double height = quantile(heights_of(cloud, ground_inliers), 0.5);
  // Something must rise clearly above it: the highest median height of the other planes.
  double top = -std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < s.planes.size(); ++k)
    if (std::find(candidates.begin(), candidates.end(), static_cast<int>(k)) == candidates.end())
      top = std::max(top, quantile(heights_of(cloud, s.planes[k].inliers), 0.5));
  if (!(top >= height + params.building_min_height * r)) return {};
  // It surrounds the rest (a low roof beside a taller block lies on one side only).
  Vec2 centre = Vec2::Zero();
  for (int i : other_inliers) centre += cloud.points[static_cast<std::size_t>(i)].head<2>();
  centre /= static_cast<double>(other_inliers.size());
  if (sectors_reached(cloud, ground_inliers, centre) < params.ground_min_sectors) return {};
  *ground_z = height;
  return candidates;
}

/// The ground when none is detected or given: the lowest building point, i.e. the lowest inlier of a roof
/// or wall plane, or of the unassigned points standing on the building's footprint (xy within one 2 r cell of
/// a roof or wall inlier: walls too sparse to be a plane, ground right at their foot). Terrain further out
/// (a sloping garden, a ditch) does not pull the building down.
double lowest_building_point(const PointCloud& cloud, const SceneStructure& s, const std::vector<PlaneRole>& roles) {
  const double cell = 2.0 * s.spacing;
  auto key = [&](const Vec3& p, int dx, int dy) {
    const auto ix = static_cast<std::int64_t>(std::floor((p.x() - s.bbox.min.x()) / cell)) + dx;
    const auto iy = static_cast<std::int64_t>(std::floor((p.y() - s.bbox.min.y()) / cell)) + dy;
    return ix * 0x100000000ll + iy;
  };
  std::unordered_map<std::int64_t, char> footprint;
  double lowest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const int k = s.point_plane[i];
    if (k < 0 || (roles[static_cast<std::size_t>(k)] != PlaneRole::Roof && roles[static_cast<std::size_t>(k)] != PlaneRole::Wall))
      continue;
    lowest = std::min(lowest, cloud.points[i].z());
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy) footprint[key(cloud.points[i], dx, dy)] = 1;
  }
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (s.point_plane[i] < 0 && footprint.count(key(cloud.points[i], 0, 0))) lowest = std::min(lowest, cloud.points[i].z());
  return std::isfinite(lowest) ? lowest : s.bbox.min.z();
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

/// Roles of the non-ground planes: vegetation, low ones and far small groups are clutter (see scene.h).
void assign_roles(const PointCloud& cloud, const SceneStructure& s, const SceneParams& params, SceneResult& out) {
  const double r = s.spacing;
  std::vector<bool> candidate(s.planes.size(), false);
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    if (out.roles[k] == PlaneRole::Ground) continue;
    const DetectedPlane& p = s.planes[k];
    out.roles[k] = is_wall(p.plane, params) ? PlaneRole::Wall : PlaneRole::Roof;
    // A roof lower than building_min_height (at its 90th percentile) is a car, a hedge or sloped terrain.
    if (out.roles[k] == PlaneRole::Roof &&
        (quantile(heights_of(cloud, p.inliers), 0.9) < out.ground_z + params.building_min_height * r ||
         is_vegetation(cloud, s, p, params)))
      out.roles[k] = PlaneRole::Clutter;
    candidate[k] = out.roles[k] != PlaneRole::Clutter;
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
double main_direction(const SceneStructure& s, const std::vector<PlaneRole>& roles) {
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

/// Walls that became one plane (the same upright normal, either way, offsets within `tol`:
/// region growing split a sparse facade into pieces) are merged into the first of them: inliers, boundary
/// and segments joined, the plane through their common centroid; the others are no longer kept.
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
  }
  for (int& k : s.point_plane)
    if (k >= 0 && head[static_cast<std::size_t>(k)] >= 0) k = head[static_cast<std::size_t>(k)];
  for (std::size_t i = 0; i < s.planes.size(); ++i) {  // the merged walls' neighbours go to their head
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
    case GroundSource::None: break;
  }
  return "none";
}

std::size_t SceneResult::count(PlaneRole r) const {
  return static_cast<std::size_t>(std::count(roles.begin(), roles.end(), r));
}

SceneResult run_scene(const PointCloud& cloud, const SceneStructure& structure, const SceneParams& params) {
  if (!(params.auto_min_roof_share >= 0 && params.auto_min_roof_share <= 1) ||
      !(params.auto_max_layered_share >= 0 && params.auto_max_layered_share <= 1) ||
      !(params.ground_max_angle_deg > 0 && params.ground_max_angle_deg < 90) ||
      !(params.wall_max_angle_deg > 0 && params.wall_max_angle_deg < 45) || params.ground_min_sectors < 0 ||
      params.ground_min_sectors > kSectors || !(params.building_min_height >= 0) ||
      !(params.main_direction_snap_deg >= 0 && params.main_direction_snap_deg < 45) ||
      (!std::isnan(params.ground_z) && !std::isfinite(params.ground_z)))
    throw Error(Status::BadInput, kStage, "parameters out of range (see scene.h)");
  SceneResult out;
  out.roof_share = roof_share(structure, cloud.size());
  out.layered_share = layered_share(cloud, structure.spacing, structure.bbox);
  // A building has a height: the data (or the roofs over a given ground) rise by building_min_height.
  const double base = std::isnan(params.ground_z) ? structure.bbox.min.z() : std::min(params.ground_z, structure.bbox.min.z());
  const bool rises = structure.bbox.max.z() - base >= params.building_min_height * structure.spacing;
  out.mode = decide_mode(params, out.roof_share, out.layered_share, rises, out.reason);
  out.roles.assign(structure.planes.size(), PlaneRole::Object);
  if (!out.is_building()) return out;

  if (!(params.given_ground_wins && !std::isnan(params.ground_z)))
    out.ground_planes = find_ground_planes(cloud, structure, params, &out.ground_z);
  if (!out.ground_planes.empty()) {
    out.ground_source = GroundSource::Plane;
    for (int k : out.ground_planes) out.roles[static_cast<std::size_t>(k)] = PlaneRole::Ground;
  } else if (!std::isnan(params.ground_z)) {
    out.ground_source = GroundSource::Given;
    out.ground_z = params.ground_z;
  } else {
    out.ground_z = structure.bbox.min.z();  // a first guess, for the clutter test below
  }
  assign_roles(cloud, structure, params, out);  // "low" is relative to the ground
  if (out.ground_source == GroundSource::None) {
    out.ground_z = lowest_building_point(cloud, structure, out.roles);
    out.ground_source = GroundSource::LowestPoints;
    assign_roles(cloud, structure, params, out);
  }
  out.main_direction = main_direction(structure, out.roles);
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
    j["ground_planes"] = scene.ground_planes;
    j["main_direction_deg"] = scene.main_direction / kDeg;
    for (PlaneRole r : {PlaneRole::Roof, PlaneRole::Wall, PlaneRole::Ground, PlaneRole::Clutter})
      j["planes"][plane_role_name(r)] = scene.count(r);
  }
  return j;
}

}  // namespace hsr
