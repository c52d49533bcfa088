// Stage 3, building mode (RecoveryParams::vertical; recovery.h's last paragraph, DESIGN.md §4): the missing
// planes are vertical walls through singular roof segments, turned onto the building's main directions, and a
// detected wall that explains a roof segment without being adjacent to it. DECISIONS #22 and #54. And the walls
// around a roof the first pass's model left out (walls_around_roof, DECISIONS #159).
#include "recovery/recovery_internal.h"

#include "core/error.h"
#include "core/rectangle.h"
#include "core/spacing.h"
#include "core/stats.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace hsr::recovery_internal {

/// Building mode: a detected (vertical) wall under a roof segment explains it even when the two planes
/// are not adjacent (sparse wall points rarely pair with roof points): parallel in xy within r_a, the
/// segment's centroid within `join` (wall_join_distance) of the wall's plane, and the wall's points reaching
/// to within r_d of it.
/// Returns the first such wall, or -1.
int explaining_wall(const SceneStructure& structure, const BoundarySegment& s, const Vec3& c, double join, double r_d,
                    double cos_a) {
  const Vec2 d = (s.b - s.a).head<2>();
  if (!(d.norm() > 0)) return -1;
  for (std::size_t k = 0; k < structure.planes.size(); ++k) {
    const DetectedPlane& w = structure.planes[k];
    if (w.plane.normal.z() != 0.0 || static_cast<int>(k) == s.plane) continue;
    const Vec2 n = w.plane.normal.head<2>().normalized();
    if (std::abs(n.dot(d.normalized())) > std::sqrt(1.0 - cos_a * cos_a)) continue;  // not parallel
    if (!(std::abs(w.plane.signed_distance(Vec3(c.x(), c.y(), w.centroid.z()))) < join)) continue;
    if (w.boundary_distance(c, true) < r_d) return static_cast<int>(k);
  }
  return -1;
}

