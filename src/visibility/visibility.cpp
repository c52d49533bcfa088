// Stage 2: visibility ratios, outward normals and the highly/barely visible labelling (see visibility.h).
#include "visibility/visibility.h"

#include "core/error.h"
#include "core/log.h"
#include "core/min_cut.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>


#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <sstream>

namespace hsr {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Triangle = K::Triangle_3;
using TriangleIterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, TriangleIterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

using Vb = CGAL::Triangulation_vertex_base_with_info_2<int, K>;
using Tds = CGAL::Triangulation_data_structure_2<Vb>;
using Delaunay = CGAL::Delaunay_triangulation_2<K, Tds>;

/// Triangles of the alpha complex of the projected inliers: Delaunay triangles whose circumradius is at
/// most alpha_r (in 2D a triangle's alpha value is its squared circumradius, so these are exactly the
/// interior faces of the regularized alpha shape). Lifted back onto the plane.
void alpha_triangles(const PointCloud& cloud, const DetectedPlane& dp, double alpha_r, int plane_index,
                     std::vector<Triangle>& out, std::vector<int>& owner) {
  std::vector<std::pair<K::Point_2, int>> pts;
  pts.reserve(dp.inliers.size());
  for (int i : dp.inliers) {
    const Vec2 q = dp.to_2d(cloud.points[static_cast<std::size_t>(i)]);
    pts.emplace_back(K::Point_2(q.x(), q.y()), i);
  }
  Delaunay dt(pts.begin(), pts.end());
  const double a2 = alpha_r * alpha_r;
  // Faces are visited in the triangulation's order, which is deterministic for a given insertion order.
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
    const K::Point_2& p0 = f->vertex(0)->point();
    const K::Point_2& p1 = f->vertex(1)->point();
    const K::Point_2& p2 = f->vertex(2)->point();
    if (CGAL::collinear(p0, p1, p2)) continue;
    if (CGAL::squared_distance(CGAL::circumcenter(p0, p1, p2), p0) > a2) continue;
    Vec3 q[3];
    for (int k = 0; k < 3; ++k) {
      const K::Point_2& p = f->vertex(k)->point();
      q[k] = dp.to_3d(Vec2(p.x(), p.y()));
      // Snap exactly onto the refit plane (to_3d is on it up to rounding).
      q[k] -= dp.plane.signed_distance(q[k]) * dp.plane.normal;
    }
    out.emplace_back(K::Point_3(q[0].x(), q[0].y(), q[0].z()), K::Point_3(q[1].x(), q[1].y(), q[1].z()),
                     K::Point_3(q[2].x(), q[2].y(), q[2].z()));
    owner.push_back(plane_index);
  }
}

}  // namespace

std::vector<Vec3> fibonacci_directions(int n) {
  std::vector<Vec3> dirs;
  dirs.reserve(static_cast<std::size_t>(std::max(n, 0)));
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n;  // strictly inside (-1, 1): no pole duplicates
    const double rad = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden * i;
    dirs.emplace_back(rad * std::cos(phi), rad * std::sin(phi), z);
  }
  return dirs;
}

std::vector<int> farthest_point_samples(const std::vector<Vec3>& points, int count) {
  std::vector<int> picked;
  if (points.empty() || count <= 0) return picked;
  const std::size_t n = points.size();
  const std::size_t want = std::min<std::size_t>(n, static_cast<std::size_t>(count));
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  std::size_t current = 0;
  while (picked.size() < want) {
    picked.push_back(static_cast<int>(current));
    std::size_t best = 0;
    double best_d = -1;
    for (std::size_t i = 0; i < n; ++i) {
      dist[i] = std::min(dist[i], (points[i] - points[current]).squaredNorm());
      if (dist[i] > best_d) { best_d = dist[i]; best = i; }  // first maximum: deterministic
    }
    if (best_d <= 0) break;  // every remaining point coincides with a picked one
    current = best;
  }
  return picked;
}

std::vector<std::pair<std::pair<int, int>, double>> mrf_edge_weights(
    int n, const std::vector<std::pair<int, int>>& edges, double w, bool normalize) {
  std::vector<std::pair<int, int>> unique;
  for (auto [a, b] : edges)
    if (a != b && a >= 0 && b >= 0 && a < n && b < n) unique.emplace_back(std::min(a, b), std::max(a, b));
  std::sort(unique.begin(), unique.end());
  unique.erase(std::unique(unique.begin(), unique.end()), unique.end());
  std::vector<int> degree(static_cast<std::size_t>(std::max(n, 0)), 0);
  for (auto [a, b] : unique) { ++degree[static_cast<std::size_t>(a)]; ++degree[static_cast<std::size_t>(b)]; }
  std::vector<std::pair<std::pair<int, int>, double>> out;
  for (auto e : unique)
    out.push_back({e, normalize ? w / std::sqrt(static_cast<double>(degree[static_cast<std::size_t>(e.first)]) *
                                                 degree[static_cast<std::size_t>(e.second)])
                                : w});
  return out;
}

