// Stage 3 in a room (RecoveryParams::split_regions, level_caps, level_sides, one_plane_per_surface, piece_boxes;
// recovery.h's paragraphs on a room): a grown region split into pieces, the tops and sides no scanner saw, one
// plane per surface, and each piece of furniture's box and the posts under its top. DECISIONS #66, #67, #70, #72,
// #73, #74 and #139.
// Plain Eigen; CGAL only behind core/rectangle.h (a piece's box).
#include "recovery/recovery_internal.h"

#include "core/hull2d.h"
#include "core/kd_tree.h"
#include "core/rectangle.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <optional>

namespace hsr::recovery_internal {

namespace {

/// A room's floor: its lowest point (what stands on the floor reaches down to it).
double room_floor(const PointCloud& cloud) {
  double floor_z = std::numeric_limits<double>::infinity();
  for (const Vec3& q : cloud.points) floor_z = std::min(floor_z, q.z());
  return floor_z;
}

/// The room's floor where a scanner saw it: the points within a spacing r above its lowest point whose normals
/// are level (within r_a, either side: estimated normals can be flipped). A scanner that saw the floor there saw
/// free space over it: what stands on the floor hides the floor under it.
std::vector<Vec3> floor_seen(const PointCloud& cloud, double floor_z, double r, double cos_a) {
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (cloud.points[i].z() - floor_z < r && (!cloud.has_normals() || std::abs(cloud.normals[i].z()) > cos_a))
      out.push_back(cloud.points[i]);
  return out;
}

/// The convex hull in plan of a detected plane's inliers.
std::vector<Vec2> plan_hull(const PointCloud& cloud, const DetectedPlane& plane) {
  std::vector<Vec2> xy;
  xy.reserve(plane.inliers.size());
  for (int p : plane.inliers) xy.push_back(cloud.points[static_cast<std::size_t>(p)].head<2>());
  return convex_hull_2d(xy);
}

/// Whether the floor was seen under a raised top (RecoveryParams::free_under_tops): a point of `floor`
/// (floor_seen) lies under the top's hull in plan (plan_hull), more than a spacing r inside its edge. Then the
/// space between the top and the floor is free, a table on legs or a chair's seat, not a block down to the floor:
/// a block there would hide the very floor points the scan holds (the model must explain its points).
bool floor_under_top(const std::vector<Vec2>& hull, const std::vector<Vec3>& floor, double r) {
  if (hull.size() < 3) return false;
  Vec2 lo = hull.front(), hi = hull.front();
  for (const Vec2& q : hull) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  for (const Vec3& q : floor) {
    const Vec2 f = q.head<2>();
    if (f.x() > lo.x() && f.x() < hi.x() && f.y() > lo.y() && f.y() < hi.y() && within_convex(hull, f, -r)) return true;
  }
  return false;
}

/// Whether an upright detected plane among `planes` (its normal within RecoveryParams::angle_deg of level) holds at
/// least RecoveryParams::upright_min_inliers inliers lower than `z` (DECISIONS #241): a surface the points hold
/// stands under the top (a desk's panel leg or drawer pedestal, a cabinet in one piece with a table), so more than
/// thin legs stand there and what stands under the top still stands on the floor. Legs and posts thinner than a
/// spacing hold no plane, but a chair's back takes a point or two of the post under its seat into its plane (the
/// post's rear face lies within the inlier distance of the back's): those are no surface under the seat.
bool upright_below(const PointCloud& cloud, const SceneStructure& structure, const std::vector<int>& planes, double z,
                   const RecoveryParams& params) {
  const double sin_a = std::sin(params.angle_deg * M_PI / 180.0);
  const int min_inliers = params.upright_min_inliers;
  for (int k : planes) {
    const DetectedPlane& dp = structure.planes[static_cast<std::size_t>(k)];
    if (!(std::abs(dp.plane.normal.z()) < sin_a)) continue;
    int below = 0;
    for (int p : dp.inliers)
      if (cloud.points[static_cast<std::size_t>(p)].z() < z && ++below >= min_inliers) return true;
  }
  return false;
}

/// A top's rim (RecoveryParams::rim_underside): the points that may stand on the edges of raised tops, on no plane
/// and facing sideways (their normal within 60 degrees of level, as lone_top's sides), sorted by height (then by
/// index) so that a top looks at the band under it alone. Empty without normals or when `wanted` is false.
std::vector<std::pair<double, int>> rim_candidates(const PointCloud& cloud, const std::vector<int>& point_plane, bool wanted) {
  std::vector<std::pair<double, int>> out;
  if (!wanted || !cloud.has_normals()) return out;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (!(i < point_plane.size() && point_plane[i] >= 0) && std::abs(cloud.normals[i].z()) < 0.5)
      out.emplace_back(cloud.points[i].z(), static_cast<int>(i));
  std::sort(out.begin(), out.end());
  return out;
}

/// Where a raised top's rim ends (RecoveryParams::rim_underside; DECISIONS #229): of `rim` (rim_candidates) the
/// points less than `thickness` under the top's plane (at `top_z`), within a spacing r of the edge of its inliers'
/// hull in plan (`hull`) and facing out of it (their normal away from the hull's middle), when at least
/// `min_points` stand there: twice their mean depth under the top's plane, no deeper than `thickness`. Why: no
/// scanner sees a top's underside, but one that sees the top's edge from the side sees its thickness: the edge's
/// points lie evenly over its height, so their mean lies half way down (a table's 4 cm edge holds a few points at
/// 80 points/m²). The mean, not the lowest: a leg's point just under the top (office 1 room seed 1: 8.6 cm under
/// a 4 cm top) moves it by its share only. NaN: fewer (the top's thickness is not known; top_thickness).
double rim_underside(const PointCloud& cloud, const std::vector<std::pair<double, int>>& rim, const std::vector<Vec2>& hull,
                     double top_z, double thickness, double r, int min_points) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (rim.empty() || hull.size() < 3 || min_points <= 0) return nan;
  Vec2 middle = Vec2::Zero();
  for (const Vec2& q : hull) middle += q;
  middle /= static_cast<double>(hull.size());
  const auto first = std::lower_bound(rim.begin(), rim.end(), std::make_pair(top_z - thickness, -1));
  double depth = 0.0;  // the rim points' depths under the top's plane, summed (in height order: same bytes)
  int count = 0;
  for (auto it = first; it != rim.end() && it->first < top_z; ++it) {
    const auto i = static_cast<std::size_t>(it->second);
    const Vec2 q = cloud.points[i].head<2>();
    if (!within_convex(hull, q, r) || within_convex(hull, q, -r) || !(cloud.normals[i].head<2>().dot(q - middle) > 0)) continue;
    depth += top_z - it->first;
    ++count;
  }
  if (count < min_points) return nan;
  constexpr double kDepthPerMeanDepth = 2.0;  // points spread evenly over a height lie half way down on average
  return top_z - std::min(thickness, kDepthPerMeanDepth * depth / static_cast<double>(count));
}

/// The height a raised top's sides and its piece's box reach down to when there is free space under it: the
/// floor was seen under it (floor_under_top; not when `floor_needed` is false: a seat, free_under_seats) and no
/// upright plane reaches under it (upright_below; among `piece_planes` when given, else among the planes whose
/// centroid lies under its hull; not asked when `uprights_deny` is false: panels_as_posts, what stands under it
/// then stands on posts): its underside, where its rim ends (rim_underside, among `rim`, with
/// RecoveryParams::rim_min_points; `*from_rim` set when given) or RecoveryParams::top_thickness spacings r below
/// the top. NaN otherwise (what stands under it stands on the floor).
double underside_of_top(const PointCloud& cloud, const SceneStructure& structure, int top,
                        const std::vector<Vec3>& floor, double r, const RecoveryParams& params,
                        const std::vector<int>* piece_planes, const std::vector<std::pair<double, int>>& rim,
                        bool* from_rim = nullptr, bool floor_needed = true, bool uprights_deny = true) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double thickness = params.top_thickness * r;
  const DetectedPlane& t = structure.planes[static_cast<std::size_t>(top)];
  const std::vector<Vec2> hull = plan_hull(cloud, t);
  if (floor_needed && !floor_under_top(hull, floor, r)) return nan;
  const double unseen = t.centroid.z() - thickness;  // whether something upright stands under it: asked there
  std::vector<int> under;
  if (piece_planes) {
    under = *piece_planes;
  } else {
    for (std::size_t k = 0; k < structure.planes.size(); ++k)
      if (static_cast<int>(k) != top && within_convex(hull, structure.planes[k].centroid.head<2>(), r))
        under.push_back(static_cast<int>(k));
  }
  if (uprights_deny && upright_below(cloud, structure, under, unseen - r, params)) return nan;
  const double rim_end = rim_underside(cloud, rim, hull, t.centroid.z(), thickness, r, params.rim_min_points);
  if (from_rim) *from_rim = std::isfinite(rim_end);
  return std::isfinite(rim_end) ? rim_end : unseen;
}

/// Whether `plane` covers the surface through `centre` facing along `normal`: within r_a of its orientation
/// (either side) and passing within a spacing r of `centre` (a surface and a plane nearer than the points'
/// spacing are one surface).
bool covers(const Plane& plane, const Vec3& normal, const Vec3& centre, double cos_a, double r) {
  return std::abs(plane.normal.dot(normal)) > cos_a && std::abs(plane.signed_distance(centre)) < r;
}

/// A detected plane's normal turned to the side its inliers were seen from (their mean normal; the plane's own
/// normal when the cloud has none).
Vec3 seen_normal(const PointCloud& cloud, const DetectedPlane& dp) {
  if (!cloud.has_normals()) return dp.plane.normal;
  Vec3 mean = Vec3::Zero();
  for (int p : dp.inliers) mean += cloud.normals[static_cast<std::size_t>(p)];
  return mean.dot(dp.plane.normal) < 0 ? Vec3(-dp.plane.normal) : dp.plane.normal;
}

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

/// A raised top that stands alone on its piece (RecoveryParams::free_under_lone_tops): fewer than `min_points` of
/// the piece's points stand more than a spacing `r` over it (nothing stands on it: no seat_step), and fewer than
/// `min_points` of them facing sideways (their normal within 60 degrees of level) stand within `r` of the edge of
/// the piece's hull in plan, more than r/2 under the top and more than `r` over the floor (`floor_z`): no side of a
/// box under it was seen. Why: a chair whose back no scanner saw is a seat alone (its post stands in the middle,
/// its 6 cm pad's edge within r/2 of its top, its cross base within r of the floor), and a crate whose sides hold
/// too few points for a plane is a top over sides still seen as points (a crate of the hall of 1,000 planes: 6
/// points on its side, 0.12-0.42 m up under its top at 0.46 m, beside a top of 13 inliers).
bool lone_top(const PointCloud& cloud, const std::vector<int>& piece, const DetectedPlane& top, double floor_z, double r,
              int min_points) {
  const double z = top.centroid.z();
  std::vector<Vec2> hull;
  for (int p : piece) hull.push_back(cloud.points[static_cast<std::size_t>(p)].head<2>());
  hull = convex_hull_2d(hull);
  int over = 0, sides = 0;
  for (int p : piece) {
    const Vec3& q = cloud.points[static_cast<std::size_t>(p)];
    if (q.z() > z + r && ++over >= min_points) return false;
    if (q.z() < z - 0.5 * r && q.z() > floor_z + r && cloud.has_normals() &&
        std::abs(cloud.normals[static_cast<std::size_t>(p)].z()) < 0.5 && !within_convex(hull, q.head<2>(), -r) &&
        ++sides >= min_points)
      return false;
  }
  return true;
}

/// A point's coordinate along `axis` (a unit vector in plan: an axis of a piece's box frame). One expression for
/// the box (box_of_piece), its step (seat_step) and its posts (posts_under_top), so that the same point gives the
/// same coordinate to the last bit in each.
double along_axis(const Vec3& q, const Vec3& axis) { return q.x() * axis.x() + q.y() * axis.y(); }

