// Tests of src/eval: validity checks and distance metrics on meshes whose answers are known analytically.
#include "eval/eval.h"

#include "core/error.h"
#include "core/log.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

namespace hsr {
namespace {

using Face = std::vector<std::uint32_t>;

/// Axis-aligned box [lo, hi] as 6 quads, counter-clockwise seen from outside.
PolygonMesh box(const Vec3& lo, const Vec3& hi) {
  PolygonMesh m;
  for (int i = 0; i < 8; ++i)  // vertex i = (x, y, z) bits
    m.vertices.emplace_back((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
  m.faces = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  return m;
}

PolygonMesh unit_cube() { return box(Vec3(0, 0, 0), Vec3(1, 1, 1)); }

/// Both meshes in one, with vertices of equal coordinates merged (so shared corners are shared indices).
PolygonMesh merged(const PolygonMesh& a, const PolygonMesh& b) {
  PolygonMesh out;
  std::map<std::array<double, 3>, std::uint32_t> index;
  auto add = [&](const PolygonMesh& m) {
    for (const Face& f : m.faces) {
      Face g;
      for (std::uint32_t v : f) {
        const Vec3& p = m.vertices[v];
        auto [it, inserted] = index.emplace(std::array<double, 3>{p.x(), p.y(), p.z()}, out.vertices.size());
        if (inserted) out.vertices.push_back(p);
        g.push_back(it->second);
      }
      out.faces.push_back(g);
    }
  };
  add(a);
  add(b);
  return out;
}

/// Prism over a counter-clockwise polygon of the z = 0 plane, from z = 0 to z = height.
PolygonMesh prism(const std::vector<Vec2>& polygon, double height) {
  PolygonMesh m;
  const auto n = static_cast<std::uint32_t>(polygon.size());
  for (const Vec2& p : polygon) m.vertices.emplace_back(p.x(), p.y(), 0.0);
  for (const Vec2& p : polygon) m.vertices.emplace_back(p.x(), p.y(), height);
  Face bottom, top;
  for (std::uint32_t i = 0; i < n; ++i) {
    bottom.push_back(n - 1 - i);
    top.push_back(n + i);
    const std::uint32_t j = (i + 1) % n;
    m.faces.push_back({i, j, n + j, n + i});
  }
  m.faces.push_back(bottom);
  m.faces.push_back(top);
  return m;
}

/// The L-shaped polygon (area 3), started at a vertex from which a triangle fan would cover the notch.
std::vector<Vec2> l_shape() { return {{2, 1}, {1, 1}, {1, 2}, {0, 2}, {0, 0}, {2, 0}}; }

/// Unit cube whose every face is an n x n grid of quads (6 n^2 faces), shared vertices.
PolygonMesh grid_cube(int n) {
  PolygonMesh cube = unit_cube();
  PolygonMesh out;
  std::map<std::array<double, 3>, std::uint32_t> index;
  auto vertex = [&](const Vec3& p) {
    auto [it, inserted] = index.emplace(std::array<double, 3>{p.x(), p.y(), p.z()}, out.vertices.size());
    if (inserted) out.vertices.push_back(p);
    return it->second;
  };
  for (const Face& f : cube.faces) {
    const Vec3 o = cube.vertices[f[0]], u = cube.vertices[f[1]] - o, w = cube.vertices[f[3]] - o;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        auto at = [&](int a, int b) { return vertex(o + u * (double(a) / n) + w * (double(b) / n)); };
        out.faces.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
      }
  }
  return out;
}

PointCloud cloud(const std::vector<Vec3>& pts) {
  PointCloud c;
  c.points = pts;
  return c;
}

/// Face centres of the unit cube moved outward by `d`.
std::vector<Vec3> offset_face_centres(double d) {
  return {{0.5, 0.5, -d}, {0.5, 0.5, 1 + d}, {0.5, -d, 0.5}, {0.5, 1 + d, 0.5}, {-d, 0.5, 0.5}, {1 + d, 0.5, 0.5}};
}

// ---------------------------------------------------------------- validity

// Issue 42's count: the points farther than a distance from the model. A roof of two parts, [0, 2] x [0, 1] at
// z = 1, modelled by the unit cube alone: the part over x in (1.525, 2] is farther than 0.525 from it, the part in
// (1, 1.525) is not (the cube's side x = 1 is nearer), the points on the cube are on it.
TEST(EvalCountFarther, ARoofPartLeftOutOfTheModelIsCounted) {
  std::vector<Vec3> roof;
  for (int i = 0; i <= 40; ++i)
    for (int j = 0; j <= 10; ++j) roof.emplace_back(0.05 * i, 0.1 * j, 1.0);
  std::size_t beyond = 0;
  for (const Vec3& p : roof) beyond += p.x() > 1.525;
  ASSERT_EQ(beyond, 10u * 11u);
  EXPECT_EQ(count_farther(roof, unit_cube(), 0.525), beyond);
  EXPECT_EQ(count_farther(roof, box(Vec3(0, 0, 0), Vec3(2, 1, 1)), 0.5), 0u) << "the whole roof modelled";
  EXPECT_EQ(count_farther(roof, PolygonMesh{}, 0.5), roof.size()) << "no model explains nothing";
  EXPECT_EQ(count_farther({}, unit_cube(), 0.5), 0u);
}

// The evaluation keeps each point's distance to the mesh (issue 43 item 1: the run's unexplained count reads them
// instead of measuring again): the same roof against the unit cube, every point's distance known exactly, in input
// order; none kept when p2m was taken over a subset.
TEST(EvalPointDistance, EachPointsDistanceToTheMeshInInputOrder) {
  PointCloud roof;
  for (int i = 0; i <= 40; ++i)
    for (int j = 0; j <= 10; ++j) roof.points.emplace_back(0.05 * i, 0.1 * j, 1.0);
  const EvalResult r = run_eval(roof, unit_cube(), nullptr);
  ASSERT_EQ(r.point_distance.size(), roof.size());
  for (std::size_t i = 0; i < roof.size(); ++i) {
    const double x = roof.points[i].x();
    EXPECT_NEAR(r.point_distance[i], x <= 1.0 ? 0.0 : x - 1.0, 1e-12) << "point " << i;
  }
  const std::vector<double> again = point_mesh_distances(roof.points, unit_cube());
  for (std::size_t i = 0; i < roof.size(); ++i) EXPECT_NEAR(r.point_distance[i], again[i], 1e-12);
  EvalParams some;
  some.max_points = 100;
  EXPECT_TRUE(run_eval(roof, unit_cube(), nullptr, some).point_distance.empty());
}

TEST(EvalValidity, UnitCubeIsValidWithVolumeOne) {
  const Validity v = check_validity(unit_cube());
  EXPECT_TRUE(v.closed);
  EXPECT_TRUE(v.manifold);
  EXPECT_TRUE(v.oriented);
  EXPECT_TRUE(v.self_intersection_free);
  EXPECT_TRUE(v.self_intersections_checked);
  EXPECT_TRUE(v.bounds_volume);
  EXPECT_TRUE(v.valid());
  EXPECT_NEAR(v.volume, 1.0, 1e-12);
  EXPECT_EQ(v.summary(), "valid");
}

TEST(EvalValidity, FinelySubdividedCubeIsValid) {
  const PolygonMesh m = grid_cube(20);
  ASSERT_EQ(m.faces.size(), 2400u);
  const Validity v = check_validity(m);
  EXPECT_TRUE(v.valid()) << v.summary();
  EXPECT_NEAR(v.volume, 1.0, 1e-12);
}

TEST(EvalValidity, InsideOutCubeIsNotOriented) {
  PolygonMesh m = unit_cube();
  for (Face& f : m.faces) std::reverse(f.begin(), f.end());
  const Validity v = check_validity(m);
  EXPECT_TRUE(v.closed);
  EXPECT_TRUE(v.manifold);
  EXPECT_FALSE(v.oriented);
  EXPECT_FALSE(v.valid());
  EXPECT_NEAR(v.volume, -1.0, 1e-12);
}

TEST(EvalValidity, OneReversedFaceIsNotOriented) {
  PolygonMesh m = unit_cube();
  std::reverse(m.faces[2].begin(), m.faces[2].end());
  const Validity v = check_validity(m);
  EXPECT_TRUE(v.closed);
  EXPECT_TRUE(v.manifold);  // orientable: only the orientation is inconsistent
  EXPECT_FALSE(v.oriented);
  EXPECT_FALSE(v.valid());
  EXPECT_NE(v.summary().find("not oriented"), std::string::npos);
}

TEST(EvalValidity, MissingFaceIsNotClosed) {
  PolygonMesh m = unit_cube();
  m.faces.pop_back();
  const Validity v = check_validity(m);
  EXPECT_FALSE(v.closed);
  EXPECT_TRUE(v.manifold);
  EXPECT_FALSE(v.oriented);
  EXPECT_FALSE(v.bounds_volume);
  EXPECT_FALSE(v.valid());
  EXPECT_EQ(v.volume, 0.0);
}

TEST(EvalValidity, CrossingTrianglesSelfIntersect) {
  PolygonMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.2, 0.2, -0.5}, {0.2, 0.2, 0.5}, {0.6, 0.1, 0}};
  m.faces = {{0, 1, 2}, {3, 4, 5}};
  EXPECT_FALSE(check_validity(m).self_intersection_free);
  // Control: the second triangle moved away no longer intersects.
  for (int i = 3; i < 6; ++i) m.vertices[i].z() += 2.0;
  EXPECT_TRUE(check_validity(m).self_intersection_free);
}

TEST(EvalValidity, InterpenetratingCubesSelfIntersect) {
  const PolygonMesh m = merged(unit_cube(), box(Vec3(0.5, 0.5, 0.5), Vec3(1.5, 1.5, 1.5)));
  const Validity v = check_validity(m);
  EXPECT_TRUE(v.closed);
  EXPECT_TRUE(v.manifold);
  EXPECT_FALSE(v.self_intersection_free);
  EXPECT_FALSE(v.bounds_volume);
  EXPECT_FALSE(v.valid());
  // The test can be skipped (then assumed).
  const Validity skipped = check_validity(m, false);
  EXPECT_FALSE(skipped.self_intersections_checked);
  EXPECT_TRUE(skipped.self_intersection_free);
}

TEST(EvalValidity, DisjointCubesAreValid) {
  const Validity v = check_validity(merged(unit_cube(), box(Vec3(2, 0, 0), Vec3(3, 1, 1))));
  EXPECT_TRUE(v.valid()) << v.summary();
  EXPECT_NEAR(v.volume, 2.0, 1e-12);
}

TEST(EvalValidity, CavityMustFaceInwards) {
  PolygonMesh inner = box(Vec3(1, 1, 1), Vec3(2, 2, 2));
  const PolygonMesh outer = box(Vec3(0, 0, 0), Vec3(3, 3, 3));
  // Inner box oriented outward too: the cavity is not a cavity, no consistent volume.
  EXPECT_FALSE(check_validity(merged(outer, inner)).bounds_volume);
  for (Face& f : inner.faces) std::reverse(f.begin(), f.end());
  const Validity v = check_validity(merged(outer, inner));
  EXPECT_TRUE(v.valid()) << v.summary();
  EXPECT_NEAR(v.volume, 26.0, 1e-12);
}

TEST(EvalValidity, CubesSharingAnEdgeAreNotManifold) {
  const PolygonMesh m = merged(unit_cube(), box(Vec3(1, 1, 0), Vec3(2, 2, 1)));
  ASSERT_EQ(m.vertices.size(), 14u);  // 2 shared
  const Validity v = check_validity(m);
  EXPECT_FALSE(v.manifold);
  EXPECT_FALSE(v.closed);
  EXPECT_FALSE(v.valid());
  // Touching only along the shared edge is not counted as a self-intersection.
  EXPECT_TRUE(v.self_intersection_free);
}

TEST(EvalValidity, CubesSharingAVertexAreNotManifold) {
  const PolygonMesh m = merged(unit_cube(), box(Vec3(1, 1, 1), Vec3(2, 2, 2)));
  ASSERT_EQ(m.vertices.size(), 15u);  // 1 shared
  const Validity v = check_validity(m);
  EXPECT_FALSE(v.manifold);
  EXPECT_FALSE(v.closed);
  EXPECT_FALSE(v.valid());
  EXPECT_TRUE(v.self_intersection_free);
}

TEST(EvalValidity, NonManifoldVertexWithCrossingFaces) {
  // Two triangles sharing only vertex 0 (a non-manifold vertex). The second is vertical and contains
  // the segment from the origin to (0.3, 0.3, 0), which lies inside the first: they cross.
  PolygonMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.3, 0.3, 1}, {0.3, 0.3, -1}};
  m.faces = {{0, 1, 2}, {0, 3, 4}};
  Validity v = check_validity(m);
  EXPECT_FALSE(v.manifold);
  EXPECT_FALSE(v.self_intersection_free);
  // Mirrored through the z axis, the second triangle meets the first only at the shared vertex.
  m.vertices[3] = {-0.3, -0.3, 1};
  m.vertices[4] = {-0.3, -0.3, -1};
  v = check_validity(m);
  EXPECT_FALSE(v.manifold);
  EXPECT_TRUE(v.self_intersection_free);
}

