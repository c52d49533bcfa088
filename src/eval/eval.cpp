// Evaluation stage, the CGAL part (DESIGN.md §3, paper §4): validity checks of a polygon mesh and the
// point/mesh distances. The JSON and text reports are in eval_report.cpp (no CGAL there).
#include "eval/eval.h"

#include "core/face_class.h"

#include "core/error.h"
#include "core/kd_tree.h"
#include "core/log.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/intersections.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/boost/graph/helpers.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace hsr {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Triangle = K::Triangle_3;
using Mesh = CGAL::Surface_mesh<Point>;
using Soup = std::vector<std::vector<std::size_t>>;

using AabbPrimitive = CGAL::AABB_triangle_primitive<K, std::vector<Triangle>::const_iterator>;
using AabbTree = CGAL::AABB_tree<CGAL::AABB_traits<K, AabbPrimitive>>;

constexpr const char* kStage = "eval";

void check_mesh_input(const PolygonMesh& mesh, const std::string& what) {
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    if (!mesh.vertices[i].allFinite())
      throw Error(Status::BadInput, kStage, what + " vertex " + std::to_string(i) + " is not finite");
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const auto& face = mesh.faces[f];
    if (face.size() < 3)
      throw Error(Status::BadInput, kStage,
                  what + " face " + std::to_string(f) + " has " + std::to_string(face.size()) +
                      " vertices (need at least 3)");
    for (std::uint32_t v : face)
      if (v >= mesh.vertices.size())
        throw Error(Status::BadInput, kStage,
                    what + " face " + std::to_string(f) + " references vertex " + std::to_string(v) +
                        " but the mesh has " + std::to_string(mesh.vertices.size()));
  }
}

bool has_repeated_index(const std::vector<std::uint32_t>& face) {
  std::vector<std::uint32_t> sorted = face;
  std::sort(sorted.begin(), sorted.end());
  return std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end();
}

/// The checks of one mesh, and its triangles (for distances).
struct Analysed {
  Validity validity;
  std::vector<Triangle> triangles;  ///< non-degenerate triangles covering the faces, shifted
};

Point shifted(const Point& p, const Vec3& shift) {
  return Point(p.x() + shift.x(), p.y() + shift.y(), p.z() + shift.z());
}

void add_triangle(const Point& a, const Point& b, const Point& c, const Vec3& shift,
                  std::vector<Triangle>& out) {
  Triangle t(shifted(a, shift), shifted(b, shift), shifted(c, shift));
  if (!t.is_degenerate()) out.push_back(t);
}

/// Fan triangles of the input faces: only used for inputs CGAL cannot turn into a polygon mesh at all
/// (a face repeating a vertex); such meshes fail every check anyway.
std::vector<Triangle> fan_triangles(const std::vector<Point>& pts, const PolygonMesh& mesh,
                                    const Vec3& shift) {
  std::vector<Triangle> out;
  for (const auto& face : mesh.faces)
    for (std::size_t i = 1; i + 1 < face.size(); ++i)
      add_triangle(pts[face[0]], pts[face[i]], pts[face[i + 1]], shift, out);
  return out;
}

/// Do the non-degenerate triangles t and u, which share the vertex locations listed in `shared` (indices
/// into t and u), meet anywhere beyond them? Exact (filtered) predicates.
bool meet_beyond_shared(const std::array<Point, 3>& t, const std::array<Point, 3>& u,
                        const std::vector<std::pair<int, int>>& shared) {
  if (shared.size() >= 3) return true;  // the same triangle twice
  if (shared.size() == 2) {
    // Sharing edge pq: they overlap only when coplanar with both third vertices on the same side of pq.
    const Point& p = t[shared[0].first];
    const Point& q = t[shared[1].first];
    const Point& a = t[3 - shared[0].first - shared[1].first];
    const Point& b = u[3 - shared[0].second - shared[1].second];
    return CGAL::orientation(p, q, a, b) == CGAL::COPLANAR && CGAL::coplanar_orientation(p, q, a, b) == CGAL::POSITIVE;
  }
  // Sharing vertex v: both triangles are star-shaped from v, so if they meet elsewhere, the far edge of
  // one of them (the edge opposite v) meets the other triangle.
  const int i = shared[0].first, j = shared[0].second;
  const K::Segment_3 far_t(t[(i + 1) % 3], t[(i + 2) % 3]), far_u(u[(j + 1) % 3], u[(j + 2) % 3]);
  return CGAL::do_intersect(far_t, K::Triangle_3(u[0], u[1], u[2])) ||
         CGAL::do_intersect(far_u, K::Triangle_3(t[0], t[1], t[2]));
}

