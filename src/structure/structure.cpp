// Stage 1 driver: normals, plane detection (region growing), refit, regularisation, adjacency, lines.
// Boundaries live in boundary.cpp, RANSAC in ransac.cpp, the dump writer in dump.cpp.
#include "structure/structure.h"
#include "structure/structure_internal.h"

#include "core/budget.h"
#include "core/error.h"
#include "core/log.h"
#include "core/spacing.h"


#include <Eigen/Eigenvalues>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <memory>
#include <numeric>
#include <queue>
#include <sstream>
#include <tuple>

namespace hsr {


bool SceneStructure::adjacent(int i, int j) const {
  if (i < 0 || i >= static_cast<int>(adjacency.size())) return false;
  return std::binary_search(adjacency[i].begin(), adjacency[i].end(), j);
}

namespace structure_detail {

KnnGraph build_knn_graph(const std::vector<Vec3>& points, const KdTree& tree, int k) {
  KnnGraph g;
  const std::size_t n = points.size();
  g.k = std::max(0, std::min<int>(k, static_cast<int>(n) - 1));
  if (g.k == 0) return g;
  g.neighbors = tree.neighbour_rows(g.k);
  return g;
}

Plane fit_plane(const std::vector<Vec3>& points, const std::vector<int>& indices, Vec3* centroid_out) {
  Vec3 c = Vec3::Zero();
  for (int i : indices) c += points[i];
  c /= static_cast<double>(std::max<std::size_t>(1, indices.size()));
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int i : indices) {
    const Vec3 d = points[i] - c;
    cov += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  Vec3 n = es.eigenvectors().col(0).normalized();
  if (!std::isfinite(n.x()) || n.norm() < 0.5) n = Vec3::UnitZ();
  Plane pl;
  pl.normal = n;
  pl.offset = -n.dot(c);
  if (centroid_out) *centroid_out = c;
  return pl;
}

void compute_second_order(SceneStructure& s) {
  const std::size_t np = s.planes.size();
  s.second_order.assign(np, {});
  for (std::size_t i = 0; i < np; ++i) {
    std::vector<int> so;
    for (int j : s.adjacency[i])
      for (int k2 : s.adjacency[j])
        if (k2 != static_cast<int>(i) && !s.adjacent(static_cast<int>(i), k2)) so.push_back(k2);
    std::sort(so.begin(), so.end());
    so.erase(std::unique(so.begin(), so.end()), so.end());
    s.second_order[i] = std::move(so);
  }
}

void compute_lines(SceneStructure& s, double min_line_angle_deg) {
  s.lines.clear();
  const double sin_min = std::sin(min_line_angle_deg * M_PI / 180.0);
  for (std::size_t i = 0; i < s.planes.size(); ++i) {
    std::vector<std::pair<int, bool>> partners;
    for (int j : s.adjacency[i]) if (j > static_cast<int>(i)) partners.emplace_back(j, true);
    for (int j : s.second_order[i]) if (j > static_cast<int>(i)) partners.emplace_back(j, false);
    std::sort(partners.begin(), partners.end());
    for (const auto& [j, adj] : partners) {
      const Plane& A = s.planes[i].plane;
      const Plane& B = s.planes[j].plane;
      Vec3 dir = A.normal.cross(B.normal);
      const double sn = dir.norm();
      if (sn < sin_min) continue;
      dir /= sn;
      // Nearest point to c on both planes: p = c + a nA + b nB with nA·p = -dA, nB·p = -dB.
      const Vec3 c = 0.5 * (s.planes[i].centroid + s.planes[j].centroid);
      const double cab = A.normal.dot(B.normal);
      const double ra = -A.offset - A.normal.dot(c), rb = -B.offset - B.normal.dot(c);
      const double det = 1.0 - cab * cab;
      const double a = (ra - cab * rb) / det, b = (rb - cab * ra) / det;
      IntersectionLine line;
      line.plane_a = static_cast<int>(i);
      line.plane_b = j;
      line.point = c + a * A.normal + b * B.normal;
      line.direction = dir;
      line.adjacent = adj;
      s.lines.push_back(line);
    }
  }
}

}  // namespace structure_detail

namespace {

using namespace structure_detail;

constexpr double kPi = 3.14159265358979323846;
double deg2rad(double d) { return d * kPi / 180.0; }

std::string cloud_name(const PointCloud& cloud) { return cloud.source.empty() ? "<memory>" : cloud.source; }

// Orients normals: towards the nearest scanner if given, else MST propagation; points the MST leaves
// unoriented are turned away from the bbox centre.
void orient_normals(const std::vector<Vec3>& pts, std::vector<Vec3>& normals, const StructureParams& params,
                    const BBox& bbox, const KnnGraph& g) {
  if (!params.scanners.empty()) {
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Vec3* best = &params.scanners.front();
      for (const auto& s : params.scanners)
        if ((s - pts[i]).squaredNorm() < (*best - pts[i]).squaredNorm()) best = &s;
      if (normals[i].dot(*best - pts[i]) < 0) normals[i] = -normals[i];
    }
    return;
  }
  const std::vector<char> reached = mst_orient(pts, normals, g, params.normal_k);
  std::size_t not_oriented = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    Vec3 nrm = normals[i];
    if (!reached[i]) {
      ++not_oriented;
      if (nrm.dot(pts[i] - bbox.center()) < 0) nrm = -nrm;
    }
    normals[i] = nrm.normalized();
  }
  if (not_oriented > 0)
    log::verbose("structure: " + std::to_string(not_oriented) +
                 " normals not reached by MST orientation, oriented away from the bbox centre");
}