TEST(EvalValidity, NonManifoldEdgeWithOverlappingFaces) {
  // Three triangles on the edge (0,0,0)-(1,0,0). The third one is coplanar with the first and on the
  // same side of the edge: they overlap.
  PolygonMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, -1, 0}, {0.5, 0.5, 0}};
  m.faces = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  Validity v = check_validity(m);
  EXPECT_FALSE(v.manifold);
  EXPECT_FALSE(v.self_intersection_free);
  m.vertices[4] = {0.5, 0, 1};  // now leaving the plane: the three only share the edge
  v = check_validity(m);
  EXPECT_FALSE(v.manifold);
  EXPECT_TRUE(v.self_intersection_free);
}

TEST(EvalValidity, ConcaveFacesAreValidWithExactVolume) {
  const PolygonMesh m = prism(l_shape(), 1.5);
  ASSERT_EQ(m.faces.size(), 8u);
  const Validity v = check_validity(m);
  EXPECT_TRUE(v.valid()) << v.summary();
  EXPECT_NEAR(v.volume, 3.0 * 1.5, 1e-12);
}

TEST(EvalValidity, ResolvedTJunctionIsValid) {
  // Vertex 8 on the edge 0-1, used by both faces along that edge (collinear consecutive vertices).
  PolygonMesh m = unit_cube();
  m.vertices.emplace_back(0.5, 0, 0);
  m.faces[0] = {0, 2, 3, 1, 8};
  m.faces[2] = {0, 8, 1, 5, 4};
  const Validity v = check_validity(m);
  EXPECT_TRUE(v.valid()) << v.summary();
  EXPECT_NEAR(v.volume, 1.0, 1e-12);
  // Left in only one of the two faces, it is a T-junction: the edges no longer match, the mesh is open.
  m.faces[2] = {0, 1, 5, 4};
  const Validity t = check_validity(m);
  EXPECT_FALSE(t.closed);
  EXPECT_FALSE(t.valid());
}

