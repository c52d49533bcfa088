// Stage 3: singular segments and missing plane recovery (see recovery.h). Plain Eigen; CGAL only behind
// core/rectangle.h (a piece's box).
#include "recovery/recovery.h"

#include "core/error.h"
#include "core/hull2d.h"
#include "core/kd_tree.h"
#include "core/log.h"
#include "core/rectangle.h"
#include "core/stats.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

namespace hsr {

std::size_t RecoveryResult::num_singular() const {
  std::size_t n = 0;
  for (const auto& plane : singular)
    for (bool s : plane) n += s;
  return n;
}

namespace {

/// Centroid of a segment: the mean of its supporting points, or its midpoint when it has none.
Vec3 segment_centroid(const PointCloud& cloud, const BoundarySegment& s) {
  return s.support.empty() ? Vec3(0.5 * (s.a + s.b)) : cloud.mean_of(s.support);
}

double mean_abs_distance(const PointCloud& cloud, const std::vector<int>& idx, const Plane& p) {
  if (idx.empty()) return 0.0;
  double sum = 0;
  for (int i : idx) sum += std::abs(p.signed_distance(cloud.points[static_cast<std::size_t>(i)]));
  return sum / static_cast<double>(idx.size());
}

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

/// The recovered plane of `segments` (any order) on `plane`, supported by their points: the invariants of
/// RecoveredPlane (segments sorted, support the sorted union).
RecoveredPlane recovered_plane(const SceneStructure& structure, const Plane& plane, std::vector<SegmentRef> segments) {
  RecoveredPlane rp;
  rp.plane = plane;
  std::sort(segments.begin(), segments.end(), [](const SegmentRef& a, const SegmentRef& b) {
    return a.plane != b.plane ? a.plane < b.plane : a.segment < b.segment;
  });
  for (const SegmentRef& s : segments) {
    const auto& sup = structure.planes[static_cast<std::size_t>(s.plane)].segments[static_cast<std::size_t>(s.segment)].support;
    rp.support.insert(rp.support.end(), sup.begin(), sup.end());
  }
  std::sort(rp.support.begin(), rp.support.end());
  rp.support.erase(std::unique(rp.support.begin(), rp.support.end()), rp.support.end());
  rp.segments = std::move(segments);
  return rp;
}

/// A room (RecoveryParams::split_regions): the region's segments in pieces, two segments in one piece when
/// their supporting points (a segment without any: its ends) come within `link` of each other, directly or
/// through other segments of the region. Pieces in the order of their first segment in `region`.
std::vector<std::vector<SegmentRef>> pieces_of_region(const PointCloud& cloud, const SceneStructure& structure,
                                                      const std::vector<SegmentRef>& region, double link) {
  const std::size_t n = region.size();
  std::vector<std::vector<Vec3>> points(n);
  for (std::size_t a = 0; a < n; ++a) {
    const BoundarySegment& s =
        structure.planes[static_cast<std::size_t>(region[a].plane)].segments[static_cast<std::size_t>(region[a].segment)];
    for (int i : s.support) points[a].push_back(cloud.points[static_cast<std::size_t>(i)]);
    if (points[a].empty()) points[a] = {s.a, s.b};
  }
  const auto near = [&](std::size_t a, std::size_t b) {
    for (const Vec3& p : points[a])
      for (const Vec3& q : points[b])
        if ((p - q).squaredNorm() < link * link) return true;
    return false;
  };
  std::vector<std::size_t> piece(n, n);  // piece index of each segment (n: none yet)
  std::vector<std::vector<SegmentRef>> out;
  for (std::size_t seed = 0; seed < n; ++seed) {
    if (piece[seed] < n) continue;
    piece[seed] = out.size();
    std::vector<std::size_t> stack{seed}, members{seed};
    while (!stack.empty()) {
      const std::size_t a = stack.back();
      stack.pop_back();
      for (std::size_t b = 0; b < n; ++b)
        if (piece[b] == n && near(a, b)) {
          piece[b] = out.size();
          stack.push_back(b);
          members.push_back(b);
        }
    }
    std::sort(members.begin(), members.end());
    out.emplace_back();
    for (std::size_t k : members) out.back().push_back(region[k]);
  }
  return out;
}

/// A room (RecoveryParams::level_caps): the tops no scanner saw, as level planes (see recovery.h).
std::vector<RecoveredPlane> level_caps(const PointCloud& cloud, const SceneStructure& structure,
                                       const RecoveryParams& params) {
  const std::size_t m = structure.planes.size();
  const double r = structure.spacing > 0 ? structure.spacing : 1.0;
  const double r_d = params.distance * r;
  const double a = params.angle_deg * M_PI / 180.0;
  std::vector<double> top(m, -std::numeric_limits<double>::infinity());
  std::vector<char> open(m, 0);  // upright, its top meeting no level plane
  for (std::size_t i = 0; i < m; ++i) {
    const DetectedPlane& upright = structure.planes[i];
    if (!(std::abs(upright.plane.normal.z()) < std::sin(a)) || upright.inliers.empty()) continue;
    for (int p : upright.inliers) top[i] = std::max(top[i], cloud.points[static_cast<std::size_t>(p)].z());
    open[i] = 1;
    if (i >= structure.adjacency.size()) continue;
    for (int k : structure.adjacency[i]) {
      const Plane& level = structure.planes[static_cast<std::size_t>(k)].plane;
      if (!(std::abs(level.normal.z()) > std::cos(a))) continue;
      const Vec3& c = upright.centroid;  // the level plane's height above it
      const double z = -(level.normal.x() * c.x() + level.normal.y() * c.y() + level.offset) / level.normal.z();
      if (std::abs(z - top[i]) < r_d) open[i] = 0;
    }
  }
  // Adjacent open planes with tops within r_d share a cap: groups in order of their lowest plane.
  std::vector<int> group(m, -1);
  std::vector<std::vector<int>> groups;
  for (std::size_t seed = 0; seed < m; ++seed) {
    if (!open[seed] || group[seed] >= 0) continue;
    group[seed] = static_cast<int>(groups.size());
    std::vector<int> stack{static_cast<int>(seed)}, members{static_cast<int>(seed)};
    while (!stack.empty()) {
      const std::size_t i = static_cast<std::size_t>(stack.back());
      stack.pop_back();
      if (i >= structure.adjacency.size()) continue;
      for (int k : structure.adjacency[i]) {
        const std::size_t ku = static_cast<std::size_t>(k);
        if (!open[ku] || group[ku] >= 0 || !(std::abs(top[ku] - top[i]) < r_d)) continue;
        group[ku] = group[seed];
        stack.push_back(k);
        members.push_back(k);
      }
    }
    std::sort(members.begin(), members.end());
    groups.push_back(std::move(members));
  }
  std::vector<RecoveredPlane> caps;
  for (const std::vector<int>& members : groups) {
    RecoveredPlane cap;
    double h = -std::numeric_limits<double>::infinity();
    for (int i : members) h = std::max(h, top[static_cast<std::size_t>(i)]);
    cap.plane.normal = Vec3(0, 0, 1);  // outward: up, the piece below
    cap.plane.offset = -h;
    for (int i : members)
      for (int p : structure.planes[static_cast<std::size_t>(i)].inliers)
        if (cloud.points[static_cast<std::size_t>(p)].z() > top[static_cast<std::size_t>(i)] - r) cap.support.push_back(p);
    std::sort(cap.support.begin(), cap.support.end());
    if (cap.support.size() < 3) continue;  // no hull
    cap.caps = members;
    caps.push_back(std::move(cap));
  }
  return caps;
}

/// A room's floor: its lowest point (what stands on the floor reaches down to it).
double room_floor(const PointCloud& cloud) {
  double floor_z = std::numeric_limits<double>::infinity();
  for (const Vec3& q : cloud.points) floor_z = std::min(floor_z, q.z());
  return floor_z;
}

/// A room (RecoveryParams::level_sides): the sides no scanner saw under a raised level top, as upright planes
/// down to the floor (see recovery.h).
std::vector<RecoveredPlane> level_sides(const PointCloud& cloud, const SceneStructure& structure,
                                        const RecoveryResult& res, const RecoveryParams& params) {
  const double r = structure.spacing > 0 ? structure.spacing : 1.0;
  const double r_d = params.distance * r;
  const double cos_a = std::cos(params.angle_deg * M_PI / 180.0);
  const double floor_z = room_floor(cloud);
  std::vector<RecoveredPlane> sides;
  for (std::size_t i = 0; i < structure.planes.size(); ++i) {
    const DetectedPlane& top = structure.planes[i];
    if (!(top.plane.normal.z() > cos_a) || !(top.centroid.z() - floor_z > r_d)) continue;  // a raised top, facing up
    for (std::size_t j = 0; j < top.segments.size(); ++j) {
      const BoundarySegment& seg = top.segments[j];
      if (!res.singular[i][j] || !(seg.length() >= params.min_wall_length * r)) continue;
      Vec3 out(seg.normal.x(), seg.normal.y(), 0.0);
      const Vec3 along = Vec3(seg.b.x() - seg.a.x(), seg.b.y() - seg.a.y(), 0.0).normalized();
      out -= out.dot(along) * along;
      if (!(out.norm() > 0.5)) continue;  // the segment's outward normal is not across its line in plan
      Plane plane;
      plane.normal = out.normalized();
      plane.offset = -plane.normal.dot(segment_centroid(cloud, seg));
      RecoveredPlane side = recovered_plane(structure, plane, {SegmentRef{static_cast<int>(i), static_cast<int>(j)}});
      for (const Vec3& e : {seg.a, seg.b}) {  // the side spans the edge, from the top down to the floor
        const Vec3 on = e - plane.normal * plane.signed_distance(e);
        side.reach.push_back(on);
        side.reach.emplace_back(on.x(), on.y(), floor_z);
      }
      sides.push_back(std::move(side));
    }
  }
  return sides;
}

/// Whether `plane` covers the surface through `centre` facing along `normal`: within r_a of its orientation
/// (either side) and passing within a spacing r of `centre` (a surface and a plane nearer than the points'
/// spacing are one surface).
bool covers(const Plane& plane, const Vec3& normal, const Vec3& centre, double cos_a, double r) {
  return std::abs(plane.normal.dot(normal)) > cos_a && std::abs(plane.signed_distance(centre)) < r;
}

/// A plane's extent: its points' convex hull in its frame (see recovery.h, one_plane_per_surface), and their
/// mean on it.
struct PlaneExtent {
  Plane plane;
  Vec3 u = Vec3::UnitX(), v = Vec3::UnitY();
  std::vector<Vec2> hull;
  Vec3 centre = Vec3::Zero();
};

PlaneExtent plane_extent(const Plane& plane, const std::vector<Vec3>& points) {
  PlaneExtent e;
  e.plane = plane;
  plane_frame(plane.normal, e.u, e.v);
  std::vector<Vec2> uv;
  uv.reserve(points.size());
  for (const Vec3& p : points) {
    uv.emplace_back(p.dot(e.u), p.dot(e.v));
    e.centre += p;
  }
  if (!points.empty()) e.centre /= static_cast<double>(points.size());
  e.centre -= plane.normal * plane.signed_distance(e.centre);
  e.hull = convex_hull_2d(uv);
  if (e.hull.empty() && !uv.empty()) e.hull = {uv.front()};  // all points at one place
  return e;
}

/// The extent of a recovered plane: its support and its reach.
PlaneExtent recovered_extent(const PointCloud& cloud, const RecoveredPlane& rp) {
  std::vector<Vec3> points = rp.reach;
  for (int p : rp.support) points.push_back(cloud.points[static_cast<std::size_t>(p)]);
  return plane_extent(rp.plane, points);
}

/// The extents of the detected planes (their inliers).
std::vector<PlaneExtent> detected_extents(const PointCloud& cloud, const SceneStructure& structure) {
  std::vector<PlaneExtent> out;
  out.reserve(structure.planes.size());
  for (const DetectedPlane& dp : structure.planes) {
    std::vector<Vec3> points;
    points.reserve(dp.inliers.size());
    for (int p : dp.inliers) points.push_back(cloud.points[static_cast<std::size_t>(p)]);
    out.push_back(plane_extent(dp.plane, points));
  }
  return out;
}

/// Whether the plane of `e` already stands for the surface through `centre` facing along `normal`: it covers
/// it, and `centre` lies within r of its extent.
bool stands_for(const PlaneExtent& e, const Vec3& normal, const Vec3& centre, double cos_a, double r) {
  return covers(e.plane, normal, centre, cos_a, r) && within_convex(e.hull, Vec2(centre.dot(e.u), centre.dot(e.v)), r);
}

/// The order in which recovered planes claim their surface (see recovery.h, one_plane_per_surface), by their
/// evidence: level caps (the top rows of several planes), then planes grown from segments (two or more, of two
/// planes or more), then upright sides (one segment; anything else with a reach).
int claim_rank(const RecoveredPlane& rp) {
  if (!rp.caps.empty() && rp.segments.empty()) return 0;
  if (rp.reach.empty()) return 1;
  return 2;
}

/// A room (RecoveryParams::one_plane_per_surface): the recovered planes whose surface no plane already stands
/// for (see recovery.h), in their order; `dropped` counts the others.
std::vector<RecoveredPlane> one_plane_per_surface(const PointCloud& cloud, const std::vector<PlaneExtent>& detected,
                                                  std::vector<RecoveredPlane> recovered, double cos_a, double r,
                                                  std::size_t* dropped) {
  std::vector<std::size_t> order(recovered.size());
  for (std::size_t q = 0; q < order.size(); ++q) order[q] = q;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return claim_rank(recovered[a]) < claim_rank(recovered[b]); });
  std::vector<PlaneExtent> claimed;
  std::vector<char> keep(recovered.size(), 0);
  for (std::size_t q : order) {
    PlaneExtent e = recovered_extent(cloud, recovered[q]);
    const auto stands = [&](const PlaneExtent& o) { return stands_for(o, e.plane.normal, e.centre, cos_a, r); };
    if (std::any_of(detected.begin(), detected.end(), stands) || std::any_of(claimed.begin(), claimed.end(), stands))
      continue;
    keep[q] = 1;
    claimed.push_back(std::move(e));
  }
  std::vector<RecoveredPlane> out;
  for (std::size_t q = 0; q < recovered.size(); ++q)
    if (keep[q]) out.push_back(std::move(recovered[q]));
  *dropped = recovered.size() - out.size();
  return out;
}

