// The building's ground: its six sources in order (building.h), and the footprint cells two of them use.
#include "scene/building/building_internal.h"
#include "scene/scene_internal.h"

#include "core/log.h"
#include "core/stats.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <unordered_set>

namespace hsr::building_detail {

using scene_detail::heights_of;
using scene_detail::kDeg;
using scene_detail::plan_cell;

namespace {

/// Number of the kSectors angular sectors about `centre` (xy) that hold at least one of the points.
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
/// more above the lowest one (median heights) stand on the ground: a low roof, not a second ground
/// (DECISIONS #78). They leave `candidates` (after the ground was found with them: they do not decide whether
/// there is one).
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

/// The building's footprint in plan: the xy cells (side footprint_cell r) holding a roof or wall inlier.
class FootprintCells {
 public:
  FootprintCells(const PointCloud& cloud, const SceneStructure& s, const std::vector<PlaneRole>& roles,
                 const BuildingParams& params)
      : cell_(params.footprint_cell * s.spacing), origin_(s.bbox.min.head<2>()) {
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

/// Source 5 (building.h): the lowest roof or wall inlier, or unassigned point on the footprint (one cell
/// around it: walls too sparse to be a plane, ground right at their foot). Terrain further out (a sloping
/// garden, a ditch) does not pull the building down. Infinity when the building has no roof or wall point.
double lowest_building_point(const PointCloud& cloud, const SceneStructure& s, const std::vector<PlaneRole>& roles,
                             const BuildingParams& params) {
  const FootprintCells footprint(cloud, s, roles, params);
  double lowest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (FootprintCells::is_building_point(s, roles, i) || (s.point_plane[i] < 0 && footprint.near(cloud.points[i], 1)))
      lowest = std::min(lowest, cloud.points[i].z());
  return lowest;
}

/// The lowest point of the roofs that rise at least `rise` above `base` (at their roof_height_quantile; all
/// roofs when none does): the least height of a roof plane over one of its inliers (on the plane, so a flat
/// roof's is its height, not its noisiest point's); infinity when there is no roof. A low plane at the very
/// bottom (a terrace, a pavement by the wall) is no roof to measure "under the roofs" from.
double lowest_roof_point(const PointCloud& cloud, const SceneStructure& s, const std::vector<PlaneRole>& roles,
                         double base, double rise, double height_quantile) {
  std::vector<bool> rises(s.planes.size(), false);
  bool any = false;
  for (std::size_t k = 0; k < s.planes.size(); ++k)
    if (roles[k] == PlaneRole::Roof)
      any = any || (rises[k] = quantile(heights_of(cloud, s.planes[k].inliers), height_quantile) >= base + rise);
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
    if (FootprintCells::is_building_point(s, roles, i) && ground.raster->sample(g.x(), g.y(), h)) z.push_back(h - ground.origin.z());
  }
  return z.empty() ? std::numeric_limits<double>::quiet_NaN() : quantile(std::move(z), 0.5);
}

/// Source 3: the median height of the classified ground points in the ring around the footprint (within
/// ground_ring r of it, not on it); NaN when fewer than ground_min_points are there.
double ground_from_points(const PointCloud& cloud, const SceneStructure& s, const std::vector<PlaneRole>& roles,
                          const SceneGround& ground, const BuildingParams& params) {
  const FootprintCells footprint(cloud, s, roles, params);
  const int grow = std::max(1, static_cast<int>(std::ceil(params.ground_ring * s.spacing / footprint.cell())));
  std::vector<double> z;
  for (const Vec3& p : ground.points)
    if (!footprint.near(p, 0) && footprint.near(p, grow)) z.push_back(p.z());
  return z.size() < static_cast<std::size_t>(params.ground_min_points) ? std::numeric_limits<double>::quiet_NaN()
                                                                       : quantile(std::move(z), 0.5);
}

}  // namespace

std::vector<int> find_ground_planes(const PointCloud& cloud, const SceneStructure& s, const BuildingParams& params,
                                    const std::vector<bool>& foliage, double* ground_z) {
  const double r = s.spacing;
  std::vector<double> all_z;
  all_z.reserve(cloud.size());
  for (const Vec3& p : cloud.points) all_z.push_back(p.z());
  const double z_low = quantile(all_z, params.ground_low_quantile);
  const double tol = std::max(params.ground_band * r, params.ground_band_share * s.bbox.size().z());
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

void choose_ground(const PointCloud& cloud, const SceneStructure& s, const BuildingParams& params,
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
    const double z = ground_from_points(cloud, s, out.roles, ground, params);
    if (std::isfinite(z)) return use(GroundSource::ClassifiedPoints, z);
  }
  if (!out.ground_planes.empty()) return use(GroundSource::Plane, plane_height);
  const double lowest = lowest_building_point(cloud, s, out.roles, params);
  const double roof_low = lowest_roof_point(cloud, s, out.roles, lowest, params.building_min_height * s.spacing,
                                            params.roof_height_quantile);
  if (lowest <= roof_low - params.under_roof_gap * s.spacing || !std::isfinite(roof_low))
    return use(GroundSource::LowestPoints, std::isfinite(lowest) ? lowest : s.bbox.min.z());
  use(GroundSource::Assumed, std::min(lowest, roof_low) - params.assumed_wall_height);
  std::ostringstream note;
  note << "nothing in the scan lies under its roofs and no ground is known: the walls are assumed "
       << params.assumed_wall_height << " tall (one storey); give the ground with --ground-z Z or --ground DTM.tif";
  out.ground_note = note.str();
}

}  // namespace hsr::building_detail