/// Self-intersection test on a triangulated mesh whose non-manifold vertices were duplicated: CGAL sees
/// the copies of one input vertex as distinct, so two faces meeting there are reported as intersecting.
/// Each reported pair that shares a vertex *location* is re-tested for contact beyond the shared part.
bool self_intersects_ignoring_duplicates(const Mesh& m) {
  using Face = Mesh::Face_index;
  std::vector<std::pair<Face, Face>> pairs;
  PMP::self_intersections(m, std::back_inserter(pairs));
  auto corners = [&](Face f) {
    std::array<Point, 3> c;
    int k = 0;
    for (auto v : CGAL::vertices_around_face(m.halfedge(f), m)) c[k++] = m.point(v);
    return c;
  };
  for (const auto& [f, g] : pairs) {
    const auto t = corners(f), u = corners(g);
    std::vector<std::pair<int, int>> shared;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (t[i] == u[j]) shared.emplace_back(i, j);
    if (shared.empty() || meet_beyond_shared(t, u, shared)) return true;
  }
  return false;
}

/// Splits every face of `m` into the triangles of triangulate_polygon, ear by ear (each ear (a, b, c) is
/// cut off the rest of its face along a -> c). Returns false when some face is not simple (its fan is
/// applied all the same, so the mesh is all triangles either way).
bool triangulate_mesh_faces(Mesh& m) {
  bool all_simple = true;
  const std::vector<Mesh::Face_index> faces(m.faces().begin(), m.faces().end());
  std::vector<Vec3> loop;
  std::vector<Mesh::Halfedge_index> into;  // per loop corner: the halfedge of the rest of the face ending there
  std::vector<std::array<std::uint32_t, 3>> ears;
  for (const auto f : faces) {
    loop.clear();
    into.clear();
    for (auto h : CGAL::halfedges_around_face(m.halfedge(f), m)) {
      const Point& p = m.point(m.target(h));
      loop.emplace_back(p.x(), p.y(), p.z());
      into.push_back(h);
    }
    if (loop.size() <= 3) continue;
    if (!triangulate_polygon(loop, ears)) all_simple = false;
    if (ears.size() != loop.size() - 2) {  // zero area: nothing to split along
      all_simple = false;
      continue;
    }
    for (std::size_t k = 0; k + 1 < ears.size(); ++k) {  // the last "ear" is what is left
      const std::uint32_t a = ears[k][0], c = ears[k][2];
      into[c] = CGAL::Euler::split_face(into[a], into[c], m);  // the new halfedge a -> c stays in the rest
    }
  }
  return all_simple;
}