/// The box of a piece (see recovery.h): its faces as recovered planes, each with its corners as reach and the
/// piece's points on no plane nearest to it as support; its sides along `facing` (radians in plan; NaN: the
/// points' smallest-area rectangle); empty when the box is thinner than `r` on some side.
std::vector<RecoveredPlane> box_of_piece(const PointCloud& cloud, const std::vector<int>& piece,
                                         const std::vector<int>& point_plane, double facing, double floor_z, double r,
                                         double r_d, int number) {
  std::vector<Vec2> xy;
  xy.reserve(piece.size());
  double top = -std::numeric_limits<double>::infinity(), low = std::numeric_limits<double>::infinity();
  for (int p : piece) {
    const Vec3& q = cloud.points[static_cast<std::size_t>(p)];
    xy.push_back(q.head<2>());
    top = std::max(top, q.z());
    low = std::min(low, q.z());
  }
  const double angle = std::isfinite(facing) ? facing : min_area_rectangle(xy).angle;
  const Vec3 u(std::cos(angle), std::sin(angle), 0.0), v(-std::sin(angle), std::cos(angle), 0.0);
  double u0 = std::numeric_limits<double>::infinity(), u1 = -u0, v0 = u0, v1 = -u0;
  for (const Vec2& q : xy) {
    const double a = q.x() * u.x() + q.y() * u.y(), b = q.x() * v.x() + q.y() * v.y();
    u0 = std::min(u0, a), u1 = std::max(u1, a), v0 = std::min(v0, b), v1 = std::max(v1, b);
  }
  const double bottom = low - floor_z > r_d ? low : floor_z;  // standing on the floor, or raised
  if (!(u1 - u0 >= r && v1 - v0 >= r && top - bottom >= r)) return {};
  auto at = [&](double a, double b, double z) { return Vec3(a * u.x() + b * v.x(), a * u.y() + b * v.y(), z); };
  struct Face { Vec3 normal; std::array<Vec3, 4> corners; };
  std::vector<Face> faces = {
      {Vec3(0, 0, 1), {at(u0, v0, top), at(u1, v0, top), at(u1, v1, top), at(u0, v1, top)}},
      {-u, {at(u0, v0, bottom), at(u0, v1, bottom), at(u0, v1, top), at(u0, v0, top)}},
      {u, {at(u1, v0, bottom), at(u1, v1, bottom), at(u1, v1, top), at(u1, v0, top)}},
      {-v, {at(u0, v0, bottom), at(u1, v0, bottom), at(u1, v0, top), at(u0, v0, top)}},
      {v, {at(u0, v1, bottom), at(u1, v1, bottom), at(u1, v1, top), at(u0, v1, top)}}};
  if (bottom > floor_z) faces.push_back({Vec3(0, 0, -1), {at(u0, v0, bottom), at(u1, v0, bottom), at(u1, v1, bottom), at(u0, v1, bottom)}});
  std::vector<RecoveredPlane> out(faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f) {
    out[f].plane.normal = faces[f].normal;
    out[f].plane.offset = -faces[f].normal.dot(faces[f].corners[0]);
    out[f].reach.assign(faces[f].corners.begin(), faces[f].corners.end());
    out[f].piece = number;
  }
  for (int p : piece) {  // each point on no plane supports the face it is nearest to (the first on ties)
    if (static_cast<std::size_t>(p) < point_plane.size() && point_plane[static_cast<std::size_t>(p)] >= 0) continue;
    std::size_t best = 0;
    for (std::size_t f = 1; f < out.size(); ++f)
      if (std::abs(out[f].plane.signed_distance(cloud.points[static_cast<std::size_t>(p)])) <
          std::abs(out[best].plane.signed_distance(cloud.points[static_cast<std::size_t>(p)])))
        best = f;
    out[best].support.push_back(p);  // piece is sorted, so each support is
  }
  return out;
}