// Unassigned points join the nearest plane among their neighbours' planes, within max_dist.
// Returns, per region, the points added (sorted).
std::vector<std::vector<int>> assign_leftovers(const std::vector<Vec3>& pts, const std::vector<Vec3>& normals,
                                               const KnnGraph& g, int k, int rounds, double max_dist,
                                               double max_angle_deg, bool signed_normals,
                                               const std::vector<std::vector<int>>& regions) {
  const double min_cos = std::cos(deg2rad(max_angle_deg));
  const std::size_t n = pts.size();
  std::vector<int> label(n, -1);
  std::vector<Plane> planes;
  for (std::size_t r = 0; r < regions.size(); ++r) {
    for (int i : regions[r]) label[i] = static_cast<int>(r);
    Plane pl = fit_plane(pts, regions[r], nullptr);
    double vote = 0;  // orient like the region's normals (matters with signed_normals)
    for (int i : regions[r]) vote += normals[i].dot(pl.normal);
    if (vote < 0) { pl.normal = -pl.normal; pl.offset = -pl.offset; }
    planes.push_back(pl);
  }
  k = std::min(k, g.k);
  std::vector<std::vector<int>> added(regions.size());
  std::size_t added_total = 0;
  for (int round = 0; round < rounds; ++round) {
    std::vector<std::pair<int, int>> add;  // decided from the previous round's labels only
    for (std::size_t i = 0; i < n; ++i) {
      if (label[i] >= 0) continue;
      int best = -1;
      double best_d = max_dist;
      const int* row = g.row(i);
      for (int a = 0; a < k; ++a) {
        const int l = label[row[a]];
        if (l < 0) continue;
        const double c = normals[i].dot(planes[l].normal);
        if ((signed_normals ? c : std::abs(c)) < min_cos) continue;
        const double d = std::abs(planes[l].signed_distance(pts[i]));
        if (d < best_d || (d == best_d && best >= 0 && l < best)) { best_d = d; best = l; }
      }
      if (best >= 0) add.emplace_back(static_cast<int>(i), best);
    }
    if (add.empty()) break;
    for (const auto& [i, l] : add) { label[i] = l; added[l].push_back(i); }
    added_total += add.size();
  }
  for (auto& a : added) std::sort(a.begin(), a.end());
  log::verbose("structure: " + std::to_string(added_total) + " leftover points assigned to planes");
  return added;
}

// A plane to build: its inliers and, after regularisation, a fixed normal (zero: least-squares fit).
// The plane is fit to `inliers` only; `extra` points (leftovers) join the inliers without moving the plane,
// so points of small undetected faces near an edge cannot tilt it.
struct Region {
  std::vector<int> inliers;
  Vec3 fixed_normal = Vec3::Zero();
  std::vector<int> extra;
};