Analysed analyse(const PolygonMesh& mesh, const Vec3& shift, bool check_self_intersections) {
  Analysed out;
  Validity& val = out.validity;
  val.self_intersections_checked = check_self_intersections;
  if (mesh.faces.empty() || mesh.vertices.empty()) return out;

  std::vector<Point> pts;
  pts.reserve(mesh.vertices.size());
  for (const Vec3& v : mesh.vertices) pts.emplace_back(v.x(), v.y(), v.z());

  if (std::any_of(mesh.faces.begin(), mesh.faces.end(), has_repeated_index)) {
    out.triangles = fan_triangles(pts, mesh, shift);
    return out;
  }

  Soup polys;
  polys.reserve(mesh.faces.size());
  for (const auto& face : mesh.faces) polys.emplace_back(face.begin(), face.end());

  // A soup that already is a polygon mesh is manifold and consistently oriented. Otherwise try to
  // re-orient it: success without duplicating a vertex means manifold (but the input's orientation was
  // inconsistent); needing duplicates means non-manifold edges or vertices.
  const bool consistent = PMP::is_polygon_soup_a_polygon_mesh(polys);
  bool manifold = consistent;
  if (!consistent) {
    const std::size_t n = pts.size();
    const bool no_duplicates = PMP::orient_polygon_soup(pts, polys);
    manifold = no_duplicates && pts.size() == n;
    if (!PMP::is_polygon_soup_a_polygon_mesh(polys)) {  // should not happen after orienting
      out.triangles = fan_triangles(pts, mesh, shift);
      return out;
    }
  }

  Mesh m;
  PMP::polygon_soup_to_polygon_mesh(pts, polys, m);
  // Our own triangulation (triangulate.cpp), which cannot crash; false for a face that is not simple.
  const bool triangulated = triangulate_mesh_faces(m);

  for (auto f : m.faces()) {
    std::vector<Point> loop;
    for (auto v : CGAL::vertices_around_face(m.halfedge(f), m)) loop.push_back(m.point(v));
    for (std::size_t i = 1; i + 1 < loop.size(); ++i)
      add_triangle(loop[0], loop[i], loop[i + 1], shift, out.triangles);
  }

  val.manifold = manifold;
  val.closed = manifold && CGAL::is_closed(m);
  if (!triangulated) {
    val.self_intersection_free = false;  // a degenerate face
    return out;
  }
  if (!check_self_intersections)
    val.self_intersection_free = true;  // assumed, see Validity::self_intersections_checked
  else if (manifold)
    val.self_intersection_free = !PMP::does_self_intersect(m);
  else
    val.self_intersection_free = !self_intersects_ignoring_duplicates(m);

  if (val.closed) {
    val.volume = PMP::volume(m);
    val.oriented = consistent && val.volume > 0 && PMP::is_outward_oriented(m);
    // does_bound_a_volume is undefined on self-intersecting meshes.
    val.bounds_volume = val.self_intersection_free && PMP::does_bound_a_volume(m);
  }
  return out;
}

/// Uniform double in [0, 1) from 53 random bits (our own mapping: portable and deterministic).
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

/// `count` points distributed uniformly by area over the triangles (deterministic given `rng`).
std::vector<Point> sample_area_uniform(const std::vector<Triangle>& triangles, std::size_t count,
                                       std::mt19937_64& rng, double* total_area = nullptr) {
  std::vector<double> cumulative(triangles.size());
  double sum = 0;
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    sum += std::sqrt(triangles[i].squared_area());
    cumulative[i] = sum;
  }
  if (total_area) *total_area = sum;
  std::vector<Point> samples;
  samples.reserve(count);
  for (std::size_t s = 0; s < count; ++s) {
    const double pick = uniform01(rng) * sum;
    std::size_t t = std::upper_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin();
    t = std::min(t, triangles.size() - 1);
    // Uniform point of a triangle: the square-root warp of two uniforms.
    const double r1 = std::sqrt(uniform01(rng)), r2 = uniform01(rng);
    const double a = 1.0 - r1, b = r1 * (1.0 - r2), c = r1 * r2;
    const Triangle& tri = triangles[t];
    samples.emplace_back(a * tri[0].x() + b * tri[1].x() + c * tri[2].x(),
                         a * tri[0].y() + b * tri[1].y() + c * tri[2].y(),
                         a * tri[0].z() + b * tri[1].z() + c * tri[2].z());
  }
  return samples;
}

/// Indices of `count` of the n points, uniformly at random without replacement (selection sampling,
/// Knuth's algorithm S), sorted; all of them when count >= n.
std::vector<std::size_t> point_subset(std::size_t n, std::size_t count, std::mt19937_64& rng) {
  std::vector<std::size_t> out;
  if (count >= n) {
    out.resize(n);
    for (std::size_t i = 0; i < n; ++i) out[i] = i;
    return out;
  }
  out.reserve(count);
  for (std::size_t i = 0; i < n && out.size() < count; ++i)
    if (uniform01(rng) * static_cast<double>(n - i) < static_cast<double>(count - out.size())) out.push_back(i);
  return out;
}

struct DistanceStats {
  double mean = 0, rms = 0, max = 0;
};

/// Squared distance of every query, in parallel (each writes its own slot: independent of the scheduling).
template <class SquaredDistance>
std::vector<double> squared_distances(const std::vector<Point>& queries, SquaredDistance&& squared_distance) {
  std::vector<double> squared(queries.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries.size(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i)
                        squared[i] = squared_distance(queries[i]);
                    });
  return squared;
}

