// Stage 3: singular segments and the recovery of missing planes from them (paper §3.3, supplement §1.2; see
// recovery.h), and run_recovery's chain, which calls a building's walls (building_walls.cpp) and a room's rules
// (room_rules.cpp) when their parameters ask. Second-order neighbours read as every plane within two hops:
// DECISIONS #5. Plain Eigen.
#include "recovery/recovery.h"

#include "recovery/recovery_internal.h"

#include "core/error.h"
#include "core/log.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <deque>
#include <sstream>

namespace hsr {

std::size_t RecoveryResult::num_singular() const {
  std::size_t n = 0;
  for (const auto& plane : singular)
    for (bool s : plane) n += s;
  return n;
}

namespace recovery_internal {

/// Centroid of a segment: the mean of its supporting points, or its midpoint when it has none.
Vec3 segment_centroid(const PointCloud& cloud, const BoundarySegment& s) {
  return s.support.empty() ? Vec3(0.5 * (s.a + s.b)) : cloud.mean_of(s.support);
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

}  // namespace recovery_internal

using namespace recovery_internal;

namespace {

/// How far intersection line `L` lies behind segment `s` (centroid `c`), against the segment's outward normal:
/// positive where the line runs inside the plane's region, 0 or negative at or beyond its edge.
double line_behind_segment(const BoundarySegment& s, const IntersectionLine& L, const Vec3& c) {
  Vec3 n = s.normal - s.normal.dot(L.direction) * L.direction;
  if (!(n.norm() > 0)) return 0.0;
  n.normalize();
  return (c - L.point).dot(n);
}

double mean_abs_distance(const PointCloud& cloud, const std::vector<int>& idx, const Plane& p) {
  if (idx.empty()) return 0.0;
  double sum = 0;
  for (int i : idx) sum += std::abs(p.signed_distance(cloud.points[static_cast<std::size_t>(i)]));
  return sum / static_cast<double>(idx.size());
}

}  // namespace

RecoveryResult run_recovery(const PointCloud& cloud, const SceneStructure& structure,
                            const RecoveryParams& params, const std::vector<bool>& enclosure,
                            const std::vector<int>& walls_around_roofs) {
  if (!(params.angle_deg > 0 && params.angle_deg < 90) || !(params.distance > 0) || params.min_segments < 1 ||
      !(params.snap_deg >= 0 && params.snap_deg < 45) || !(params.min_wall_length >= 0) ||
      !(params.roof_min_tilt_deg >= 0 && params.roof_min_tilt_deg < 90) || !std::isfinite(params.main_direction) ||
      !(params.wall_join_distance > 0) || !(params.wall_edge_quantile >= 0 && params.wall_edge_quantile <= 1) ||
      params.min_piece_points < 1 || !std::isfinite(params.around_side_same_wall))
    throw Error(Status::BadInput, "recovery",
                "parameters: 0 < angle_deg < 90, distance > 0, min_segments >= 1, 0 <= snap_deg < 45, "
                "min_wall_length >= 0, 0 <= roof_min_tilt_deg < 90, wall_join_distance > 0, 0 <= wall_edge_quantile <= 1, "
                "min_piece_points >= 1, around_side_same_wall finite");
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
        // Building mode: a line well inside the roof (behind the segment) is another of its edges, not this one's.
        if (params.vertical && line_behind_segment(s, L, c) > params.partner_max_behind * r &&
            params.partner_max_behind >= 0)
          continue;
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
    std::size_t around = 0;
    for (int roof : walls_around_roofs)
      for (RecoveredPlane& wall : walls_around_roof(cloud, structure, roof, params)) {
        take_the_plane_of_a_wall_there(res.recovered, params.around_side_same_wall * r, cos_a, wall);
        res.recovered.push_back(std::move(wall));
        ++around;
      }
    log::info("[recovery] " + std::to_string(res.num_singular()) + " singular segments, " +
              std::to_string(res.recovered.size()) + " walls recovered (vertical prior" +
              (around ? ", " + std::to_string(around) + " of them around " +
                            std::to_string(walls_around_roofs.size()) + " roofs the first model left out"
                      : std::string()) + ")");
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
  std::size_t heads = 0;
  if (params.opening_heads)
    for (RecoveredPlane& part : slab_openings(cloud, structure, params)) {
      heads += part.caps.size() == 2;  // a head (its jambs: two segments each)
      res.recovered.push_back(std::move(part));
    }

  if (params.one_plane_per_surface)
    res.recovered = one_plane_per_surface(cloud, detected_extents(cloud, structure), std::move(res.recovered), cos_a, r,
                                          &res.covered);
  std::size_t pieces = 0, piece_faces = 0, corners = 0;
  if (params.piece_boxes) {
    // A piece's box stands for the planes its own segments would recover; one facing along none of its faces
    // is a corner's artefact (a boundary segment cutting across the corner of an alpha shape): left out.
    std::vector<char> corner(res.recovered.size(), 0);
    std::vector<RecoveredPlane> boxes = piece_boxes(cloud, structure, enclosure, params, res.recovered, &pieces, corner,
                                                       res.solid_slabs);
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
  if (caps || sides || pieces || heads)
    msg << " (" << caps << " of them level caps, " << sides << " upright sides under tops, " << heads
        << " heads of openings through slabs, " << piece_faces
        << " faces of " << pieces << " pieces' boxes, " << corners << " planes across a boxed piece's corners left out, "
        << res.covered << " on a surface a plane already stood for left out)";
  msg << " (r_a " << params.angle_deg << " deg, r_d " << r_d << ")";
  log::info(msg.str());
  return res;
}

}  // namespace hsr