namespace {

/// Unit horizontal direction of a segment in xy, or zero when it is (nearly) vertical.
Vec2 xy_direction(const BoundarySegment& s) {
  const Vec2 d = (s.b - s.a).head<2>();
  const double len = d.norm();
  return len > 0.3 * s.length() && len > 0 ? Vec2(d / len) : Vec2::Zero();
}

/// A wall under construction: a vertical line in xy (unit normal `n`, n·x + d = 0), its supporting points and
/// its extent along the line.
struct WallFit {
  Vec2 n = Vec2::UnitX();
  double d = 0.0;
  bool snapped = false;
  double lo = 0.0, hi = 0.0;  ///< extent along the line direction (-n.y, n.x)
  double distance(const Vec2& p) const { return n.dot(p) + d; }
  double along(const Vec2& p) const { return -n.y() * p.x() + n.x() * p.y(); }
};

/// The wall through one segment: its direction snapped to the main directions when close, facing the
/// segment's outward normal, through its supporting points' centroid.
WallFit seed_wall(const PointCloud& cloud, const BoundarySegment& s, const RecoveryParams& params) {
  const Vec2 dir = xy_direction(s);
  WallFit w;
  w.n = Vec2(-dir.y(), dir.x());
  if (w.n.dot(s.normal.head<2>()) < 0) w.n = -w.n;
  double a = std::atan2(w.n.y(), w.n.x());
  const double off = std::remainder(a - params.main_direction, M_PI / 2.0);
  if (std::abs(off) <= params.snap_deg * M_PI / 180.0) {
    a -= off;
    w.n = Vec2(std::cos(a), std::sin(a));
    w.snapped = true;
  }
  const Vec2 c = segment_centroid(cloud, s).head<2>();
  w.d = -w.n.dot(c);
  w.lo = std::min(w.along(s.a.head<2>()), w.along(s.b.head<2>()));
  w.hi = std::max(w.along(s.a.head<2>()), w.along(s.b.head<2>()));
  return w;
}

/// Refits the wall's line to its supporting points in xy (only the offset when its direction is snapped).
void refit_wall(const PointCloud& cloud, const std::vector<int>& support, WallFit& w) {
  Vec2 c = Vec2::Zero();
  for (int i : support) c += cloud.points[static_cast<std::size_t>(i)].head<2>();
  c /= static_cast<double>(support.size());
  if (!w.snapped) {
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (int i : support) {
      const Vec2 e = cloud.points[static_cast<std::size_t>(i)].head<2>() - c;
      cov += e * e.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
    Vec2 n = eig.eigenvectors().col(0);
    if (eig.eigenvalues()(1) > 16.0 * std::max(eig.eigenvalues()(0), 0.0)) w.n = n.dot(w.n) < 0 ? Vec2(-n) : n;
  }
  w.d = -w.n.dot(c);
}

/// A wall fitted through a roof's outline points runs through their middle, so about half of them lie
/// beyond it, on the roof plane outside the building, where they would vote for a strip of volume along the
/// wall. The roof's edge lies beyond its outermost points: the wall is moved out to where `edge_quantile`
/// (RecoveryParams::wall_edge_quantile, 1: all) of its supporting points are inside it — scaled by the balance of
/// its segments' supporting points facing its way against those facing the other way (a step edge between two
/// roofs is fitted from both sides: no move), and `beyond` further (RecoveryParams::wall_beyond_points spacings
/// of its roofs in plan, the edge past the outermost points: core/spacing.h edge_beyond_outermost_points), scaled
/// the same way.
void shift_to_the_edge(const PointCloud& cloud, const SceneStructure& structure, const std::vector<SegmentRef>& members,
                       const std::vector<int>& support, double edge_quantile, double beyond, WallFit& w) {
  double same = 0, opposite = 0;
  for (const SegmentRef& m : members) {
    const BoundarySegment& seg = structure.planes[static_cast<std::size_t>(m.plane)].segments[static_cast<std::size_t>(m.segment)];
    (seg.normal.head<2>().dot(w.n) >= 0 ? same : opposite) += static_cast<double>(seg.support.size());
  }
  if (!(same + opposite > 0) || support.empty()) return;
  std::vector<double> d;
  d.reserve(support.size());
  for (int i : support) d.push_back(w.distance(cloud.points[static_cast<std::size_t>(i)].head<2>()));
  w.d -= (std::max(0.0, quantile(std::move(d), edge_quantile)) + beyond) * (same - opposite) / (same + opposite);
}

/// The spacing in plan of the roofs whose outline segments make a wall (core/spacing.h plan_spacing over the
/// inliers of each member's plane, pooled: the sum of their hulls' areas over the sum of their inliers).
double members_plan_spacing(const PointCloud& cloud, const SceneStructure& structure, const std::vector<SegmentRef>& members) {
  std::vector<int> planes;
  for (const SegmentRef& m : members) planes.push_back(m.plane);
  std::sort(planes.begin(), planes.end());
  planes.erase(std::unique(planes.begin(), planes.end()), planes.end());
  double area = 0, count = 0;
  for (int k : planes) {
    std::vector<Vec2> xy;
    for (int i : structure.planes[static_cast<std::size_t>(k)].inliers) xy.push_back(cloud.points[static_cast<std::size_t>(i)].head<2>());
    const double s = plan_spacing(xy);
    area += s * s * static_cast<double>(xy.size());
    count += s > 0 ? static_cast<double>(xy.size()) : 0.0;
  }
  return count > 0 ? std::sqrt(area / count) : 0.0;
}

/// The extent [lo, hi] of a roof's inliers along a wall's direction in plan.
std::pair<double, double> roof_extent_along(const PointCloud& cloud, const SceneStructure& structure, int plane,
                                            const WallFit& w) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int i : structure.planes[static_cast<std::size_t>(plane)].inliers) {
    const double t = w.along(cloud.points[static_cast<std::size_t>(i)].head<2>());
    lo = std::min(lo, t);
    hi = std::max(hi, t);
  }
  return {lo, hi};
}