/// Squared distance of every query to the tree's triangles, the queries taken in `order` (a permutation of
/// their indices that keeps neighbours in space together, KdTree::leaf_order) in fixed blocks, in parallel
/// (so the result does not depend on the scheduling). Within a block each query starts from the previous
/// one's closest point, which lies close by: the search sphere is tight at once. The minimum distance does
/// not depend on the hint.
std::vector<double> tree_squared_distances(const AabbTree& tree, const std::vector<Point>& queries,
                                           const std::vector<int>& order) {
  constexpr std::size_t kBlock = 256;
  std::vector<double> squared(queries.size());
  const std::size_t blocks = (order.size() + kBlock - 1) / kBlock;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t b = range.begin(); b != range.end(); ++b) {
      const std::size_t first = b * kBlock, last = std::min(order.size(), first + kBlock);
      auto hint = tree.closest_point_and_primitive(queries[static_cast<std::size_t>(order[first])]);
      for (std::size_t i = first; i < last; ++i) {
        const Point& q = queries[static_cast<std::size_t>(order[i])];
        if (i > first) hint = tree.closest_point_and_primitive(q, hint);
        squared[static_cast<std::size_t>(order[i])] = CGAL::squared_distance(q, hint.first);
      }
    }
  });
  return squared;
}

/// Distance statistics of precomputed squared distances, summed sequentially in query order.
DistanceStats stats_of_squared(const std::vector<double>& squared) {
  DistanceStats st;
  if (squared.empty()) return st;
  double sum = 0, sum_sq = 0;
  for (const double d2 : squared) {
    const double d = std::sqrt(d2);
    sum += d;
    sum_sq += d2;
    st.max = std::max(st.max, d);
  }
  st.mean = sum / squared.size();
  st.rms = std::sqrt(sum_sq / squared.size());
  return st;
}

/// Distance statistics of the queries; the sums are taken sequentially in query order.
template <class SquaredDistance>
DistanceStats distance_stats(const std::vector<Point>& queries, SquaredDistance&& squared_distance) {
  return stats_of_squared(squared_distances(queries, squared_distance));
}

/// AABB tree over `triangles` (which must outlive it), ready for parallel distance queries.
void build_distance_tree(AabbTree& tree, const std::vector<Triangle>& triangles) {
  tree.insert(triangles.begin(), triangles.end());
  tree.build();  // built up front, before the parallel queries
  tree.accelerate_distance_queries();
}

}  // namespace

std::vector<double> point_mesh_distances(const std::vector<Vec3>& points, const PolygonMesh& mesh) {
  return point_mesh_distances(points, mesh, points.empty() ? std::vector<int>{} : KdTree(points).leaf_order());
}

std::vector<double> point_mesh_distances(const std::vector<Vec3>& points, const PolygonMesh& mesh,
                                         const std::vector<int>& order) {
  check_mesh_input(mesh, "mesh");
  std::vector<Triangle> triangles;
  for (const auto& t : triangulate_faces(mesh)) {
    const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    add_triangle(Point(a.x(), a.y(), a.z()), Point(b.x(), b.y(), b.z()), Point(c.x(), c.y(), c.z()), Vec3::Zero(),
                 triangles);
  }
  std::vector<double> out(points.size(), std::numeric_limits<double>::infinity());
  if (triangles.empty()) return out;
  AabbTree tree;
  build_distance_tree(tree, triangles);
  std::vector<Point> queries;
  queries.reserve(points.size());
  for (const Vec3& p : points) queries.emplace_back(p.x(), p.y(), p.z());
  // In the points' kd-tree leaf order, each query hinted by its neighbour's closest point (as run_eval's p2m).
  const std::vector<double> squared = tree_squared_distances(tree, queries, order);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = std::sqrt(squared[i]);
  return out;
}

std::size_t count_farther(const std::vector<Vec3>& points, const PolygonMesh& mesh, double distance) {
  if (points.empty()) return 0;
  if (mesh.faces.empty()) return points.size();
  const std::vector<double> d = point_mesh_distances(points, mesh);
  return static_cast<std::size_t>(std::count_if(d.begin(), d.end(), [distance](double x) { return x > distance; }));
}

