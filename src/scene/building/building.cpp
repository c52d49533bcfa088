// The building kind's chain (building.h): ground planes, roles, the ground from its sources, roles against
// it, the main direction; then the building's own structure for the later stages (upright walls on the main
// directions, coplanar walls merged, roof outlines completed) and its roofs' outward sides.
#include "scene/building/building_internal.h"
#include "scene/scene_internal.h"

#include "core/error.h"
#include "core/log.h"
#include "core/rectangle.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace hsr {

using scene_detail::kDeg;
using scene_detail::kStage;

namespace {

/// Two upright walls whose normals agree to this (|cos| of the angle between them, from 1) face the same way:
/// after stand_upright() walls on a main direction have the same normal up to rounding.
constexpr double kSameUprightNormal = 1e-9;

bool any_roof(const std::vector<PlaneRole>& roles) {
  return std::find(roles.begin(), roles.end(), PlaneRole::Roof) != roles.end();
}

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
      if (std::abs(dot) < 1.0 - kSameUprightNormal || std::abs(a.plane.offset - (dot > 0 ? 1 : -1) * b.plane.offset) > tol)
        continue;
      head[j] = static_cast<int>(i);
      keep[j] = false;
      scene_detail::join_plane(a, b);
    }
  }
  scene_detail::redirect_joined(s, head);
}

/// A roof part's outline along the building's main directions: each side of the roof's inliers' rectangle
/// in the main frame that its points line (at least outline_min_points within outline_band r of it, spanning
/// outline_min_span of its length) but no boundary segment follows (the alpha shape's segment fitting misses
/// sides with stray points) gets a segment: along the side, through its points, facing out. Stage 3 then
/// treats it like any other.
void complete_outline(const PointCloud& cloud, double r, double main_direction, const BuildingParams& params,
                      DetectedPlane& roof) {
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
        if (d.norm() > 0 && std::abs(d.normalized().dot(along)) > std::cos(params.outline_parallel_deg * kDeg) &&
            seg.normal.head<2>().dot(out) > 0 && std::abs(coord - at) < params.outline_covered_distance * r)
          covered = true;
      }
      if (covered || !(length > 0)) continue;
      BoundarySegment seg;
      double smin = std::numeric_limits<double>::infinity(), smax = -smin;
      for (int i : roof.inliers) {
        const Vec2 p = cloud.points[static_cast<std::size_t>(i)].head<2>();
        if (std::abs((axis ? p.dot(e1) : p.dot(e0)) - at) > params.outline_band * r) continue;
        seg.support.push_back(i);
        smin = std::min(smin, p.dot(along));
        smax = std::max(smax, p.dot(along));
      }
      if (seg.support.size() < static_cast<std::size_t>(params.outline_min_points) ||
          smax - smin < params.outline_min_span * length)
        continue;
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