TEST(EvalValidity, DegenerateFacesDoNotCrash) {
  PolygonMesh m = unit_cube();
  m.vertices.emplace_back(2, 0, 0);
  m.faces.push_back({0, 1, 8});  // zero area: collinear
  EXPECT_FALSE(check_validity(m).valid());
  PolygonMesh repeated = unit_cube();
  repeated.faces[0] = {0, 2, 3, 1, 2};  // a vertex twice in one face
  const Validity v = check_validity(repeated);
  EXPECT_FALSE(v.manifold);
  EXPECT_FALSE(v.valid());
  // Distances still work on what is left of such a mesh.
  EvalParams params;
  params.mesh_samples = 100;
  const EvalResult r = run_eval(cloud(offset_face_centres(0.1)), repeated, nullptr, params);
  EXPECT_NEAR(r.accuracy.p2m_max * r.diagonal, 0.1, 1e-12);
  PolygonMesh flat;
  flat.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  flat.faces = {{0, 1, 2}};
  EXPECT_THROW(run_eval(cloud(offset_face_centres(0.1)), flat, nullptr, params), Error);
}

TEST(EvalValidity, BadIndicesThrow) {
  PolygonMesh m = unit_cube();
  m.faces[0][1] = 8;
  try {
    check_validity(m);
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_EQ(e.status(), Status::BadInput);
    EXPECT_EQ(e.stage(), "eval");
  }
  EXPECT_FALSE(check_validity(PolygonMesh{}).valid());
}

