// Triangulation and point-to-mesh distances of src/eval (the routines eval, the HTML report and Python's
// hsr.triangulate share), and the polygon class that crashed CGAL's PMP::triangulate_faces inside
// run_eval (issue 15): exactly simple "U" pieces of a coplanar region split around a hole
// (thin_polygons.h).
#include "eval/eval.h"

#include "core/face_class.h"
#include "thin_polygons.h"

#include <gtest/gtest.h>

#include <gmpxx.h>

#include <cmath>
#include <initializer_list>
#include <numeric>
#include <random>
#include <sstream>
#include <string>

namespace hsr {
namespace {

using Tris = std::vector<std::array<std::uint32_t, 3>>;

PolygonMesh unit_cube() {
  PolygonMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  m.faces = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  return m;
}

/// L-shaped face in z = 0: [0,2]x[0,2] minus [1,2]x[1,2] (area 3), counter-clockwise seen from +z.
PolygonMesh l_shape() {
  PolygonMesh m;
  m.vertices = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}};
  m.faces = {{0, 1, 2, 3, 4, 5}};
  return m;
}

/// Newell's vector about the first corner, as triangulate_polygon computes it (its dominant axis picks
/// the projection).
Vec3 loop_normal(const std::vector<Vec3>& loop) {
  std::vector<Vec3> local;
  for (const Vec3& p : loop) local.push_back(p - loop[0]);
  std::vector<std::uint32_t> order(loop.size());
  std::iota(order.begin(), order.end(), 0u);
  return newell_vector(local, order);
}

/// Twice the signed area of `corners` of `loop` in the plane that drops coordinate `axis`, mirrored when
/// `sign` < 0 (rationals from the doubles).
mpq_class twice_area(const std::vector<Vec3>& loop, const std::vector<std::uint32_t>& corners, int axis, int sign) {
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  mpq_class sum = 0;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const Vec3 &p = loop[corners[i]], &q = loop[corners[(i + 1) % corners.size()]];
    sum += mpq_class(p[u]) * mpq_class(q[v]) - mpq_class(q[u]) * mpq_class(p[v]);
  }
  return sign * sum;
}

/// Whether `tris` triangulates `loop` exactly as projected along `axis` (mirrored when sign < 0):
/// triangles of positive area whose areas sum to the loop's (a triangle outside the loop or overlapping
/// another would break the sum).
bool triangulates_in(const std::vector<Vec3>& loop, const Tris& tris, int axis, int sign) {
  std::vector<std::uint32_t> all(loop.size());
  std::iota(all.begin(), all.end(), 0u);
  mpq_class total = 0;
  for (const auto& t : tris) {
    const mpq_class a = twice_area(loop, {t[0], t[1], t[2]}, axis, sign);
    if (sgn(a) <= 0) return false;
    total += a;
  }
  return total == twice_area(loop, all, axis, sign);
}

/// Checks exactly that `tris` has loop.size() - 2 triangles and triangulates `loop` in one of the planes
/// that drop a coordinate: the normal's dominant axis, or, for a face only a few ulps wide whose normal is
/// rounding, another one (triangulate_polygon tries them all).
void expect_triangulates(const std::vector<Vec3>& loop, const Tris& tris) {
  ASSERT_EQ(tris.size(), loop.size() - 2);
  bool found = false;
  for (int axis = 0; axis < 3 && !found; ++axis)
    for (int sign : {1, -1}) found = found || triangulates_in(loop, tris, axis, sign);
  EXPECT_TRUE(found) << "no projection in which the triangles are positive and cover the loop exactly";
}

TEST(Triangulate, NonConvexFaceGivesPositiveTrianglesCoveringItsArea) {
  const PolygonMesh l = l_shape();
  const Tris tris = triangulate_faces(l);
  ASSERT_EQ(tris.size(), 4u);
  double area = 0;
  for (const auto& t : tris) {
    const Vec3 n = (l.vertices[t[1]] - l.vertices[t[0]]).cross(l.vertices[t[2]] - l.vertices[t[0]]);
    EXPECT_GT(n.z(), 0) << "triangle keeps the face's orientation";
    area += 0.5 * n.norm();
  }
  EXPECT_NEAR(area, 3.0, 1e-12);
  EXPECT_EQ(triangulate_faces(unit_cube()).size(), 12u);
}

