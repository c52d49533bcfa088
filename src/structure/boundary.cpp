// Stage 1, per plane: 2D frame, regularized alpha shape of the projected inliers (area and boundary points),
// 2D boundary normals (PCA of boundary neighbours, oriented away from the inliers), 2D segments by region
// growing on boundary points (CGAL Shape_detection), group-based regularisation, lift to 3D (DESIGN.md
// "Boundaries and segments").
#include "structure/structure_internal.h"

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Shape_detection/Region_growing/Region_growing.h>
#include <CGAL/Shape_detection/Region_growing/Region_growing_on_point_set.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/property_map.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numeric>
#include <queue>

namespace hsr::structure_detail {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<int, K>;      // index into the input points
using Fb = CGAL::Triangulation_face_base_with_info_2<char, K>;       // 1: interior face of the alpha shape
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Dt = CGAL::Delaunay_triangulation_2<K, Tds>;

constexpr double kPi = 3.14159265358979323846;

Vec2 perp(const Vec2& d) { return {-d.y(), d.x()}; }

// Deterministic in-plane frame: u is the normal crossed with the coordinate axis least aligned with it.
void make_frame(DetectedPlane& p) {
  const Vec3 n = p.plane.normal;
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (std::abs(n(a)) < std::abs(n(axis))) axis = a;
  p.frame_u = n.cross(Vec3::Unit(axis)).normalized();
  p.frame_v = n.cross(p.frame_u);
  p.frame_origin = p.centroid - p.plane.signed_distance(p.centroid) * n;
}

// Unit direction of the principal axis of 2D points (and their centroid).
Vec2 principal_direction(const std::vector<Vec2>& q, Vec2* centroid) {
  Vec2 c = Vec2::Zero();
  for (const auto& x : q) c += x;
  c /= static_cast<double>(std::max<std::size_t>(1, q.size()));
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const auto& x : q) cov += (x - c) * (x - c).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov);
  Vec2 d = es.eigenvectors().col(1);
  if (!std::isfinite(d.x()) || d.norm() < 0.5) d = Vec2::UnitX();
  if (centroid) *centroid = c;
  return d.normalized();
}

struct Segment2 {
  Vec2 a, b, normal;
  std::vector<int> support;  // indices into the boundary arrays
  double length() const { return (b - a).norm(); }
};

// Group-based regularisation (no QP): orientations snap to the longest segment's direction or its
// orthogonal within `angle_tol`, else start a new reference; then near-collinear parallel segments (same
// normal side, offsets within `offset_tol`) share their length-weighted mean offset. Segments rotate about
// their midpoints and keep their extent along the new direction.
void regularize_segments(std::vector<Segment2>& segs, double angle_tol, double offset_tol) {
  std::vector<std::size_t> order(segs.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return segs[a].length() > segs[b].length(); });
  std::vector<double> refs;  // reference orientations in [0, pi)
  std::vector<double> theta(segs.size());
  auto wrap = [](double t) { t = std::fmod(t, kPi); return t < 0 ? t + kPi : t; };
  auto diff = [&](double a, double b) { double d = std::abs(wrap(a - b)); return std::min(d, kPi - d); };
  for (std::size_t idx : order) {
    const Vec2 d = segs[idx].b - segs[idx].a;
    const double t = wrap(std::atan2(d.y(), d.x()));
    double snapped = t;
    bool found = false;
    for (double ref : refs) {
      for (double cand : {ref, wrap(ref + kPi / 2)})
        if (diff(t, cand) <= angle_tol) { snapped = cand; found = true; break; }
      if (found) break;
    }
    if (!found) refs.push_back(t);
    theta[idx] = snapped;
  }
  for (std::size_t i = 0; i < segs.size(); ++i) {
    Segment2& s = segs[i];
    const Vec2 dir(std::cos(theta[i]), std::sin(theta[i]));
    const Vec2 mid = 0.5 * (s.a + s.b);
    const double half = 0.5 * s.length();
    Vec2 nrm = perp(dir);
    if (nrm.dot(s.normal) < 0) nrm = -nrm;
    s.a = mid - half * dir;
    s.b = mid + half * dir;
    s.normal = nrm;
  }
  // Collinear groups among segments sharing an orientation and a normal side.
  std::vector<bool> done(segs.size(), false);
  for (std::size_t oi = 0; oi < order.size(); ++oi) {
    const std::size_t i = order[oi];
    if (done[i]) continue;
    std::vector<std::size_t> group{i};
    const double off_i = segs[i].normal.dot(0.5 * (segs[i].a + segs[i].b));
    for (std::size_t oj = oi + 1; oj < order.size(); ++oj) {
      const std::size_t j = order[oj];
      if (done[j] || segs[j].normal.dot(segs[i].normal) < 1.0 - 1e-9) continue;
      if (std::abs(segs[j].normal.dot(0.5 * (segs[j].a + segs[j].b)) - off_i) <= offset_tol) group.push_back(j);
    }
    double wsum = 0, osum = 0;
    for (std::size_t j : group) {
      done[j] = true;
      const double w = std::max(segs[j].length(), 1e-12);
      wsum += w;
      osum += w * segs[i].normal.dot(0.5 * (segs[j].a + segs[j].b));
    }
    const double target = osum / wsum;
    for (std::size_t j : group) {
      Segment2& s = segs[j];
      const double shift = target - segs[i].normal.dot(0.5 * (s.a + s.b));
      s.normal = segs[i].normal;  // identical (up to rounding) by construction; make it exact
      s.a += shift * s.normal;
      s.b += shift * s.normal;
    }
  }
}