std::vector<bool> label_mrf(const std::vector<double>& v, const std::vector<std::pair<int, int>>& edges,
                            double w, bool normalize) {
  // Label 1 = highly visible: cost(x=1) = 1 - v, cost(x=0) = v (DESIGN.md: switch at 0.5); Potts w_ij.
  const int n = static_cast<int>(v.size());
  MinCutProblem problem;
  problem.cost0.resize(v.size());
  problem.cost1.resize(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    const double vi = std::clamp(v[i], 0.0, 1.0);
    problem.cost0[i] = vi;
    problem.cost1[i] = 1.0 - vi;
  }
  for (const auto& [e, wij] : mrf_edge_weights(n, edges, w, normalize))
    if (wij > 0) problem.edges.push_back({e.first, e.second, wij, wij});
  problem.residual_tolerance = 1e-12;  // costs are O(1): ties and rounding noise go to barely visible
  return min_cut_labels(problem);
}

std::size_t orient_inlier_normals(const SceneStructure& structure, const VisibilityResult& visibility,
                                  std::vector<Vec3>& normals) {
  std::size_t flipped = 0;
  for (std::size_t i = 0; i < structure.planes.size(); ++i)
    for (int k : structure.planes[i].inliers) {
      Vec3& n = normals[static_cast<std::size_t>(k)];
      if (n.dot(visibility.outward_normal[i]) < 0) {
        n = -n;
        ++flipped;
      }
    }
  return flipped;
}