// ---------------------------------------------------------------- distances

TEST(EvalAccuracy, PointsAtKnownOffsetFromCube) {
  EvalParams params;
  params.mesh_samples = 1000;
  const EvalResult r = run_eval(cloud(offset_face_centres(0.1)), unit_cube(), nullptr, params);
  const double diag = 1.2 * std::sqrt(3.0);
  EXPECT_NEAR(r.diagonal, diag, 1e-12);
  EXPECT_NEAR(r.accuracy.p2m_mean, 0.1 / diag, 1e-9);
  EXPECT_NEAR(r.accuracy.p2m_rms, 0.1 / diag, 1e-9);
  EXPECT_NEAR(r.accuracy.p2m_max, 0.1 / diag, 1e-9);
  EXPECT_FALSE(r.accuracy.has_truth);
  EXPECT_TRUE(r.validity.valid());
  EXPECT_EQ(r.vertices, 8u);
  EXPECT_EQ(r.faces, 6u);
  EXPECT_EQ(r.points, 6u);
  EXPECT_NEAR(r.mesh_area, 6.0, 1e-12);
}

TEST(EvalAccuracy, MixedOffsetsGiveMeanRmsAndMax) {
  // Distances 0 (on a face), 0.1 (outside), 0.3 (inside: the nearest face y = 0 is 0.3 away), 0 (corners).
  const std::vector<Vec3> pts = {{0.5, 0.5, 0.0}, {0.5, 0.5, 1.1}, {0.5, 0.3, 0.5}, {0, 0, 0}, {1, 1, 1}};
  const EvalResult r = run_eval(cloud(pts), unit_cube(), nullptr, EvalParams{1000, 1, true});
  const double diag = std::sqrt(1 + 1 + 1.1 * 1.1);
  const std::vector<double> d = {0.0, 0.1, 0.3, 0.0, 0.0};
  double mean = 0, sq = 0;
  for (double x : d) mean += x / d.size(), sq += x * x / d.size();
  EXPECT_NEAR(r.accuracy.p2m_mean, mean / diag, 1e-9);
  EXPECT_NEAR(r.accuracy.p2m_rms, std::sqrt(sq) / diag, 1e-9);
  EXPECT_NEAR(r.accuracy.p2m_max, 0.3 / diag, 1e-9);
}