// Neighbour query over an adjacency list (boundary graph).
struct ListNeighborQuery {
  const std::vector<std::vector<int>>* adj;
  void operator()(std::size_t i, std::vector<std::size_t>& out) const {
    for (int j : (*adj)[i]) out.push_back(static_cast<std::size_t>(j));
  }
};

}  // namespace

// ---- The regularized alpha shape, computed on the points near its outline only ---------------------------
//
// CGAL's Alpha_shape_2 of n points costs a Delaunay triangulation of all of them and ordered maps of every
// face's and edge's alpha interval (25 s for the 16 planes of a 3 M-point scan), though its boundary only
// involves points near the outline. This finds those points and gives the same boundary:
//  * A face is interior when its squared circumradius (CGAL's Compute_squared_radius_2, the number
//    Alpha_shape_2 compares) is <= alpha^2; a boundary (REGULAR) edge has one interior face and one
//    exterior one (circumradius > alpha, or the infinite face beyond the convex hull).
//  * A vertex p of an exterior face lies on an empty open disk of radius alpha (inside the face's empty
//    circumdisk, or in the empty half-plane beyond a hull edge): its centre c has no point within alpha.
//    On a grid of side h, c's cell centre is then at least alpha - h sqrt(2) from every occupied cell's
//    centre ("open" cell), and p's cell centre within alpha + h sqrt(2) of it. The candidates S (points
//    whose cell is that close to an open cell) hold every boundary vertex.
//  * The interior face across a boundary edge (a, b) has its third vertex within 2 alpha of a. Q: the
//    points within 2 alpha of S (cell sizes added). In the Delaunay triangulation of Q, an edge with both
//    ends in S and exactly one interior face is a boundary edge of the full shape, and every boundary edge
//    appears so: an interior face with a vertex in S has its circumdisk within 2 alpha of that vertex,
//    where Q holds every point, so it is a Delaunay face of the full set too, and so is the interior face
//    across such an edge when there is one.
// Four cocircular points (a Delaunay tie) may be split by another diagonal; both triangles then have the
// same circumradius, so the boundary does not change. The area is the shoelace sum over the boundary edges.