/// RecoveredPlane::reach: the points of the wall's line at the ends of its member roofs' extent along it, a
/// spacing above the highest of its roofs there: the wall reaches over the eave all along it, so its roof
/// meets it inside the polygon and stops there (a wall whose top ran under the eave would let the roof pass
/// over it and slope on down outside the building).
std::vector<Vec3> wall_reach(const PointCloud& cloud, const SceneStructure& structure, const std::vector<SegmentRef>& members,
                             double r, const WallFit& w) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const SegmentRef& m : members) {
    const auto [a, b] = roof_extent_along(cloud, structure, m.plane, w);
    lo = std::min(lo, a);
    hi = std::max(hi, b);
  }
  const Vec2 dir(-w.n.y(), w.n.x()), foot = -w.d * w.n;  // foot: the line's point nearest the origin
  std::vector<Vec3> reach;
  for (double t : {lo, hi}) {
    const Vec2 xy = foot + t * dir;
    double top = -std::numeric_limits<double>::infinity();
    for (const SegmentRef& m : members) {
      const Plane& roof = structure.planes[static_cast<std::size_t>(m.plane)].plane;
      top = std::max(top, -(roof.normal.x() * xy.x() + roof.normal.y() * xy.y() + roof.offset) / roof.normal.z());
    }
    reach.emplace_back(xy.x(), xy.y(), top + r);
  }
  return reach;
}

/// Two outline segments of one roof facing opposite ways are its two sides: the roof lies between them, so
/// they are never one wall, however close (a shed a metre wide is narrower than wall_join_distance).
bool faces_a_member_across_its_roof(const SceneStructure& structure, const std::vector<SegmentRef>& members,
                                    const SegmentRef& candidate) {
  const auto& planes = structure.planes;
  const Vec3& nc = planes[static_cast<std::size_t>(candidate.plane)].segments[static_cast<std::size_t>(candidate.segment)].normal;
  for (const SegmentRef& m : members) {
    if (m.plane != candidate.plane) continue;
    const Vec3& nm = planes[static_cast<std::size_t>(m.plane)].segments[static_cast<std::size_t>(m.segment)].normal;
    if (nm.head<2>().dot(nc.head<2>()) < 0) return true;
  }
  return false;
}

}  // namespace