TEST(EvalAccuracy, MeshToPointsAgainstCubeCorners) {
  // Points = the 8 corners. A uniform point of a face is, on average, (sqrt2 + ln(1 + sqrt2)) / 6 away
  // from its nearest corner (mean distance from a square's corner, for the quarter square), and at most
  // sqrt(0.5) (the face centre). The full evaluation (200,000 samples, as `hsr eval`): the self-check's 2,000
  // state a standard error wider than these bounds.
  const PolygonMesh cube = unit_cube();
  EvalParams full;
  full.samples_per_point = 0;
  const EvalResult r = run_eval(cloud(cube.vertices), cube, nullptr, full);
  const double diag = std::sqrt(3.0);
  const double mean = (std::sqrt(2.0) + std::log(1 + std::sqrt(2.0))) / 6.0;
  EXPECT_NEAR(r.accuracy.m2p_mean * diag / mean, 1.0, 3e-3);
  EXPECT_LE(r.accuracy.m2p_max * diag, std::sqrt(0.5) + 1e-12);
  EXPECT_GT(r.accuracy.m2p_max * diag, std::sqrt(0.5) - 0.01);
  EXPECT_NEAR(r.accuracy.p2m_max, 0.0, 1e-15);
}

TEST(EvalAccuracy, TheSelfCheckSamplesScaleWithThePointsAndStateTheirError) {
  // Without a truth the mesh gets 1 sample per input point, at least 2,000, at most 200,000; the known mean
  // (MeshToPointsAgainstCubeCorners) lies within 4 of the stated standard errors of the estimate.
  const EvalParams p;
  EXPECT_EQ(mesh_sample_count(p, 8, false), 2000u);
  EXPECT_EQ(mesh_sample_count(p, 5000, false), 5000u);
  EXPECT_EQ(mesh_sample_count(p, 1000000, false), 200000u);
  EXPECT_EQ(mesh_sample_count(p, 8, true), 200000u) << "against a truth: every sample";
  EvalParams full;
  full.samples_per_point = 0;
  EXPECT_EQ(mesh_sample_count(full, 8, false), 200000u);
  const PolygonMesh cube = unit_cube();
  const EvalResult r = run_eval(cloud(cube.vertices), cube, nullptr);
  EXPECT_EQ(r.mesh_samples, 2000u);
  const double diag = std::sqrt(3.0);
  const double mean = (std::sqrt(2.0) + std::log(1 + std::sqrt(2.0))) / 6.0;
  ASSERT_GT(r.accuracy.m2p_mean_stderr, 0.0);
  EXPECT_LT(std::abs(r.accuracy.m2p_mean * diag - mean), 4.0 * r.accuracy.m2p_mean_stderr * diag);
  EXPECT_LT(r.accuracy.m2p_mean_stderr * diag, 0.02 * mean) << "2,000 samples: under 2 % of the mean";
}

TEST(EvalAccuracy, MeshToPointsMeasuredLaterAreTheSameFigures) {
  // A run whose model may be thrown away leaves the mesh -> points figures for later (issue 43); measured
  // later they are the same numbers, bit for bit, as measured at once; nothing is left for later with a truth.
  const PolygonMesh cube = unit_cube();
  const PointCloud points = cloud(offset_face_centres(0.1));
  const EvalResult now = run_eval(points, cube, nullptr);
  EvalResult later = run_eval(points, cube, nullptr, EvalParams{}, MeshToPoints::Later);
  ASSERT_TRUE(later.m2p_later);
  EXPECT_EQ(later.accuracy.m2p_mean, 0.0);
  EXPECT_EQ(later.mesh_area, 0.0);
  EXPECT_EQ(later.accuracy.p2m_mean, now.accuracy.p2m_mean) << "points -> mesh are measured at once";
  add_mesh_to_points(points, cube, EvalParams{}, later);
  EXPECT_FALSE(later.m2p_later);
  EXPECT_GT(now.accuracy.m2p_mean, 0.0);
  EXPECT_EQ(later.accuracy.m2p_mean, now.accuracy.m2p_mean);
  EXPECT_EQ(later.accuracy.m2p_max, now.accuracy.m2p_max);
  EXPECT_EQ(later.accuracy.m2p_mean_stderr, now.accuracy.m2p_mean_stderr);
  EXPECT_EQ(later.mesh_area, now.mesh_area);
  const EvalResult with_truth = run_eval(points, cube, &cube, EvalParams{}, MeshToPoints::Later);
  EXPECT_FALSE(with_truth.m2p_later);
  EXPECT_GT(with_truth.accuracy.m2p_mean, 0.0);
}