namespace {

constexpr double kSqrt2 = 1.4142135623730951;
constexpr std::size_t kBandMinPoints = 4096;  ///< below this, every point goes into the triangulation

/// Squared Euclidean distance transform of a W x H grid (Felzenszwalb & Huttenlocher), in squared cell
/// units between cell centres: 0 on `site` cells. Exact (integers); kFar where the grid has no site.
constexpr std::int64_t kFar = std::int64_t(1) << 40;
std::vector<std::int64_t> distance_transform(const std::vector<char>& site, int w, int h) {
  std::vector<std::int64_t> out(site.size()), f(static_cast<std::size_t>(std::max(w, h))),
      d(static_cast<std::size_t>(std::max(w, h)));
  std::vector<int> v(static_cast<std::size_t>(std::max(w, h)));
  std::vector<double> z(static_cast<std::size_t>(std::max(w, h)) + 1);
  auto pass = [&](int n) {  // lower envelope of the parabolas (q - v)^2 + f(v) over the sites f < kFar
    int k = -1;
    for (int q = 0; q < n; ++q) {
      if (f[q] >= kFar) continue;
      double sq = 0;
      while (k >= 0) {
        const int p = v[k];
        sq = (static_cast<double>(f[q] + std::int64_t(q) * q) - static_cast<double>(f[p] + std::int64_t(p) * p)) /
             (2.0 * (q - p));
        if (sq <= z[k]) --k;
        else break;
      }
      ++k;
      v[k] = q;
      z[k] = k == 0 ? -std::numeric_limits<double>::infinity() : sq;
      z[k + 1] = std::numeric_limits<double>::infinity();
    }
    if (k < 0) { std::fill(d.begin(), d.begin() + n, kFar); return; }
    for (int q = 0, j = 0; q < n; ++q) {
      while (z[j + 1] < q) ++j;
      d[q] = std::int64_t(q - v[j]) * (q - v[j]) + f[v[j]];
    }
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) f[x] = site[static_cast<std::size_t>(y) * w + x] ? 0 : kFar;
    pass(w);
    for (int x = 0; x < w; ++x) out[static_cast<std::size_t>(y) * w + x] = d[x];
  }
  for (int x = 0; x < w; ++x) {
    for (int y = 0; y < h; ++y) f[y] = out[static_cast<std::size_t>(y) * w + x];
    pass(h);
    for (int y = 0; y < h; ++y) out[static_cast<std::size_t>(y) * w + x] = std::min(d[y], kFar);
  }
  return out;
}

/// Per point: 2 candidate boundary vertex (S), 1 needed around the candidates (Q \ S), 0 not needed.
/// All 2 when the plane is small or too sparse for the grid to pay (more than 6 cells per point).
std::vector<std::uint8_t> alpha_band(const std::vector<Vec2>& q, double alpha) {
  std::vector<std::uint8_t> band(q.size(), 2);
  if (q.size() < kBandMinPoints || !(alpha > 0)) return band;
  Vec2 lo = q.front(), hi = q.front();
  for (const Vec2& p : q) { lo = lo.cwiseMin(p); hi = hi.cwiseMax(p); }
  const double h = alpha / 4;
  const int pad = 6;  // open cells beyond the hull lie within alpha + h of it
  const double wd = std::floor((hi.x() - lo.x()) / h) + 1 + 2 * pad, hd = std::floor((hi.y() - lo.y()) / h) + 1 + 2 * pad;
  if (!(wd * hd <= 6.0 * static_cast<double>(q.size()) + 65536.0)) return band;
  const int w = static_cast<int>(wd), ht = static_cast<int>(hd);
  auto cell = [&](const Vec2& p) {
    const int cx = std::clamp(static_cast<int>(std::floor((p.x() - lo.x()) / h)) + pad, 0, w - 1);
    const int cy = std::clamp(static_cast<int>(std::floor((p.y() - lo.y()) / h)) + pad, 0, ht - 1);
    return static_cast<std::size_t>(cy) * w + cx;
  };
  std::vector<char> occupied(static_cast<std::size_t>(w) * ht, 0);
  for (const Vec2& p : q) occupied[cell(p)] = 1;
  // Thresholds in squared cell units, widened by a relative 1e-9 (rounding) and, for Q, one cell.
  const double a = alpha / h;
  const double open_min = (a - kSqrt2) * (a - kSqrt2) * (1 - 1e-9);
  const double s_max = (a + kSqrt2) * (a + kSqrt2) * (1 + 1e-9);
  const double q_max = (3 * a + 2 * kSqrt2 + 1) * (3 * a + 2 * kSqrt2 + 1);
  std::vector<std::int64_t> e = distance_transform(occupied, w, ht);
  std::vector<char> open(e.size());
  for (std::size_t c = 0; c < e.size(); ++c) open[c] = static_cast<double>(e[c]) >= open_min;
  e = distance_transform(open, w, ht);
  for (std::size_t i = 0; i < q.size(); ++i) {
    const double d = static_cast<double>(e[cell(q[i])]);
    band[i] = d <= s_max ? 2 : (d <= q_max ? 1 : 0);
  }
  return band;
}