std::vector<RecoveredPlane> recover_walls(const PointCloud& cloud, const SceneStructure& structure,
                                          const RecoveryParams& params, const RecoveryResult& res) {
  const double r = structure.spacing > 0 ? structure.spacing : 1.0;
  const double r_d = params.distance * r;
  const double cos_a = std::cos(params.angle_deg * M_PI / 180.0);
  const double min_tilt = std::sin(params.roof_min_tilt_deg * M_PI / 180.0);
  const double join = params.wall_join_distance * r;
  struct Item {
    SegmentRef ref;
    double length;
  };
  std::vector<Item> order;  // singular roof segments that are not vertical, longest first
  for (std::size_t i = 0; i < structure.planes.size(); ++i) {
    if (!(std::abs(structure.planes[i].plane.normal.z()) > min_tilt)) continue;
    for (std::size_t j = 0; j < res.singular[i].size(); ++j) {
      const BoundarySegment& s = structure.planes[i].segments[j];
      if (res.singular[i][j] && xy_direction(s).norm() > 0)
        order.push_back({{static_cast<int>(i), static_cast<int>(j)}, s.length()});
    }
  }
  std::stable_sort(order.begin(), order.end(), [](const Item& a, const Item& b) { return a.length > b.length; });
  auto seg = [&](const SegmentRef& s) -> const BoundarySegment& {
    return structure.planes[static_cast<std::size_t>(s.plane)].segments[static_cast<std::size_t>(s.segment)];
  };

  std::vector<char> used(order.size(), 0);
  std::vector<RecoveredPlane> walls;
  for (std::size_t seed = 0; seed < order.size(); ++seed) {
    if (used[seed]) continue;
    used[seed] = 1;
    WallFit w = seed_wall(cloud, seg(order[seed].ref), params);
    std::vector<SegmentRef> members{order[seed].ref};
    std::vector<int> support = seg(order[seed].ref).support;
    double length = order[seed].length;
    for (bool grew = true; grew;) {  // admit segments until none joins (each pass in the fixed order)
      grew = false;
      for (std::size_t t = 0; t < order.size(); ++t) {
        if (used[t]) continue;
        const BoundarySegment& c = seg(order[t].ref);
        const Vec2 dir = xy_direction(c);
        if (std::abs(Vec2(-w.n.y(), w.n.x()).dot(dir)) < cos_a) continue;
        double dist = 0;
        for (int i : c.support) dist += std::abs(w.distance(cloud.points[static_cast<std::size_t>(i)].head<2>()));
        if (c.support.empty() || !(dist / static_cast<double>(c.support.size()) < join)) continue;
        if (faces_a_member_across_its_roof(structure, members, order[t].ref)) continue;
        const double a = w.along(c.a.head<2>()), b = w.along(c.b.head<2>());
        if (std::min(a, b) > w.hi + 2.0 * r_d || std::max(a, b) < w.lo - 2.0 * r_d) continue;
        used[t] = 1;
        grew = true;
        members.push_back(order[t].ref);
        support.insert(support.end(), c.support.begin(), c.support.end());
        length += order[t].length;
        w.lo = std::min({w.lo, a, b});
        w.hi = std::max({w.hi, a, b});
        std::sort(support.begin(), support.end());
        support.erase(std::unique(support.begin(), support.end()), support.end());
        refit_wall(cloud, support, w);
      }
    }
    shift_to_the_edge(cloud, structure, members, support, params.wall_edge_quantile,
                      edge_beyond_outermost_points(members_plan_spacing(cloud, structure, members), params.wall_beyond_points), w);
    // A side as long as half its roof's extent along it is one of the roof's sides, whatever the minimum
    // wall length (a shed's short side is shorter than 4 r).
    const auto [roof_lo, roof_hi] = roof_extent_along(cloud, structure, order[seed].ref.plane, w);
    if (length < std::min(params.min_wall_length * r, 0.5 * (roof_hi - roof_lo)) || support.empty()) continue;
    RecoveredPlane rp;
    rp.plane.normal = Vec3(w.n.x(), w.n.y(), 0.0);
    rp.plane.offset = w.d;
    std::sort(members.begin(), members.end(), [](const SegmentRef& a, const SegmentRef& b) {
      return a.plane != b.plane ? a.plane < b.plane : a.segment < b.segment;
    });
    rp.segments = std::move(members);
    std::sort(support.begin(), support.end());
    support.erase(std::unique(support.begin(), support.end()), support.end());
    rp.reach = wall_reach(cloud, structure, rp.segments, r, w);
    rp.support = std::move(support);
    walls.push_back(std::move(rp));
  }
  return walls;
}