TEST(EvalAccuracy, PointsInsideTheCube) {
  // Deep inside a subdivided cube every point is at the distance of its nearest face plane.
  const PolygonMesh m = grid_cube(8);
  std::vector<Vec3> pts;
  std::mt19937_64 rng(5);
  for (int i = 0; i < 5000; ++i)
    pts.emplace_back(double(rng() >> 11) * 0x1.0p-53, double(rng() >> 11) * 0x1.0p-53, double(rng() >> 11) * 0x1.0p-53);
  EvalParams params;
  params.mesh_samples = 1000;
  const EvalResult r = run_eval(cloud(pts), m, nullptr, params);
  double sum = 0, max_d = 0;
  for (const Vec3& p : pts) {
    const double d = std::min({p.x(), p.y(), p.z(), 1 - p.x(), 1 - p.y(), 1 - p.z()});
    sum += d;
    max_d = std::max(max_d, d);
  }
  EXPECT_NEAR(r.accuracy.p2m_max * r.diagonal, max_d, 1e-12);
  EXPECT_NEAR(r.accuracy.p2m_mean * r.diagonal, sum / pts.size(), 1e-12);
}

TEST(EvalAccuracy, CubeAgainstItselfAsTruth) {
  const PolygonMesh cube = unit_cube();
  const EvalResult r = run_eval(cloud(cube.vertices), cube, &cube);
  EXPECT_TRUE(r.accuracy.has_truth);
  EXPECT_LT(r.accuracy.chamfer, 1e-12);
  EXPECT_LT(r.accuracy.hausdorff, 1e-12);
}

TEST(EvalAccuracy, CubeAgainstScaledCubeAsTruth) {
  // Truth: the cube scaled by 1.1 about its centre, i.e. [-0.05, 1.05]^3. Every point of the unit cube
  // is exactly 0.05 from it; a truth point is 0.05 away over the central square of its face,
  // sqrt(0.05^2 + t^2) over the edge strips and sqrt(0.05^2 + t^2 + u^2) over the corner squares, the
  // farthest being the corners at 0.05 sqrt(3).
  const PolygonMesh cube = unit_cube();
  const PolygonMesh truth = box(Vec3::Constant(-0.05), Vec3::Constant(1.05));
  const EvalResult r = run_eval(cloud(cube.vertices), cube, &truth);
  const double diag = std::sqrt(3.0), e = 0.05;
  const int n = 400;
  double strip = 0, corner = 0;  // mean distances over a strip / a corner square (midpoint rule)
  for (int i = 0; i < n; ++i) {
    const double t = e * (i + 0.5) / n;
    strip += std::sqrt(e * e + t * t) / n;
    for (int j = 0; j < n; ++j) {
      const double u = e * (j + 0.5) / n;
      corner += std::sqrt(e * e + t * t + u * u) / (double(n) * n);
    }
  }
  const double truth_to_mesh = (1.0 * e + 4 * e * strip + 4 * e * e * corner) / (1.1 * 1.1);
  const double chamfer = 0.5 * (e + truth_to_mesh) / diag;
  EXPECT_NEAR(r.accuracy.chamfer / chamfer, 1.0, 1e-3);
  const double hausdorff = e * std::sqrt(3.0) / diag;
  EXPECT_LE(r.accuracy.hausdorff, hausdorff + 1e-12);
  EXPECT_NEAR(r.accuracy.hausdorff / hausdorff, 1.0, 0.02);
}

TEST(EvalAccuracy, ConcaveFaceIsTriangulatedInsideItsOutline) {
  // A point above the L's notch, level with the top face: 0.4 from the side wall x = 1; a triangle fan
  // from the first vertex would cover the notch and put it at distance 0.
  const PolygonMesh m = prism(l_shape(), 1.0);
  EvalParams params;
  params.mesh_samples = 1000;
  const std::vector<Vec3> pts = {{1.4, 1.4, 1.0}, {0, 0, 0}, {2, 0, 1}};
  const EvalResult r = run_eval(cloud(pts), m, nullptr, params);
  EXPECT_NEAR(r.accuracy.p2m_max * r.diagonal, 0.4, 1e-12);
  EXPECT_NEAR(r.mesh_area, 2 * 3.0 + 8.0, 1e-12);
}

