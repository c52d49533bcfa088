// Stage 2: visibility ratios, outward normals and the highly/barely visible labelling (see visibility.h).
#include "visibility/visibility.h"

#include "core/error.h"
#include "core/hull2d.h"
#include "core/log.h"
#include "core/min_cut.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

namespace hsr {

namespace {

/// One plane's alpha shape as a ray target: its plane, frame and boundary loops (2D), with the boundary
/// edges bucketed by rows of v so that a point-in-shape test (crossing parity) only reads one row.
/// The shape is the union of the alpha triangles (Delaunay triangles of circumradius <= alpha), bounded by
/// exactly these edges, so "the ray meets the shape" is the ray meeting one of those triangles.
class ShapeTarget {
 public:
  ShapeTarget(const DetectedPlane& dp, std::vector<Vec2> q, const std::vector<std::array<int, 2>>& edges) : dp_(&dp) {
    for (const auto& e : edges) {
      const Vec2 &a = q[static_cast<std::size_t>(e[0])], &b = q[static_cast<std::size_t>(e[1])];
      if (a.y() == b.y()) continue;  // horizontal edges never change the parity of a horizontal ray
      edges_.push_back({a, b});
    }
    if (edges_.empty()) return;
    lo_ = hi_ = edges_.front().a;
    for (const Edge& e : edges_)
      for (const Vec2& p : {e.a, e.b}) { lo_ = lo_.cwiseMin(p); hi_ = hi_.cwiseMax(p); }
    rows_ = std::max<std::size_t>(1, static_cast<std::size_t>(std::sqrt(static_cast<double>(edges_.size()))));
    row_height_ = (hi_.y() - lo_.y()) / static_cast<double>(rows_);
    if (!(row_height_ > 0)) rows_ = 1, row_height_ = 1;
    bucket_start_.assign(rows_ + 1, 0);
    auto rows_of = [&](const Edge& e, std::size_t& r0, std::size_t& r1) {
      r0 = row(std::min(e.a.y(), e.b.y()));
      r1 = row(std::max(e.a.y(), e.b.y()));
    };
    for (const Edge& e : edges_) {
      std::size_t r0, r1;
      rows_of(e, r0, r1);
      for (std::size_t r = r0; r <= r1; ++r) ++bucket_start_[r + 1];
    }
    for (std::size_t r = 0; r < rows_; ++r) bucket_start_[r + 1] += bucket_start_[r];
    bucket_.resize(bucket_start_.back());
    std::vector<std::size_t> fill(bucket_start_.begin(), bucket_start_.end() - 1);
    for (std::size_t k = 0; k < edges_.size(); ++k) {
      std::size_t r0, r1;
      rows_of(edges_[k], r0, r1);
      for (std::size_t r = r0; r <= r1; ++r) bucket_[fill[r]++] = static_cast<int>(k);
    }
  }

  /// A box holding every point where hit() can succeed: the shape's 2D box lifted to the plane, padded by
  /// `pad` (rounding of o + t d). Invalid when the shape has no edge (hit() never succeeds).
  BBox box3d(double pad) const {
    BBox b;
    if (edges_.empty()) return b;
    for (double x : {lo_.x(), hi_.x()})
      for (double y : {lo_.y(), hi_.y()}) b.extend(dp_->to_3d(Vec2(x, y)));
    b.min.array() -= pad;
    b.max.array() += pad;
    return b;
  }

  /// Ray parameter t >= 0 where o + t d meets the shape; infinity when it does not (or runs in the plane).
  double hit(const Vec3& o, const Vec3& d) const {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    if (edges_.empty()) return kInf;
    const Plane& pl = dp_->plane;
    const double denom = pl.normal.dot(d);
    if (denom == 0) return kInf;
    const double t = -pl.signed_distance(o) / denom;
    if (!(t >= 0)) return kInf;
    const Vec2 p = dp_->to_2d(o + t * d);
    if (p.x() < lo_.x() || p.x() > hi_.x() || p.y() < lo_.y() || p.y() > hi_.y()) return kInf;
    return inside(p) ? t : kInf;
  }