Validity check_validity(const PolygonMesh& mesh, bool check_self_intersections) {
  check_mesh_input(mesh, "mesh");
  return analyse(mesh, Vec3::Zero(), check_self_intersections).validity;
}

std::size_t mesh_sample_count(const EvalParams& params, std::size_t points, bool has_truth) {
  if (has_truth || params.samples_per_point == 0) return params.mesh_samples;
  const std::size_t scaled = std::max(params.min_mesh_samples, params.samples_per_point * points);
  return std::min(params.mesh_samples, scaled);
}

namespace {

/// The mesh -> points half of run_eval: res.mesh_samples samples drawn area-uniformly on the triangles with `rng`
/// (a fresh generator of the run's seed), each one's nearest input point in `kd`; fills the m2p figures and
/// mesh_area (fractions: times `inv`, 1 / the points' diagonal) and returns the samples (a truth's Chamfer
/// measures them again). One routine for run_eval and add_mesh_to_points: the same figures either way.
std::vector<Point> measure_mesh_to_points(const std::vector<Triangle>& triangles, const KdTree& kd, double inv,
                                          std::mt19937_64& rng, EvalResult& res) {
  std::vector<Point> mesh_samples = sample_area_uniform(triangles, res.mesh_samples, rng, &res.mesh_area);
  // Nearest input point of each sample (all points; exact, the same distances as CGAL's kd-tree).
  const DistanceStats m2p = distance_stats(mesh_samples, [&](const Point& q) {
    double d2 = 0;
    kd.nearest(Vec3(q.x(), q.y(), q.z()), &d2);
    return d2;
  });
  res.accuracy.m2p_mean = m2p.mean * inv;
  res.accuracy.m2p_max = m2p.max * inv;
  const double variance = std::max(0.0, m2p.rms * m2p.rms - m2p.mean * m2p.mean);
  res.accuracy.m2p_mean_stderr = std::sqrt(variance / static_cast<double>(mesh_samples.size())) * inv;
  res.m2p_later = false;
  return mesh_samples;
}

}  // namespace

void add_mesh_to_points(const PointCloud& points, const PolygonMesh& mesh, const EvalParams& params, EvalResult& res) {
  if (!res.m2p_later) return;
  const Analysed am = analyse(mesh, mesh.origin - points.origin, false);  // the same triangles as run_eval's
  const KdTree kd(points.points);
  std::mt19937_64 rng(params.seed);
  measure_mesh_to_points(am.triangles, kd, 1.0 / res.diagonal, rng, res);
}