// Planes from inlier lists: refit, orient the normal with the inliers' normals, sort by size.
std::vector<DetectedPlane> make_planes(const std::vector<Vec3>& pts, const std::vector<Vec3>& normals,
                                       std::vector<Region> regions) {
  std::sort(regions.begin(), regions.end(), [](const Region& a, const Region& b) {
    const std::size_t na = a.inliers.size() + a.extra.size(), nb = b.inliers.size() + b.extra.size();
    if (na != nb) return na > nb;
    return a.inliers.front() < b.inliers.front();
  });
  std::vector<DetectedPlane> planes;
  for (auto& reg : regions) {
    DetectedPlane p;
    Vec3 fit_centroid;
    p.plane = fit_plane(pts, reg.inliers, &fit_centroid);
    if (reg.fixed_normal.squaredNorm() > 0) {
      p.plane.normal = reg.fixed_normal;
      p.plane.offset = -reg.fixed_normal.dot(fit_centroid);
    }
    p.inliers = std::move(reg.inliers);
    if (!reg.extra.empty()) {
      p.inliers.insert(p.inliers.end(), reg.extra.begin(), reg.extra.end());
      std::sort(p.inliers.begin(), p.inliers.end());
    }
    p.centroid = Vec3::Zero();
    for (int i : p.inliers) p.centroid += pts[i];
    p.centroid /= static_cast<double>(p.inliers.size());
    double vote = 0;
    for (int i : p.inliers) vote += normals[i].dot(p.plane.normal);
    if (vote < 0) { p.plane.normal = -p.plane.normal; p.plane.offset = -p.plane.offset; }
    planes.push_back(std::move(p));
  }
  return planes;
}

/// Planes that are one plane up to the rounding of their fits (normals within ~1e-6 rad, offsets within
/// kCoincidentOffset of the diagonal) get one equation: the first one's (the larger plane). Points sampled
/// exactly on one plane in several regions (CAD clouds: fit4cad_PC3 has four regions on x = const) are fit
/// to equations a few ulps apart, which the exact partition takes for distinct planes 1e-15 apart: cells
/// thinner than the coordinates' precision, and an output that touches itself once rounded to doubles.
constexpr double kCoincidentCos = 1.0 - 1e-12;
constexpr double kCoincidentOffset = 1e-9;
std::size_t share_coincident_equations(std::vector<DetectedPlane>& planes, double diagonal) {
  std::size_t shared = 0;
  for (std::size_t j = 1; j < planes.size(); ++j)
    for (std::size_t i = 0; i < j; ++i) {
      const Plane &a = planes[i].plane, &b = planes[j].plane;
      const double c = a.normal.dot(b.normal);
      if (std::abs(c) < kCoincidentCos) continue;
      const double sign = c > 0 ? 1.0 : -1.0;
      if (std::abs(sign * a.offset - b.offset) > kCoincidentOffset * diagonal) continue;
      if (a.normal != sign * b.normal || a.offset != sign * b.offset) ++shared;
      planes[j].plane.normal = sign * a.normal;
      planes[j].plane.offset = sign * a.offset;
      break;
    }
  return shared;
}

// Regularisation: snap near-parallel normals to their weighted mean, merge near-coplanar planes.
std::vector<Region> regularize_planes(std::vector<DetectedPlane>& planes, double angle_deg, double max_offset) {
  const double cos_tol = std::cos(deg2rad(angle_deg));
  const std::size_t n = planes.size();
  std::vector<int> group(n, -1);
  std::vector<Vec3> group_normal;
  for (std::size_t i = 0; i < n; ++i) {  // planes sorted by size: the largest seeds each group
    if (group[i] >= 0) continue;
    const int gid = static_cast<int>(group_normal.size());
    group[i] = gid;
    const Vec3 ni = planes[i].plane.normal;
    Vec3 sum = ni * static_cast<double>(planes[i].inliers.size());
    for (std::size_t j = i + 1; j < n; ++j) {
      if (group[j] >= 0) continue;
      const double c = ni.dot(planes[j].plane.normal);
      if (std::abs(c) >= cos_tol) {
        group[j] = gid;
        sum += (c < 0 ? -1.0 : 1.0) * planes[j].plane.normal * static_cast<double>(planes[j].inliers.size());
      }
    }
    group_normal.push_back(sum.normalized());
  }
  // Snap normals, then merge coplanar members of each group.
  std::vector<Region> merged;
  std::vector<bool> used(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 gn = group_normal[group[i]];
    planes[i].plane.normal = planes[i].plane.normal.dot(gn) < 0 ? -gn : gn;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (used[i]) continue;
    used[i] = true;
    std::vector<int> inl = planes[i].inliers;
    const Vec3 gn = group_normal[group[i]];
    const double oi = gn.dot(planes[i].centroid);
    for (std::size_t j = i + 1; j < n; ++j) {
      if (used[j] || group[j] != group[i]) continue;
      // Same side only: the two faces of a thin wall are parallel and close but must stay two planes.
      if (planes[j].plane.normal.dot(planes[i].plane.normal) <= 0) continue;
      if (std::abs(gn.dot(planes[j].centroid) - oi) < max_offset) {
        used[j] = true;
        inl.insert(inl.end(), planes[j].inliers.begin(), planes[j].inliers.end());
      }
    }
    std::sort(inl.begin(), inl.end());
    merged.push_back({std::move(inl), gn});
  }
  return merged;
}