/// Boundary of the alpha shape of `q` restricted to the points with band[i] > 0 (see above).
AlphaShapeBoundary boundary_of_band(const std::vector<Vec2>& q, const std::vector<std::uint8_t>& band, double radius) {
  AlphaShapeBoundary out;
  // Points at one location are one vertex: the smallest index stands for them (so the answer does not
  // depend on which subset is triangulated, nor on the insertion order).
  std::vector<int> keep;
  for (std::size_t i = 0; i < q.size(); ++i)
    if (band[i] > 0) keep.push_back(static_cast<int>(i));
  std::sort(keep.begin(), keep.end(), [&](int a, int b) {
    const Vec2 &u = q[static_cast<std::size_t>(a)], &v = q[static_cast<std::size_t>(b)];
    return u.x() != v.x() ? u.x() < v.x() : (u.y() != v.y() ? u.y() < v.y() : a < b);
  });
  keep.erase(std::unique(keep.begin(), keep.end(), [&](int a, int b) { return q[static_cast<std::size_t>(a)] == q[static_cast<std::size_t>(b)]; }),
             keep.end());
  std::sort(keep.begin(), keep.end());
  std::vector<std::pair<K::Point_2, int>> input;
  input.reserve(keep.size());
  for (const int i : keep) input.emplace_back(K::Point_2(q[static_cast<std::size_t>(i)].x(), q[static_cast<std::size_t>(i)].y()), i);
  Dt dt;
  dt.insert(input.begin(), input.end());
  out.dimension = dt.dimension();
  if (dt.dimension() < 2) return out;
  const double a2 = radius * radius;
  const auto squared_radius = K().compute_squared_radius_2_object();
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f)
    f->info() = squared_radius(f->vertex(0)->point(), f->vertex(1)->point(), f->vertex(2)->point()) <= a2;
  auto interior = [&](Dt::Face_handle f) { return !dt.is_infinite(f) && f->info(); };
  for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e) {
    Dt::Face_handle f = e->first;
    int i = e->second;
    if (band[static_cast<std::size_t>(f->vertex(Dt::cw(i))->info())] != 2 ||
        band[static_cast<std::size_t>(f->vertex(Dt::ccw(i))->info())] != 2)
      continue;
    Dt::Face_handle g = f->neighbor(i);
    if (interior(f) == interior(g)) continue;
    if (!interior(f)) { const int j = g->index(f); f = g; i = j; }
    // Counter-clockwise face: ccw(i) -> cw(i) has the face on its left.
    out.edges.push_back({f->vertex(Dt::ccw(i))->info(), f->vertex(Dt::cw(i))->info()});
    out.inner.push_back(f->vertex(i)->info());
  }
  // Sorted by their endpoints (the order does not depend on the triangulation's).
  std::vector<std::size_t> order(out.edges.size());
  std::iota(order.begin(), order.end(), 0);
  auto key = [&](std::size_t k) {
    return std::make_pair(std::min(out.edges[k][0], out.edges[k][1]), std::max(out.edges[k][0], out.edges[k][1]));
  };
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return key(x) < key(y); });
  AlphaShapeBoundary sorted;
  sorted.dimension = out.dimension;
  for (std::size_t k : order) {
    sorted.edges.push_back(out.edges[k]);
    sorted.inner.push_back(out.inner[k]);
    const Vec2 &p = q[static_cast<std::size_t>(out.edges[k][0])], &r = q[static_cast<std::size_t>(out.edges[k][1])];
    sorted.area += 0.5 * (p.x() * r.y() - r.x() * p.y());
  }
  return sorted;
}

}  // namespace

}  // namespace hsr::structure_detail

namespace hsr {

double DetectedPlane::boundary_distance(const Vec3& c, bool xy) const {
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3& b : boundary_points) best = std::min(best, xy ? (b - c).head<2>().norm() : (b - c).norm());
  return best;
}

AlphaShapeBoundary alpha_shape_boundary(const std::vector<Vec2>& points, double radius) {
  using namespace structure_detail;
  const std::vector<std::uint8_t> band = alpha_band(points, radius);
  AlphaShapeBoundary out = boundary_of_band(points, band, radius);
  // A band that came out flat while the whole set is not (cannot happen for a dense plane; cheap to rule out).
  if (out.dimension < 2 && std::count(band.begin(), band.end(), 0) > 0)
    out = boundary_of_band(points, std::vector<std::uint8_t>(points.size(), 2), radius);
  return out;
}

}  // namespace hsr