/// The planes of a piece, sorted, when each lies in it (fewer than `stray` of its inliers elsewhere: fewer points
/// than a neighbourhood are no surface there); nullopt when one reaches beyond it (the piece is part of something
/// larger).
std::optional<std::vector<int>> planes_of_piece(const SceneStructure& structure, const std::vector<int>& piece,
                                                std::size_t stray) {
  std::map<int, std::size_t> count;
  for (int p : piece)
    if (static_cast<std::size_t>(p) < structure.point_plane.size() && structure.point_plane[static_cast<std::size_t>(p)] >= 0)
      ++count[structure.point_plane[static_cast<std::size_t>(p)]];
  std::vector<int> planes;
  for (const auto& [k, c] : count) {
    if (structure.planes[static_cast<std::size_t>(k)].inliers.size() - c >= stray) return std::nullopt;
    planes.push_back(k);
  }
  return planes;
}

/// The direction in plan (radians) of the piece's largest upright plane: its box's sides follow it. NaN when it
/// has none (the box then follows its points' smallest-area rectangle).
double facing_of_piece(const SceneStructure& structure, const std::vector<int>& planes, double angle_deg) {
  double facing = std::numeric_limits<double>::quiet_NaN();
  std::size_t largest = 0;
  for (int k : planes) {
    const DetectedPlane& dp = structure.planes[static_cast<std::size_t>(k)];
    if (std::abs(dp.plane.normal.z()) < std::sin(angle_deg * M_PI / 180.0) && dp.inliers.size() > largest)
      largest = dp.inliers.size(), facing = std::atan2(dp.plane.normal.y(), dp.plane.normal.x());
  }
  return facing;
}