EvalResult run_eval(const PointCloud& points, const PolygonMesh& mesh, const PolygonMesh* truth,
                    const EvalParams& params, MeshToPoints m2p) {
  if (points.empty()) throw Error(Status::BadInput, kStage, "no input points to evaluate against");
  if (mesh.faces.empty() || mesh.vertices.empty())
    throw Error(Status::BadInput, kStage, "the mesh to evaluate is empty");
  if (truth && (truth->faces.empty() || truth->vertices.empty()))
    throw Error(Status::BadInput, kStage, "the ground-truth mesh is empty");
  for (std::size_t i = 0; i < points.points.size(); ++i)
    if (!points.points[i].allFinite())
      throw Error(Status::BadInput, kStage, "input point " + std::to_string(i) + " is not finite");
  check_mesh_input(mesh, "mesh");
  if (truth) check_mesh_input(*truth, "truth");

  const double t_start = log::now_seconds();
  EvalResult res;
  res.vertices = mesh.num_vertices();
  res.faces = mesh.num_faces();
  res.regions = surface_regions(mesh);
  res.face_sizes = face_sizes(mesh);
  res.points = points.size();
  res.mesh_samples = mesh_sample_count(params, points.size(), truth != nullptr);
  res.diagonal = bounding_box(points.points).diagonal();
  if (!(res.diagonal > 0))
    throw Error(Status::BadInput, kStage, "all input points are identical (zero bbox diagonal)");

  // Everything is compared in the points' local frame.
  Analysed am = analyse(mesh, mesh.origin - points.origin, params.check_self_intersections);
  res.validity = am.validity;
  if (am.triangles.empty()) throw Error(Status::BadInput, kStage, "the mesh has zero area");
  const double t_validity = log::now_seconds();

  // Points -> mesh over all points, or a seeded subset of them for large inputs (EvalParams::max_points);
  // its own generator, so the mesh samples below are the same either way.
  std::vector<Point> input;
  std::vector<std::size_t> subset;
  {
    std::mt19937_64 subset_rng(params.seed ^ 0x9e3779b97f4a7c15ULL);
    const std::size_t want = params.max_points > 0 ? params.max_points : points.size();
    subset = point_subset(points.size(), want, subset_rng);
    input.reserve(subset.size());
    for (std::size_t i : subset) input.emplace_back(points.points[i].x(), points.points[i].y(), points.points[i].z());
  }
  res.points_evaluated = input.size();

  AabbTree mesh_tree;
  build_distance_tree(mesh_tree, am.triangles);
  const double inv = 1.0 / res.diagonal;

  // The points' kd-tree (also mesh -> points below) gives the queries an order that keeps neighbours together.
  const KdTree kd(points.points);
  std::vector<int> order;
  {
    std::vector<int> position(points.size(), -1);  // point index -> its query (subset is sorted)
    for (std::size_t q = 0; q < subset.size(); ++q) position[subset[q]] = static_cast<int>(q);
    order.reserve(subset.size());
    for (int i : kd.leaf_order())
      if (position[static_cast<std::size_t>(i)] >= 0) order.push_back(position[static_cast<std::size_t>(i)]);
  }
  std::vector<double> p2m_squared = tree_squared_distances(mesh_tree, input, order);
  const DistanceStats p2m = stats_of_squared(p2m_squared);
  if (subset.size() == points.size()) {  // every point, in input order (the subset is sorted)
    res.point_distance.resize(p2m_squared.size());
    for (std::size_t i = 0; i < p2m_squared.size(); ++i) res.point_distance[i] = std::sqrt(p2m_squared[i]);
  }
  res.accuracy.p2m_mean = p2m.mean * inv;
  res.accuracy.p2m_rms = p2m.rms * inv;
  res.accuracy.p2m_max = p2m.max * inv;
  // The queries freed before the mesh samples are drawn: the evaluation's peak is otherwise both together.
  std::vector<double>().swap(p2m_squared);
  std::vector<Point>().swap(input);
  std::vector<std::size_t>().swap(subset);
  std::vector<int>().swap(order);

  const double t_p2m = log::now_seconds();
  std::mt19937_64 rng(params.seed);
  std::vector<Point> mesh_samples;
  if (m2p == MeshToPoints::Now || truth)
    mesh_samples = measure_mesh_to_points(am.triangles, kd, inv, rng, res);
  else
    res.m2p_later = true;

  if (truth) {
    Analysed at = analyse(*truth, truth->origin - points.origin, false);
    if (at.triangles.empty()) throw Error(Status::BadInput, kStage, "the ground-truth mesh has zero area");
    AabbTree truth_tree;
    build_distance_tree(truth_tree, at.triangles);
    const std::vector<Point> truth_samples = sample_area_uniform(at.triangles, params.mesh_samples, rng);
    const DistanceStats to_truth =
        distance_stats(mesh_samples, [&](const Point& q) { return truth_tree.squared_distance(q); });
    const DistanceStats to_mesh =
        distance_stats(truth_samples, [&](const Point& q) { return mesh_tree.squared_distance(q); });
    res.accuracy.has_truth = true;
    res.accuracy.chamfer = 0.5 * (to_truth.mean + to_mesh.mean) * inv;
    res.accuracy.hausdorff = std::max(to_truth.max, to_mesh.max) * inv;
    res.accuracy.truth_to_mesh_mean = to_mesh.mean * inv;
    res.accuracy.mesh_to_truth_mean = to_truth.mean * inv;
    res.accuracy.truth_to_mesh_max = to_mesh.max * inv;
    res.accuracy.mesh_to_truth_max = to_truth.max * inv;
  }
  std::ostringstream msg;
  msg << "[eval] validity " << (t_validity - t_start) << " s, points->mesh " << (t_p2m - t_validity)
      << " s, sampling and the rest " << (log::now_seconds() - t_p2m)
      << " s (" << res.points << " points, p2m over " << res.points_evaluated << ", " << am.triangles.size()
      << " triangles, " << res.mesh_samples
      << " samples per mesh)";
  log::verbose(msg.str());
  return res;
}

}  // namespace hsr