TEST(Triangulate, FlatCornersAndClockwiseProjectionsAreTriangulated) {
  // A square in the plane x = 1 seen from -x (its projection drops x and runs clockwise in (y, z)), with
  // flat corners on every side, as T-junction resolution leaves them.
  std::vector<Vec3> loop;
  for (int i = 0; i < 4; ++i) loop.emplace_back(1, 0, i);
  for (int i = 0; i < 4; ++i) loop.emplace_back(1, i, 4);
  for (int i = 0; i < 4; ++i) loop.emplace_back(1, 4, 4 - i);
  for (int i = 0; i < 4; ++i) loop.emplace_back(1, 4 - i, 0);
  Tris tris;
  ASSERT_TRUE(triangulate_polygon(loop, tris));
  expect_triangulates(loop, tris);
  EXPECT_LT(loop_normal(loop).x(), 0);
  EXPECT_TRUE(triangulates_in(loop, tris, 0, -1)) << "oriented like the face: clockwise in (y, z)";
}

TEST(Triangulate, NonSimpleAndDegenerateLoopsReturnFalseWithoutCrashing) {
  Tris tris;
  const std::vector<Vec3> bow_tie = {{0, 0, 0}, {2, 2, 0}, {2, 0, 0}, {0, 2, 0}};
  EXPECT_FALSE(triangulate_polygon(bow_tie, tris));
  // Two squares touching at a corner, as one loop through the shared point (a pinch).
  const std::vector<Vec3> pinch = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {2, 1, 0}, {2, 2, 0}, {1, 2, 0}, {1, 1, 0}, {0, 1, 0}};
  EXPECT_FALSE(triangulate_polygon(pinch, tris));
  const std::vector<Vec3> collinear = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}};
  EXPECT_FALSE(triangulate_polygon(collinear, tris));
  EXPECT_TRUE(tris.empty());
  const std::vector<Vec3> spike = {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {1, 2, 0}, {1, 3, 0}, {1, 2, 0}, {0, 2, 0}};
  EXPECT_FALSE(triangulate_polygon(spike, tris));
  EXPECT_FALSE(triangulate_polygon({{0, 0, 0}, {1, 0, 0}}, tris));
}

// The crash class: every seed is triangulated without a crash; a strip wider than the doubles' spacing is
// simple once rounded and must give loop.size() - 2 triangles turning like the face, covering its area
// exactly.
TEST(Triangulate, ThinPiecesOfSplitRegionsNeverCrash) {
  int simple = 0, below_rounding = 0;
  Tris tris;
  for (std::uint64_t seed = 0; seed < 5000; ++seed) {
    const test::ThinPolygon p = test::thin_u_polygon(seed);
    const bool ok = triangulate_polygon(p.loop, tris);
    if (p.width_over_ulp >= 16) {
      ASSERT_TRUE(ok) << "seed " << seed << ", width/ulp " << p.width_over_ulp;
      expect_triangulates(p.loop, tris);
      ++simple;
    } else if (p.width_over_ulp < 1) {
      ++below_rounding;
    }
  }
  EXPECT_GT(simple, 4000);
  EXPECT_GT(below_rounding, 100);
}

/// A closed prism: the thin U as its top, a copy moved by `height` along the U plane's normal axis as its
/// bottom, and one quad per side.
PolygonMesh prism_over(const std::vector<Vec3>& loop, const Vec3& offset) {
  PolygonMesh m;
  const auto n = static_cast<std::uint32_t>(loop.size());
  for (const Vec3& p : loop) m.vertices.push_back(p);
  for (const Vec3& p : loop) m.vertices.push_back(p - offset);
  std::vector<std::uint32_t> top(n), bottom(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    top[i] = i;
    bottom[i] = 2 * n - 1 - i;
    const std::uint32_t j = (i + 1) % n;
    m.faces.push_back({j, i, n + i, n + j});
  }
  m.faces.push_back(top);
  m.faces.push_back(bottom);
  return m;
}