/// Per detected plane, the recovered planes it supports (a segment of it, or it among a cap's), ascending.
std::vector<std::vector<int>> recovered_from(std::size_t planes, const std::vector<RecoveredPlane>& recovered) {
  std::vector<std::vector<int>> from(planes);
  for (std::size_t q = 0; q < recovered.size(); ++q) {
    for (const SegmentRef& g : recovered[q].segments) from[static_cast<std::size_t>(g.plane)].push_back(static_cast<int>(q));
    for (int k : recovered[q].caps) from[static_cast<std::size_t>(k)].push_back(static_cast<int>(q));
  }
  for (std::vector<int>& qs : from) qs.erase(std::unique(qs.begin(), qs.end()), qs.end());  // q ascending already
  return from;
}

/// A room (RecoveryParams::piece_boxes): each piece's box completes the faces no plane of it covers (see
/// recovery.h). `recovered`: the planes recovered so far (one recovered from the piece's planes covers a face);
/// `corner` (one flag per recovered plane) marks those grown from segments of a boxed piece's planes alone that
/// face along none of its box's faces.
std::vector<RecoveredPlane> piece_boxes(const PointCloud& cloud, const SceneStructure& structure,
                                         const std::vector<bool>& enclosure, const RecoveryParams& params,
                                         const std::vector<RecoveredPlane>& recovered, std::size_t* pieces,
                                         std::vector<char>& corner) {
  const double r = structure.spacing > 0 ? structure.spacing : 1.0;
  const double link = structure.alpha_radius > 0 ? structure.alpha_radius : 3.0 * r;
  const double cos_a = std::cos(params.angle_deg * M_PI / 180.0);
  const double floor_z = room_floor(cloud);
  std::vector<int> off;  // the points on no enclosing plane
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const int k = i < structure.point_plane.size() ? structure.point_plane[i] : -1;
    if (k < 0 || static_cast<std::size_t>(k) >= enclosure.size() || !enclosure[static_cast<std::size_t>(k)])
      off.push_back(static_cast<int>(i));
  }
  std::vector<int> enclosing;
  for (std::size_t k = 0; k < enclosure.size() && k < structure.planes.size(); ++k)
    if (enclosure[k]) enclosing.push_back(static_cast<int>(k));
  const std::vector<std::vector<int>> from = recovered_from(structure.planes.size(), recovered);
  std::vector<RecoveredPlane> faces;
  *pieces = 0;
  for (const std::vector<int>& piece : linked_groups(cloud.points, off, link)) {
    if (static_cast<int>(piece.size()) < params.min_piece_points) continue;
    const std::optional<std::vector<int>> planes =
        planes_of_piece(structure, piece, static_cast<std::size_t>(params.min_piece_points));
    if (!planes) continue;
    std::vector<RecoveredPlane> box =
        box_of_piece(cloud, piece, structure.point_plane, facing_of_piece(structure, *planes, params.angle_deg),
                     floor_z, r, params.distance * r, static_cast<int>(*pieces));
    std::vector<int> own_recovered;  // recovered from the piece's planes (a cap, a side, a grown plane)
    for (int k : *planes) own_recovered.insert(own_recovered.end(), from[static_cast<std::size_t>(k)].begin(), from[static_cast<std::size_t>(k)].end());
    std::sort(own_recovered.begin(), own_recovered.end());
    own_recovered.erase(std::unique(own_recovered.begin(), own_recovered.end()), own_recovered.end());
    std::vector<Vec3> axes;  // the box's face normals (its faces move into `faces` below)
    for (const RecoveredPlane& f : box) axes.push_back(f.plane.normal);
    std::size_t kept = 0;
    for (RecoveredPlane& face : box) {
      Vec3 centre = Vec3::Zero();
      for (const Vec3& q : face.reach) centre += q;
      centre /= static_cast<double>(face.reach.size());
      const auto by = [&](const Plane& plane) { return covers(plane, face.plane.normal, centre, cos_a, r); };
      const auto detected = [&](int k) { return by(structure.planes[static_cast<std::size_t>(k)].plane); };
      if (std::any_of(planes->begin(), planes->end(), detected) || std::any_of(enclosing.begin(), enclosing.end(), detected) ||
          std::any_of(own_recovered.begin(), own_recovered.end(), [&](int q) { return by(recovered[static_cast<std::size_t>(q)].plane); }))
        continue;
      face.caps = *planes;  // adjacent to the piece's planes too
      faces.push_back(std::move(face));
      ++kept;
    }
    if (kept) ++*pieces;
    const auto own = [&](const SegmentRef& g) { return std::binary_search(planes->begin(), planes->end(), g.plane); };
    for (int q : own_recovered) {
      const RecoveredPlane& o = recovered[static_cast<std::size_t>(q)];
      const bool grown = o.caps.empty() && o.reach.empty() && !o.segments.empty();  // region growing's
      corner[static_cast<std::size_t>(q)] = corner[static_cast<std::size_t>(q)] ||
          (!axes.empty() && grown && std::all_of(o.segments.begin(), o.segments.end(), own) &&
           std::none_of(axes.begin(), axes.end(), [&](const Vec3& n) { return std::abs(n.dot(o.plane.normal)) > cos_a; }));
    }
  }
  return faces;
}

}  // namespace