 private:
  struct Edge { Vec2 a, b; };
  std::size_t row(double y) const {
    const double r = std::floor((y - lo_.y()) / row_height_);
    return static_cast<std::size_t>(std::clamp(r, 0.0, static_cast<double>(rows_ - 1)));
  }
  /// Crossing parity of the ray from p towards +u (half-open in v, so a vertex is counted once).
  bool inside(const Vec2& p) const {
    const std::size_t r = row(p.y());
    bool in = false;
    for (std::size_t k = bucket_start_[r]; k < bucket_start_[r + 1]; ++k) {
      const Edge& e = edges_[static_cast<std::size_t>(bucket_[k])];
      if ((e.a.y() > p.y()) == (e.b.y() > p.y())) continue;
      const double x = e.a.x() + (p.y() - e.a.y()) * (e.b.x() - e.a.x()) / (e.b.y() - e.a.y());
      if (x > p.x()) in = !in;
    }
    return in;
  }

  const DetectedPlane* dp_;
  std::vector<Edge> edges_;
  Vec2 lo_ = Vec2::Zero(), hi_ = Vec2::Zero();
  std::size_t rows_ = 1;
  double row_height_ = 1;
  std::vector<std::size_t> bucket_start_;
  std::vector<int> bucket_;
};

/// The ray target of each plane: its structure boundary when the radius is the structure's, else the alpha
/// shape of its projected inliers with this radius.
std::vector<ShapeTarget> shape_targets(const PointCloud& cloud, const SceneStructure& structure, double alpha_r,
                                       bool structure_radius) {
  std::vector<std::optional<ShapeTarget>> targets(structure.planes.size());
  tbb::parallel_for(std::size_t(0), structure.planes.size(), [&](std::size_t i) {
    const DetectedPlane& dp = structure.planes[i];
    if (structure_radius) {
      std::vector<Vec2> q(dp.boundary.size());
      for (std::size_t s = 0; s < q.size(); ++s) q[s] = dp.to_2d(cloud.points[static_cast<std::size_t>(dp.boundary[s])]);
      targets[i].emplace(dp, std::move(q), dp.boundary_edges);
    } else {
      std::vector<Vec2> q(dp.inliers.size());
      for (std::size_t s = 0; s < q.size(); ++s) q[s] = dp.to_2d(cloud.points[static_cast<std::size_t>(dp.inliers[s])]);
      const AlphaShapeBoundary shape = alpha_shape_boundary(q, alpha_r);
      targets[i].emplace(dp, std::move(q), shape.edges);
    }
  });
  std::vector<ShapeTarget> out;
  out.reserve(targets.size());
  for (auto& t : targets) out.push_back(std::move(*t));
  return out;
}

/// The largest absolute coordinate of the planes' inliers (the scale of the rounding in o + t d).
double structure_extent(const PointCloud& cloud, const SceneStructure& structure) {
  double e = 0.0;
  for (const DetectedPlane& dp : structure.planes)
    for (int p : dp.inliers) e = std::max(e, cloud.points[static_cast<std::size_t>(p)].cwiseAbs().maxCoeff());
  return e;
}

/// Where the ray o + t d (t >= 0) enters `b`: its smallest t in the box, or infinity when it misses it.
double ray_enters(const BBox& b, const Vec3& o, const Vec3& inv_d) {
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (std::isinf(inv_d[k])) {  // parallel to the slab: inside it or never
      if (o[k] < b.min[k] || o[k] > b.max[k]) return std::numeric_limits<double>::infinity();
      continue;
    }
    double a = (b.min[k] - o[k]) * inv_d[k], c = (b.max[k] - o[k]) * inv_d[k];
    if (a > c) std::swap(a, c);
    t0 = std::max(t0, a);
    t1 = std::min(t1, c);
    if (t0 > t1) return std::numeric_limits<double>::infinity();
  }
  return t0;
}

/// A bounding volume hierarchy over the planes' shape boxes (the paper's AABB tree over the alpha shapes,
/// one box per plane): a ray tests only the shapes whose box it enters before its best hit so far, so the
/// first hits are exactly those of testing every plane (nearest t, ties to the smaller plane index: a box is
/// skipped only when the ray enters it strictly after the best hit), at about log(planes) boxes per ray.
class ShapeBvh {
 public:
  ShapeBvh(const std::vector<ShapeTarget>& targets, double pad) : targets_(targets) {
    std::vector<int> ids;
    for (std::size_t j = 0; j < targets.size(); ++j) {
      boxes_.push_back(targets[j].box3d(pad));
      if (boxes_.back().valid()) ids.push_back(static_cast<int>(j));
    }
    order_ = ids;
    if (!order_.empty()) build(0, static_cast<int>(order_.size()));
  }