/// The walls around a roof part the first pass's model left out (run_recovery's walls_around_roofs, DECISIONS
/// #159): the four sides of its inliers' smallest-area rectangle in plan, turned onto the building's main
/// direction when within snap_deg of it, each a wall facing out through the outermost inliers on its side
/// (its support), spanning the side (RecoveredPlane::reach: the side's ends a spacing above the roof's highest
/// corner; stage 4 drops every wall to the ground) and adjacent to the roof (RecoveredPlane::caps).
/// Why: a roof part standing on another roof (AHN3_11936: a 5 m² sloped structure of 56 points on a flat roof)
/// lies inside the building's outline, and when its own outline holds no segment (13 boundary points in three
/// sides of 4 or 5) no wall is recovered under it: its plane's polygon bounds no cell of its own, and the min-cut
/// leaves it out. The rectangle, not the alpha shape's segments: those are what is missing.
std::vector<RecoveredPlane> walls_around_roof(const PointCloud& cloud, const SceneStructure& structure, int roof,
                                              const RecoveryParams& params) {
  if (roof < 0 || static_cast<std::size_t>(roof) >= structure.planes.size())
    throw Error(Status::Internal, "recovery", "walls_around_roofs: no plane " + std::to_string(roof));
  const DetectedPlane& plane = structure.planes[static_cast<std::size_t>(roof)];
  if (plane.plane.normal.z() == 0.0 || plane.inliers.empty()) return {};  // a wall, or nothing: no roof
  const double r = structure.spacing > 0 ? structure.spacing : 1.0;
  std::vector<Vec2> xy;
  xy.reserve(plane.inliers.size());
  for (int i : plane.inliers) xy.push_back(cloud.points[static_cast<std::size_t>(i)].head<2>());
  const RectangleDirection rect = min_area_rectangle(xy);
  if (!(rect.width > 0)) return {};  // the points span no area in plan
  double angle = rect.angle;
  const double off = std::remainder(angle - params.main_direction, M_PI / 2.0);
  if (std::abs(off) <= params.snap_deg * M_PI / 180.0) angle -= off;
  const Vec2 e0(std::cos(angle), std::sin(angle)), e1(-e0.y(), e0.x());
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  std::array<int, 4> outermost{-1, -1, -1, -1};  // the inlier on each side: -e0, +e0, -e1, +e1
  for (int i : plane.inliers) {
    const Vec2 p = cloud.points[static_cast<std::size_t>(i)].head<2>();
    const Vec2 q(p.dot(e0), p.dot(e1));
    if (q.x() < lo.x()) lo.x() = q.x(), outermost[0] = i;
    if (q.x() > hi.x()) hi.x() = q.x(), outermost[1] = i;
    if (q.y() < lo.y()) lo.y() = q.y(), outermost[2] = i;
    if (q.y() > hi.y()) hi.y() = q.y(), outermost[3] = i;
  }
  const auto corner = [&](double u, double v) { return Vec2(u * e0 + v * e1); };
  const std::array<Vec2, 4> corners{corner(lo.x(), lo.y()), corner(hi.x(), lo.y()), corner(hi.x(), hi.y()),
                                    corner(lo.x(), hi.y())};
  const Plane& pl = plane.plane;
  double top = -std::numeric_limits<double>::infinity();
  for (const Vec2& c : corners) top = std::max(top, -(pl.normal.x() * c.x() + pl.normal.y() * c.y() + pl.offset) / pl.normal.z());
  top += r;
  // side k: its outward normal, its coordinate along it, its two corners
  const std::array<Vec2, 4> out{-e0, e0, -e1, e1};
  const std::array<double, 4> at{-lo.x(), hi.x(), -lo.y(), hi.y()};
  const std::array<std::array<int, 2>, 4> ends{{{3, 0}, {1, 2}, {0, 1}, {2, 3}}};
  std::vector<RecoveredPlane> walls;
  for (std::size_t k = 0; k < 4; ++k) {
    RecoveredPlane rp;
    rp.plane.normal = Vec3(out[k].x(), out[k].y(), 0.0);
    rp.plane.offset = -at[k];
    rp.support = {outermost[k]};
    for (int e : ends[k]) rp.reach.emplace_back(corners[static_cast<std::size_t>(e)].x(), corners[static_cast<std::size_t>(e)].y(), top);
    rp.caps = {roof};
    walls.push_back(std::move(rp));
  }
  return walls;
}

/// A side of a roof's rectangle on (nearly) the plane of a wall already there takes that wall's plane, its own
/// orientation kept (RecoveryParams::around_side_same_wall, DECISIONS #191). Why: a plane a rounding error off
/// another leaves faces closer than the output's precision (an invalid model); coplanar, the partition puts them
/// on one support plane.
void take_the_plane_of_a_wall_there(const std::vector<RecoveredPlane>& walls, double distance, double cos_a,
                                    RecoveredPlane& side) {
  if (!(distance >= 0) || side.reach.size() < 2 || side.plane.normal.z() != 0.0) return;
  const RecoveredPlane* best = nullptr;
  double best_off = distance;
  for (const RecoveredPlane& w : walls) {
    if (w.plane.normal.z() != 0.0 || std::abs(w.plane.normal.dot(side.plane.normal)) < cos_a) continue;
    double off = 0;  // the farther of the side's two ends from the wall's plane
    for (const Vec3& e : side.reach)
      off = std::max(off, std::abs(w.plane.normal.head<2>().dot(e.head<2>()) + w.plane.offset));
    if (off <= best_off && (!best || off < best_off)) best = &w, best_off = off;  // strict: the first wins ties
  }
  if (!best) return;
  const bool same_way = best->plane.normal.dot(side.plane.normal) > 0;
  side.plane.normal = same_way ? best->plane.normal : Vec3(-best->plane.normal);
  side.plane.offset = same_way ? best->plane.offset : -best->plane.offset;
}

}  // namespace hsr::recovery_internal