TEST(EvalValidity, PrismsOverTheCrashingPolygonsDoNotCrash) {
  // 1511, 4017 and 4375 crashed CGAL's triangulate_faces; 7 and 8 are strips far wider than the rounding.
  for (std::uint64_t seed : {1511u, 4017u, 4375u, 7u, 8u}) {
    const test::ThinPolygon p = test::thin_u_polygon(seed);
    const Vec3 n = loop_normal(p.loop).normalized();
    const PolygonMesh prism = prism_over(p.loop, 10.0 * n);
    const Validity v = check_validity(prism);
    if (p.width_over_ulp >= 16) {
      EXPECT_TRUE(v.valid()) << "seed " << seed << ": " << v.summary();
    } else {
      // The rounded strip touches or crosses itself: the mesh as written is not valid, and eval says so.
      EXPECT_FALSE(v.valid()) << "seed " << seed << ", width/ulp " << p.width_over_ulp;
    }
    PointCloud cloud;
    cloud.points = p.loop;
    EvalParams params;
    params.mesh_samples = 1000;
    const EvalResult r = run_eval(cloud, prism, nullptr, params);
    EXPECT_LT(r.accuracy.p2m_max, 1e-9) << "the corners lie on the mesh";
  }
}

// fuzz_extraction's first finding (issue 15): an extraction output, valid exactly, in which corners 6, 46
// and 32 (OBJ numbering) were collinear before rounding, on the line where faces 19 and 21 meet. Clipping
// the ear (32, 4, 6) in doubles left the sliver (32, 6, 46), which the rounding pushes through face 21: the
// mesh was reported self-intersecting. With robust ears first it is valid, as it is exactly.
TEST(EvalValidity, CornersCollinearBeforeRoundingGiveNoSliverTriangle) {
  const char* obj = R"(v 0 0.125 0
v 0 0 0
v 0 0 0.083333333333333329
v 0 0.75 0
v 0 0.56249999999999989 0
v 0 0.56249999999999989 0.18750000000000003
v 1 0 0
v 1 0.74999999999999989 0
v 1 0.24999999999999994 1
v 1 0 1
v 0.56249999999999989 0 0
v 0.56249999999999989 0 0.25000000000000006
v 0.8125 0 0
v 0.75 0 1
v 0.56249999999999989 0 0.62499999999999978
v 0.56249999999999989 0 0.28125
v 0.47500000000000003 0 0.32500000000000001
v 0.5 0 0.37499999999999994
v 0.4464285714285714 0 0.39285714285714279
v 0.46875 0 0.4375
v 0.18750000000000006 0 0.62499999999999989
v 0.4375 0 0.37499999999999994
v 0.42500000000000004 0 0.34999999999999998
v 0.4107142857142857 0 0.35714285714285715
v 0.29166666666666669 0.41666666666666669 0
v 0.12500000000000036 0.49999999999999983 0
v 0.031249999999999983 0.53124999999999989 0
v 0.62500000000000022 0.33333333333333315 0
v 0.64062499999999989 0.32812499999999994 0
v 0.43749999999999994 0.12499999999999996 0
v 0.8125 0.56249999999999989 0
v 0.49431818181818182 0.068181818181818107 0.35227272727272735
v 0.5089285714285714 0.10714285714285716 0.30357142857142855
v 0.46249999999999997 0.037499999999999901 0.35000000000000003
v 0.48124999999999996 0.081249999999999947 0.29999999999999999
v 0.4642857142857143 0.098214285714285643 0.23214285714285721
v 0.48749999999999999 0.074999999999999942 0.32500000000000001
v 0.12500000000000036 0.43749999999999956 0.06250000000000025
v 0.51874999999999993 0.043749999999999963 0.32499999999999996
v 0.62500000000000022 0.2916666666666673 0.041666666666665853
v 0.35000000000000003 0.21249999999999988 0.17500000000000007
v 0.54166666666666663 0.020833333333333315 0.27083333333333337
v 0.5 0.062499999999999944 0.25000000000000006
v 0.5625 0.125 0.24999999999999997
v 0.51249999999999996 0.049999999999999954 0.29999999999999999
v 0.46874999999999994 0.093749999999999986 0.34375000000000006
f 1 2 3
f 4 5 6
f 7 8 9 10
f 2 11 12 13 7 10 14 15 16 17 18 19 20 21 22 23 24 3
f 2 1 25 26 27 5 4 28 29 30 11
f 7 13 31 8
f 10 9 14
f 32 15 14 9 8 31 33
f 34 35 36 23 22
f 20 19 34 37 32
f 27 26 38
f 19 18 39 35 34
f 40 29 28
f 38 26 25 41
f 17 16 42 43
f 41 24 23 36
f 18 17 43 30 29 40 44 45 39
f 13 12 42 45 44 33 31
f 37 34 22 21 46
f 44 40 28 4 6 46 21 20 32 33
f 1 3 24 41 25
f 15 32 37 46 6 5 27 38 41 36 35 39 45 42 16
f 12 11 30 43 42)";
  PolygonMesh m;
  std::istringstream in(obj);
  std::string tag;
  while (in >> tag) {
    if (tag == "v") {
      Vec3 p;
      in >> p.x() >> p.y() >> p.z();
      m.vertices.push_back(p);
    } else if (tag == "f") {
      std::string line;
      std::getline(in, line);
      std::istringstream f(line);
      std::vector<std::uint32_t> face;
      for (std::uint32_t v; f >> v;) face.push_back(v - 1);
      m.faces.push_back(face);
    }
  }
  ASSERT_EQ(m.vertices.size(), 46u);
  ASSERT_EQ(m.faces.size(), 23u);
  const Validity v = check_validity(m);
  EXPECT_TRUE(v.valid()) << v.summary();
}