TEST(EvalAccuracy, OriginsAreHonoured) {
  // The same geometry expressed with different local origins gives the same distances.
  PolygonMesh cube = unit_cube();
  const std::vector<Vec3> pts = offset_face_centres(0.1);
  const EvalResult a = run_eval(cloud(pts), cube, nullptr, EvalParams{1000, 3, true});
  const Vec3 shift(1000.0, -250.0, 12.5);
  for (Vec3& v : cube.vertices) v -= shift;
  cube.origin = shift;
  const EvalResult b = run_eval(cloud(pts), cube, nullptr, EvalParams{1000, 3, true});
  EXPECT_NEAR(b.accuracy.p2m_max, a.accuracy.p2m_max, 1e-12);
  EXPECT_NEAR(b.accuracy.m2p_mean, a.accuracy.m2p_mean, 1e-12);
}

TEST(EvalAccuracy, EmptyInputsThrow) {
  const PolygonMesh cube = unit_cube();
  for (int which = 0; which < 3; ++which) {
    try {
      if (which == 0) run_eval(PointCloud{}, cube, nullptr);
      if (which == 1) run_eval(cloud(cube.vertices), PolygonMesh{}, nullptr);
      if (which == 2) run_eval(cloud({Vec3(1, 1, 1), Vec3(1, 1, 1)}), cube, nullptr);
      FAIL() << "no exception for case " << which;
    } catch (const Error& e) {
      EXPECT_EQ(e.status(), Status::BadInput);
      EXPECT_EQ(e.stage(), "eval");
    }
  }
}

TEST(EvalReport, JsonIsDeterministicAndComplete) {
  const PolygonMesh cube = unit_cube();
  const PolygonMesh truth = box(Vec3::Constant(-0.05), Vec3::Constant(1.05));
  EvalParams params;
  params.mesh_samples = 5000;
  params.seed = 7;
  const std::string a = to_json(run_eval(cloud(cube.vertices), cube, &truth, params)).dump();
  const std::string b = to_json(run_eval(cloud(cube.vertices), cube, &truth, params)).dump();
  EXPECT_EQ(a, b);
  params.seed = 8;
  const std::string c = to_json(run_eval(cloud(cube.vertices), cube, &truth, params)).dump();
  EXPECT_NE(a, c);  // the sampling depends on the seed

  const nlohmann::json j = nlohmann::json::parse(a);
  EXPECT_EQ(j["vertices"], 8);
  EXPECT_EQ(j["faces"], 6);
  EXPECT_EQ(j["points"], 8);
  EXPECT_TRUE(j["validity"]["valid"].get<bool>());
  EXPECT_DOUBLE_EQ(j["validity"]["volume"].get<double>(), 1.0);
  EXPECT_TRUE(j["accuracy"]["has_truth"].get<bool>());
  for (const char* key : {"p2m_mean", "p2m_rms", "p2m_max", "m2p_mean", "m2p_max", "chamfer", "hausdorff"})
    EXPECT_TRUE(j["accuracy"].contains(key)) << key;
  const nlohmann::json no_truth = to_json(run_eval(cloud(cube.vertices), cube, nullptr, params));
  EXPECT_FALSE(no_truth["accuracy"].contains("chamfer"));
}

TEST(EvalReport, SummaryMentionsPercentagesAndFailures) {
  const PolygonMesh cube = unit_cube();
  EvalParams params;
  params.mesh_samples = 1000;
  const EvalResult r = run_eval(cloud(offset_face_centres(0.1)), cube, nullptr, params);
  const std::string s = summary(r);
  char expected[64];
  std::snprintf(expected, sizeof expected, "p2m mean %.3f%%", 100 * 0.1 / (1.2 * std::sqrt(3.0)));
  EXPECT_NE(s.find(expected), std::string::npos) << s;
  PolygonMesh open = cube;
  open.faces.pop_back();
  const std::string bad = summary(run_eval(cloud(offset_face_centres(0.1)), open, nullptr, params));
  EXPECT_NE(bad.find("not closed"), std::string::npos) << bad;
}