// Mutual kNN pairs between inliers of two planes. A pair involving a leftover point (not a region member)
// counts only when both points lie within `near` of both planes (the pair straddles their crossing): a
// leftover can sit on a small undetected face between two planes that do not touch.
void compute_adjacency(SceneStructure& s, const std::vector<Vec3>& pts, const KnnGraph& g,
                       const StructureParams& params, const std::vector<char>& core, double near) {
  const std::size_t np = s.planes.size();
  const int k = std::min(params.adjacency_k, g.k);
  std::map<std::pair<int, int>, int> pair_count;
  for (std::size_t i = 0; i < s.point_plane.size(); ++i) {
    const int pi = s.point_plane[i];
    if (pi < 0) continue;
    const int* row = g.row(i);
    for (int a = 0; a < k; ++a) {
      const int j = row[a];
      if (static_cast<std::size_t>(j) <= i) continue;  // count each unordered pair once
      const int pj = s.point_plane[j];
      if (pj < 0 || pj == pi) continue;
      if (!(core[i] && core[j])) {
        const Plane &a = s.planes[pi].plane, &b = s.planes[pj].plane;
        if (std::abs(b.signed_distance(pts[i])) > near || std::abs(a.signed_distance(pts[j])) > near) continue;
      }
      const int* rowj = g.row(j);
      if (std::find(rowj, rowj + k, static_cast<int>(i)) == rowj + k) continue;  // not mutual
      ++pair_count[{std::min(pi, pj), std::max(pi, pj)}];
    }
  }
  s.adjacency.assign(np, {});
  for (const auto& [key, count] : pair_count)
    if (count >= params.min_adjacent_pairs) {
      s.adjacency[key.first].push_back(key.second);
      s.adjacency[key.second].push_back(key.first);
    }
  for (auto& a : s.adjacency) std::sort(a.begin(), a.end());
  compute_second_order(s);
}

/// The outline segments' fields of the detection's report (lengths in units, spacing r): params_json's, and
/// what resegment_structure writes over them.
void segment_params_json(const StructureParams& p, double r, nlohmann::json& j) {
  j["segment_max_distance"] = p.segment_max_distance * r;
  j["segment_max_angle_deg"] = p.segment_max_angle_deg;
  j["min_segment_points"] = p.min_segment_points;
  j["regularize_segments"] = p.regularize_segments;
  j["segment_angle_tolerance_deg"] = p.segment_angle_tolerance_deg;
  j["segment_collinear_tolerance"] = p.segment_collinear_tolerance * r;
}

nlohmann::json params_json(const StructureParams& p, double r, const MinimumPlane& min_plane) {
  nlohmann::json j;
  j["spacing"] = r;
  j["normal_k"] = p.normal_k;
  j["detector"] = p.detector == PlaneDetector::RegionGrowing ? "region_growing" : "ransac";
  j["region_k"] = p.region_k;
  j["max_distance"] = p.max_distance * r;
  j["max_angle_deg"] = p.max_angle_deg;
  j["signed_normals"] = p.signed_normals;
  j["leftover_rounds"] = p.leftover_rounds;
  j["leftover_max_angle_deg"] = p.leftover_max_angle_deg;
  j["min_region_points"] = min_plane.points;
  j["min_region_width"] = min_plane.width;
  if (p.detector == PlaneDetector::Ransac) {
    j["ransac_probability"] = p.ransac_probability;
    j["ransac_cluster_epsilon"] = p.ransac_cluster_epsilon * r;
    j["seed"] = p.seed;
  }
  j["regularize"] = p.regularize;
  j["regularize_angle_deg"] = p.regularize_angle_deg;
  j["alpha_radius"] = p.alpha_radius * r;
  j["boundary_normal_k"] = p.boundary_normal_k;
  segment_params_json(p, r, j);
  j["adjacency_k"] = p.adjacency_k;
  j["min_adjacent_pairs"] = p.min_adjacent_pairs;
  j["min_line_angle_deg"] = p.min_line_angle_deg;
  j["max_seed_failures"] = p.max_seed_failures;
  j["scanners"] = p.scanners.size();
  return j;
}

