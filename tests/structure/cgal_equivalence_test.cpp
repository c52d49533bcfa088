// Stage 1's own implementations against the CGAL code they replaced (issue 16): the alpha-shape boundary
// computed near the outline only vs CGAL's Alpha_shape_2 of all points, region growing with running
// moments vs CGAL's Region_growing, the MST normal orientation vs CGAL's mst_orient_normals. Each must
// give the same answer (edge sets, regions, signs), on inputs large enough for the fast paths to be taken.
#include "core/spacing.h"
#include "structure/structure.h"
#include "structure/structure_internal.h"
#include "structure_test_util.h"
#include "synth/synth.h"

#include <CGAL/Alpha_shape_2.h>
#include <CGAL/Alpha_shape_face_base_2.h>
#include <CGAL/Alpha_shape_vertex_base_2.h>
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Shape_detection/Region_growing/Region_growing.h>
#include <CGAL/Shape_detection/Region_growing/Region_growing_on_point_set.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/mst_orient_normals.h>
#include <CGAL/property_map.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <tuple>

namespace hsr {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using structure_detail::KnnGraph;

// ---- alpha shapes -----------------------------------------------------------------------------------

using Segment = std::pair<std::pair<double, double>, std::pair<double, double>>;
/// An edge by its end points' coordinates (duplicated points make indices ambiguous, not geometry).
Segment segment(const std::vector<Vec2>& q, int a, int b) {
  std::pair<double, double> u{q[a].x(), q[a].y()}, v{q[b].x(), q[b].y()};
  return {std::min(u, v), std::max(u, v)};
}

/// Boundary edges (as segments) and area of CGAL's regularized Alpha_shape_2 of all the points.
std::pair<std::set<Segment>, double> cgal_alpha_shape(const std::vector<Vec2>& q, double radius) {
  using Vb0 = CGAL::Triangulation_vertex_base_with_info_2<int, K>;
  using Vb = CGAL::Alpha_shape_vertex_base_2<K, Vb0>;
  using Fb = CGAL::Alpha_shape_face_base_2<K>;
  using Dt = CGAL::Delaunay_triangulation_2<K, CGAL::Triangulation_data_structure_2<Vb, Fb>>;
  using AlphaShape = CGAL::Alpha_shape_2<Dt>;
  std::vector<std::pair<K::Point_2, int>> input;
  for (std::size_t i = 0; i < q.size(); ++i) input.emplace_back(K::Point_2(q[i].x(), q[i].y()), static_cast<int>(i));
  Dt dt;
  dt.insert(input.begin(), input.end());
  AlphaShape as(dt, radius * radius, AlphaShape::REGULARIZED);
  std::set<Segment> edges;
  for (auto e = as.alpha_shape_edges_begin(); e != as.alpha_shape_edges_end(); ++e) {
    if (as.classify(*e) != AlphaShape::REGULAR) continue;
    edges.insert(segment(q, e->first->vertex(Dt::cw(e->second))->info(), e->first->vertex(Dt::ccw(e->second))->info()));
  }
  double area = 0;
  for (auto f = as.finite_faces_begin(); f != as.finite_faces_end(); ++f)
    if (as.classify(f) == AlphaShape::INTERIOR)
      area += std::abs(CGAL::area(f->vertex(0)->point(), f->vertex(1)->point(), f->vertex(2)->point()));
  return {edges, area};
}

/// A dense square with two holes, a thin slot and a sparse corner: every kind of outline.
std::vector<Vec2> plane_with_holes(std::size_t n, bool quantized, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  std::vector<Vec2> q;
  while (q.size() < n) {
    Vec2 p(u(rng), u(rng));
    if ((p - Vec2(3, 3)).norm() < 1.2 || (p - Vec2(7, 6)).norm() < 0.6) continue;  // holes
    if (p.x() > 5 && p.x() < 5.15 && p.y() > 1) continue;                          // a slot
    if (p.x() > 8.5 && p.y() > 8.5 && rng() % 8 != 0) continue;                     // sparse corner
    if (quantized) p = (p * 40).array().round() / 40;                              // a 2.5 cm grid: cocircular ties
    q.push_back(p);
  }
  return q;
}

TEST(AlphaShapeBoundary, SameEdgesAndAreaAsCgalAlphaShape2) {
  for (bool quantized : {false, true}) {
    const std::vector<Vec2> q = plane_with_holes(40000, quantized, quantized ? 11 : 12);
    const double spacing = 10.0 / std::sqrt(40000.0);
    for (double radius : {1.5 * spacing, 3.0 * spacing}) {
      const AlphaShapeBoundary mine = alpha_shape_boundary(q, radius);
      const auto [edges, area] = cgal_alpha_shape(q, radius);
      std::map<std::pair<double, double>, int> first;  // smallest index at each location
      for (int i = static_cast<int>(q.size()) - 1; i >= 0; --i) first[{q[i].x(), q[i].y()}] = i;
      std::set<Segment> got;
      for (const auto& e : mine.edges) {
        got.insert(segment(q, e[0], e[1]));
        for (int v : {e[0], e[1]}) EXPECT_EQ((first[{q[v].x(), q[v].y()}]), v) << "a duplicated location stands for its smallest index";
      }
      EXPECT_EQ(got.size(), mine.edges.size()) << "an edge listed twice";
      EXPECT_EQ(got, edges) << (quantized ? "quantized" : "random") << " radius " << radius;
      EXPECT_NEAR(mine.area, area, 1e-9 * area);
      EXPECT_GT(edges.size(), 400u);  // a real outline (holes, slot), not a few hull edges
      // Oriented with the shape on the left: the inner vertex is left of each edge.
      for (std::size_t k = 0; k < mine.edges.size(); ++k) {
        const Vec2 a = q[mine.edges[k][0]], b = q[mine.edges[k][1]], c = q[mine.inner[k]];
        EXPECT_GT((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x(), 0.0);
      }
    }
  }
}

TEST(AlphaShapeBoundary, CollinearAndTinyInputs) {
  std::vector<Vec2> line;
  for (int i = 0; i < 5000; ++i) line.emplace_back(0.001 * i, 0.002 * i);
  EXPECT_LT(alpha_shape_boundary(line, 0.01).dimension, 2);
  const AlphaShapeBoundary tri = alpha_shape_boundary({{0, 0}, {1, 0}, {0, 1}}, 10.0);
  EXPECT_EQ(tri.edges.size(), 3u);
  EXPECT_NEAR(tri.area, 0.5, 1e-15);
  EXPECT_TRUE(alpha_shape_boundary({{0, 0}, {1, 0}, {0, 1}}, 0.1).edges.empty());
}

// ---- region growing -----------------------------------------------------------------------------------

struct GraphNeighborQuery {
  const KnnGraph* graph;
  int k;
  void operator()(std::size_t i, std::vector<std::size_t>& out) const {
    for (int j = 0; j < k; ++j) out.push_back(static_cast<std::size_t>(graph->row(i)[j]));
  }
};

/// CGAL 5.5's region growing as stage 1 ran it before (unsigned normals).
std::vector<std::vector<int>> cgal_regions(const std::vector<Vec3>& pts, const std::vector<Vec3>& normals,
                                           const KnnGraph& g, const StructureParams& params, double r,
                                           std::size_t min_points) {
  using Item = std::pair<K::Point_3, K::Vector_3>;
  using Range = std::vector<Item>;
  using PMap = CGAL::First_of_pair_property_map<Item>;
  using NMap = CGAL::Second_of_pair_property_map<Item>;
  using Region = CGAL::Shape_detection::Point_set::Least_squares_plane_fit_region<K, Range, PMap, NMap>;
  using Sorting = CGAL::Shape_detection::Point_set::Least_squares_plane_fit_sorting<K, Range, GraphNeighborQuery, PMap>;
  using RG = CGAL::Shape_detection::Region_growing<Range, GraphNeighborQuery, Region, typename Sorting::Seed_map>;
  Range items;
  for (std::size_t i = 0; i < pts.size(); ++i)
    items.emplace_back(K::Point_3(pts[i].x(), pts[i].y(), pts[i].z()), K::Vector_3(normals[i].x(), normals[i].y(), normals[i].z()));
  GraphNeighborQuery query{&g, std::min(params.region_k, g.k)};
  Region region(items, params.max_distance * r, params.max_angle_deg, min_points);
  Sorting sorting(items, query);
  sorting.sort();
  RG rg(items, query, region, sorting.seed_map());
  std::vector<std::vector<std::size_t>> regions;
  rg.detect(std::back_inserter(regions));
  std::vector<std::vector<int>> out;
  for (const auto& reg : regions) {
    std::vector<int> v(reg.begin(), reg.end());
    std::sort(v.begin(), v.end());
    out.push_back(std::move(v));
  }
  return out;
}

/// The scans, with normals (synth: towards the scanner) or estimated ones (PCA, oriented by MST).
struct Scene {
  std::string name;
  PointCloud cloud;
};
std::vector<Scene> scenes() {
  std::vector<Scene> out;
  for (const char* model : {"house", "room", "courtyard"}) {
    SynthParams sp;
    sp.target_points = 60000;
    out.push_back({model, run_synth(model, sp).cloud});
  }
  test::Sampled box;
  test::sample_box(box, Vec3(0, 0, 0), Vec3(2, 1.5, 1), 4000, 0.003, 5, false);
  out.push_back({"noisy box without normals", box.cloud});
  return out;
}

// With the default cap on reseeding after failures (StructureParams::max_seed_failures) and without it.
TEST(RegionGrowing, SameRegionsAsCgalRegionGrowing) {
  for (const Scene& sc : scenes())
  for (int max_failures : {64, 0}) {
    StructureParams params;
    params.max_seed_failures = max_failures;
    const std::vector<Vec3>& pts = sc.cloud.points;
    const KdTree tree(pts);
    const double r = average_spacing(pts, tree);
    const KnnGraph g = structure_detail::build_knn_graph(pts, tree, 12);
    std::vector<Vec3> normals = sc.cloud.normals;
    if (normals.empty()) normals = structure_detail::estimate_normals(pts, g, params.normal_k);
    const std::size_t min_points = std::max<std::size_t>(30, static_cast<std::size_t>(std::ceil(0.003 * pts.size())));
    // Points only (no area test), as CGAL's region growing.
    const auto mine = structure_detail::detect_planes_region_growing(pts, normals, g, params, r, {min_points, 0.0});
    const auto cgal = cgal_regions(pts, normals, g, params, r, min_points);
    EXPECT_GE(mine.size(), 5u) << sc.name;
    EXPECT_EQ(mine, cgal) << sc.name << " max_seed_failures " << max_failures;
  }
}

// ---- MST orientation -------------------------------------------------------------------------------

TEST(MstOrientation, SameSignsAsCgalMstOrientNormals) {
  for (const Scene& sc : scenes()) {
    const std::vector<Vec3>& pts = sc.cloud.points;
    const KdTree tree(pts);
    const KnnGraph g = structure_detail::build_knn_graph(pts, tree, 12);
    const std::vector<Vec3> raw = structure_detail::estimate_normals(pts, g, 12);
    std::vector<Vec3> mine = raw;
    const std::vector<char> reached = structure_detail::mst_orient(pts, mine, g, 12);

    using Item = std::tuple<K::Point_3, K::Vector_3, std::size_t>;
    std::vector<Item> items;
    for (std::size_t i = 0; i < pts.size(); ++i)
      items.emplace_back(K::Point_3(pts[i].x(), pts[i].y(), pts[i].z()), K::Vector_3(raw[i].x(), raw[i].y(), raw[i].z()), i);
    const auto unoriented = CGAL::mst_orient_normals(
        items, 12, CGAL::parameters::point_map(CGAL::Nth_of_tuple_property_map<0, Item>())
                       .normal_map(CGAL::Nth_of_tuple_property_map<1, Item>()));
    std::size_t differ = 0, reached_count = 0;
    for (auto it = items.begin(); it != items.end(); ++it) {
      const std::size_t i = std::get<2>(*it);
      const bool cgal_reached = it < unoriented;
      EXPECT_EQ(static_cast<bool>(reached[i]), cgal_reached) << sc.name << " point " << i;
      const K::Vector_3& v = std::get<1>(*it);
      differ += (Vec3(v.x(), v.y(), v.z()).dot(mine[i]) < 0);
      reached_count += cgal_reached;
    }
    EXPECT_EQ(differ, 0u) << sc.name << ": normals oriented the other way than CGAL's";
    EXPECT_GT(reached_count, pts.size() / 4) << sc.name;
  }
}

}  // namespace
}  // namespace hsr