TEST(EvalLarge, TwoHundredThousandSamplesAndHundredThousandPoints) {
  const PolygonMesh m = grid_cube(30);  // 5400 quads
  std::vector<Vec3> pts;
  std::uint64_t state = 12345;
  auto next = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(state >> 11) * 0x1.0p-53;
  };
  // Points as a scan would give them: near the surface, here within 0.01 of a face and at least 0.02
  // from its border, so each point's distance is exactly its offset from its own face.
  std::vector<double> offsets;
  for (int i = 0; i < 100000; ++i) {
    const int axis = i % 3;
    const bool high = (i / 3) % 2;
    const double offset = 0.02 * next() - 0.01;
    Vec3 p(0.02 + 0.96 * next(), 0.02 + 0.96 * next(), 0.02 + 0.96 * next());
    p[axis] = high ? 1.0 + offset : -offset;
    pts.push_back(p);
    offsets.push_back(std::abs(offset));
  }
  const EvalResult r = run_eval(cloud(pts), m, nullptr);  // 200k samples by default (its speed: bench/)
  EXPECT_TRUE(r.validity.valid());
  double sum = 0, max_d = 0;
  for (double d : offsets) sum += d, max_d = std::max(max_d, d);
  EXPECT_NEAR(r.accuracy.p2m_max * r.diagonal, max_d, 1e-12);
  EXPECT_NEAR(r.accuracy.p2m_mean * r.diagonal, sum / offsets.size(), 1e-12);
  // Samples on the surface are close to some point (the points are dense near the face interiors; the
  // 0.02 margins and the edges are the farthest).
  EXPECT_LT(r.accuracy.m2p_max * r.diagonal, 0.05);
}

TEST(EvalLarge, ValidityOfTwentyThousandFaces) {
  const PolygonMesh m = grid_cube(60);  // 21600 quads, 43200 triangles
  const Validity v = check_validity(m);
  EXPECT_TRUE(v.valid()) << v.summary();
  EXPECT_NEAR(v.volume, 1.0, 1e-12);
}

// Inputs above EvalParams::max_points are measured on a seeded uniform subset (issue 16): exactly that many
// points, the same ones for the same seed, a mean within its statistical error of the full one; at or
// below the limit (and with 0) every point counts.
TEST(EvalLarge, PointsToMeshOnASubsetAboveMaxPoints) {
  const PolygonMesh m = unit_cube();
  std::uint64_t state = 99;
  auto next = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(state >> 11) * 0x1.0p-53;
  };
  std::vector<Vec3> pts;
  double sum = 0;
  for (int i = 0; i < 60000; ++i) {  // on the faces, offset outwards by 0 .. 0.02 (exactly their distances)
    const int axis = i % 3;
    const double offset = 0.02 * next();
    Vec3 p(0.05 + 0.9 * next(), 0.05 + 0.9 * next(), 0.05 + 0.9 * next());
    p[axis] = 1.0 + offset;
    pts.push_back(p);
    sum += offset;
  }
  EvalParams all;
  all.max_points = 0;
  const EvalResult full = run_eval(cloud(pts), m, nullptr, all);
  EXPECT_EQ(full.points_evaluated, pts.size());
  EXPECT_NEAR(full.accuracy.p2m_mean * full.diagonal, sum / pts.size(), 1e-12);

  EvalParams at_limit;
  at_limit.max_points = pts.size();
  const EvalResult same = run_eval(cloud(pts), m, nullptr, at_limit);
  EXPECT_EQ(same.points_evaluated, pts.size());
  EXPECT_EQ(same.accuracy.p2m_mean, full.accuracy.p2m_mean);
  EXPECT_EQ(same.accuracy.m2p_mean, full.accuracy.m2p_mean);  // the mesh samples do not depend on the subset

  EvalParams sub;
  sub.max_points = 5000;
  const EvalResult a = run_eval(cloud(pts), m, nullptr, sub);
  const EvalResult b = run_eval(cloud(pts), m, nullptr, sub);
  EXPECT_EQ(a.points_evaluated, 5000u);
  EXPECT_EQ(a.accuracy.p2m_mean, b.accuracy.p2m_mean);
  EXPECT_EQ(a.accuracy.p2m_max, b.accuracy.p2m_max);
  EXPECT_EQ(a.accuracy.m2p_mean, full.accuracy.m2p_mean);
  // Offsets uniform on [0, 0.02]: standard deviation 0.0058, standard error of 5000 of them 8e-5.
  EXPECT_NEAR(a.accuracy.p2m_mean * a.diagonal, sum / pts.size(), 4e-4);
  EXPECT_NE(a.accuracy.p2m_mean, full.accuracy.p2m_mean);  // it is a subset
  EXPECT_LE(a.accuracy.p2m_max, full.accuracy.p2m_max);
  EXPECT_EQ(to_json(a)["points_evaluated"], 5000);
  EXPECT_NE(summary(a).find("over a random 5000"), std::string::npos);
  sub.seed = 2;
  EXPECT_NE(run_eval(cloud(pts), m, nullptr, sub).accuracy.p2m_mean, a.accuracy.p2m_mean);
}

}  // namespace
}  // namespace hsr