/// The plane of a face of a piece's box frame (a box's or a post's side, top or bottom): outward normal `n`, lying
/// at `at` along it (n . x = at). Why: its offset is taken from that coordinate, not from one of its corners, so
/// faces at one coordinate are one plane to the last bit; from a corner, the rounding of its other coordinates set
/// them ulps apart, and the partition cut a cell thinner than the doubles' precision between them: a chair's base
/// reaching as far as its box, its post's side and the box's side 2e-16 to 2e-15 m apart, left office 4 rooms
/// seeds 1 and 3 invalid with free_under_seats (DECISIONS #179).
Plane frame_face_plane(const Vec3& n, double at) {
  Plane plane;
  plane.normal = n;
  plane.offset = -at;
  return plane;
}

/// A face of a piece's frame box (a post's side, a board slab's side or bottom): its outward normal, its coordinate
/// along that normal (frame_face_plane) and the corners it reaches over.
struct FrameFace {
  Vec3 normal;
  double at = 0.0;
  std::array<Vec3, 4> corners;
};

/// One recovered plane of piece `piece` per face, appended to `out`.
void push_frame_faces(const std::vector<FrameFace>& faces, int piece, std::vector<RecoveredPlane>& out) {
  for (const FrameFace& face : faces) {
    RecoveredPlane f;
    f.plane = frame_face_plane(face.normal, face.at);
    f.reach.assign(face.corners.begin(), face.corners.end());
    f.piece = piece;
    out.push_back(std::move(f));
  }
}

/// Where a piece's box steps in (seat_step): at height `z` the box narrows to [u0, u1] x [v0, v1] in its frame.
struct SeatStep {
  double z = 0.0, u0 = 0.0, u1 = 0.0, v0 = 0.0, v1 = 0.0;
  int top = -1;  ///< the detected plane of the top (the seat); -1: a level of points on no plane (seat_level)
};

/// The height of a seat no plane holds (RecoveryParams::seat_min_points; DECISIONS #194): the most populous level
/// of the piece's points on no plane facing up (within r_a of up, `cos_a`) more than `r_d` above `floor_z`, at
/// least `min_points` of them within r/2 of each other's height; their mean height. Why: a chair's seat is about
/// 0.47 x 0.47 m, 15-18 points at 80 points/m², often fewer than the room's smallest plane (min_piece_points), so
/// its piece's one plane was its back's: no top, no step, the box ran from the floor to the back's top over the
/// seat, and 28 of the offices' 46 missing chairs were such pieces (their seat and post lost). A flat run of points
/// facing up is a surface facing up whether or not a plane was fitted to it. NaN: none.
double seat_level(const PointCloud& cloud, const std::vector<int>& piece, const std::vector<int>& point_plane,
                  double floor_z, double r, double r_d, double cos_a, int min_points) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (min_points <= 0 || !cloud.has_normals()) return nan;
  std::vector<double> z;  // the raised points on no plane facing up
  for (int p : piece) {
    const auto i = static_cast<std::size_t>(p);
    if (i < point_plane.size() && point_plane[i] >= 0) continue;
    if (cloud.normals[i].z() > cos_a && cloud.points[i].z() - floor_z > r_d) z.push_back(cloud.points[i].z());
  }
  std::sort(z.begin(), z.end());
  std::size_t best = 0, best_lo = 0, lo = 0;  // the window [lo, hi] of heights within r/2 of z[lo] holding most
  for (std::size_t hi = 0; hi < z.size(); ++hi) {
    while (z[hi] - z[lo] > 0.5 * r) ++lo;
    if (hi + 1 - lo > best) best = hi + 1 - lo, best_lo = lo;
  }
  if (static_cast<int>(best) < min_points) return nan;
  double sum = 0.0;
  for (std::size_t k = best_lo; k < best_lo + best; ++k) sum += z[k];
  return sum / static_cast<double>(best);
}

/// A seat under a back (RecoveryParams::step_min_free, step_min_width, step_min_points; DECISIONS #141): the
/// piece's highest raised level plane facing up (a detected top, not the room's floor: `r_d` above `floor_z`, the
/// piece_top_height) over which at least `min_points` of its points stand more than a spacing r, when those points
/// span at least `min_free` less than the whole piece along an axis of its box's frame (`angle`, radians in plan). The box then ends at that top
/// (its centroid's height) and only the rectangle of the points above it (each side at least `min_width`, widened
/// away from the side they face, their mean normal within 60 degrees of the axis; else about their middle) stands
/// higher. Why: a chair's box ran from its seat's underside to its back's top over the whole seat, so the seat's
/// top lay inside the box and the space where one sits was solid: of 49 chairs missing 33 had their 0.4-0.6 m band
/// (the seat's top and edges) farther than 5 cm from the model (bench/results/indoor_office.md, 2026-12-05). The
/// points over a seat are its back's and nothing else's: what stands higher than a top over part of it only is not
/// the box's. nullopt: no such top (the box is one block, #70).
std::optional<SeatStep> seat_step(const PointCloud& cloud, const SceneStructure& structure, const std::vector<int>& piece,
                                  const std::vector<int>& planes, double angle, double floor_z, double r, double r_d,
                                  double cos_a, double min_free, double min_width, int min_points, int seat_min_points) {
  if (!(min_free > 0)) return std::nullopt;
  const Vec3 u(std::cos(angle), std::sin(angle), 0.0), v(-std::sin(angle), std::cos(angle), 0.0);
  std::vector<std::pair<double, int>> tops;  // the raised level tops' heights and planes, highest first
  for (int k : planes) {
    const DetectedPlane& t = structure.planes[static_cast<std::size_t>(k)];
    if (t.plane.normal.z() > cos_a && t.centroid.z() - floor_z > r_d) tops.emplace_back(t.centroid.z(), k);
  }
  if (tops.empty()) {  // no plane holds a raised top: a seat of points on no plane (seat_level)
    const double z = seat_level(cloud, piece, structure.point_plane, floor_z, r, r_d, cos_a, seat_min_points);
    if (std::isfinite(z)) tops.emplace_back(z, -1);
  }
  std::sort(tops.rbegin(), tops.rend());
  double lo[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  double hi[2] = {-lo[0], -lo[1]};
  for (int p : piece) {
    const Vec3& q = cloud.points[static_cast<std::size_t>(p)];
    lo[0] = std::min(lo[0], along_axis(q, u)), hi[0] = std::max(hi[0], along_axis(q, u));
    lo[1] = std::min(lo[1], along_axis(q, v)), hi[1] = std::max(hi[1], along_axis(q, v));
  }
  for (const auto& [z, top] : tops) {
    double a[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
    double b[2] = {-a[0], -a[1]};
    Vec3 facing = Vec3::Zero();
    int above = 0;
    for (int p : piece) {
      const Vec3& q = cloud.points[static_cast<std::size_t>(p)];
      if (!(q.z() > z + r)) continue;
      ++above;
      a[0] = std::min(a[0], along_axis(q, u)), b[0] = std::max(b[0], along_axis(q, u));
      a[1] = std::min(a[1], along_axis(q, v)), b[1] = std::max(b[1], along_axis(q, v));
      if (cloud.has_normals()) facing += cloud.normals[static_cast<std::size_t>(p)];
    }
    if (above < min_points) continue;  // nothing stands on this top: a lower one may hold the back
    if (!(hi[0] - lo[0] - (b[0] - a[0]) >= min_free || hi[1] - lo[1] - (b[1] - a[1]) >= min_free)) return std::nullopt;
    if (facing.norm() > 0) facing.normalize();
    for (int k = 0; k < 2; ++k) {
      if (b[k] - a[k] >= min_width) continue;
      const double along = facing.dot(k == 0 ? u : v);
      if (along > 0.5) a[k] = b[k] - min_width;  // its points on the + side: the rest lies behind them
      else if (along < -0.5) b[k] = a[k] + min_width;
      else {
        const double mid = 0.5 * (a[k] + b[k]);
        a[k] = mid - 0.5 * min_width, b[k] = mid + 0.5 * min_width;
      }
    }
    return SeatStep{z, a[0], b[0], a[1], b[1], top};
  }
  return std::nullopt;
}

/// A plane of a piece as seen: its normal turned to the side its inliers were seen from (seen_normal) and its
/// centroid.
struct SeenPlane {
  Vec3 seen, centroid;
};

/// A side of a piece's box behind an inner face (RecoveryParams::inner_face_depth; DECISIONS #154): the side at
/// `bound` along the unit vector `n` (its outward normal: the box's top or an upright side), when the piece's
/// planes within r of it facing along `n` (within r_a, `cos_a`) were all seen from inside the box (their seen
/// normal against `n`) and fewer than `min_points` of its points within r of it face out along `n` (the side's own
/// surface seen on no plane), moves out to `depth` beyond the farthest of them; `bound` otherwise. Why: a board or panel
/// seen from one side only, from inside the piece (an open shelf's top board seen from below, a side panel seen
/// through the open front), leaves its inner face at the points' extreme, where the box's side lay: the inner face
/// covered the side (covers() reads a plane within r of a face as that face), so the board had one plane and no
/// thickness, and the min-cut made it air (the shelves held the largest share of truth -> mesh on the office,
/// bench/results/indoor_office.md). What lies behind a surface seen from in front of it is not air, as behind
/// a piece's one seen side (min_piece_depth).
double behind_inner_faces(const PointCloud& cloud, const std::vector<int>& piece, const std::vector<SeenPlane>& planes,
                          const Vec3& n, double bound, double r, double cos_a, double depth, int min_points) {
  if (!(depth > 0)) return bound;
  if (cloud.has_normals()) {  // the side itself was seen: points of the piece there facing out of the box
    int out = 0;
    for (int p : piece)
      if (cloud.points[static_cast<std::size_t>(p)].dot(n) > bound - r && cloud.normals[static_cast<std::size_t>(p)].dot(n) > cos_a &&
          ++out >= min_points)
        return bound;
  }
  double inner = -std::numeric_limits<double>::infinity();
  for (const SeenPlane& p : planes) {
    const double along = p.seen.dot(n), at = p.centroid.dot(n);
    if (std::abs(along) <= cos_a || std::abs(at - bound) > r) continue;
    if (along > 0) return bound;  // its outer face was seen: it is the side
    inner = std::max(inner, at);
  }
  return std::isfinite(inner) ? std::max(bound, inner + depth) : bound;
}

/// Where a piece seen from one side only reaches back from (RecoveryParams::depth_from_seen_face; DECISIONS #206),
/// as a coordinate along `n` (a unit vector in plan: the way its seen face faces, an axis of its box's frame, `w`
/// the other): its points' extreme that way (`front`), or, when `from_face` is set and the extreme of its points
/// standing within the seen face's span along `w` (its inliers' `face`) lies more than a spacing r behind
/// `front`, that extreme. Why: something of the piece beside its seen face stands in front of it, and its box
/// reached only min_piece_depth behind that: an open shelf seen only from behind (its front facing a wall), in one
/// piece with a pillar 0.2 m beside it whose front stands 0.37 m before the shelf's back, got a box from the
/// pillar's front to 0.11 m behind the shelf's back, the shelf's 0.38 m body air (office 1 room seed 3: 1.09 of
/// its 1.57 m² of truth -> mesh). What stands in front of the face within its span (a chair's seat before its
/// back) is the piece's front there, as before.
double seen_face_front(const PointCloud& cloud, const std::vector<int>& piece, const std::vector<int>& face,
                       const Vec3& n, const Vec3& w, double front, double r, bool from_face) {
  if (!from_face || face.empty()) return front;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int p : face) {
    const double b = along_axis(cloud.points[static_cast<std::size_t>(p)], w);
    lo = std::min(lo, b), hi = std::max(hi, b);
  }
  double within = -std::numeric_limits<double>::infinity();
  for (int p : piece) {
    const Vec3& q = cloud.points[static_cast<std::size_t>(p)];
    const double b = along_axis(q, w);
    if (b >= lo && b <= hi) within = std::max(within, along_axis(q, n));
  }
  return front - within > r ? within : front;
}

/// A circle in plan (round_plan).
struct PlanCircle {
  Vec2 centre;
  double radius = 0.0;
};

/// Whether a piece is round (RecoveryParams::round_sides; DECISIONS #240): the circle fitted in plan (least squares,
/// Kasa's algebraic fit about the points' mean) to its points facing sideways (normal within r_a of level,
/// `sin_a`) explains them better than the rectangle [u0, u1] x [v0, v1] along `u`, `v` (the summed distance to the
/// circle less than to the rectangle's nearest side) and as closely as its planes explain their inliers (the mean
/// distance to the circle no more than `plane_residual`, sideways_plane_residual), with its centre inside the
/// rectangle grown by `r` and its diameter no more than the rectangle's longer side and 2 r. The result decides: a
/// box's faces explain a cabinet's or a shelf's points (they lie on the rectangle and on planes), a circle a
/// pillar's seen arc (1-3 times closer than its facets' planes on the 18 offices; other pieces 10 times farther).
/// nullopt: not round.
std::optional<PlanCircle> round_plan(const PointCloud& cloud, const std::vector<int>& piece, const Vec3& u,
                                     const Vec3& v, double u0, double u1, double v0, double v1, double r, double sin_a,
                                     double plane_residual) {
  if (!cloud.has_normals()) return std::nullopt;
  std::vector<Vec2> xy;
  for (int p : piece)
    if (std::abs(cloud.normals[static_cast<std::size_t>(p)].z()) < sin_a)
      xy.push_back(cloud.points[static_cast<std::size_t>(p)].head<2>());
  constexpr std::size_t kCircleUnknowns = 3;  // a circle's centre and radius: more points than that to judge it
  if (xy.size() <= kCircleUnknowns) return std::nullopt;
  Vec2 mean = Vec2::Zero();
  for (const Vec2& q : xy) mean += q;
  mean /= static_cast<double>(xy.size());
  // x^2 + y^2 + D x + E y + F = 0 about the mean, least squares: the normal equations of [x y 1] [D E F]' = -(x^2+y^2).
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const Vec2& q : xy) {
    const Vec2 d = q - mean;
    const Eigen::Vector3d row(d.x(), d.y(), 1.0);
    a += row * row.transpose();
    b -= row * d.squaredNorm();
  }
  const Eigen::Vector3d sol = a.ldlt().solve(b);
  const Vec2 centre = mean + Vec2(-0.5 * sol(0), -0.5 * sol(1));
  const double r2 = 0.25 * (sol(0) * sol(0) + sol(1) * sol(1)) - sol(2);
  if (!(r2 > 0) || !std::isfinite(r2)) return std::nullopt;
  const double radius = std::sqrt(r2);
  const double cu = centre.x() * u.x() + centre.y() * u.y(), cv = centre.x() * v.x() + centre.y() * v.y();
  if (!(cu > u0 - r && cu < u1 + r && cv > v0 - r && cv < v1 + r)) return std::nullopt;
  if (!(2.0 * radius <= std::max(u1 - u0, v1 - v0) + 2.0 * r)) return std::nullopt;
  double to_circle = 0.0, to_rectangle = 0.0;
  for (const Vec2& q : xy) {
    to_circle += std::abs((q - centre).norm() - radius);
    const double qa = q.x() * u.x() + q.y() * u.y(), qb = q.x() * v.x() + q.y() * v.y();
    to_rectangle += std::min({std::abs(qa - u0), std::abs(qa - u1), std::abs(qb - v0), std::abs(qb - v1)});
  }
  const double count = static_cast<double>(xy.size());
  if (!(to_circle < to_rectangle) || !(to_circle <= plane_residual * count)) return std::nullopt;
  return PlanCircle{centre, radius};
}