void check_building_params(const BuildingParams& p) {
  const auto fail = [](const char* field) {
    throw Error(Status::BadInput, kStage, std::string("building parameter ") + field + " out of range (see scene/building/building.h)");
  };
  if (!(p.ground_max_angle_deg > 0 && p.ground_max_angle_deg < 90)) fail("ground_max_angle_deg");
  if (!(p.wall_max_angle_deg > 0 && p.wall_max_angle_deg < 45)) fail("wall_max_angle_deg");
  if (p.ground_min_sectors < 0 || p.ground_min_sectors > building_detail::kSectors) fail("ground_min_sectors");
  if (!(p.building_min_height >= 0)) fail("building_min_height");
  if (!(p.car_max_width >= 0)) fail("car_max_width");
  if (!(p.car_max_height >= 0)) fail("car_max_height");
  if (!(p.main_direction_snap_deg >= 0 && p.main_direction_snap_deg < 45)) fail("main_direction_snap_deg");
  if (!(p.ground_ring > 0)) fail("ground_ring");
  if (!(p.assumed_wall_height > 0) || !std::isfinite(p.assumed_wall_height)) fail("assumed_wall_height");
  if (!std::isnan(p.ground_z) && !std::isfinite(p.ground_z)) fail("ground_z");
  if (p.ground_min_points < 1) fail("ground_min_points");
  if (!(p.ground_low_quantile >= 0 && p.ground_low_quantile <= 1)) fail("ground_low_quantile");
  if (!(p.roof_height_quantile >= 0 && p.roof_height_quantile <= 1)) fail("roof_height_quantile");
  if (!(p.ground_band >= 0) || !(p.ground_band_share >= 0)) fail("ground_band");
  if (!(p.footprint_cell > 0)) fail("footprint_cell");
  if (p.main_direction_smoothing_deg < 0 || p.main_direction_smoothing_deg >= 45) fail("main_direction_smoothing_deg");
  if (!(p.main_direction_window_deg >= 0 && p.main_direction_window_deg < 45)) fail("main_direction_window_deg");
  if (!std::isfinite(p.main_direction_raster_tolerance))
    fail("main_direction_raster_tolerance");
  if (!(p.main_direction_min_fill >= 0 && p.main_direction_min_fill <= 1)) fail("main_direction_min_fill");
  if (p.outline_min_points < 1) fail("outline_min_points");
  if (p.small_plane_points < 0 || (p.small_plane_points > 0 && p.small_plane_points < 3)) fail("small_plane_points");
  if (!(p.small_plane_width >= 0) || !std::isfinite(p.small_plane_width)) fail("small_plane_width");
  if (!std::isfinite(p.small_wall_max_overhang)) fail("small_wall_max_overhang");
  if (!(p.small_roof_max_slope_deg > 0 && p.small_roof_max_slope_deg <= 90)) fail("small_roof_max_slope_deg");
  if (!(p.small_roof_eave_drop >= 0) || !std::isfinite(p.small_roof_eave_drop)) fail("small_roof_eave_drop");
  if (p.finer_outline_points < 0 || (p.finer_outline_points > 0 && p.finer_outline_points < 2)) fail("finer_outline_points");
  if (!(p.finer_outline_min_gain >= 0 && p.finer_outline_min_gain < 1)) fail("finer_outline_min_gain");
  if (!(p.outline_prism_roof_quantile >= 0 && p.outline_prism_roof_quantile <= 1)) fail("outline_prism_roof_quantile");
  if (p.finer_outline_runs < 1) fail("finer_outline_runs");
  if (p.finer_outline_runs_on_footprint < 1) fail("finer_outline_runs_on_footprint");
  if (!(p.tighter_planes_distance >= 0)) fail("tighter_planes_distance");
  if (!(p.tighter_planes_second_distance >= 0)) fail("tighter_planes_second_distance");
  if (p.tighter_planes_second_max_points < 0) fail("tighter_planes_second_max_points");
  if (p.left_out_roof_min_points < 3) fail("left_out_roof_min_points");
  if (!(p.left_out_roof_max_under >= 0)) fail("left_out_roof_max_under");
  if (!std::isfinite(p.unseen_roof_distance)) fail("unseen_roof_distance");
  if (!(p.gable_half_distance > 0) || !std::isfinite(p.gable_half_distance)) fail("gable_half_distance");
  if (!(p.gable_half_min_pitch_deg >= 0 && p.gable_half_min_pitch_deg < 90)) fail("gable_half_min_pitch_deg");
}

bool keep_finer_outline(bool first_valid, double first_p2m, std::size_t first_small_faces, bool finer_valid,
                        double finer_p2m, std::size_t finer_small_faces, const BuildingParams& params) {
  if (!finer_valid) return false;
  if (!first_valid) return true;
  return finer_p2m < (1.0 - params.finer_outline_min_gain) * first_p2m && finer_small_faces <= first_small_faces;
}

bool keep_tighter_planes(bool first_valid, double first_p2m, std::size_t first_small_faces, std::size_t first_far_points,
                         bool tighter_valid, double tighter_p2m, std::size_t tighter_small_faces,
                         std::size_t tighter_far_points, const BuildingParams& params) {
  if (!tighter_valid) return false;
  if (!first_valid) return true;
  if (!(tighter_p2m < (1.0 - params.finer_outline_min_gain) * first_p2m)) return false;
  return tighter_small_faces <= first_small_faces || tighter_far_points < first_far_points;
}

bool no_more_unseen_roof(double first_p2m_sum, double first_unseen, double other_p2m_sum, double other_unseen,
                         const BuildingParams& params) {
  if (!(params.unseen_roof_distance > 0)) return true;
  return other_p2m_sum + other_unseen <= first_p2m_sum + first_unseen;
}

std::size_t points_under_roof(const PointCloud& cloud, const DetectedPlane& roof, double r, double far,
                              const std::vector<double>* point_distance) {
  std::vector<Vec2> xy;
  xy.reserve(roof.inliers.size());
  for (int i : roof.inliers) xy.push_back(cloud.points[static_cast<std::size_t>(i)].head<2>());
  const RectangleDirection rect = min_area_rectangle(xy);
  if (!(rect.width > 0) || roof.plane.normal.z() == 0.0) return 0;
  const Vec2 e0(std::cos(rect.angle), std::sin(rect.angle)), e1(-e0.y(), e0.x());
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec2& p : xy) {
    const Vec2 q(p.dot(e0), p.dot(e1));
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  lo.array() += r;
  hi.array() -= r;
  const Plane& pl = roof.plane;
  std::size_t under = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3& p = cloud.points[i];
    const Vec2 q(p.head<2>().dot(e0), p.head<2>().dot(e1));
    if (q.x() <= lo.x() || q.x() >= hi.x() || q.y() <= lo.y() || q.y() >= hi.y()) continue;
    if (point_distance && i < point_distance->size() && !((*point_distance)[i] > far)) continue;  // explained
    const double z = -(pl.normal.x() * p.x() + pl.normal.y() * p.y() + pl.offset) / pl.normal.z();
    under += p.z() < z - far;
  }
  return under;
}