void check_params(const StructureParams& p) {
  auto bad = [](const std::string& what) { throw Error(Status::BadInput, "structure", "invalid parameter: " + what); };
  if (p.normal_k < 3) bad("normal_k must be >= 3");
  if (p.region_k < 1) bad("region_k must be >= 1");
  if (!(p.max_distance > 0)) bad("max_distance must be > 0");
  if (!(p.max_angle_deg > 0 && p.max_angle_deg <= 90)) bad("max_angle_deg must be in (0, 90]");
  if (p.min_region_points < 3) bad("min_region_points must be >= 3");
  if (!(p.min_region_width >= 0) || !std::isfinite(p.min_region_width)) bad("min_region_width must be >= 0");
  if (!(p.min_region_fraction >= 0) || !(p.min_region_fraction <= 1)) bad("min_region_fraction must be in [0, 1]");
  if (!(p.alpha_radius > 0)) bad("alpha_radius must be > 0");
  if (p.adjacency_k < 1) bad("adjacency_k must be >= 1");
  if (!(p.spacing >= 0)) bad("spacing must be >= 0");
  if (p.max_seed_failures < 0 || p.max_seed_failures > 255) bad("max_seed_failures must be in [0, 255]");
}

}  // namespace

namespace {

/// Whether `cache` holds the graph build_knn_graph(pts, tree, k) gives (k clamped as it clamps it).
bool cached_graph_fits(const KnnGraphCache& cache, const std::vector<Vec3>& pts, int k) {
  const int clamped = std::max(0, std::min<int>(k, static_cast<int>(pts.size()) - 1));
  return cache.graph && cache.graph->k == clamped && cache.data == pts.data() && cache.size == pts.size() &&
         !pts.empty() && cache.first == pts.front() && cache.last == pts.back();
}

/// Whether `cache` (whose graph fits) holds the normals run_structure would estimate and orient with `params`.
bool kept_normals_fit(const KnnGraphCache& cache, const StructureParams& params) {
  return cache.normals.size() == cache.size && cache.normals_k == params.normal_k &&
         cache.normals_scanners == params.scanners;
}

void keep_graph(KnnGraphCache& cache, std::shared_ptr<const structure_detail::KnnGraph> graph, const std::vector<Vec3>& pts,
                double spacing = 0.0) {
  cache.graph = std::move(graph);
  cache.spacing = spacing;
  cache.normals.clear();  // made over another graph
  cache.normals_k = 0;
  cache.normals_scanners.clear();
  cache.data = pts.data();
  cache.size = pts.size();
  cache.first = pts.empty() ? Vec3::Zero() : pts.front();
  cache.last = pts.empty() ? Vec3::Zero() : pts.back();
}

}  // namespace