TEST(PointMeshDistance, KnownDistancesToCube) {
  const PolygonMesh cube = unit_cube();
  const std::vector<Vec3> q = {{0.5, 0.5, 0.5}, {2, 0.5, 0.5}, {2, 2, 0.5}, {2, 2, 2}, {0.3, 0.7, 1.0}, {0.5, 0.5, -0.25}};
  const std::vector<double> d = point_mesh_distances(q, cube);
  ASSERT_EQ(d.size(), q.size());
  EXPECT_NEAR(d[0], 0.5, 1e-12);
  EXPECT_NEAR(d[1], 1.0, 1e-12);
  EXPECT_NEAR(d[2], std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(d[3], std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(d[4], 0.0, 1e-12);
  EXPECT_NEAR(d[5], 0.25, 1e-12);
}

TEST(PointMeshDistance, NonConvexFaceUsesItsEdgesOverTheNotch) {
  const PolygonMesh l = l_shape();
  // Above the missing quarter: the nearest points are on the notch's edges, e.g. (1.5,1,0), not the plane (1.0).
  const std::vector<double> d = point_mesh_distances({{1.5, 1.5, 1.0}, {0.5, 1.5, 1.0}, {1.5, 0.5, -2.0}}, l);
  EXPECT_NEAR(d[0], std::sqrt(0.25 + 1.0), 1e-12);
  EXPECT_NEAR(d[1], 1.0, 1e-12);
  EXPECT_NEAR(d[2], 2.0, 1e-12);
  EXPECT_TRUE(std::isinf(point_mesh_distances({{0, 0, 0}}, PolygonMesh{})[0]));
}

// Thousands of points, in blocks of queries each started from its neighbour's closest point: every distance is
// the exact one (a hint never decides the answer), here the distance to the unit cube's surface.
TEST(PointMeshDistance, HintedQueriesGiveEveryPointsExactDistance) {
  const PolygonMesh cube = unit_cube();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 2.0);
  std::vector<Vec3> q(5000);
  for (Vec3& p : q) p = Vec3(u(rng), u(rng), u(rng));
  const std::vector<double> d = point_mesh_distances(q, cube);
  ASSERT_EQ(d.size(), q.size());
  for (std::size_t i = 0; i < q.size(); ++i) {
    const Vec3& p = q[i];
    const Vec3 outside = (p.cwiseMax(Vec3::Zero()).cwiseMin(Vec3::Ones()) - p);
    const double inside = std::min(p.minCoeff(), (Vec3::Ones() - p).minCoeff());
    const double exact = outside.norm() > 0 ? outside.norm() : inside;
    ASSERT_NEAR(d[i], exact, 1e-12) << "point " << i;
  }
}

TEST(PointMeshDistance, AgreesWithRunEvalOnTheSamePoints) {
  const PolygonMesh l = l_shape();
  PointCloud cloud;
  cloud.points = {{1.5, 1.5, 1.0}, {0.5, 1.5, 1.0}, {1.5, 0.5, -2.0}, {3, 3, 0}};
  EvalParams params;
  params.mesh_samples = 100;
  const EvalResult r = run_eval(cloud, l, nullptr, params);
  const std::vector<double> d = point_mesh_distances(cloud.points, l);
  EXPECT_NEAR(r.accuracy.p2m_max * r.diagonal, *std::max_element(d.begin(), d.end()), 1e-12);
}

}  // namespace
}  // namespace hsr