VisibilityResult run_visibility(const PointCloud& cloud, const SceneStructure& structure,
                                const VisibilityParams& params) {
  if (params.keypoints < 1 || params.directions < 2 || params.smoothness < 0 || params.max_iterations < 1)
    throw Error(Status::BadInput, "visibility",
                "parameters: keypoints >= 1, directions >= 2, smoothness >= 0, max_iterations >= 1 required");
  const std::size_t m = structure.planes.size();
  VisibilityResult res;
  res.ratio.assign(m, 0.0);
  res.ratio_sphere.assign(m, 0.0);
  res.outward_normal.resize(m);
  res.initially_highly.assign(m, false);
  res.highly.assign(m, false);
  if (m == 0) return res;

  const double r = structure.spacing > 0 ? structure.spacing : 1.0;
  // One alpha radius per run: the structure's resolved one, or (a hand-made structure) its default.
  double alpha_r = (params.alpha_radius > 0 ? params.alpha_radius : StructureParams{}.alpha_radius) * r;
  if (!(params.alpha_radius > 0)) {
    if (structure.params.is_object() && structure.params.contains("alpha_radius") &&
        structure.params["alpha_radius"].is_number())
      alpha_r = structure.params["alpha_radius"].get<double>();
  }

  // AABB tree over the triangulated alpha shapes of all planes.
  std::vector<Triangle> triangles;
  std::vector<int> owner;
  for (std::size_t i = 0; i < m; ++i)
    alpha_triangles(cloud, structure.planes[i], alpha_r, static_cast<int>(i), triangles, owner);
  Tree tree(triangles.begin(), triangles.end());
  tree.build();

  // Cast every ray once: its first hit never changes, only the labels do.
  const std::vector<Vec3> dirs = fibonacci_directions(params.directions);
  struct Ray { int hit; int dir; };
  std::vector<std::vector<Ray>> rays(m);
  for (std::size_t i = 0; i < m; ++i) {
    const DetectedPlane& dp = structure.planes[i];
    std::vector<Vec3> pts;
    pts.reserve(dp.inliers.size());
    for (int p : dp.inliers) pts.push_back(cloud.points[static_cast<std::size_t>(p)]);
    const std::vector<int> keys = farthest_point_samples(pts, params.keypoints);
    const int self = static_cast<int>(i);
    auto skip = [&](const TriangleIterator& id) { return owner[static_cast<std::size_t>(id - triangles.begin())] == self; };
    for (int k : keys) {
      Vec3 o = pts[static_cast<std::size_t>(k)];
      o -= dp.plane.signed_distance(o) * dp.plane.normal;  // the light sits on its alpha shape
      const K::Point_3 origin(o.x(), o.y(), o.z());
      for (int t = 0; t < static_cast<int>(dirs.size()); ++t) {
        const Vec3& d = dirs[static_cast<std::size_t>(t)];
        const K::Ray_3 ray(origin, K::Vector_3(d.x(), d.y(), d.z()));
        const auto hit = tree.first_intersection(ray, skip);
        const int hit_plane = hit ? owner[static_cast<std::size_t>(hit->second - triangles.begin())] : -1;
        rays[i].push_back({hit_plane, t});
      }
    }
    res.rays += rays[i].size();
  }

  // Initial normals: the structure's plane normals, turned to the majority of their inliers' normals.
  std::vector<Vec3> normal(m);
  std::vector<double> inlier_agreement(m, 0.0);  // signed majority of inlier normals vs plane normal
  for (std::size_t i = 0; i < m; ++i) {
    const DetectedPlane& dp = structure.planes[i];
    long agree = 0;
    for (int p : dp.inliers) {
      const std::size_t pi = static_cast<std::size_t>(p);
      const Vec3* pn = pi < structure.normals.size() ? &structure.normals[pi]
                       : (cloud.has_normals() ? &cloud.normals[pi] : nullptr);
      if (pn) agree += pn->dot(dp.plane.normal) >= 0 ? 1 : -1;
    }
    normal[i] = agree >= 0 ? dp.plane.normal : Vec3(-dp.plane.normal);
    inlier_agreement[i] = static_cast<double>(agree);
  }

  std::vector<bool> highly(m, false);
  // Visible counts per side (+: along normal[i]) for plane i under the current labels.
  auto count = [&](std::size_t i, const Vec3& n, int& vis_pos, int& tot_pos, int& vis_neg, int& tot_neg) {
    vis_pos = tot_pos = vis_neg = tot_neg = 0;
    for (const Ray& ray : rays[i]) {
      const Vec3& d = dirs[static_cast<std::size_t>(ray.dir)];
      const bool visible = ray.hit < 0 || (highly[static_cast<std::size_t>(ray.hit)] &&
                                           normal[static_cast<std::size_t>(ray.hit)].dot(d) < 0);
      if (n.dot(d) > 0) { ++tot_pos; vis_pos += visible; } else { ++tot_neg; vis_neg += visible; }
    }
  };
  auto frac = [](int a, int b) { return b > 0 ? static_cast<double>(a) / b : 0.0; };
  // Ratio of plane i and the side it prefers (+1 along normal[i], -1 against, 0 no preference).
  auto evaluate = [&](std::size_t i, double& ratio, double& sphere, int& side) {
    int vp, tp, vn, tn;
    count(i, normal[i], vp, tp, vn, tn);
    const double fp = frac(vp, tp), fn = frac(vn, tn);
    side = fp > fn ? 1 : (fn > fp ? -1 : 0);
    sphere = frac(vp + vn, tp + tn);
    ratio = params.one_sided ? std::max(fp, fn) : sphere;
  };

  int iterations = 0;
  for (; iterations < params.max_iterations;) {
    ++iterations;
    std::vector<std::size_t> promoted;
    std::vector<int> sides;
    for (std::size_t i = 0; i < m; ++i) {
      if (highly[i]) continue;
      double ratio, sphere;
      int side;
      evaluate(i, ratio, sphere, side);
      if (ratio > params.threshold) { promoted.push_back(i); sides.push_back(side); }
    }
    for (std::size_t k = 0; k < promoted.size(); ++k) {
      highly[promoted[k]] = true;
      if (sides[k] < 0) normal[promoted[k]] = -normal[promoted[k]];
    }
    if (promoted.empty()) break;
  }
  res.iterations = iterations;

  // Scanner inside (indoor): the enclosing planes' visible sides disagree with their inliers' normals.
  double parity = 0;
  for (std::size_t i = 0; i < m; ++i)
    if (highly[i])
      parity += (normal[i].dot(structure.planes[i].plane.normal) >= 0 ? 1.0 : -1.0) *
                (inlier_agreement[i] >= 0 ? 1.0 : -1.0) * static_cast<double>(structure.planes[i].inliers.size());
  for (std::size_t i = 0; i < m; ++i) {
    double ratio, sphere;
    int side;
    evaluate(i, ratio, sphere, side);
    if (!highly[i]) {
      if (side < 0) normal[i] = -normal[i];
      else if (side == 0 && parity < 0) normal[i] = -normal[i];
    }
    res.ratio[i] = ratio;
    res.ratio_sphere[i] = sphere;
    res.outward_normal[i] = normal[i].normalized();
    res.initially_highly[i] = highly[i];
  }

  std::vector<std::pair<int, int>> edges;
  for (std::size_t i = 0; i < m && i < structure.adjacency.size(); ++i)
    for (int j : structure.adjacency[i])
      if (static_cast<int>(i) < j) edges.emplace_back(static_cast<int>(i), j);
  res.highly = label_mrf(res.ratio, edges, params.smoothness, params.normalize_smoothness);

  std::size_t n_high = 0;
  for (bool h : res.highly) n_high += h;
  std::ostringstream msg;
  msg << "[visibility] " << res.rays << " rays, " << triangles.size() << " alpha triangles, " << iterations
      << " passes, " << n_high << " of " << m << " planes highly visible";
  log::info(msg.str());
  return res;
}

}  // namespace hsr