  /// The first plane the ray from `o` along `d` meets, other than `self` (-1: none).
  int first_hit(const Vec3& o, const Vec3& d, int self) const {
    int best_j = -1;
    double best = std::numeric_limits<double>::infinity();
    if (nodes_.empty()) return best_j;
    const Vec3 inv(1.0 / d.x(), 1.0 / d.y(), 1.0 / d.z());
    int stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& n = nodes_[static_cast<std::size_t>(stack[--top])];
      const double enters = ray_enters(n.box, o, inv);
      if (std::isinf(enters) || enters > best) continue;  // missed, or entered after the best hit
      if (n.left < 0) {
        for (int k = n.first; k < n.first + n.count; ++k) {
          const int j = order_[static_cast<std::size_t>(k)];
          if (j == self) continue;
          const double t = targets_[static_cast<std::size_t>(j)].hit(o, d);
          if (t < best || (t == best && t < std::numeric_limits<double>::infinity() && j < best_j)) {
            best = t;
            best_j = j;
          }
        }
        continue;
      }
      stack[top++] = n.left;
      stack[top++] = n.right;
    }
    return best_j;
  }

 private:
  struct Node {
    BBox box;
    int left = -1, right = -1;  ///< children (-1: a leaf)
    int first = 0, count = 0;   ///< a leaf's planes: order_[first, first + count)
  };
  static constexpr int kLeaf = 4;

  int build(int first, int last) {
    const int id = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
    BBox box, centres;
    for (int k = first; k < last; ++k) {
      const BBox& b = boxes_[static_cast<std::size_t>(order_[static_cast<std::size_t>(k)])];
      box.extend(b.min);
      box.extend(b.max);
      centres.extend(b.center());
    }
    nodes_[static_cast<std::size_t>(id)].box = box;
    if (last - first <= kLeaf) {
      nodes_[static_cast<std::size_t>(id)].first = first;
      nodes_[static_cast<std::size_t>(id)].count = last - first;
      return id;
    }
    int axis = 0;
    const Vec3 ext = centres.size();
    if (ext.y() > ext[axis]) axis = 1;
    if (ext.z() > ext[axis]) axis = 2;
    const int mid = first + (last - first) / 2;
    auto key = [&](int j) { return std::make_pair(boxes_[static_cast<std::size_t>(j)].center()[axis], j); };
    std::sort(order_.begin() + first, order_.begin() + last, [&](int a, int b) { return key(a) < key(b); });
    const int left = build(first, mid);
    const int right = build(mid, last);
    nodes_[static_cast<std::size_t>(id)].left = left;
    nodes_[static_cast<std::size_t>(id)].right = right;
    return id;
  }

  const std::vector<ShapeTarget>& targets_;
  std::vector<BBox> boxes_;
  std::vector<int> order_;
  std::vector<Node> nodes_;
};

}  // namespace

bool rays_tell_sides_apart(int visible_one_side, int visible_other_side) {
  const double a = visible_one_side, b = visible_other_side;
  return std::abs(a - b) > 2.0 * std::sqrt(a + b);
}

bool scanned_from_inside(double parity, double enclosing_inliers) {
  return enclosing_inliers > 0 && parity < -0.5 * enclosing_inliers;
}

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
    out.push_back({e, normalize ? w / std::max(degree[static_cast<std::size_t>(e.first)],
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

std::vector<std::vector<int>> first_hits(const PointCloud& cloud, const SceneStructure& structure,
                                         const VisibilityParams& params) {
  return first_hits(cloud, structure, params, light_origins(cloud, structure, params));
}

std::vector<std::vector<int>> first_hits(const PointCloud& cloud, const SceneStructure& structure,
                                         const VisibilityParams& params, const std::vector<std::vector<Vec3>>& lights) {
  const std::size_t m = structure.planes.size();
  const double r = structure.spacing > 0 ? structure.spacing : 1.0;
  const double structure_alpha = structure.alpha_radius;
  // One alpha radius per run: visibility's own, else the structure's, else (a hand-made structure) the
  // structure stage's default.
  double alpha_r = params.alpha_radius * r;
  if (!(params.alpha_radius > 0))
    alpha_r = structure_alpha > 0 ? structure_alpha : StructureParams{}.alpha_radius * r;

  // Every plane's alpha shape as a ray target (the union of its alpha triangles, bounded by its boundary).
  const std::vector<ShapeTarget> targets = shape_targets(cloud, structure, alpha_r, alpha_r == structure_alpha);
  // Planes in parallel, each filling its own rays; the first hit is the smallest t, ties to the smaller plane.
  const ShapeBvh bvh(targets, 1e-9 * std::max(1.0, structure_extent(cloud, structure)));
  const std::vector<Vec3> dirs = fibonacci_directions(params.directions);
  std::vector<std::vector<int>> hits(m);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m, 1), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i)
      for (const Vec3& o : lights[i])
        for (const Vec3& d : dirs) hits[i].push_back(bvh.first_hit(o, d, static_cast<int>(i)));  // ignores its own plane
  });
  return hits;
}