SceneStructure run_structure(const PointCloud& cloud, const StructureParams& params, KnnGraphCache* keep) {
  check_params(params);
  const std::string name = cloud_name(cloud);
  const auto& pts = cloud.points;
  const std::size_t n = pts.size();
  if (n < 3)
    throw Error(Status::BadInput, "structure",
                "need at least 3 points to detect planes, " + name + " has " + std::to_string(n));
  for (const auto& p : pts)
    if (!p.allFinite()) throw Error(Status::BadInput, "structure", "non-finite coordinate in " + name);

  SceneStructure s;
  s.bbox = bounding_box(pts);
  // Global PCA: reject inputs with no 2D extent (identical or collinear points).
  {
    std::vector<int> all(n);
    std::iota(all.begin(), all.end(), 0);
    Vec3 c = Vec3::Zero();
    for (const auto& p : pts) c += p;
    c /= static_cast<double>(n);
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& p : pts) cov += (p - c) * (p - c).transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov / static_cast<double>(n));
    const Vec3 ev = es.eigenvalues().cwiseMax(0.0).cwiseSqrt();
    if (!(ev(2) > 1e-12 * std::max(1.0, c.norm())))
      throw Error(Status::BadInput, "structure", "all points of " + name + " are identical");
    if (ev(1) < 1e-6 * ev(2))
      throw Error(Status::BadInput, "structure", "all points of " + name + " lie on one line: no plane to detect");
  }
  // One kd-tree for the kNN graph (and the spacing, read off the graph); dropped once the graph is built. A graph (and spacing) kept
  // from an earlier run on the same points is taken as it is (KnnGraphCache): the same graph, no tree.
  double t_phase = log::now_seconds(), c_phase = log::cpu_seconds();
  const int graph_k = std::max({params.normal_k, params.region_k, params.adjacency_k});
  const bool cached = keep && cached_graph_fits(*keep, pts, graph_k) && (params.spacing > 0 || keep->spacing > 0);
  std::unique_ptr<KdTree> tree;
  if (!cached) tree = std::make_unique<KdTree>(pts);
  const auto graph_held = cached ? keep->graph : std::make_shared<const KnnGraph>(build_knn_graph(pts, *tree, graph_k));
  const KnnGraph& graph = *graph_held;
  // The spacing from the graph's rows where they reach its k neighbours (the same value as the tree's queries).
  const int spacing_k = 6;
  const double measured = params.spacing > 0 ? 0.0
                          : cached           ? keep->spacing
                          : graph.k >= std::min<int>(spacing_k, static_cast<int>(n) - 1)
                              ? average_spacing_of_rows(pts, graph.neighbors, graph.k, spacing_k)
                              : average_spacing(pts, *tree, spacing_k);
  const double r = params.spacing > 0 ? params.spacing : measured;
  if (!(r > 0))
    throw Error(Status::BadInput, "structure",
                "average spacing of " + name + " is 0 (too many duplicate points); pass a spacing");
  s.spacing = r;
  s.alpha_radius = params.alpha_radius * r;
  MinimumPlane min_plane;
  min_plane.points = std::max<std::size_t>(
      static_cast<std::size_t>(params.min_region_points),
      static_cast<std::size_t>(std::ceil(params.min_region_fraction * static_cast<double>(n))));
  min_plane.width = params.min_region_width * r;
  min_plane.distinct = params.min_region_distinct;
  const std::size_t min_points = min_plane.points;
  s.params = params_json(params, r, min_plane);
  {
    std::ostringstream os;
    os << "structure: " << n << " points, spacing r = " << r << ", max distance " << params.max_distance * r
       << ", max angle " << params.max_angle_deg << " deg, min plane " << min_points << " points and "
       << min_plane.width << " wide, alpha radius " << params.alpha_radius * r;
    log::info(os.str());
  }

  auto phase_done = [&](const char* what) {
    const double t = log::now_seconds(), c = log::cpu_seconds();
    std::ostringstream os;
    os << "structure: " << what << " " << std::fixed << std::setprecision(3) << t - t_phase << " s (CPU "
       << c - c_phase << " s)";
    log::verbose(os.str());
    t_phase = t;
    c_phase = c;
  };
  if (keep && !cached) keep_graph(*keep, graph_held, pts, measured);
  tree.reset();
  phase_done(cached ? "the kept kNN graph" : "kd-tree, spacing and kNN graph");

  if (cloud.has_normals()) {
    s.normals = cloud.normals;
    log::verbose("structure: using the normals of " + name);
  } else if (cached && kept_normals_fit(*keep, params)) {
    s.normals = keep->normals;
    log::verbose("structure: the kept normals (PCA, k = " + std::to_string(params.normal_k) + ")");
  } else {
    s.normals = estimate_normals(pts, graph, params.normal_k);
    orient_normals(pts, s.normals, params, s.bbox, graph);
    log::verbose("structure: estimated normals (PCA, k = " + std::to_string(params.normal_k) + ")");
    if (keep && keep->graph == graph_held) {
      keep->normals = s.normals;
      keep->normals_k = params.normal_k;
      keep->normals_scanners = params.scanners;
    }
  }

  phase_done("normals");
  std::vector<std::vector<int>> regions =
      params.detector == PlaneDetector::RegionGrowing
          ? detect_planes_region_growing(pts, s.normals, graph, params, r, min_plane)
          : detect_planes_ransac(pts, s.normals, params, r, min_points);
  if (params.detector == PlaneDetector::Ransac)  // region growing keeps only regions large enough
    regions.erase(std::remove_if(regions.begin(), regions.end(),
                                 [&](const std::vector<int>& v) {
                                   return !is_large_enough(pts, v, fit_plane(pts, v, nullptr).normal, min_plane);
                                 }),
                  regions.end());
  if (regions.empty())
    throw Error(Status::NoPlanes, "structure",
                "no plane found in " + name + ": no region of at least " + std::to_string(min_points) +
                    " points, " + std::to_string(params.min_region_width) + " r wide, within " +
                    std::to_string(params.max_distance) + " r of a plane (try a larger max_distance or max_angle, "
                    "or a smaller --min-plane-points / --min-plane-width)");

  phase_done("plane detection");
  std::vector<char> core(n, 0);
  for (const auto& reg : regions) for (int i : reg) core[i] = 1;
  std::vector<std::vector<int>> leftovers(regions.size());
  if (params.leftover_rounds > 0)
    leftovers = assign_leftovers(pts, s.normals, graph, params.region_k, params.leftover_rounds, params.max_distance * r,
                                 params.leftover_max_angle_deg, params.signed_normals, regions);
  {
    std::vector<Region> regs;
    for (std::size_t i = 0; i < regions.size(); ++i) regs.push_back({std::move(regions[i]), Vec3::Zero(), std::move(leftovers[i])});
    s.planes = make_planes(pts, s.normals, std::move(regs));
  }
  if (params.regularize) {
    // Snapped normals are kept; only the offsets are refit (through the merged centroids).
    auto merged = regularize_planes(s.planes, params.regularize_angle_deg, params.max_distance * r);
    const std::size_t before = s.planes.size();
    s.planes = make_planes(pts, s.normals, std::move(merged));
    log::verbose("structure: regularisation merged " + std::to_string(before - s.planes.size()) + " planes");
  }

  if (const std::size_t shared = params.share_coincident_planes ? share_coincident_equations(s.planes, s.bbox.diagonal()) : 0)
    log::verbose("structure: " + std::to_string(shared) + " planes given the equation of a plane they coincide with");
  s.point_plane.assign(n, -1);
  for (std::size_t p = 0; p < s.planes.size(); ++p)
    for (int i : s.planes[p].inliers) s.point_plane[i] = static_cast<int>(p);

  {
    phase_done("leftovers and refit");
    // Planes are independent: one task each (largest first), each writing only its own plane.
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s.planes.size(), 1), [&](const tbb::blocked_range<std::size_t>& range) {
      for (std::size_t p = range.begin(); p != range.end(); ++p) {
        check_budget("structure");
        compute_boundary(pts, static_cast<int>(p), s.planes[p], params, r);
      }
    });
    phase_done("boundaries and segments");
  }

  compute_adjacency(s, pts, graph, params, core, params.max_distance * r);
  compute_lines(s, params.min_line_angle_deg);
  phase_done("adjacency and lines");

  std::size_t assigned = 0, segments = 0, edges = 0;
  for (const auto& p : s.planes) { assigned += p.inliers.size(); segments += p.segments.size(); }
  for (const auto& a : s.adjacency) edges += a.size();
  log::info("structure: " + std::to_string(s.planes.size()) + " planes (" + std::to_string(assigned) + " of " +
            std::to_string(n) + " points), " + std::to_string(segments) + " boundary segments, " +
            std::to_string(edges / 2) + " adjacent pairs, " + std::to_string(s.lines.size()) + " intersection lines");
  return s;
}