namespace hsr::structure_detail {

void compute_boundary(const std::vector<Vec3>& points, int plane_index, DetectedPlane& plane,
                      const StructureParams& params, double r) {
  make_frame(plane);
  plane.area = 0;
  plane.boundary.clear();
  plane.boundary_points.clear();
  plane.boundary_normals.clear();
  plane.boundary_edges.clear();
  plane.segments.clear();

  std::vector<Vec2> projected(plane.inliers.size());
  for (std::size_t k = 0; k < plane.inliers.size(); ++k) projected[k] = plane.to_2d(points[static_cast<std::size_t>(plane.inliers[k])]);
  const AlphaShapeBoundary shape = alpha_shape_boundary(projected, params.alpha_radius * r);
  if (shape.dimension < 2) return;  // collinear inliers: no area, no boundary
  plane.area = std::abs(shape.area);

  // Boundary edges with outward normals (length-weighted), in input indices.
  std::map<int, int> local;  // input index -> boundary slot (sorted by input index below)
  struct Edge { int a, b; Vec2 outward; };
  std::vector<Edge> edges;
  for (std::size_t k = 0; k < shape.edges.size(); ++k) {
    const Vec2 &a = projected[static_cast<std::size_t>(shape.edges[k][0])], &b = projected[static_cast<std::size_t>(shape.edges[k][1])];
    const Vec2& inner = projected[static_cast<std::size_t>(shape.inner[k])];
    Vec2 nrm = perp(b - a);
    if (nrm.norm() == 0) continue;
    nrm.normalize();
    if (nrm.dot(inner - a) > 0) nrm = -nrm;
    const int ia = plane.inliers[static_cast<std::size_t>(shape.edges[k][0])];
    const int ib = plane.inliers[static_cast<std::size_t>(shape.edges[k][1])];
    edges.push_back({ia, ib, nrm * (b - a).norm()});
    local[ia] = 0;
    local[ib] = 0;
  }
  if (edges.empty()) return;
  int slot = 0;
  for (auto& [idx, s] : local) s = slot++;
  const std::size_t nb = local.size();
  std::vector<Vec2> q(nb), outward(nb, Vec2::Zero());
  std::vector<std::vector<int>> adj(nb);
  plane.boundary.resize(nb);
  for (const auto& [idx, s] : local) {
    plane.boundary[s] = idx;
    q[s] = plane.to_2d(points[idx]);
  }
  std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) {
    return std::make_pair(std::min(x.a, x.b), std::max(x.a, x.b)) < std::make_pair(std::min(y.a, y.b), std::max(y.a, y.b));
  });
  for (const auto& e : edges) {
    const int a = local[e.a], b = local[e.b];
    outward[a] += e.outward;
    outward[b] += e.outward;
    adj[a].push_back(b);
    adj[b].push_back(a);
    plane.boundary_edges.push_back({a, b});
  }
  for (auto& l : adj) { std::sort(l.begin(), l.end()); l.erase(std::unique(l.begin(), l.end()), l.end()); }

  // 2D normals: PCA of the boundary neighbours within graph distance, sign from the adjacent edges.
  const int hops = std::max(1, params.boundary_normal_k / 2);
  plane.boundary_normals.resize(nb);
  plane.boundary_points.resize(nb);
  std::vector<int> seen(nb, -1);
  for (std::size_t s = 0; s < nb; ++s) {
    std::vector<int> nbh{static_cast<int>(s)};
    seen[s] = static_cast<int>(s);
    for (std::size_t head = 0, level_end = 1, level = 0; head < nbh.size() && level < static_cast<std::size_t>(hops);) {
      for (; head < level_end; ++head)
        for (int t : adj[nbh[head]])
          if (seen[t] != static_cast<int>(s)) { seen[t] = static_cast<int>(s); nbh.push_back(t); }
      level_end = nbh.size();
      ++level;
    }
    std::vector<Vec2> local_pts;
    for (int t : nbh) local_pts.push_back(q[t]);
    Vec2 nrm = local_pts.size() >= 3 ? perp(principal_direction(local_pts, nullptr)) : outward[s];
    if (nrm.norm() == 0) nrm = Vec2::UnitX();
    nrm.normalize();
    if (nrm.dot(outward[s]) < 0) nrm = -nrm;
    plane.boundary_normals[s] = nrm;
    plane.boundary_points[s] = plane.to_3d(q[s]);
  }

  segment_boundary(points, plane_index, plane, params, r);
}