/// The mean distance of a piece's points facing sideways (normal within r_a of level, `sin_a`) that lie on a
/// detected plane to that plane: how closely planes explain its upright surfaces (round_plan). NaN: none on a plane.
double sideways_plane_residual(const PointCloud& cloud, const SceneStructure& structure, const std::vector<int>& piece,
                               double sin_a) {
  if (!cloud.has_normals()) return std::numeric_limits<double>::quiet_NaN();
  double sum = 0.0;
  std::size_t count = 0;
  for (int p : piece) {
    const auto i = static_cast<std::size_t>(p);
    if (!(i < structure.point_plane.size() && structure.point_plane[i] >= 0)) continue;
    if (!(std::abs(cloud.normals[i].z()) < sin_a)) continue;
    const DetectedPlane& dp = structure.planes[static_cast<std::size_t>(structure.point_plane[i])];
    sum += std::abs(dp.plane.signed_distance(cloud.points[i]));
    ++count;
  }
  return count > 0 ? sum / static_cast<double>(count) : std::numeric_limits<double>::quiet_NaN();
}

/// The box of a piece (see recovery.h): its faces as recovered planes, each with its corners as reach and the
/// piece's points on no plane nearest to it as support; its sides along `facing` (radians in plan; NaN: the
/// points' smallest-area rectangle); its bottom at least `underside` (a top of it with free space under it,
/// underside_of_top; NaN: none); at least `depth` deep behind its face `seen` (a unit vector in plan along its
/// sides' normals, or zero: none; one_seen_side; `seen_face` that face's plane's inliers, seen_face_front with
/// `from_seen_face`); empty when the box is thinner than `r` on some side, but a box hanging from a top whose rim
/// set the underside (`rim_measured`, rim_underside) is as thin as that rim says. With a
/// `step` (seat_step) the box ends at the step's height and a second box, over the step's rectangle only, stands
/// on it up to the piece's top (no bottom of its own); `*upper_part` (when given) flags the faces that hold part
/// of that upper box. Its top and upright sides stand behind the inner faces among `planes` (behind_inner_faces,
/// `inner_depth`, `inner_min_points`; not with a step: #141's upper box has its own rule for a back's two sides).
std::vector<RecoveredPlane> box_of_piece(const PointCloud& cloud, const std::vector<int>& piece,
                                         const std::vector<int>& point_plane, double facing, double floor_z, double r,
                                         double r_d, double underside, bool rim_measured, const Vec3& seen,
                                         const std::vector<int>& seen_face, bool from_seen_face, double depth, int number,
                                         const std::optional<SeatStep>& step, std::vector<char>* upper_part,
                                         const std::vector<SeenPlane>& planes, double cos_a, double inner_depth,
                                         int inner_min_points, int round_sides, double plane_residual) {
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
  for (int p : piece) {
    const Vec3& q = cloud.points[static_cast<std::size_t>(p)];
    const double a = along_axis(q, u), b = along_axis(q, v);
    u0 = std::min(u0, a), u1 = std::max(u1, a), v0 = std::min(v0, b), v1 = std::max(v1, b);
  }
  if (!step) {
    const auto behind = [&](const Vec3& n, double bound) {
      return behind_inner_faces(cloud, piece, planes, n, bound, r, cos_a, inner_depth, inner_min_points);
    };
    top = behind(Vec3(0, 0, 1), top);
    u1 = behind(u, u1);
    u0 = -behind(-u, -u0);
    v1 = behind(v, v1);
    v0 = -behind(-v, -v0);
  }
  // Round (round_plan): its sides around the circle its points show, whichever side they were seen from.
  const double sin_a = std::sqrt(std::max(0.0, 1.0 - cos_a * cos_a));
  const std::optional<PlanCircle> round = round_sides >= 3 && !step && !std::isfinite(underside)
                                              ? round_plan(cloud, piece, u, v, u0, u1, v0, v1, r, sin_a, plane_residual)
                                              : std::nullopt;
  if (seen.dot(u) > 0.5)  // seen from +u only: it reaches back from its seen face
    u0 = std::min(u0, seen_face_front(cloud, piece, seen_face, u, v, u1, r, from_seen_face) - depth);
  if (seen.dot(u) < -0.5) u1 = std::max(u1, -seen_face_front(cloud, piece, seen_face, -u, v, -u0, r, from_seen_face) + depth);
  double bottom = low - floor_z > r_d ? low : floor_z;  // standing on the floor, or raised
  if (underside > bottom) bottom = underside;  // the floor seen under its top: free space under it
  const bool hangs_from_rim = rim_measured && bottom == underside;  // its height is the rim's, measured
  if (!(u1 - u0 >= r && v1 - v0 >= r && (top - bottom >= r || (hangs_from_rim && top > bottom)))) return {};
  auto at = [&](double a, double b, double z) { return Vec3(a * u.x() + b * v.x(), a * u.y() + b * v.y(), z); };
  struct Face { Vec3 normal; double at; std::vector<Vec3> corners; };  // `at`: its coordinate along its normal
  const bool stepped = step && step->z > bottom && step->z < top;
  const double lower_top = stepped ? step->z : top;
  std::vector<Face> faces;
  if (round) {  // round_sides faces around the circle, the first facing along u; each through its arc's mean
    const double half = M_PI / round_sides;
    const double mid = round->radius * std::sin(half) / half;  // the face's distance from the centre
    const Vec3 c(round->centre.x(), round->centre.y(), 0.0);
    std::vector<Vec3> ring;  // the corners in plan, the i-th between faces i and i + 1
    for (int i = 0; i < round_sides; ++i) {
      const double t = angle + (2 * i + 1) * half;
      ring.push_back(c + (mid / std::cos(half)) * Vec3(std::cos(t), std::sin(t), 0.0));
    }
    auto lift = [](Vec3 q, double z) { return q.z() = z, q; };
    Face top_face{Vec3(0, 0, 1), lower_top, {}};
    for (const Vec3& q : ring) top_face.corners.push_back(lift(q, lower_top));
    faces.push_back(top_face);
    for (int i = 0; i < round_sides; ++i) {
      const double t = angle + 2 * i * half;
      const Vec3 n(std::cos(t), std::sin(t), 0.0);
      const Vec3& a = ring[static_cast<std::size_t>((i + round_sides - 1) % round_sides)];
      const Vec3& b = ring[static_cast<std::size_t>(i)];
      faces.push_back({n, n.dot(c) + mid, {lift(a, bottom), lift(b, bottom), lift(b, lower_top), lift(a, lower_top)}});
    }
    if (bottom > floor_z) {
      Face bottom_face{Vec3(0, 0, -1), -bottom, {}};
      for (const Vec3& q : ring) bottom_face.corners.push_back(lift(q, bottom));
      faces.push_back(bottom_face);
    }
  } else {
    faces = {
        {Vec3(0, 0, 1), lower_top, {at(u0, v0, lower_top), at(u1, v0, lower_top), at(u1, v1, lower_top), at(u0, v1, lower_top)}},
        {-u, -u0, {at(u0, v0, bottom), at(u0, v1, bottom), at(u0, v1, lower_top), at(u0, v0, lower_top)}},
        {u, u1, {at(u1, v0, bottom), at(u1, v1, bottom), at(u1, v1, lower_top), at(u1, v0, lower_top)}},
        {-v, -v0, {at(u0, v0, bottom), at(u1, v0, bottom), at(u1, v0, lower_top), at(u0, v0, lower_top)}},
        {v, v1, {at(u0, v1, bottom), at(u1, v1, bottom), at(u1, v1, lower_top), at(u0, v1, lower_top)}}};
    if (bottom > floor_z)
      faces.push_back({Vec3(0, 0, -1), -bottom, {at(u0, v0, bottom), at(u1, v0, bottom), at(u1, v1, bottom), at(u0, v1, bottom)}});
  }
  std::vector<char> upper(faces.size(), 0);
  if (stepped) {  // the part above the seat: over the step's rectangle only, standing on the lower box's top
    // A side of it within r of the lower box's side facing the same way is that side (a chair's back stands on
    // the seat's rear edge): one plane, the lower side reaching up to the top there. Two planes nearer than the
    // points' spacing are one surface (DECISIONS #73), and two coplanar faces left the min-cut an invalid model.
    double a0 = step->u0, a1 = step->u1, b0 = step->v0, b1 = step->v1;
    const bool same[4] = {std::abs(a0 - u0) < r, std::abs(a1 - u1) < r, std::abs(b0 - v0) < r, std::abs(b1 - v1) < r};
    if (same[0]) a0 = u0;
    if (same[1]) a1 = u1;
    if (same[2]) b0 = v0;
    if (same[3]) b1 = v1;
    const double z0 = step->z;
    faces.push_back({Vec3(0, 0, 1), top, {at(a0, b0, top), at(a1, b0, top), at(a1, b1, top), at(a0, b1, top)}});
    upper.push_back(1);
    const Face sides[4] = {{-u, -a0, {at(a0, b0, z0), at(a0, b1, z0), at(a0, b1, top), at(a0, b0, top)}},
                           {u, a1, {at(a1, b0, z0), at(a1, b1, z0), at(a1, b1, top), at(a1, b0, top)}},
                           {-v, -b0, {at(a0, b0, z0), at(a1, b0, z0), at(a1, b0, top), at(a0, b0, top)}},
                           {v, b1, {at(a0, b1, z0), at(a1, b1, z0), at(a1, b1, top), at(a0, b1, top)}}};
    for (int k = 0; k < 4; ++k) {
      if (same[k]) {  // faces[1 + k] is the lower side facing the same way
        faces[static_cast<std::size_t>(1 + k)].corners.insert(faces[static_cast<std::size_t>(1 + k)].corners.end(),
                                                              sides[k].corners.begin(), sides[k].corners.end());
        upper[static_cast<std::size_t>(1 + k)] = 1;
      } else {
        faces.push_back(sides[k]);
        upper.push_back(1);
      }
    }
  }
  if (upper_part) *upper_part = upper;
  std::vector<RecoveredPlane> out(faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f) {
    out[f].plane = frame_face_plane(faces[f].normal, faces[f].at);
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

/// The posts under a raised top with free space under it (RecoveryParams::post_min_points, post_link,
/// post_min_width; DECISIONS #139): the piece's points lower than the top's underside (`underside`, the box's
/// bottom) grouped in plan (linked within `link`), each group of at least `min_points` a post: four upright faces
/// in the box's frame (`angle`, radians in plan) around the group, from the floor up to the underside, each side at
/// least `min_width` across (widened away from the side its points face, their mean normal within 60 degrees of an
/// axis; else about their middle). Why: since #100 a table's top keeps the free space under it, and its legs, thin
/// posts whose 0-13 points hold no plane, were air: 17-38 % of a table's seen surface, and the table lost by its
/// legs (bench/results/indoor_office.md, 2026-12-05). The points under the top are the legs' and nothing else's
/// (underside_of_top: no upright plane reaches under it), so each group of them stands where a leg stands. Each
/// face's support is its group's points on no plane nearest to it (they vote for the post, as a box's do).
std::vector<RecoveredPlane> posts_under_top(const PointCloud& cloud, const std::vector<int>& piece,
                                            const std::vector<int>& point_plane, double angle, double floor_z,
                                            double underside, double link, int min_points, double min_width, int number) {
  std::vector<RecoveredPlane> out;
  if (!std::isfinite(underside) || min_points <= 0 || !(underside - floor_z > min_width)) return out;
  std::vector<Vec3> flat;  // the piece's points under the top, on the floor's level: grouped in plan
  std::vector<int> under, subset;
  for (int p : piece)
    if (cloud.points[static_cast<std::size_t>(p)].z() < underside) {
      under.push_back(p);
      subset.push_back(static_cast<int>(flat.size()));
      flat.emplace_back(cloud.points[static_cast<std::size_t>(p)].x(), cloud.points[static_cast<std::size_t>(p)].y(), 0.0);
    }
  if (static_cast<int>(under.size()) < min_points) return out;
  const Vec3 u(std::cos(angle), std::sin(angle), 0.0), v(-std::sin(angle), std::cos(angle), 0.0);
  for (const std::vector<int>& group : linked_groups(flat, subset, link)) {
    if (static_cast<int>(group.size()) < min_points) continue;
    double lo[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
    double hi[2] = {-lo[0], -lo[1]};
    Vec3 facing = Vec3::Zero();
    for (int g : group) {
      const std::size_t p = static_cast<std::size_t>(under[static_cast<std::size_t>(g)]);
      const double c[2] = {along_axis(cloud.points[p], u), along_axis(cloud.points[p], v)};
      for (int a = 0; a < 2; ++a) lo[a] = std::min(lo[a], c[a]), hi[a] = std::max(hi[a], c[a]);
      if (cloud.has_normals()) facing += cloud.normals[p];
    }
    if (facing.norm() > 0) facing.normalize();
    for (int a = 0; a < 2; ++a) {
      if (hi[a] - lo[a] >= min_width) continue;
      const double along = facing.dot(a == 0 ? u : v);
      if (along > 0.5) lo[a] = hi[a] - min_width;        // its points on the post's + side: it lies behind them
      else if (along < -0.5) hi[a] = lo[a] + min_width;
      else {
        const double mid = 0.5 * (lo[a] + hi[a]);
        lo[a] = mid - 0.5 * min_width, hi[a] = mid + 0.5 * min_width;
      }
    }
    auto at = [&](double a, double b, double z) { return Vec3(a * u.x() + b * v.x(), a * u.y() + b * v.y(), z); };
    const double z0 = floor_z, z1 = underside;
    const std::vector<FrameFace> faces = {
        {-u, -lo[0], {at(lo[0], lo[1], z0), at(lo[0], hi[1], z0), at(lo[0], hi[1], z1), at(lo[0], lo[1], z1)}},
        {u, hi[0], {at(hi[0], lo[1], z0), at(hi[0], hi[1], z0), at(hi[0], hi[1], z1), at(hi[0], lo[1], z1)}},
        {-v, -lo[1], {at(lo[0], lo[1], z0), at(hi[0], lo[1], z0), at(hi[0], lo[1], z1), at(lo[0], lo[1], z1)}},
        {v, hi[1], {at(lo[0], hi[1], z0), at(hi[0], hi[1], z0), at(hi[0], hi[1], z1), at(lo[0], hi[1], z1)}}};
    const std::size_t first = out.size();
    push_frame_faces(faces, number, out);
    std::vector<int> points;
    for (int g : group) points.push_back(under[static_cast<std::size_t>(g)]);
    std::sort(points.begin(), points.end());
    for (int p : points) {  // each point on no plane supports the post's face it is nearest to (the first on ties)
      if (static_cast<std::size_t>(p) < point_plane.size() && point_plane[static_cast<std::size_t>(p)] >= 0) continue;
      std::size_t best = first;
      for (std::size_t f = first + 1; f < out.size(); ++f)
        if (std::abs(out[f].plane.signed_distance(cloud.points[static_cast<std::size_t>(p)])) <
            std::abs(out[best].plane.signed_distance(cloud.points[static_cast<std::size_t>(p)])))
          best = f;
      out[best].support.push_back(p);
    }
  }
  return out;
}

/// The raised tops among `tops` (a piece's tops with free space under them, their undersides `at`) that its box
/// hangs from: their underside within a spacing r of the box's bottom `underside` (RecoveryParams::
/// boards_over_underside; DECISIONS #198). Why: a shelf's plinth top, 8 cm up, is floor to floor_seen, so each of
/// its boards over it had the floor seen under it and free space (#100, #180's panels as posts); the box's bottom
/// hung under the lowest board, and the boards above, inside the box, were tops to board_slabs and got no slab:
/// one plane each with the compartments the scanners looked into on both its sides, so the min-cut made them air
/// (8 of the offices' 21 missing shelves). Only the top the box hangs from stands on its underside; a top higher
/// in the box is a board like any level plane of the piece.
std::vector<int> tops_at_bottom(const std::vector<int>& tops, const std::vector<double>& at, double underside, double r) {
  std::vector<int> out;
  for (std::size_t i = 0; i < tops.size(); ++i)
    if (at[i] - underside <= r) out.push_back(tops[i]);
  return out;
}

/// The slabs of a piece's box where it hangs from its raised tops (RecoveryParams::solid_slabs; DECISIONS #230): for
/// each top it hangs from (`tops`, tops_at_bottom's), the half-spaces of the box's four upright sides, its bottom
/// and the top's plane facing up. None when the box has no bottom at `underside` (it stands on the floor or on its
/// own lowest point). Why: the box is the top's thickness down to the underside its rim measured, solid; a level
/// facet inside it (another top's plane through it) is no surface the points show (ExtractionParams::
/// slab_facet_weight).
std::vector<std::vector<Plane>> slabs_of_box(const SceneStructure& structure, const std::vector<RecoveredPlane>& box,
                                             const std::vector<int>& tops, double underside) {
  std::vector<std::vector<Plane>> out;
  std::vector<Plane> frame;  // its upright sides and its bottom (box_of_piece's faces 1-4 and its bottom)
  for (std::size_t f = 1; f < box.size() && f <= 4; ++f) frame.push_back(box[f].plane);
  const auto bottom = std::find_if(box.begin(), box.end(), [&](const RecoveredPlane& f) {
    return f.plane.normal.z() == -1.0 && f.plane.offset == underside;
  });
  if (frame.size() != 4 || bottom == box.end()) return out;
  frame.push_back(bottom->plane);
  const auto with_top = [&](const Plane& top) {
    std::vector<Plane> slab = frame;
    slab.push_back(top);
    out.push_back(std::move(slab));
  };
  for (int k : tops) {
    Plane top = structure.planes[static_cast<std::size_t>(k)].plane;
    if (top.normal.z() < 0) top.normal = -top.normal, top.offset = -top.offset;
    with_top(top);
  }
  return out;
}

/// The slabs of a piece's boards (RecoveryParams::board_thickness, board_min_points; DECISIONS #186): each level
/// plane of the piece (not a top with its underside, `free_under`) seen from one side only, with free space on its
/// other side, gets its board's unseen face `thickness` behind it and four upright edges in the box's frame
/// (`angle`, radians in plan) around its inliers' rectangle (widened by r on each side, within the piece's points),
/// from that face to the plane. Free space behind it: seen from below, the board of an open shelf or its top seen
/// from inside a compartment (nothing closed is seen from below); seen from above, at least `min_points` of the
/// piece's points facing up under its rectangle lower than the board's unseen face by more than r (a lower board or
/// the plinth seen through the open front); a plane seen from above within `thickness` + r of the floor stands on
/// it (a plinth: the slab reaches down to the floor, no bottom face). Why: a shelf's boards are 2 cm thick, and one
/// plane of one face is no solid: the cells on both of its sides were the compartments the scanners looked into,
/// the min-cut labelled them air, and the board was nothing (the offices' shelves: 35 of 63 present, 29.2 of the
/// 82.8 m² of truth -> mesh; 72 of the 147 m² of their boards farther than 5 cm from the model). Each face's support
/// is the piece's points on no plane within r/2 of the slab, nearest to it (a board's front edge).
std::vector<RecoveredPlane> board_slabs(const PointCloud& cloud, const SceneStructure& structure,
                                        const std::vector<int>& piece, const std::vector<int>& planes,
                                        const std::vector<int>& free_under, double angle, double floor_z, double r,
                                        double cos_a, double thickness, int min_points, int number) {
  std::vector<RecoveredPlane> out;
  if (!(thickness > 0) || min_points <= 0) return out;
  const Vec3 u(std::cos(angle), std::sin(angle), 0.0), v(-std::sin(angle), std::cos(angle), 0.0);
  double plo[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  double phi[2] = {-plo[0], -plo[1]};
  for (int p : piece) {
    const Vec3& q = cloud.points[static_cast<std::size_t>(p)];
    const double c[2] = {along_axis(q, u), along_axis(q, v)};
    for (int a = 0; a < 2; ++a) plo[a] = std::min(plo[a], c[a]), phi[a] = std::max(phi[a], c[a]);
  }
  for (int k : planes) {
    const DetectedPlane& dp = structure.planes[static_cast<std::size_t>(k)];
    if (std::abs(dp.plane.normal.z()) <= cos_a || std::find(free_under.begin(), free_under.end(), k) != free_under.end())
      continue;
    const double from_above = seen_normal(cloud, dp).z() > 0 ? 1.0 : -1.0;  // the side its inliers were seen from
    double lo[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
    double hi[2] = {-lo[0], -lo[1]};
    for (int p : dp.inliers) {
      const Vec3& q = cloud.points[static_cast<std::size_t>(p)];
      const double c[2] = {along_axis(q, u), along_axis(q, v)};
      for (int a = 0; a < 2; ++a) lo[a] = std::min(lo[a], c[a]), hi[a] = std::max(hi[a], c[a]);
    }
    for (int a = 0; a < 2; ++a) lo[a] = std::max(lo[a] - r, plo[a]), hi[a] = std::min(hi[a] + r, phi[a]);
    const double z = dp.centroid.z();
    double far = z - from_above * thickness;  // the board's unseen face
    bool on_floor = false;
    if (from_above > 0) {
      on_floor = z - floor_z <= thickness + r;
      int under = 0;
      for (int p : piece) {
        if (on_floor) break;
        const Vec3& q = cloud.points[static_cast<std::size_t>(p)];
        const double a = along_axis(q, u), b = along_axis(q, v);
        if (q.z() < far - r && a > lo[0] && a < hi[0] && b > lo[1] && b < hi[1] && cloud.has_normals() &&
            cloud.normals[static_cast<std::size_t>(p)].z() > cos_a && ++under >= min_points)
          break;
      }
      if (!on_floor && under < min_points) continue;
      if (on_floor) far = floor_z;
    }
    auto at = [&](double a, double b, double h) { return Vec3(a * u.x() + b * v.x(), a * u.y() + b * v.y(), h); };
    auto on_plane = [&](double a, double b) {  // the corner on the board's plane (a detected plane is level within r_a)
      const Vec3 q = at(a, b, z);
      return Vec3(q.x(), q.y(), z - dp.plane.signed_distance(q) / dp.plane.normal.z());
    };
    auto side = [&](double a0, double b0, double a1, double b1) {  // an upright edge from `far` to the plane
      return std::array<Vec3, 4>{at(a0, b0, far), at(a1, b1, far), on_plane(a1, b1), on_plane(a0, b0)};
    };
    std::vector<FrameFace> faces = {{-u, -lo[0], side(lo[0], lo[1], lo[0], hi[1])},
                               {u, hi[0], side(hi[0], lo[1], hi[0], hi[1])},
                               {-v, -lo[1], side(lo[0], lo[1], hi[0], lo[1])},
                               {v, hi[1], side(lo[0], hi[1], hi[0], hi[1])}};
    if (!on_floor)
      faces.push_back({Vec3(0, 0, -from_above), -from_above * far,
                       {at(lo[0], lo[1], far), at(hi[0], lo[1], far), at(hi[0], hi[1], far), at(lo[0], hi[1], far)}});
    const std::size_t first = out.size();
    push_frame_faces(faces, number, out);
    const double z0 = std::min(z, far) - 0.5 * r, z1 = std::max(z, far) + 0.5 * r;
    for (int p : piece) {  // its points on no plane within r/2 of the slab support its face nearest to them
      if (static_cast<std::size_t>(p) < structure.point_plane.size() && structure.point_plane[static_cast<std::size_t>(p)] >= 0)
        continue;
      const Vec3& q = cloud.points[static_cast<std::size_t>(p)];
      const double a = along_axis(q, u), b = along_axis(q, v);
      if (q.z() < z0 || q.z() > z1 || a < lo[0] - 0.5 * r || a > hi[0] + 0.5 * r || b < lo[1] - 0.5 * r || b > hi[1] + 0.5 * r)
        continue;
      std::size_t best = first;
      for (std::size_t f = first + 1; f < out.size(); ++f)
        if (std::abs(out[f].plane.signed_distance(q)) < std::abs(out[best].plane.signed_distance(q))) best = f;
      out[best].support.push_back(p);
    }
  }
  return out;
}

/// The slabs of an open shelf's boards seen edge-on (RecoveryParams::edge_boards, edge_board_min_points,
/// edge_board_height, edge_board_min_width; DECISIONS #217). For each upright plane of the piece and the side its
/// inliers were seen from, taken as the axis `a` of the piece's box (`box`) nearest that side: the points on no
/// plane (`loose`, of any piece or none) inside the box (within r/2 of it), facing along `a` (within r_a, `cos_a`)
/// and more than `depth` in front of the plane within its span along the box's other axis (widened by r), are
/// grouped by height (linked within `height`); a group of at least `min_points`, no taller than `height`, spread
/// at least `min_width` along the plane, reaching the box's front (within r of its face along `a`), and with no
/// level plane of the piece within r of its height, is a board's front edge: a `thickness` slab about its mean
/// height from the box's front back to the plane, across the plane's span (under the box's top when it reaches
/// within r/2 of it; from the floor when it reaches within r/2 of that). A bound within r of a face of the box is
/// that face (its coordinate to the last bit) and is not added again: two planes nearer than r cut slivers
/// (DECISIONS #73). Why: from stations 1.5 m up the shelves' boards at 0.9-1.9 m are seen edge-on: no point faces
/// up or down, 1-4 points of each 2 cm front edge hold no plane, more than the piece link in front of the back,
/// so in no piece (or one too small to count), and the model there was the back's slab alone (DECISIONS #212).
/// Points facing the way the back's inner face was seen from, at the box's front, at one height across it: in an
/// open shelf nothing but a board's edge stands so.
std::vector<RecoveredPlane> edge_boards(const PointCloud& cloud, const SceneStructure& structure,
                                        const std::vector<int>& loose, const std::vector<int>& planes,
                                        const std::vector<RecoveredPlane>& box, double floor_z, double r, double cos_a,
                                        double depth, double thickness, double height, double min_width, int min_points,
                                        int number) {
  std::vector<RecoveredPlane> out;
  if (!(thickness > 0) || min_points <= 0 || !cloud.has_normals() || box.empty()) return out;
  const double inf = std::numeric_limits<double>::infinity();
  const double sin_a = std::sqrt(std::max(0.0, 1.0 - cos_a * cos_a));
  double top = -inf, bottom = floor_z;  // the box's top and bottom
  for (const RecoveredPlane& f : box) {
    if (f.plane.normal.z() == 1.0) top = std::max(top, -f.plane.offset);
    if (f.plane.normal.z() == -1.0) bottom = f.plane.offset;
  }
  // The box's upright face with outward normal `n` (exactly: the box's normals are its axes): its coordinate along
  // n (frame_face_plane's `at`); NaN when none.
  const auto box_at = [&](const Vec3& n) {
    for (const RecoveredPlane& f : box)
      if (f.plane.normal.z() == 0.0 && (f.plane.normal - n).squaredNorm() < 1e-18) return -f.plane.offset;
    return std::numeric_limits<double>::quiet_NaN();
  };
  std::vector<double> levels;  // the heights of the piece's level planes
  for (int k : planes) {
    const DetectedPlane& dp = structure.planes[static_cast<std::size_t>(k)];
    if (std::abs(dp.plane.normal.z()) > cos_a) levels.push_back(dp.centroid.z());
  }
  const auto z_of = [&](int p) { return cloud.points[static_cast<std::size_t>(p)].z(); };
  std::vector<std::pair<Vec3, double>> made;  // each board's axis and height: one slab per edge
  for (int k : planes) {
    const DetectedPlane& dp = structure.planes[static_cast<std::size_t>(k)];
    if (std::abs(dp.plane.normal.z()) >= sin_a) continue;
    const Vec3 seen = seen_normal(cloud, dp);
    Vec3 a = Vec3::Zero();  // the box's axis nearest the side the plane was seen from
    for (const RecoveredPlane& f : box)
      if (f.plane.normal.z() == 0.0 && f.plane.normal.dot(seen) > a.dot(seen)) a = f.plane.normal;
    if (!(a.dot(seen) > cos_a)) continue;
    const Vec3 w(-a.y(), a.x(), 0.0);
    const double front = box_at(a), box_back = -box_at(-a), box_w0 = -box_at(-w), box_w1 = box_at(w);
    if (!std::isfinite(front) || !std::isfinite(box_back) || !std::isfinite(box_w0) || !std::isfinite(box_w1)) continue;
    const double back = along_axis(dp.centroid, a);
    double lo = inf, hi = -inf;
    for (int p : dp.inliers) {
      const double b = along_axis(cloud.points[static_cast<std::size_t>(p)], w);
      lo = std::min(lo, b), hi = std::max(hi, b);
    }
    lo = std::max(lo - r, box_w0 - 0.5 * r), hi = std::min(hi + r, box_w1 + 0.5 * r);
    std::vector<int> edge;  // its candidates, by height
    for (int p : loose) {
      const Vec3& q = cloud.points[static_cast<std::size_t>(p)];
      const double s = along_axis(q, a), b = along_axis(q, w);
      if (cloud.normals[static_cast<std::size_t>(p)].dot(a) > cos_a && s - back > depth && s <= front + 0.5 * r &&
          b >= lo && b <= hi && q.z() >= bottom - 0.5 * r && q.z() <= top + 0.5 * r)
        edge.push_back(p);
    }
    std::sort(edge.begin(), edge.end(), [&](int x, int y) { return z_of(x) < z_of(y) || (z_of(x) == z_of(y) && x < y); });
    for (std::size_t i = 0, j = 0; i < edge.size(); i = j) {
      for (j = i + 1; j < edge.size() && z_of(edge[j]) - z_of(edge[j - 1]) <= height;) ++j;
      if (static_cast<int>(j - i) < min_points || z_of(edge[j - 1]) - z_of(edge[i]) > height) continue;
      double zc = 0, b0 = inf, b1 = -inf, reach = -inf;
      for (std::size_t m = i; m < j; ++m) {
        const Vec3& q = cloud.points[static_cast<std::size_t>(edge[m])];
        zc += q.z() / static_cast<double>(j - i);
        b0 = std::min(b0, along_axis(q, w)), b1 = std::max(b1, along_axis(q, w)), reach = std::max(reach, along_axis(q, a));
      }
      if (b1 - b0 < min_width || front - reach > r ||
          std::any_of(levels.begin(), levels.end(), [&](double z) { return std::abs(z - zc) <= r; }) ||
          std::any_of(made.begin(), made.end(), [&](const auto& m) { return m.first == a && std::abs(m.second - zc) <= height; }))
        continue;
      // Its extent behind the front and up; across, the box's (a board runs from side to side); a bound within r
      // of the box's face is that face.
      double rear = back;
      const double w0 = box_w0, w1 = box_w1;
      const bool own_back = rear - box_back > r;
      if (!own_back) rear = box_back;
      double z0 = zc - 0.5 * thickness, z1 = zc + 0.5 * thickness;
      const bool own_top = top - z1 > 0.5 * r;
      if (!own_top) z1 = top, z0 = top - thickness;
      const bool own_bottom = z0 - bottom > 0.5 * r;
      if (!own_bottom) z0 = bottom;
      if (!(front - rear >= 0.5 * r && w1 - w0 >= r && z1 > z0)) continue;
      made.emplace_back(a, zc);
      auto at = [&](double s, double t, double z) { return Vec3(s * a.x() + t * w.x(), s * a.y() + t * w.y(), z); };
      const auto level = [&](double z) {
        return std::array<Vec3, 4>{at(rear, w0, z), at(front, w0, z), at(front, w1, z), at(rear, w1, z)};
      };
      const auto upright = [&](double s0, double t0, double s1, double t1) {
        return std::array<Vec3, 4>{at(s0, t0, z0), at(s1, t1, z0), at(s1, t1, z1), at(s0, t0, z1)};
      };
      std::vector<FrameFace> faces;
      if (own_top) faces.push_back({Vec3(0, 0, 1), z1, level(z1)});
      if (own_bottom) faces.push_back({Vec3(0, 0, -1), -z0, level(z0)});
      if (own_back) faces.push_back({-a, -rear, upright(rear, w0, rear, w1)});
      push_frame_faces(faces, number, out);
    }
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

/// A piece seen from one side only (RecoveryParams::min_piece_depth): the direction in plan its largest upright
/// plane faces (its inliers' mean normal; the plane's own normal without normals), when no other upright plane of
/// the piece faces against it within r_a; zero otherwise (a piece seen from both sides is as thin as its points
/// say). Its box reaches back from that face (box_of_piece): what no scanner saw behind a seen face is not air.
/// `*face` (when given) is set to that plane's number.
Vec3 one_seen_side(const PointCloud& cloud, const SceneStructure& structure, const std::vector<int>& planes, double angle_deg,
                   int* face = nullptr) {
  const double sin_a = std::sin(angle_deg * M_PI / 180.0), cos_a = std::cos(angle_deg * M_PI / 180.0);
  int largest = -1;
  for (int k : planes) {
    const DetectedPlane& dp = structure.planes[static_cast<std::size_t>(k)];
    if (std::abs(dp.plane.normal.z()) < sin_a &&
        (largest < 0 || dp.inliers.size() > structure.planes[static_cast<std::size_t>(largest)].inliers.size()))
      largest = k;
  }
  if (largest < 0) return Vec3::Zero();
  const DetectedPlane& front = structure.planes[static_cast<std::size_t>(largest)];
  if (face) *face = largest;
  Vec3 facing = front.plane.normal;
  if (cloud.has_normals()) {
    Vec3 mean = Vec3::Zero();
    for (int p : front.inliers) mean += cloud.normals[static_cast<std::size_t>(p)];
    if (mean.dot(facing) < 0) facing = -facing;
  }
  facing.z() = 0;
  facing.normalize();
  for (int k : planes) {
    const DetectedPlane& dp = structure.planes[static_cast<std::size_t>(k)];
    if (k == largest || std::abs(dp.plane.normal.z()) >= sin_a) continue;
    Vec3 n = dp.plane.normal;
    if (cloud.has_normals()) {
      Vec3 mean = Vec3::Zero();
      for (int p : dp.inliers) mean += cloud.normals[static_cast<std::size_t>(p)];
      if (mean.dot(n) < 0) n = -n;
    }
    if (n.dot(facing) < -cos_a) return Vec3::Zero();
  }
  return facing;
}

/// The height down to which the piece's planes that cover an upright side of its box (`covering`) stand for it:
/// the lowest inlier of any of them (RecoveryParams::box_side_gap). A plane covers a side by orientation and
/// distance (covers), not by extent: a chair's back lies on its box's back side but holds points above the seat
/// only, and the side dropped for it left the cell under the seat open to the room (DECISIONS #120).
double lowest_covering_inlier(const PointCloud& cloud, const SceneStructure& structure, const std::vector<int>& covering) {
  double low = std::numeric_limits<double>::infinity();
  for (int k : covering)
    for (int p : structure.planes[static_cast<std::size_t>(k)].inliers) low = std::min(low, cloud.points[static_cast<std::size_t>(p)].z());
  return low;
}

/// A side of a piece's box that its covering planes stand for only down to `low` (lowest_covering_inlier): when
/// `low` lies more than `gap` above the side's bottom, the side is kept from its bottom up to `low` (true, its
/// reach's upper corners lowered); otherwise it is covered (false). A level face (the top, the bottom) is covered
/// whole; a side's normal is level by construction (box_of_piece).
bool side_below_cover(RecoveredPlane& face, double low, double gap) {
  if (!(gap > 0) || face.plane.normal.z() != 0.0 || face.reach.empty()) return false;
  double bottom = std::numeric_limits<double>::infinity();
  for (const Vec3& q : face.reach) bottom = std::min(bottom, q.z());
  if (!(low - bottom > gap)) return false;
  for (Vec3& q : face.reach) q.z() = std::min(q.z(), low);
  return true;
}

/// The planes `covering` a piece's box's bottom face but the tops it hangs under (`tops`: the raised tops whose
/// underside set the bottom, underside_of_top). The bottom lies top_thickness r under such a top by construction,
/// and covers() reads a plane within r of a face as that face: with top_thickness 1 the top's own plane "covered"
/// its underside or not by the rounding of its fit and tilt, and a lone table on legs lost its box's bottom (the
/// cell under the top ran down to the floor, whose points voted it air) at some seeds and kept it at others
/// (DECISIONS #129). A plane seen at the underside still covers it.
std::vector<int> not_its_own_tops(const std::vector<int>& covering, const std::vector<int>& tops) {
  std::vector<int> out;
  for (int k : covering)
    if (std::find(tops.begin(), tops.end(), k) == tops.end()) out.push_back(k);
  return out;
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

}  // namespace

/// A room's pieces of furniture (RecoveryParams::piece_link, piece_split_link; DECISIONS #70, #209): the points
/// `off` (on no enclosing plane) linked within `link`, each group then split into the parts of it that are each an
/// object of their own: linked within `split_link` (the inliers of one detected plane together, a surface the points
/// hold is one surface, but where `min_points` of them lie in each of two parts: one plane grown across the coplanar
/// faces of two things, which joins neither when `across_planes`, DECISIONS #210), at least `min_points` points, holding a detected
/// plane's inliers. `*groups_out` (when given) gets each piece's whole linked group. The rest of
/// the group (a leg, a seat's or a post's few points, on no plane) joins the part with the point nearest to it
/// (ties: the smaller point index). One part or none: the group is one piece. Each piece sorted; the pieces in
/// the order of their first point. Why: the alpha radius (3 r, about 0.33 m at 80 points/m²) links two things
/// that stand 0.15-0.3 m apart, and one piece got one box over both: a shelf with the table or the pillar beside
/// it, a chair with the desk it is tucked at (#162: 45 of the 18 offices' pieces held two or more pieces of
/// furniture, a third of truth -> mesh), the box's bottom under the table's top for the shelf too, the shelf's
/// boards inside the table's box. Points closer than two spacings sample one surface; a gap of two to three
/// spacings between two parts that each hold a surface of their own is between two things. A tighter link for
/// every piece broke chairs and tables into groups smaller than a piece (#162); here what holds no plane of its
/// own stays with what it stands nearest to.
std::vector<std::vector<int>> furniture_pieces(const std::vector<Vec3>& points, const std::vector<int>& point_plane,
                                               const std::vector<int>& off, double link, double split_link,
                                               int min_points, bool across_planes, std::vector<std::vector<int>>* groups_out) {
  std::vector<std::vector<int>> pieces;
  for (std::vector<int>& group : linked_groups(points, off, link)) {
    const auto whole = [&] {
      if (groups_out) groups_out->push_back(group);
      pieces.push_back(std::move(group));
    };
    if (!(split_link > 0) || static_cast<int>(group.size()) < 2 * min_points) {
      whole();
      continue;
    }
    const std::vector<std::vector<int>> sub = linked_groups(points, group, split_link);
    std::vector<int> root(sub.size());  // sub-groups holding inliers of one plane are one part
    for (std::size_t i = 0; i < root.size(); ++i) root[i] = static_cast<int>(i);
    const auto find = [&](int i) {
      while (root[static_cast<std::size_t>(i)] != i)
        i = root[static_cast<std::size_t>(i)] = root[static_cast<std::size_t>(root[static_cast<std::size_t>(i)])];
      return i;
    };
    std::map<int, std::map<int, int>> holding;  // a plane -> its inliers per sub-group
    for (std::size_t g = 0; g < sub.size(); ++g)
      for (int p : sub[g]) {
        const int k = static_cast<std::size_t>(p) < point_plane.size() ? point_plane[static_cast<std::size_t>(p)] : -1;
        if (k >= 0) ++holding[k][static_cast<int>(g)];
      }
    for (const auto& [k, per] : holding) {  // its inliers' sub-groups join the one holding most of them, but two holding min_points each
      int major = -1, most = 0, majors = 0;
      for (const auto& [g, c] : per) {
        if (c >= min_points) ++majors;
        if (c > most) most = c, major = g;
      }
      for (const auto& [g, c] : per) {
        if (across_planes && majors >= 2 && c >= min_points) continue;
        const int a = find(major), b = find(g);
        if (a != b) root[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
      }
    }
    std::vector<std::vector<int>> parts;  // by root, in the order of their first sub-group
    std::vector<int> part_of(sub.size(), -1);
    std::vector<char> has_plane;
    for (std::size_t g = 0; g < sub.size(); ++g) {
      const std::size_t r0 = static_cast<std::size_t>(find(static_cast<int>(g)));
      if (part_of[r0] < 0) part_of[r0] = static_cast<int>(parts.size()), parts.emplace_back(), has_plane.push_back(0);
      const std::size_t q = static_cast<std::size_t>(part_of[r0]);
      parts[q].insert(parts[q].end(), sub[g].begin(), sub[g].end());
      for (int p : sub[g])
        if (static_cast<std::size_t>(p) < point_plane.size() && point_plane[static_cast<std::size_t>(p)] >= 0) has_plane[q] = 1;
    }
    std::vector<int> cores;  // the parts that are objects of their own
    for (std::size_t q = 0; q < parts.size(); ++q)
      if (has_plane[q] && static_cast<int>(parts[q].size()) >= min_points) cores.push_back(static_cast<int>(q));
    if (cores.size() < 2) {
      whole();
      continue;
    }
    std::vector<Vec3> core_xyz;
    std::vector<int> core_point, core_owner;  // per point of the tree: its index, its core (into `cores`)
    for (std::size_t c = 0; c < cores.size(); ++c)
      for (int p : parts[static_cast<std::size_t>(cores[c])])
        core_point.push_back(p), core_owner.push_back(static_cast<int>(c));
    std::vector<std::size_t> order(core_point.size());  // the tree over the core points by index: ties go to the smaller
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return core_point[a] < core_point[b]; });
    for (std::size_t i : order) core_xyz.push_back(points[static_cast<std::size_t>(core_point[i])]);
    const KdTree tree(core_xyz);
    std::vector<std::vector<int>> out(cores.size());
    for (std::size_t c = 0; c < cores.size(); ++c) out[c] = parts[static_cast<std::size_t>(cores[c])];
    for (std::size_t q = 0; q < parts.size(); ++q) {
      if (std::find(cores.begin(), cores.end(), static_cast<int>(q)) != cores.end()) continue;
      double best = std::numeric_limits<double>::infinity();
      int to = 0;
      for (int p : parts[q]) {  // parts[q] is in ascending order of its sub-groups, each sorted: first wins ties
        double d2 = 0;
        const int i = tree.nearest(points[static_cast<std::size_t>(p)], &d2);
        if (d2 < best) best = d2, to = core_owner[order[static_cast<std::size_t>(i)]];
      }
      out[static_cast<std::size_t>(to)].insert(out[static_cast<std::size_t>(to)].end(), parts[q].begin(), parts[q].end());
    }
    for (std::vector<int>& piece : out) std::sort(piece.begin(), piece.end());
    std::sort(out.begin(), out.end(), [](const std::vector<int>& a, const std::vector<int>& b) { return a.front() < b.front(); });
    for (std::vector<int>& piece : out) {
      if (groups_out) groups_out->push_back(group);
      pieces.push_back(std::move(piece));
    }
  }
  return pieces;
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

/// A room (RecoveryParams::level_sides): the sides no scanner saw under a raised level top, as upright planes
/// down to the floor (see recovery.h).
std::vector<RecoveredPlane> level_sides(const PointCloud& cloud, const SceneStructure& structure,
                                        const RecoveryResult& res, const RecoveryParams& params) {
  const double r = structure.spacing > 0 ? structure.spacing : 1.0;
  const double r_d = params.distance * r;
  const double cos_a = std::cos(params.angle_deg * M_PI / 180.0);
  const double floor_z = room_floor(cloud);
  const std::vector<Vec3> floor = params.free_under_tops ? floor_seen(cloud, floor_z, r, cos_a) : std::vector<Vec3>{};
  const std::vector<std::pair<double, int>> rim = rim_candidates(cloud, structure.point_plane, params.rim_underside);
  std::vector<RecoveredPlane> sides;
  for (std::size_t i = 0; i < structure.planes.size(); ++i) {
    const DetectedPlane& top = structure.planes[i];
    if (!(top.plane.normal.z() > cos_a) || !(top.centroid.z() - floor_z > r_d)) continue;  // a raised top, facing up
    const double underside = underside_of_top(cloud, structure, static_cast<int>(i), floor, r, params, nullptr, rim);
    const double bottom = std::isfinite(underside) ? underside : floor_z;
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
      for (const Vec3& e : {seg.a, seg.b}) {  // the side spans the edge, from the top down to the floor (its underside)
        const Vec3 on = e - plane.normal * plane.signed_distance(e);
        side.reach.push_back(on);
        side.reach.emplace_back(on.x(), on.y(), bottom);
      }
      sides.push_back(std::move(side));
    }
  }
  return sides;
}

namespace {

/// Whether detected planes a and b are the two faces of one slab: upright, parallel within r_a (either way), and
/// nearer each other than `thickness` (a's centroid from b's plane).
bool slab_faces(const SceneStructure& structure, int a, int b, double sin_a, double cos_a, double thickness) {
  const DetectedPlane& pa = structure.planes[static_cast<std::size_t>(a)];
  const DetectedPlane& pb = structure.planes[static_cast<std::size_t>(b)];
  return std::abs(pa.plane.normal.z()) < sin_a && std::abs(pb.plane.normal.z()) < sin_a &&
         std::abs(pa.plane.normal.dot(pb.plane.normal)) > cos_a && std::abs(pb.plane.signed_distance(pa.centroid)) < thickness;
}

/// A jamb of an opening through a slab: an upright boundary segment of each face at one place along the slab.
struct SlabJamb {
  double t = 0;      ///< position along the slab (metres along `along`)
  int side = 0;      ///< +1: the opening lies towards +along (the segments' outward normals point there), -1: towards -along
  SegmentRef on_a, on_b;
};

/// The jambs of the slab with faces a and b: an upright segment of a (its direction within the jamb angle of
/// vertical, its outward normal within it of the slab's direction; `cos_j` its cosine, RecoveryParams::
/// jamb_angle_deg) and one of b facing the same way, nearer each other along the slab than r; in order along it.
std::vector<SlabJamb> slab_jambs(const PointCloud& cloud, const SceneStructure& structure, int a, int b,
                                 const Vec3& along, double cos_j, double r) {
  const auto upright = [&](int k) {
    std::vector<std::pair<double, int>> out;  // (t, side) per segment, -side 0 when not upright across
    const DetectedPlane& dp = structure.planes[static_cast<std::size_t>(k)];
    for (const BoundarySegment& seg : dp.segments) {
      const Vec3 d = seg.b - seg.a;
      const double c = seg.normal.dot(along);
      const bool up = d.norm() > 0 && std::abs(d.normalized().z()) > cos_j && std::abs(c) > cos_j;
      out.emplace_back(along.dot(segment_centroid(cloud, seg)), up ? (c > 0 ? 1 : -1) : 0);
    }
    return out;
  };
  const auto ja = upright(a), jb = upright(b);
  std::vector<SlabJamb> jambs;
  for (std::size_t i = 0; i < ja.size(); ++i) {
    if (ja[i].second == 0) continue;
    int best = -1;
    for (std::size_t j = 0; j < jb.size(); ++j)
      if (jb[j].second == ja[i].second && std::abs(jb[j].first - ja[i].first) < r &&
          (best < 0 || std::abs(jb[j].first - ja[i].first) < std::abs(jb[static_cast<std::size_t>(best)].first - ja[i].first)))
        best = static_cast<int>(j);
    if (best < 0) continue;
    jambs.push_back({0.5 * (ja[i].first + jb[static_cast<std::size_t>(best)].first), ja[i].second,
                     SegmentRef{a, static_cast<int>(i)}, SegmentRef{b, best}});
  }
  std::stable_sort(jambs.begin(), jambs.end(), [](const SlabJamb& x, const SlabJamb& y) { return x.t < y.t; });
  return jambs;
}

/// The head of an opening (RecoveryParams::lintel_gap): the lowest row of its lintel, the points `between` the
/// jambs hanging from the highest one, with no gap in height wider than `gap` between one and the next; lower
/// points stand apart from the lintel. A jamb found a few centimetres inside the opening's true edge (its
/// segments' mean) counts the edge's own rows between the jambs, at any height down to the floor: taking the
/// lowest of all put the head at a chair seat's height or rejected the opening as reaching down to the floor, and
/// the doorway stayed closed above it (issue 41 item 5). `gap` 0: the lowest of all (DECISIONS #97).
double lintel_head(const PointCloud& cloud, const std::vector<int>& between, double gap) {
  std::vector<double> z;
  z.reserve(between.size());
  for (int p : between) z.push_back(cloud.points[static_cast<std::size_t>(p)].z());
  if (z.empty()) return std::numeric_limits<double>::infinity();
  std::sort(z.begin(), z.end(), std::greater<>());
  std::size_t k = 0;
  while (k + 1 < z.size() && (gap <= 0 || z[k] - z[k + 1] <= gap)) ++k;
  return z[k];
}

/// A point of face f at position t along the slab and height z.
Vec3 on_face(const DetectedPlane& f, const Vec3& along, double t, double z) {
  Vec3 c = f.centroid + (t - along.dot(f.centroid)) * along;
  c -= f.plane.normal * f.plane.signed_distance(c);
  c.z() = z;
  return c;
}

/// Where an opening's edge stands at a jamb (RecoveryParams::jamb_at_edge): the outermost, towards the opening, of
/// the slab faces' inliers below the head within `reach` of the jamb along the slab; `jamb.t` when there is none.
/// A jamb's segments are fitted to the edge's boundary points, a strip of about a spacing, so their mean lies
/// about half a spacing inside the wall (office 6 rooms seeds 1 and 2: 3-5 cm): the faces' points between it and
/// the true edge then lay on the doorway's own facets, facing out of it, and with a piece's plane cutting the
/// doorway at a seat's height their votes made the cell above it solid, a block across the doorway (issue 41
/// item 5). Below the head nothing of the faces stands in the opening, so the outermost inlier there is the
/// edge, and every point of the faces lies on the wall's side of it.
double opening_edge(const PointCloud& cloud, const DetectedPlane& fa, const DetectedPlane& fb, const SlabJamb& jamb,
                    const Vec3& along, double head, double reach) {
  double edge = jamb.t;
  bool found = false;
  for (const DetectedPlane* f : {&fa, &fb})
    for (int p : f->inliers) {
      const Vec3& q = cloud.points[static_cast<std::size_t>(p)];
      const double t = along.dot(q);
      if (!(q.z() < head) || !(std::abs(t - jamb.t) < reach)) continue;
      if (!found || jamb.side * (t - edge) > 0) edge = t;
      found = true;
    }
  return found ? edge : jamb.t;
}

}  // namespace

/// A room (RecoveryParams::opening_heads): the jambs and heads of the openings through slabs (see recovery.h).
std::vector<RecoveredPlane> slab_openings(const PointCloud& cloud, const SceneStructure& structure,
                                          const RecoveryParams& params) {
  const double r = structure.spacing > 0 ? structure.spacing : 1.0;
  const double r_d = params.distance * r;
  const double sin_a = std::sin(params.angle_deg * M_PI / 180.0), cos_a = std::cos(params.angle_deg * M_PI / 180.0);
  const double floor_z = room_floor(cloud);
  std::vector<RecoveredPlane> out;
  const int m = static_cast<int>(structure.planes.size());
  for (int a = 0; a < m; ++a)
    for (int b = a + 1; b < m; ++b) {
      if (!slab_faces(structure, a, b, sin_a, cos_a, params.slab_thickness * r)) continue;
      const DetectedPlane& fa = structure.planes[static_cast<std::size_t>(a)];
      const DetectedPlane& fb = structure.planes[static_cast<std::size_t>(b)];
      const Vec3 along = Vec3(-fa.plane.normal.y(), fa.plane.normal.x(), 0.0).normalized();
      const std::vector<SlabJamb> jambs =
          slab_jambs(cloud, structure, a, b, along, std::cos(params.jamb_angle_deg * M_PI / 180.0), r);
      for (std::size_t k = 0; k < jambs.size(); ++k) {
        if (jambs[k].side != 1) continue;  // an opening's first jamb; its other: the next one facing back
        std::size_t e = k + 1;
        while (e < jambs.size() && jambs[e].side != -1) ++e;
        if (e == jambs.size()) continue;
        const double t0 = jambs[k].t, t1 = jambs[e].t;
        if (!(t1 - t0 > 2.0 * r)) continue;
        std::vector<int> between;  // the faces' inliers between the jambs: the lintel
        for (const DetectedPlane* f : {&fa, &fb})
          for (int p : f->inliers) {
            const double t = along.dot(cloud.points[static_cast<std::size_t>(p)]);
            if (t > t0 + 0.5 * r && t < t1 - 0.5 * r) between.push_back(p);
          }
        const double head = lintel_head(cloud, between, params.lintel_gap * r);
        between.erase(std::remove_if(between.begin(), between.end(),
                                     [&](int p) { return cloud.points[static_cast<std::size_t>(p)].z() < head; }),
                      between.end());
        // An opening from the floor with a lintel over it: nothing between the jambs below the head, the head
        // well above the floor, and the lintel seen.
        if (between.size() < 3 || !(head - floor_z > r_d)) continue;
        double edge[2] = {t0, t1};  // where each jamb's plane stands along the slab
        for (int s = 0; s < 2; ++s) {  // the jambs, across the slab from the floor to the head
          const SlabJamb* j = s == 0 ? &jambs[k] : &jambs[e];
          std::vector<SegmentRef> segs = {j->on_a, j->on_b};
          Plane plane;
          plane.normal = static_cast<double>(j->side) * along;  // outward: into the opening, as the segments face
          std::vector<int> pts;
          for (const SegmentRef& g : segs) {
            const BoundarySegment& seg = structure.planes[static_cast<std::size_t>(g.plane)].segments[static_cast<std::size_t>(g.segment)];
            pts.insert(pts.end(), seg.support.begin(), seg.support.end());
          }
          if (params.jamb_at_edge) {
            edge[s] = opening_edge(cloud, fa, fb, *j, along, head, r);
            plane.offset = -plane.normal.dot(on_face(fa, along, edge[s], 0.0));
          } else {
            plane.offset = -plane.normal.dot(pts.empty() ? on_face(fa, along, j->t, 0.0) : cloud.mean_of(pts));
          }
          RecoveredPlane jamb = recovered_plane(structure, plane, segs);
          for (const DetectedPlane* f : {&fa, &fb})
            for (double z : {floor_z, head}) jamb.reach.push_back(on_face(*f, along, edge[s], z));
          out.push_back(std::move(jamb));
        }
        RecoveredPlane h;
        h.plane.normal = Vec3(0, 0, -1);  // outward: down, the lintel above
        h.plane.offset = head;
        for (int p : between)
          if (cloud.points[static_cast<std::size_t>(p)].z() < head + r) h.support.push_back(p);
        std::sort(h.support.begin(), h.support.end());
        for (const DetectedPlane* f : {&fa, &fb})
          for (double t : edge) h.reach.push_back(on_face(*f, along, t, head));
        h.caps = {a, b};
        out.push_back(std::move(h));
      }
    }
  return out;
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

/// How high above the room's floor a piece's level plane facing up is a raised top, in metres
/// (RecoveryParams::piece_top_height; r_d when not set). Why: a chair's seat (0.48-0.54 m on the synth office) lay
/// under r_d (0.55 m at 80 points/m²), so it was no top: no free space under it, no step at it, and the chair's box
/// stood from the floor to its back's top with the seat inside (DECISIONS #168). The floor's points lie within a
/// spacing of the floor; a top two spacings above it is clear of them.
double piece_top_height(const RecoveryParams& params, double r) {
  return params.piece_top_height > 0 ? params.piece_top_height * r : params.distance * r;
}

/// A room (RecoveryParams::piece_boxes): each piece's box completes the faces no plane of it covers (see
/// recovery.h). `recovered`: the planes recovered so far (one recovered from the piece's planes covers a face);
/// `corner` (one flag per recovered plane) marks those grown from segments of a boxed piece's planes alone that
/// face along none of its box's faces.
std::vector<RecoveredPlane> piece_boxes(const PointCloud& cloud, const SceneStructure& structure,
                                         const std::vector<bool>& enclosure, const RecoveryParams& params,
                                         const std::vector<RecoveredPlane>& recovered, std::size_t* pieces,
                                         std::vector<char>& corner, std::vector<std::vector<Plane>>& slabs) {
  const double r = structure.spacing > 0 ? structure.spacing : 1.0;
  const double link = params.piece_link > 0 ? params.piece_link * r : structure.alpha_radius > 0 ? structure.alpha_radius : 3.0 * r;
  const double cos_a = std::cos(params.angle_deg * M_PI / 180.0);
  const double floor_z = room_floor(cloud);
  const double top_height = piece_top_height(params, r);
  const std::vector<Vec3> floor = params.free_under_tops ? floor_seen(cloud, floor_z, r, cos_a) : std::vector<Vec3>{};
  const std::vector<std::pair<double, int>> rim = rim_candidates(cloud, structure.point_plane, params.rim_underside);
  std::vector<int> off;  // the points on no enclosing plane
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const int k = i < structure.point_plane.size() ? structure.point_plane[i] : -1;
    if (k < 0 || static_cast<std::size_t>(k) >= enclosure.size() || !enclosure[static_cast<std::size_t>(k)])
      off.push_back(static_cast<int>(i));
  }
  std::vector<int> loose;  // the points on no plane (edge_boards)
  if (params.edge_boards)
    for (std::size_t i = 0; i < cloud.size(); ++i)
      if (!(i < structure.point_plane.size() && structure.point_plane[i] >= 0)) loose.push_back(static_cast<int>(i));
  std::vector<int> enclosing;
  for (std::size_t k = 0; k < enclosure.size() && k < structure.planes.size(); ++k)
    if (enclosure[k]) enclosing.push_back(static_cast<int>(k));
  const std::vector<std::vector<int>> from = recovered_from(structure.planes.size(), recovered);
  std::vector<RecoveredPlane> faces;
  *pieces = 0;
  std::vector<std::vector<int>> groups;  // per piece, its whole linked group
  const std::vector<std::vector<int>> all_pieces = furniture_pieces(cloud.points, structure.point_plane, off, link,
                                                       params.piece_split_link * r, params.min_piece_points,
                                                       params.piece_split_across_planes, &groups);
  for (std::size_t pi = 0; pi < all_pieces.size(); ++pi) {
    const std::vector<int>& piece = all_pieces[pi];
    if (static_cast<int>(piece.size()) < params.min_piece_points) continue;
    // Its planes lie in its group (a plane across two parts of it, #210, lies in both); those it holds inliers of.
    if (!planes_of_piece(structure, groups[pi], static_cast<std::size_t>(params.min_piece_points))) continue;
    const std::optional<std::vector<int>> planes =
        planes_of_piece(structure, piece, std::numeric_limits<std::size_t>::max());
    int seen_plane = -1;  // the plane of its one seen side
    const Vec3 seen =
        params.min_piece_depth > 0 ? one_seen_side(cloud, structure, *planes, params.angle_deg, &seen_plane) : Vec3::Zero();
    static const std::vector<int> kNoFace;
    const std::vector<int>& seen_face = seen_plane >= 0 ? structure.planes[static_cast<std::size_t>(seen_plane)].inliers : kNoFace;
    double facing = facing_of_piece(structure, *planes, params.angle_deg);
    if (!std::isfinite(facing)) {  // the points' smallest-area rectangle (box_of_piece's own choice)
      std::vector<Vec2> xy;
      for (int p : piece) xy.push_back(cloud.points[static_cast<std::size_t>(p)].head<2>());
      facing = min_area_rectangle(xy).angle;
    }
    const std::optional<SeatStep> step =
        seat_step(cloud, structure, piece, *planes, facing, floor_z, r, top_height, cos_a,
                  params.step_min_free * r, params.step_min_width * r, params.step_min_points, params.seat_min_points);
    double underside = std::numeric_limits<double>::quiet_NaN();  // the lowest underside of its raised tops
    bool underside_from_rim = false;  // that underside is where its top's rim ends (rim_underside)
    std::vector<int> free_under;  // its raised tops with free space under them (their undersides set `underside`)
    std::vector<double> free_under_at;  // the underside of each
    for (int k : *planes) {
      const DetectedPlane& top = structure.planes[static_cast<std::size_t>(k)];
      if (top.plane.normal.z() > cos_a && top.centroid.z() - floor_z > top_height) {
        // free_under_seats; free_under_lone_tops: a top with nothing of its piece standing on it is a seat too.
        const bool seat = (params.free_under_seats && step && step->top == k) ||
                          (params.free_under_lone_tops && params.free_under_seats && !step &&
                           lone_top(cloud, piece, top, floor_z, r, params.step_min_points));
        // The floor seen under it is free space whatever stands there (panels_as_posts: on posts), else a seat's
        // free space when nothing upright stands under it (free_under_seats).
        bool from_rim = false;
        double u = params.panels_as_posts
                       ? underside_of_top(cloud, structure, k, floor, r, params, &*planes, rim, &from_rim, true, false)
                       : std::numeric_limits<double>::quiet_NaN();
        if (!std::isfinite(u)) u = underside_of_top(cloud, structure, k, floor, r, params, &*planes, rim, &from_rim, !seat);
        if (std::isfinite(u)) free_under.push_back(k), free_under_at.push_back(u);
        if (std::isfinite(u) && !(u >= underside)) underside = u, underside_from_rim = from_rim;
      }
    }
    // A seat no plane holds (seat_level) has free space under it as a seat's plane has (free_under_seats): its
    // underside top_thickness under it when no upright plane of the piece reaches under that.
    if (step && step->top < 0 && params.free_under_seats && params.free_under_tops) {
      const double u = step->z - params.top_thickness * r;
      if (!upright_below(cloud, structure, *planes, u - r, params) && !(u >= underside))
        underside = u, underside_from_rim = false;
    }
    std::vector<char> upper_part;  // per face of the box: it holds part of the box above its step (box_of_piece)
    std::vector<SeenPlane> seen_planes;
    for (int k : *planes) {
      const DetectedPlane& dp = structure.planes[static_cast<std::size_t>(k)];
      seen_planes.push_back({seen_normal(cloud, dp), dp.centroid});
    }
    const double inner_depth = step ? 0.0 : params.inner_face_depth * r;
    std::vector<RecoveredPlane> box =
        box_of_piece(cloud, piece, structure.point_plane, facing, floor_z, r, params.distance * r, underside,
                     underside_from_rim, seen,
                     seen_face, params.depth_from_seen_face, params.min_piece_depth * r, static_cast<int>(*pieces), step, &upper_part, seen_planes, cos_a,
                     inner_depth, params.step_min_points, params.round_sides,
                     sideways_plane_residual(cloud, structure, piece, std::sin(params.angle_deg * M_PI / 180.0)));
    if (params.solid_slabs && underside_from_rim)
      for (std::vector<Plane>& slab : slabs_of_box(structure, box, tops_at_bottom(free_under, free_under_at, underside, r), underside))
        slabs.push_back(std::move(slab));
    std::vector<RecoveredPlane> posts =
        box.empty() ? std::vector<RecoveredPlane>{}
                    : posts_under_top(cloud, piece, structure.point_plane, facing, floor_z, underside,
                                      params.post_link * r, params.post_min_points, params.post_min_width * r,
                                      static_cast<int>(*pieces));
    std::vector<RecoveredPlane> boards =
        box.empty() ? std::vector<RecoveredPlane>{}
                    : board_slabs(cloud, structure, piece, *planes,
                                  params.boards_over_underside ? tops_at_bottom(free_under, free_under_at, underside, r)
                                                               : free_under,
                                  facing, floor_z, r, cos_a,
                                  params.board_thickness * r, params.board_min_points, static_cast<int>(*pieces));
    for (RecoveredPlane& f : boards) posts.push_back(std::move(f));
    if (params.edge_boards)
      for (RecoveredPlane& f : edge_boards(cloud, structure, loose, *planes, box, floor_z, r, cos_a, params.min_piece_depth * r,
                                           params.board_thickness * r, params.edge_board_height * r,
                                           params.edge_board_min_width * r, params.edge_board_min_points,
                                           static_cast<int>(*pieces)))
        posts.push_back(std::move(f));
    if (!posts.empty()) {  // a post's or a board's points vote for it, not for the box around it
      std::vector<int> on_posts;
      for (const RecoveredPlane& f : posts) on_posts.insert(on_posts.end(), f.support.begin(), f.support.end());
      std::sort(on_posts.begin(), on_posts.end());
      on_posts.erase(std::unique(on_posts.begin(), on_posts.end()), on_posts.end());
      for (RecoveredPlane& f : box) {
        std::vector<int> kept_support;
        std::set_difference(f.support.begin(), f.support.end(), on_posts.begin(), on_posts.end(), std::back_inserter(kept_support));
        f.support = std::move(kept_support);
      }
    }
    std::vector<int> own_recovered;  // recovered from the piece's planes (a cap, a side, a grown plane)
    for (int k : *planes) own_recovered.insert(own_recovered.end(), from[static_cast<std::size_t>(k)].begin(), from[static_cast<std::size_t>(k)].end());
    std::sort(own_recovered.begin(), own_recovered.end());
    own_recovered.erase(std::unique(own_recovered.begin(), own_recovered.end()), own_recovered.end());
    // A bottom hanging as thin as its tops' rims lies within r of what was recovered from those tops (their caps,
    // their planes grown again): those stand for the tops, not for the underside (as not_its_own_tops).
    std::vector<int> from_its_tops;
    if (underside_from_rim)
      for (int k : free_under) from_its_tops.insert(from_its_tops.end(), from[static_cast<std::size_t>(k)].begin(), from[static_cast<std::size_t>(k)].end());
    std::sort(from_its_tops.begin(), from_its_tops.end());
    std::vector<Vec3> axes;  // the box's face normals (its faces move into `faces` below)
    for (const RecoveredPlane& f : box) axes.push_back(f.plane.normal);
    std::size_t kept = 0;
    for (std::size_t f = 0; f < box.size(); ++f) {
      RecoveredPlane& face = box[f];
      Vec3 centre = Vec3::Zero();
      for (const Vec3& q : face.reach) centre += q;
      centre /= static_cast<double>(face.reach.size());
      const auto by = [&](const Plane& plane) { return covers(plane, face.plane.normal, centre, cos_a, r); };
      // The part above a step is as thin as a chair's back, both its sides within r of the back's plane: there a
      // plane of the piece covers only the side it was seen from (its inliers' mean normal along the face's).
      const bool thin = f < upper_part.size() && upper_part[f];
      const auto detected = [&](int k) {
        const DetectedPlane& dp = structure.planes[static_cast<std::size_t>(k)];
        return by(dp.plane) && (!thin || seen_normal(cloud, dp).dot(face.plane.normal) > cos_a);
      };
      // A plane of the piece seen from inside the box is an inner face (behind_inner_faces), not its side: when the
      // box stands behind inner faces (inner_depth > 0), on its top and upright sides (its bottom hangs under a
      // top). A room's wall or floor covers a side from either side (a cabinet against a wall).
      const bool outer_only = inner_depth > 0 && face.plane.normal.z() > -cos_a;
      const auto own_detected = [&](int k) {
        return detected(k) && !(outer_only && seen_normal(cloud, structure.planes[static_cast<std::size_t>(k)])
                                                      .dot(face.plane.normal) < -cos_a);
      };
      const auto own_covers = [&](int q) {
        return by(recovered[static_cast<std::size_t>(q)].plane) &&
               !(face.plane.normal.z() < 0 && std::binary_search(from_its_tops.begin(), from_its_tops.end(), q));
      };
      if (std::any_of(enclosing.begin(), enclosing.end(), detected) || std::any_of(own_recovered.begin(), own_recovered.end(), own_covers))
        continue;
      std::vector<int> covering;  // the piece's planes lying on the face
      std::copy_if(planes->begin(), planes->end(), std::back_inserter(covering), own_detected);
      if (face.plane.normal.z() < 0) covering = not_its_own_tops(covering, free_under);
      if (!covering.empty() &&
          !side_below_cover(face, lowest_covering_inlier(cloud, structure, covering), params.box_side_gap * r))
        continue;
      face.caps = *planes;  // adjacent to the piece's planes too
      faces.push_back(std::move(face));
      ++kept;
    }
    for (RecoveredPlane& post : posts) {  // after the box's faces, with its number: adjacent to them and each other
      post.caps = *planes;
      faces.push_back(std::move(post));
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

}  // namespace hsr::recovery_internal