std::vector<int> left_out_roofs(const PointCloud& cloud, const SceneStructure& building,
                                const std::vector<double>& point_distance, double far, std::size_t min_points,
                                double max_under, bool under_unexplained) {
  std::vector<int> left;
  std::vector<double> d;
  for (std::size_t k = 0; k < building.planes.size(); ++k) {
    const DetectedPlane& p = building.planes[k];
    if (p.plane.normal.z() == 0.0 || p.inliers.size() < min_points) continue;
    d.clear();
    for (int i : p.inliers)
      if (static_cast<std::size_t>(i) < point_distance.size()) d.push_back(point_distance[static_cast<std::size_t>(i)]);
    if (d.size() < min_points) continue;
    const auto mid = d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2);
    std::nth_element(d.begin(), mid, d.end());
    if (!(*mid > far)) continue;
    const std::size_t under =
        points_under_roof(cloud, p, building.spacing, far, under_unexplained ? &point_distance : nullptr);
    log::verbose("[scene] building: roof " + std::to_string(k) + " of " + std::to_string(p.inliers.size()) +
                 " inliers left out of the model, " + std::to_string(under) +
                     (under_unexplained ? " points under it off the model" : " points under it"));
    if (static_cast<double>(under) > max_under * static_cast<double>(p.inliers.size())) continue;
    left.push_back(static_cast<int>(k));
  }
  return left;
}

std::vector<int> carried_roofs(const SceneStructure& building, const std::vector<std::vector<int>>& walled) {
  std::vector<int> roofs;
  for (const std::vector<int>& roof : walled) {
    if (roof.empty()) continue;
    int best = -1;
    std::size_t best_shared = 0;
    for (std::size_t k = 0; k < building.planes.size(); ++k) {
      const DetectedPlane& p = building.planes[k];
      if (p.plane.normal.z() == 0.0) continue;  // a wall
      std::size_t shared = 0;
      for (int i : p.inliers) shared += std::binary_search(roof.begin(), roof.end(), i);
      if (shared > best_shared) best = static_cast<int>(k), best_shared = shared;
    }
    if (best >= 0 && 2 * best_shared >= roof.size()) roofs.push_back(best);
  }
  std::sort(roofs.begin(), roofs.end());
  roofs.erase(std::unique(roofs.begin(), roofs.end()), roofs.end());
  return roofs;
}

namespace {

/// The error of a building scan with no plane left to be a roof. With walls left it is degenerate: walls alone
/// enclose nothing, and their points' outline is not the building's (two facades of a footprint make an L). With
/// none (every plane foliage or clutter) the detection found nothing usable for a building, as when it finds no
/// plane at all: Status::NoPlanes, which gets the outline prism where that applies (pipeline_prism.cpp; a sparse
/// roof whose one plane looks as rough as a crown: Vaihingen_00009 at half density, a fresh draw, 70 of its 74
/// points on one plane taken for foliage).
Error no_roof_error(const SceneResult& out) {
  const std::size_t walls = out.count(PlaneRole::Wall);
  return Error(walls > 0 ? Status::DegenerateInput : Status::NoPlanes, kStage,
               "building mode: no plane is left to be a roof (" + std::to_string(out.count(PlaneRole::Clutter)) +
                   " foliage or clutter, " + std::to_string(walls) + " wall planes); try --scene object");
}

}  // namespace

void building_scene(const PointCloud& cloud, const SceneStructure& structure, const BuildingParams& params,
                    const SceneGround& ground, const std::vector<bool>& foliage, SceneResult& out) {
  using namespace building_detail;
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
  if (!any_roof(out.roles)) throw no_roof_error(out);
  // ...then the ground from its sources, and the roles against it: cars, hedges and terrain are low (not
  // against an assumed ground: nothing lies under the roofs, a low roof is a low part of the building).
  choose_ground(cloud, structure, params, ground, plane_height, out);
  if (out.ground_source != GroundSource::Assumed) {
    for (PlaneRole& r : out.roles)
      if (r != PlaneRole::Ground) r = PlaneRole::Object;
    assign_roles(cloud, structure, params, foliage, true, out);
  }
  out.main_direction = main_direction(cloud, structure, out.roles, params);
  if (!out.ground_note.empty()) log::warn("[scene] " + out.ground_note);
  std::ostringstream msg;
  msg << "[scene] building: ground at z = " << out.ground_z << " (" << ground_source_name(out.ground_source) << "), "
      << out.count(PlaneRole::Roof) << " roof, " << out.count(PlaneRole::Wall) << " wall, "
      << out.count(PlaneRole::Ground) << " ground, " << out.count(PlaneRole::Clutter) << " clutter planes; main direction "
      << out.main_direction / kDeg << " deg";
  log::verbose(msg.str());
}

SceneStructure building_planes(const PointCloud& cloud, const SceneStructure& structure, const SceneResult& scene,
                               const BuildingParams& params) {
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
    if (keep[k] && scene.roles[k] == PlaneRole::Roof)
      complete_outline(cloud, s.spacing, scene.main_direction, params, s.planes[k]);
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

}  // namespace hsr
