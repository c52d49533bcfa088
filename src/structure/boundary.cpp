// Stage 1, per plane: 2D frame, regularized alpha shape of the projected inliers (area and boundary points),
// 2D boundary normals (PCA of boundary neighbours, oriented away from the inliers), 2D segments by region
// growing on boundary points (CGAL Shape_detection), group-based regularisation, lift to 3D (DESIGN.md
// "Boundaries and segments").
#include "structure/structure_internal.h"

#include <CGAL/Alpha_shape_2.h>
#include <CGAL/Alpha_shape_face_base_2.h>
#include <CGAL/Alpha_shape_vertex_base_2.h>
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Shape_detection/Region_growing/Region_growing.h>
#include <CGAL/Shape_detection/Region_growing/Region_growing_on_point_set.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/property_map.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <queue>

namespace hsr::structure_detail {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb0 = CGAL::Triangulation_vertex_base_with_info_2<int, K>;
using Vb = CGAL::Alpha_shape_vertex_base_2<K, Vb0>;
using Fb = CGAL::Alpha_shape_face_base_2<K>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Dt = CGAL::Delaunay_triangulation_2<K, Tds>;
using AlphaShape = CGAL::Alpha_shape_2<Dt>;

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

void compute_boundary(const std::vector<Vec3>& points, int plane_index, DetectedPlane& plane,
                      const StructureParams& params, double r) {
  make_frame(plane);
  plane.area = 0;
  plane.boundary.clear();
  plane.boundary_points.clear();
  plane.boundary_normals.clear();
  plane.segments.clear();

  std::vector<std::pair<K::Point_2, int>> input;
  input.reserve(plane.inliers.size());
  for (int i : plane.inliers) {
    const Vec2 q = plane.to_2d(points[i]);
    input.emplace_back(K::Point_2(q.x(), q.y()), i);
  }
  Dt dt;
  dt.insert(input.begin(), input.end());
  if (dt.dimension() < 2) return;  // collinear inliers: no area, no boundary
  const double alpha_r = params.alpha_radius * r;
  AlphaShape as(dt, alpha_r * alpha_r, AlphaShape::REGULARIZED);

  for (auto f = as.finite_faces_begin(); f != as.finite_faces_end(); ++f) {
    if (as.classify(f) != AlphaShape::INTERIOR) continue;
    const auto &p0 = f->vertex(0)->point(), &p1 = f->vertex(1)->point(), &p2 = f->vertex(2)->point();
    plane.area += std::abs(CGAL::area(p0, p1, p2));
  }

  // Boundary edges (REGULAR in a regularized shape: exactly one interior side), with outward normals.
  std::map<int, int> local;  // input index -> boundary slot (sorted by input index below)
  struct Edge { int a, b; Vec2 outward; };
  std::vector<Edge> edges;
  for (auto e = as.alpha_shape_edges_begin(); e != as.alpha_shape_edges_end(); ++e) {
    if (as.classify(*e) != AlphaShape::REGULAR) continue;
    auto f = e->first;
    const int i = e->second;
    auto va = f->vertex(Dt::cw(i)), vb = f->vertex(Dt::ccw(i));
    const Vec2 a(va->point().x(), va->point().y()), b(vb->point().x(), vb->point().y());
    Vec2 inner;  // a vertex on the interior side
    if (!as.is_infinite(f) && as.classify(f) == AlphaShape::INTERIOR) {
      inner = Vec2(f->vertex(i)->point().x(), f->vertex(i)->point().y());
    } else {
      auto g = f->neighbor(i);
      const int mi = g->index(f);
      inner = Vec2(g->vertex(mi)->point().x(), g->vertex(mi)->point().y());
    }
    Vec2 nrm = perp(b - a);
    if (nrm.norm() == 0) continue;
    nrm.normalize();
    if (nrm.dot(inner - a) > 0) nrm = -nrm;
    edges.push_back({va->info(), vb->info(), nrm * (b - a).norm()});
    local[va->info()] = 0;
    local[vb->info()] = 0;
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