void segment_boundary(const std::vector<Vec3>& points, int plane_index, DetectedPlane& plane,
                      const StructureParams& params, double r) {
  plane.segments.clear();
  const std::size_t nb = plane.boundary.size();
  if (nb == 0) return;
  // The boundary graph and the points in the plane's frame, as compute_boundary made them.
  std::vector<Vec2> q(nb);
  for (std::size_t s = 0; s < nb; ++s) q[s] = plane.to_2d(points[static_cast<std::size_t>(plane.boundary[s])]);
  std::vector<std::vector<int>> adj(nb);
  for (const auto& e : plane.boundary_edges) {
    adj[static_cast<std::size_t>(e[0])].push_back(e[1]);
    adj[static_cast<std::size_t>(e[1])].push_back(e[0]);
  }
  for (auto& l : adj) { std::sort(l.begin(), l.end()); l.erase(std::unique(l.begin(), l.end()), l.end()); }

  // 2D segments: region growing along the boundary graph with a least-squares line fit.
  using Item = std::pair<K::Point_2, K::Vector_2>;
  using Range = std::vector<Item>;
  using PMap = CGAL::First_of_pair_property_map<Item>;
  using NMap = CGAL::Second_of_pair_property_map<Item>;
  using Region = CGAL::Shape_detection::Point_set::Least_squares_line_fit_region<K, Range, PMap, NMap>;
  using Sorting = CGAL::Shape_detection::Point_set::Least_squares_line_fit_sorting<K, Range, ListNeighborQuery, PMap>;
  using RG = CGAL::Shape_detection::Region_growing<Range, ListNeighborQuery, Region, typename Sorting::Seed_map>;
  Range items;
  items.reserve(nb);
  for (std::size_t s = 0; s < nb; ++s)
    items.emplace_back(K::Point_2(q[s].x(), q[s].y()),
                       K::Vector_2(plane.boundary_normals[s].x(), plane.boundary_normals[s].y()));
  // Neighbours: boundary points within two hops, so one noisy point does not cut a segment.
  std::vector<std::vector<int>> adj2(nb);
  for (std::size_t s = 0; s < nb; ++s) {
    std::vector<int> l = adj[s];
    for (int t : adj[s]) l.insert(l.end(), adj[t].begin(), adj[t].end());
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
    l.erase(std::remove(l.begin(), l.end(), static_cast<int>(s)), l.end());
    adj2[s] = std::move(l);
  }
  ListNeighborQuery query{&adj2};
  Region region(items, params.segment_max_distance * r, params.segment_max_angle_deg,
                static_cast<std::size_t>(std::max(2, params.min_segment_points)));
  Sorting sorting(items, query);
  sorting.sort();
  RG rg(items, query, region, sorting.seed_map());
  std::vector<std::vector<std::size_t>> regions;
  rg.detect(std::back_inserter(regions));

  std::vector<Segment2> segs;
  for (const auto& reg : regions) {
    std::vector<Vec2> sp;
    Vec2 nsum = Vec2::Zero();
    for (std::size_t s : reg) { sp.push_back(q[s]); nsum += plane.boundary_normals[s]; }
    Vec2 c;
    const Vec2 d = principal_direction(sp, &c);
    double tmin = 0, tmax = 0;
    for (const auto& x : sp) { const double t = (x - c).dot(d); tmin = std::min(tmin, t); tmax = std::max(tmax, t); }
    if (tmax - tmin <= 0) continue;
    Segment2 seg;
    seg.a = c + tmin * d;
    seg.b = c + tmax * d;
    seg.normal = perp(d);
    if (seg.normal.dot(nsum) < 0) seg.normal = -seg.normal;
    for (std::size_t s : reg) seg.support.push_back(static_cast<int>(s));
    segs.push_back(std::move(seg));
  }
  if (params.regularize_segments)
    regularize_segments(segs, params.segment_angle_tolerance_deg * kPi / 180.0, params.segment_collinear_tolerance * r);

  for (const auto& s2 : segs) {
    BoundarySegment seg;
    seg.a = plane.to_3d(s2.a);
    seg.b = plane.to_3d(s2.b);
    seg.normal = (s2.normal.x() * plane.frame_u + s2.normal.y() * plane.frame_v).normalized();
    for (int s : s2.support) seg.support.push_back(plane.boundary[s]);
    std::sort(seg.support.begin(), seg.support.end());
    seg.plane = plane_index;
    plane.segments.push_back(std::move(seg));
  }
}

}  // namespace hsr::structure_detail