SceneStructure resegment_structure(const PointCloud& cloud, const SceneStructure& detected, const StructureParams& params) {
  using namespace structure_detail;
  check_params(params);
  if (detected.point_plane.size() != cloud.size())
    throw Error(Status::Internal, "structure", "resegment_structure: the detection is not of this cloud");
  SceneStructure s = detected;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s.planes.size(), 1), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t p = range.begin(); p != range.end(); ++p)
      segment_boundary(cloud.points, static_cast<int>(p), s.planes[p], params, s.spacing);
  });
  segment_params_json(params, s.spacing, s.params);
  return s;
}

}  // namespace hsr

namespace hsr {

namespace {

/// The kNN graph of add_small_planes and add_planes: the cache's when it fits, else built (and left in the cache).
std::shared_ptr<const structure_detail::KnnGraph> small_planes_graph(const std::vector<Vec3>& pts,
                                                                     const StructureParams& params, KnnGraphCache* cache) {
  using namespace structure_detail;
  const int graph_k = std::max({params.normal_k, params.region_k, params.adjacency_k});
  if (cache && cached_graph_fits(*cache, pts, graph_k)) return cache->graph;
  const KdTree tree(pts);
  auto graph = std::make_shared<const KnnGraph>(build_knn_graph(pts, tree, graph_k));
  if (cache) keep_graph(*cache, graph, pts);
  return graph;
}

/// `s` with planes of the inlier lists `regions` appended (add_small_planes' and add_planes' common part).
SceneStructure append_planes(const std::vector<Vec3>& pts, const SceneStructure& s, std::vector<std::vector<int>> regions,
                             const StructureParams& params, const structure_detail::KnnGraph& graph) {
  using namespace structure_detail;
  const std::size_t n = pts.size();
  const double r = s.spacing;
  std::vector<Region> regs;
  for (auto& reg : regions) regs.push_back({std::move(reg), Vec3::Zero(), {}});
  std::vector<DetectedPlane> added = make_planes(pts, s.normals, std::move(regs));

  SceneStructure out = s;
  const std::size_t first = out.planes.size();
  for (DetectedPlane& p : added) {
    const auto index = static_cast<int>(out.planes.size());
    for (int i : p.inliers) out.point_plane[static_cast<std::size_t>(i)] = index;
    out.planes.push_back(std::move(p));
  }
  for (std::size_t p = first; p < out.planes.size(); ++p)
    compute_boundary(pts, static_cast<int>(p), out.planes[p], params, r);
  // Adjacency of the new planes (mutual kNN pairs of inliers, as compute_adjacency counts them between
  // detected regions); the first planes' adjacency among themselves is kept as it was.
  const int k = std::min(params.adjacency_k, graph.k);
  std::map<std::pair<int, int>, int> pair_count;
  for (std::size_t i = 0; i < n; ++i) {
    const int pi = out.point_plane[i];
    if (pi < 0) continue;
    const int* row = graph.row(i);
    for (int a = 0; a < k; ++a) {
      const int j = row[a];
      if (static_cast<std::size_t>(j) <= i) continue;
      const int pj = out.point_plane[static_cast<std::size_t>(j)];
      if (pj < 0 || pj == pi || (static_cast<std::size_t>(pi) < first && static_cast<std::size_t>(pj) < first)) continue;
      const int* rowj = graph.row(static_cast<std::size_t>(j));
      if (std::find(rowj, rowj + k, static_cast<int>(i)) == rowj + k) continue;
      ++pair_count[{std::min(pi, pj), std::max(pi, pj)}];
    }
  }
  out.adjacency.resize(out.planes.size());
  for (const auto& [key, count] : pair_count)
    if (count >= params.min_adjacent_pairs) {
      out.adjacency[static_cast<std::size_t>(key.first)].push_back(key.second);
      out.adjacency[static_cast<std::size_t>(key.second)].push_back(key.first);
    }
  for (auto& a : out.adjacency) std::sort(a.begin(), a.end());
  compute_second_order(out);
  compute_lines(out, params.min_line_angle_deg);
  return out;
}

}  // namespace

SceneStructure add_small_planes(const PointCloud& cloud, const SceneStructure& s, const std::vector<bool>& eligible,
                                const StructureParams& params, std::size_t min_points, double min_width,
                                KnnGraphCache* cache) {
  using namespace structure_detail;
  const auto& pts = cloud.points;
  const std::size_t n = pts.size();
  if (eligible.size() != n || s.point_plane.size() != n || s.normals.size() != n)
    throw Error(Status::Internal, "structure", "add_small_planes: one flag, plane and normal per point expected");
  std::vector<char> taken(n, 1);
  std::size_t on_no_plane = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (eligible[i] && s.point_plane[i] < 0) {
      taken[i] = 0;
      ++on_no_plane;
    }
  if (on_no_plane < min_points) return s;
  const std::shared_ptr<const KnnGraph> graph = small_planes_graph(pts, params, cache);
  MinimumPlane min_plane;
  min_plane.points = min_points;
  min_plane.width = min_width;
  std::vector<std::vector<int>> regions = detect_planes_region_growing(pts, s.normals, *graph, params, s.spacing, min_plane, taken);
  if (regions.empty()) return s;
  SceneStructure out = append_planes(pts, s, std::move(regions), params, *graph);
  log::info("structure: " + std::to_string(out.planes.size() - s.planes.size()) + " small planes among " +
            std::to_string(on_no_plane) + " points on no plane");
  return out;
}

SceneStructure add_planes(const PointCloud& cloud, const SceneStructure& s, std::vector<std::vector<int>> inliers,
                          const StructureParams& params, KnnGraphCache* cache) {
  const std::size_t n = cloud.points.size();
  if (s.point_plane.size() != n || s.normals.size() != n)
    throw Error(Status::Internal, "structure", "add_planes: one plane and normal per point expected");
  for (const std::vector<int>& list : inliers)
    for (int i : list)
      if (i < 0 || static_cast<std::size_t>(i) >= n || s.point_plane[static_cast<std::size_t>(i)] >= 0)
        throw Error(Status::Internal, "structure", "add_planes: an inlier out of range or on a plane already");
  inliers.erase(std::remove_if(inliers.begin(), inliers.end(), [](const std::vector<int>& l) { return l.size() < 3; }),
                inliers.end());
  if (inliers.empty()) return s;
  const std::shared_ptr<const structure_detail::KnnGraph> graph = small_planes_graph(cloud.points, params, cache);
  return append_planes(cloud.points, s, std::move(inliers), params, *graph);
}

}  // namespace hsr