std::vector<std::vector<Vec3>> light_origins(const PointCloud& cloud, const SceneStructure& structure,
                                             const VisibilityParams& params) {
  std::vector<std::vector<Vec3>> lights(structure.planes.size());
  tbb::parallel_for(std::size_t(0), structure.planes.size(), [&](std::size_t i) {
    const DetectedPlane& dp = structure.planes[i];
    std::vector<Vec3> pts;
    pts.reserve(dp.inliers.size());
    for (int p : dp.inliers) pts.push_back(cloud.points[static_cast<std::size_t>(p)]);
    for (int k : farthest_point_samples(pts, params.keypoints)) {
      Vec3 o = pts[static_cast<std::size_t>(k)];
      o -= dp.plane.signed_distance(o) * dp.plane.normal;  // the light sits on its alpha shape
      lights[i].push_back(o);
    }
  });
  return lights;
}

std::size_t close_room(const PointCloud& cloud, const SceneStructure& structure, const VisibilityParams& params,
                       const std::vector<std::vector<Vec3>>& lights, const std::vector<bool>& enclosure,
                       std::vector<std::vector<int>>& hits) {
  // Each enclosing plane as its inliers' convex hull, in its own frame.
  std::vector<int> walls;
  std::vector<ShapeTarget> hulls;
  for (std::size_t j = 0; j < structure.planes.size(); ++j) {
    if (!enclosure[j]) continue;
    const DetectedPlane& dp = structure.planes[j];
    std::vector<Vec2> pts;
    pts.reserve(dp.inliers.size());
    for (int p : dp.inliers) pts.push_back(dp.to_2d(cloud.points[static_cast<std::size_t>(p)]));
    std::vector<Vec2> hull = convex_hull_2d(pts);
    if (hull.size() < 3) continue;
    std::vector<std::array<int, 2>> edges;
    for (std::size_t k = 0; k < hull.size(); ++k)
      edges.push_back({static_cast<int>(k), static_cast<int>((k + 1) % hull.size())});
    walls.push_back(static_cast<int>(j));
    hulls.emplace_back(dp, std::move(hull), edges);
  }
  // A light on an enclosing plane's own plane (a piece of the floor beside the floor) is not closed in by it.
  // (The structure's resolved max_distance is absolute; a hand-made structure has none: the default, in r.)
  const double r = structure.spacing > 0 ? structure.spacing : 1.0;
  const double on_plane = structure.params.is_object() && structure.params.contains("max_distance")
                              ? structure.params["max_distance"].get<double>()
                              : StructureParams{}.max_distance * r;
  const std::vector<Vec3> dirs = fibonacci_directions(params.directions);
  std::vector<std::size_t> closed(hits.size(), 0);
  tbb::parallel_for(std::size_t(0), hits.size(), [&](std::size_t i) {
    for (std::size_t k = 0; k < hits[i].size(); ++k) {
      if (hits[i][k] >= 0) continue;
      const Vec3& o = lights[i][k / dirs.size()];
      const Vec3& d = dirs[k % dirs.size()];
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t w = 0; w < walls.size(); ++w) {
        const int j = walls[w];
        if (static_cast<std::size_t>(j) == i ||
            std::abs(structure.planes[static_cast<std::size_t>(j)].plane.signed_distance(o)) <= on_plane)
          continue;
        const double t = hulls[w].hit(o, d);
        if (t < best) best = t, hits[i][k] = j;
      }
      closed[i] += hits[i][k] >= 0;
    }
  });
  std::size_t total = 0;
  for (std::size_t c : closed) total += c;
  return total;
}