namespace {
/// Building mode: vertical walls grown over singular roof segments (see recovery.h).
std::vector<RecoveredPlane> recover_walls(const PointCloud& cloud, const SceneStructure& structure,
                                          const RecoveryParams& params, const RecoveryResult& res);
}  // namespace

RecoveryResult run_recovery(const PointCloud& cloud, const SceneStructure& structure,
                            const RecoveryParams& params, const std::vector<bool>& enclosure) {
  if (!(params.angle_deg > 0 && params.angle_deg < 90) || !(params.distance > 0) || params.min_segments < 1 ||
      !(params.snap_deg >= 0 && params.snap_deg < 45) || !(params.min_wall_length >= 0) ||
      !(params.roof_min_tilt_deg >= 0 && params.roof_min_tilt_deg < 90) || !std::isfinite(params.main_direction) ||
      !(params.wall_join_distance > 0) || params.min_piece_points < 1)
    throw Error(Status::BadInput, "recovery",
                "parameters: 0 < angle_deg < 90, distance > 0, min_segments >= 1, 0 <= snap_deg < 45, "
                "min_wall_length >= 0, 0 <= roof_min_tilt_deg < 90, wall_join_distance > 0, min_piece_points >= 1");
  const std::size_t m = structure.planes.size();
  const double r = structure.spacing > 0 ? structure.spacing : 1.0;
  const double r_d = params.distance * r;
  const double cos_a = std::cos(params.angle_deg * M_PI / 180.0);

  RecoveryResult res;
  res.singular.resize(m);
  res.partner.resize(m);

  // Lines of each plane (both first-order and second-order pairs).
  std::vector<std::vector<std::size_t>> lines_of(m);
  for (std::size_t l = 0; l < structure.lines.size(); ++l) {
    const IntersectionLine& L = structure.lines[l];
    if (L.plane_a >= 0 && static_cast<std::size_t>(L.plane_a) < m) lines_of[static_cast<std::size_t>(L.plane_a)].push_back(l);
    if (L.plane_b >= 0 && static_cast<std::size_t>(L.plane_b) < m) lines_of[static_cast<std::size_t>(L.plane_b)].push_back(l);
  }

  // --- singular segments
  for (std::size_t i = 0; i < m; ++i) {
    const auto& segs = structure.planes[i].segments;
    res.singular[i].assign(segs.size(), true);
    res.partner[i].assign(segs.size(), -1);
    for (std::size_t j = 0; j < segs.size(); ++j) {
      const BoundarySegment& s = segs[j];
      if (!(s.length() > 0)) continue;
      const Vec3 dir = (s.b - s.a).normalized();
      const Vec3 c = segment_centroid(cloud, s);
      double best = r_d;
      for (std::size_t l : lines_of[i]) {
        const IntersectionLine& L = structure.lines[l];
        if (std::abs(L.direction.dot(dir)) < cos_a) continue;
        const Vec3 q = c - L.point;
        const double dist = (q - q.dot(L.direction) * L.direction).norm();
        const int k = L.plane_a == static_cast<int>(i) ? L.plane_b : L.plane_a;
        // Building mode: the partner must reach the segment (an aerial roof's edge lies near the line of
        // many planes that are nowhere near it: flat roofs and slopes have parallel horizontal lines).
        if (params.vertical && !(structure.planes[static_cast<std::size_t>(k)].boundary_distance(c) < r_d))
          continue;
        if (dist < best) {  // strict: the first (lowest plane pair) wins ties
          best = dist;
          res.singular[i][j] = false;
          res.partner[i][j] = k;
        }
      }
      if (params.vertical && res.singular[i][j])
        res.partner[i][j] = explaining_wall(structure, s, c, params.wall_join_distance * r, r_d, cos_a);
      if (res.partner[i][j] >= 0) res.singular[i][j] = false;
    }
  }

  if (params.vertical) {
    res.recovered = recover_walls(cloud, structure, params, res);
    log::info("[recovery] " + std::to_string(res.num_singular()) + " singular segments, " +
              std::to_string(res.recovered.size()) + " walls recovered (vertical prior)");
    return res;
  }

  // --- region growing over singular segments, longest first
  struct Item { SegmentRef ref; double length; };
  std::vector<Item> order;
  for (std::size_t i = 0; i < m; ++i)
    for (std::size_t j = 0; j < res.singular[i].size(); ++j)
      if (res.singular[i][j])
        order.push_back({{static_cast<int>(i), static_cast<int>(j)}, structure.planes[i].segments[j].length()});
  std::stable_sort(order.begin(), order.end(), [](const Item& a, const Item& b) { return a.length > b.length; });

  // Planes within two hops of each plane, itself included, sorted.
  std::vector<std::vector<int>> hood(m);
  for (std::size_t i = 0; i < m; ++i) {
    std::vector<int>& h = hood[i];
    h.push_back(static_cast<int>(i));
    if (i < structure.adjacency.size()) h.insert(h.end(), structure.adjacency[i].begin(), structure.adjacency[i].end());
    if (i < structure.second_order.size())
      h.insert(h.end(), structure.second_order[i].begin(), structure.second_order[i].end());
    std::sort(h.begin(), h.end());
    h.erase(std::unique(h.begin(), h.end()), h.end());
  }

  std::vector<std::vector<bool>> visited(m);
  for (std::size_t i = 0; i < m; ++i) visited[i].assign(res.singular[i].size(), false);
  auto seg = [&](const SegmentRef& s) -> const BoundarySegment& {
    return structure.planes[static_cast<std::size_t>(s.plane)].segments[static_cast<std::size_t>(s.segment)];
  };

  for (const Item& seed : order) {
    const SegmentRef sr = seed.ref;
    if (visited[static_cast<std::size_t>(sr.plane)][static_cast<std::size_t>(sr.segment)]) continue;
    visited[static_cast<std::size_t>(sr.plane)][static_cast<std::size_t>(sr.segment)] = true;
    const BoundarySegment& s0 = seg(sr);
    if (!(s0.normal.norm() > 0.5)) continue;
    const Vec3 seed_normal = s0.normal.normalized();
    Plane plane;
    plane.normal = seed_normal;
    plane.offset = -seed_normal.dot(segment_centroid(cloud, s0));
    std::vector<SegmentRef> region{sr};
    std::vector<int> support = s0.support;
    std::deque<SegmentRef> queue{sr};
    while (!queue.empty()) {
      const SegmentRef cur = queue.front();
      queue.pop_front();
      for (int q : hood[static_cast<std::size_t>(cur.plane)]) {
        const auto& segs = structure.planes[static_cast<std::size_t>(q)].segments;
        for (std::size_t t = 0; t < segs.size(); ++t) {
          if (!res.singular[static_cast<std::size_t>(q)][t] || visited[static_cast<std::size_t>(q)][t]) continue;
          const BoundarySegment& cand = segs[t];
          if (!(cand.normal.norm() > 0.5)) continue;
          if (std::abs(cand.normal.normalized().dot(plane.normal)) < cos_a) continue;
          const double d = cand.support.empty()
                               ? 0.5 * (std::abs(plane.signed_distance(cand.a)) + std::abs(plane.signed_distance(cand.b)))
                               : mean_abs_distance(cloud, cand.support, plane);
          if (!(d < r_d)) continue;
          const SegmentRef cr{q, static_cast<int>(t)};
          visited[static_cast<std::size_t>(q)][t] = true;
          region.push_back(cr);
          queue.push_back(cr);
          support.insert(support.end(), cand.support.begin(), cand.support.end());
          // Refit: least squares over the supporting points, kept only if well conditioned and still
          // within r_a of the seed (a line's points alone do not fix a plane).
          std::sort(support.begin(), support.end());
          support.erase(std::unique(support.begin(), support.end()), support.end());
          const Vec3 c = cloud.mean_of(support);
          Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
          for (int p : support) {
            const Vec3 e = cloud.points[static_cast<std::size_t>(p)] - c;
            cov += e * e.transpose();
          }
          Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
          const Vec3 ev = eig.eigenvalues();
          Vec3 n = eig.eigenvectors().col(0);
          if (ev(1) > 16.0 * std::max(ev(0), 0.0) && std::abs(n.dot(seed_normal)) >= cos_a) {
            if (n.dot(seed_normal) < 0) n = -n;
            plane.normal = n.normalized();
          }
          plane.offset = -plane.normal.dot(c);
        }
      }
    }
    std::vector<int> source_planes;
    for (const SegmentRef& s : region) source_planes.push_back(s.plane);
    std::sort(source_planes.begin(), source_planes.end());
    source_planes.erase(std::unique(source_planes.begin(), source_planes.end()), source_planes.end());
    if (static_cast<int>(region.size()) < params.min_segments || source_planes.size() < 2) continue;
    // Orientation: along the sum of the segments' normals (their outward direction), for determinism.
    Vec3 nsum = Vec3::Zero();
    for (const SegmentRef& s : region) nsum += seg(s).normal;
    if (nsum.dot(plane.normal) < 0) { plane.normal = -plane.normal; plane.offset = -plane.offset; }
    const std::vector<std::vector<SegmentRef>> pieces =
        params.split_regions ? pieces_of_region(cloud, structure, region, r_d) : std::vector<std::vector<SegmentRef>>{region};
    for (const std::vector<SegmentRef>& piece : pieces) {
      RecoveredPlane rp = recovered_plane(structure, plane, piece);
      if (pieces.size() > 1 && !rp.support.empty()) rp.plane.offset = -plane.normal.dot(cloud.mean_of(rp.support));
      res.recovered.push_back(std::move(rp));
    }
  }
  std::size_t caps = 0;
  if (params.level_caps)
    for (RecoveredPlane& cap : level_caps(cloud, structure, params)) {
      res.recovered.push_back(std::move(cap));
      ++caps;
    }
  std::size_t sides = 0;
  if (params.level_sides)
    for (RecoveredPlane& side : level_sides(cloud, structure, res, params)) {
      res.recovered.push_back(std::move(side));
      ++sides;
    }

  if (params.one_plane_per_surface)
    res.recovered = one_plane_per_surface(cloud, detected_extents(cloud, structure), std::move(res.recovered), cos_a, r,
                                          &res.covered);
  std::size_t pieces = 0, piece_faces = 0, corners = 0;
  if (params.piece_boxes) {
    // A piece's box stands for the planes its own segments would recover; one facing along none of its faces
    // is a corner's artefact (a boundary segment cutting across the corner of an alpha shape): left out.
    std::vector<char> corner(res.recovered.size(), 0);
    std::vector<RecoveredPlane> boxes = piece_boxes(cloud, structure, enclosure, params, res.recovered, &pieces, corner);
    std::vector<RecoveredPlane> kept;
    for (std::size_t q = 0; q < res.recovered.size(); ++q)
      if (corner[q]) ++corners;
      else kept.push_back(std::move(res.recovered[q]));
    res.recovered = std::move(kept);
    for (RecoveredPlane& face : boxes) {
      res.recovered.push_back(std::move(face));
      ++piece_faces;
    }
  }

  std::ostringstream msg;
  msg << "[recovery] " << res.num_singular() << " singular segments, " << res.recovered.size() << " recovered planes";
  if (caps || sides || pieces)
    msg << " (" << caps << " of them level caps, " << sides << " upright sides under tops, " << piece_faces
        << " faces of " << pieces << " pieces' boxes, " << corners << " planes across a boxed piece's corners left out, "
        << res.covered << " on a surface a plane already stood for left out)";
  msg << " (r_a " << params.angle_deg << " deg, r_d " << r_d << ")";
  log::info(msg.str());
  return res;
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
/// wall. The roof's edge lies beyond its outermost points: the wall is moved out to where 90 % of its
/// supporting points are inside it — scaled by the balance of its segments' supporting points facing its way
/// against those facing the other way (a step edge between two roofs is fitted from both sides: no move).
void shift_to_the_edge(const PointCloud& cloud, const SceneStructure& structure, const std::vector<SegmentRef>& members,
                       const std::vector<int>& support, WallFit& w) {
  double same = 0, opposite = 0;
  for (const SegmentRef& m : members) {
    const BoundarySegment& seg = structure.planes[static_cast<std::size_t>(m.plane)].segments[static_cast<std::size_t>(m.segment)];
    (seg.normal.head<2>().dot(w.n) >= 0 ? same : opposite) += static_cast<double>(seg.support.size());
  }
  if (!(same + opposite > 0) || support.empty()) return;
  std::vector<double> d;
  d.reserve(support.size());
  for (int i : support) d.push_back(w.distance(cloud.points[static_cast<std::size_t>(i)].head<2>()));
  w.d -= std::max(0.0, quantile(std::move(d), 0.9)) * (same - opposite) / (same + opposite);
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
    shift_to_the_edge(cloud, structure, members, support, w);
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

}  // namespace

}  // namespace hsr