VisibilityResult subset_visibility(const VisibilityResult& v, const std::vector<int>& from) {
  VisibilityResult out;
  out.scanned_from_inside = v.scanned_from_inside;
  out.iterations = v.iterations;
  out.rays = v.rays;
  out.closed_rays = v.closed_rays;
  for (int k : from) {
    const auto i = static_cast<std::size_t>(k);
    out.ratio.push_back(v.ratio[i]);
    out.ratio_sphere.push_back(v.ratio_sphere[i]);
    out.outward_normal.push_back(v.outward_normal[i]);
    out.initially_highly.push_back(v.initially_highly[i]);
    out.highly.push_back(v.highly[i]);
  }
  return out;
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

  // Cast every ray once: its first hit never changes, only the labels do (and, in a room, the escapes that
  // close_room closes).
  struct Ray { int hit; int dir; };
  std::vector<std::vector<Ray>> rays(m);
  const std::vector<std::vector<Vec3>> lights = light_origins(cloud, structure, params);
  std::vector<std::vector<int>> hits = first_hits(cloud, structure, params, lights);
  auto take_hits = [&] {
    for (std::size_t i = 0; i < m; ++i) {
      rays[i].clear();
      rays[i].reserve(hits[i].size());
      for (std::size_t k = 0; k < hits[i].size(); ++k)
        rays[i].push_back({hits[i][k], static_cast<int>(k % static_cast<std::size_t>(params.directions))});
    }
  };
  take_hits();
  for (const auto& h : hits) res.rays += h.size();
  const std::vector<Vec3> dirs = fibonacci_directions(params.directions);

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

  const std::vector<Vec3> initial_normal = normal;
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
  // `sides_apart` (optional): whether the visible counts differ beyond their noise (rays_tell_sides_apart).
  auto evaluate = [&](std::size_t i, double& ratio, double& sphere, int& side, bool* sides_apart = nullptr) {
    int vp, tp, vn, tn;
    count(i, normal[i], vp, tp, vn, tn);
    const double fp = frac(vp, tp), fn = frac(vn, tn);
    side = fp > fn ? 1 : (fn > fp ? -1 : 0);
    if (sides_apart) *sides_apart = rays_tell_sides_apart(vp, vn);
    sphere = frac(vp + vn, tp + tn);
    ratio = params.one_sided ? std::max(fp, fn) : sphere;
  };

  // Algorithm 1: promote until the highly visible set stops growing (at most max_iterations passes).
  int iterations = 0;
  auto label = [&] {
    for (int pass = 0; pass < params.max_iterations; ++pass) {
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
  };
  label();

  // Scanner inside (indoor): the enclosing planes' visible sides disagree with their inliers' normals.
  double parity = 0, enclosing_inliers = 0;
  for (std::size_t i = 0; i < m; ++i)
    if (highly[i]) {
      const double n = static_cast<double>(structure.planes[i].inliers.size());
      parity += (normal[i].dot(structure.planes[i].plane.normal) >= 0 ? 1.0 : -1.0) *
                (inlier_agreement[i] >= 0 ? 1.0 : -1.0) * n;
      enclosing_inliers += n;
    }
  res.scanned_from_inside = scanned_from_inside(parity, enclosing_inliers);
  if (params.close_room && (res.scanned_from_inside || params.room)) {
    // A room is closed: what its furniture's rays escape through are the shadows the furniture casts on the
    // floor, walls and ceiling, not openings. Label again with those escapes closed.
    res.closed_rays = close_room(cloud, structure, params, lights, highly, hits);
    take_hits();
    highly.assign(m, false);
    normal = initial_normal;
    label();
  }
  res.iterations = iterations;
  for (std::size_t i = 0; i < m; ++i) {
    double ratio, sphere;
    int side;
    bool sides_apart = false;
    evaluate(i, ratio, sphere, side, &sides_apart);
    if (!highly[i]) {
      // Scanned from inside, a barely visible plane's rays meet the room on one side and its own piece on
      // the other: the few that escape through gaps in the enclosure tell nothing, its inliers' normals do.
      // Elsewhere its rays decide only when their counts differ beyond their noise.
      if (res.scanned_from_inside || !sides_apart) side = 0;
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
  std::size_t boundary_edges = 0;
  for (const DetectedPlane& dp : structure.planes) boundary_edges += dp.boundary_edges.size();
  msg << "[visibility] " << res.rays << " rays, " << boundary_edges << " alpha-shape boundary edges, " << iterations
      << " passes, " << n_high << " of " << m << " planes highly visible";
  log::info(msg.str());
  return res;
}

}  // namespace hsr
