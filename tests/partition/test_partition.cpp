// Stage 5 tests: exact cell complex, validate(), exhaustive and bsp partitioners (kinetic and
// hierarchical: test_kinetic.cpp).
#include "core/error.h"
#include "partition/partition.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>

#include "partition_fixtures.h"
#include "test_util.h"

namespace hsr {
namespace {

CellComplex partition(const std::vector<ConvexPolygon>& polys, Partitioner method, double margin = 0.05,
                      BBox box = unit_box()) {
  PartitionInput in{polys, box};
  PartitionParams params;
  params.method = method;
  params.bbox_margin = margin;
  return run_partition(in, params);
}

std::string describe(const ValidationReport& r) {
  std::string s;
  for (const auto& p : r.problems) s += p + "\n";
  return s;
}

// Partitions with both methods, validates both (with coverage), checks volumes and bsp <= exhaustive.
// Returns {exhaustive cells, bsp cells}.
std::pair<std::size_t, std::size_t> check_both(const std::vector<ConvexPolygon>& polys, double margin = 0.05,
                                               BBox box = unit_box()) {
  std::pair<std::size_t, std::size_t> counts;
  for (Partitioner m : {Partitioner::Exhaustive, Partitioner::Bsp}) {
    CellComplex cx = partition(polys, m, margin, box);
    ValidationReport r = validate(cx, &polys);
    EXPECT_TRUE(r.ok) << partitioner_name(m) << ":\n" << describe(r);
    Rational sum = 0;
    for (const Cell& c : cx.cells) sum += c.volume;
    EXPECT_EQ(sum, box_volume(cx)) << partitioner_name(m);
    (m == Partitioner::Exhaustive ? counts.first : counts.second) = cx.cells.size();
  }
  EXPECT_LE(counts.second, counts.first);
  return counts;
}

TEST(Partition, EmptyInputIsTheBox) {
  auto [ex, bsp] = check_both({});
  EXPECT_EQ(ex, 1u);
  EXPECT_EQ(bsp, 1u);
  CellComplex cx = partition({}, Partitioner::Bsp);
  EXPECT_EQ(cx.facets.size(), 6u);
  EXPECT_EQ(cx.vertices.size(), 8u);
}

TEST(Partition, BoxIsEnlargedByTheMarginAndDyadic) {
  ExactPoint lo, hi;
  partition_box(unit_box(), 0.05, lo, hi);
  const double m = 0.05 * std::sqrt(3.0);
  EXPECT_LE(lo.x.get_d(), -m);
  EXPECT_GE(hi.x.get_d(), 1 + m);
  EXPECT_LE(hi.x.get_d(), 1 + m + 1.0 / 512);  // rounded to the 2^-10 grid, not more
  // Dyadic: the denominators are powers of two.
  for (const Rational* r : {&lo.x, &lo.y, &lo.z, &hi.x, &hi.y, &hi.z}) {
    mpz_class den = r->get_den();
    EXPECT_EQ(den & (den - 1), 0) << r->get_str();
  }
  partition_box(unit_box(), 0.0, lo, hi);
  EXPECT_EQ(lo.x, 0);
  EXPECT_EQ(hi.z, 1);
}

TEST(Partition, AxisAlignedFullPlanesGiveKPlusOneCells) {
  for (int k = 1; k <= 5; ++k) {
    std::vector<ConvexPolygon> polys;
    for (int i = 0; i < k; ++i) polys.push_back(axis_polygon(i, 0, (i + 1.0) / (k + 1.0)));
    auto [ex, bsp] = check_both(polys);
    EXPECT_EQ(ex, static_cast<std::size_t>(k + 1));
    EXPECT_EQ(bsp, static_cast<std::size_t>(k + 1));
  }
}

TEST(Partition, ThreeOrthogonalPlanesThroughTheCentreGiveEightCells) {
  std::vector<ConvexPolygon> polys = {axis_polygon(0, 0, 0.5), axis_polygon(1, 1, 0.5), axis_polygon(2, 2, 0.5)};
  auto [ex, bsp] = check_both(polys);
  EXPECT_EQ(ex, 8u);
  EXPECT_EQ(bsp, 8u);
  // Each cell is an exact octant of the box.
  CellComplex cx = partition(polys, Partitioner::Exhaustive);
  for (const Cell& c : cx.cells) EXPECT_EQ(c.volume, box_volume(cx) / 8);
}

TEST(Partition, CubeFaces) {
  // Faces of the cube [0.25, 0.75]^3: the arrangement of its 6 planes has 27 cells; bsp inserts the
  // faces in order (equal areas): x faces split the box in 3 slabs, the y faces split only the middle
  // slab, the z faces only the middle column: 7 cells, the cube being one of them.
  std::vector<ConvexPolygon> polys;
  for (int axis = 0; axis < 3; ++axis)
    for (double v : {0.25, 0.75}) polys.push_back(axis_polygon(static_cast<int>(polys.size()), axis, v, 0.25, 0.75));
  auto [ex, bsp] = check_both(polys);
  EXPECT_EQ(ex, 27u);
  EXPECT_EQ(bsp, 7u);
  CellComplex cx = partition(polys, Partitioner::Bsp);
  int cubes = 0;
  for (const Cell& c : cx.cells) cubes += c.volume == Rational(1, 8);
  EXPECT_EQ(cubes, 1);
}

TEST(Partition, RandomPolygonSets) {
  for (int n : {1, 2, 3, 5, 8, 12, 20, 30})
    for (std::uint64_t seed = 1; seed <= (n <= 12 ? 4u : 2u); ++seed) {
      SCOPED_TRACE("n=" + std::to_string(n) + " seed=" + std::to_string(seed));
      auto polys = random_polygons(seed * 1000 + n, n);
      auto [ex, bsp] = check_both(polys);
      EXPECT_GE(bsp, 1u);
      // n planes in general position cut the box in at most 1 + n + C(n,2) + C(n,3) cells.
      const std::size_t bound = 1 + n + n * (n - 1) / 2 + n * (n - 1) * (n - 2) / 6;
      EXPECT_LE(ex, bound);
    }
}

// Exact side of `p` w.r.t. the facet plane, +1 meaning the side of `cell`.
int inner_side(const CellComplex& cx, int cell, std::uint32_t f, const ExactPoint& p) {
  const ExactPlane& e = cx.planes[cx.facets[f].plane].exact;
  const int s = sgn(e.a * p.x + e.b * p.y + e.c * p.z + e.d);
  return cx.facets[f].cells[0] == cell ? s : -s;
}

ExactPoint vertex_average(const CellComplex& cx, int cell) {
  std::vector<std::uint32_t> vs;
  for (auto f : cx.cells[cell].facets)
    for (auto v : cx.facets[f].vertices) vs.push_back(v);
  std::sort(vs.begin(), vs.end());
  vs.erase(std::unique(vs.begin(), vs.end()), vs.end());
  ExactPoint c{0, 0, 0};
  for (auto v : vs) {
    c.x += cx.vertices[v].x;
    c.y += cx.vertices[v].y;
    c.z += cx.vertices[v].z;
  }
  const Rational n(static_cast<long>(vs.size()));
  return {c.x / n, c.y / n, c.z / n};
}

// The bsp complex is a coarsening of the exhaustive one: each exhaustive cell lies in exactly one bsp cell
// (checked exactly on an interior point and on all its vertices), and the exhaustive cells inside a bsp
// cell add up exactly to its volume.
void expect_bsp_coarsens_exhaustive(const std::vector<ConvexPolygon>& polys) {
  const CellComplex ex = partition(polys, Partitioner::Exhaustive), bsp = partition(polys, Partitioner::Bsp);
  std::vector<Rational> filled(bsp.cells.size(), 0);
  for (int c = 0; c < static_cast<int>(ex.cells.size()); ++c) {
    const ExactPoint inside = vertex_average(ex, c);
    int owner = -1, owners = 0;
    for (int b = 0; b < static_cast<int>(bsp.cells.size()); ++b) {
      bool strictly = true;
      for (auto f : bsp.cells[b].facets) strictly &= inner_side(bsp, b, f, inside) > 0;
      if (strictly) { owner = b; ++owners; }
    }
    ASSERT_EQ(owners, 1) << "exhaustive cell " << c;
    for (auto ef : ex.cells[c].facets)
      for (auto v : ex.facets[ef].vertices)
        for (auto f : bsp.cells[owner].facets) ASSERT_GE(inner_side(bsp, owner, f, ex.vertices[v]), 0);
    filled[owner] += ex.cells[c].volume;
  }
  for (std::size_t b = 0; b < bsp.cells.size(); ++b) EXPECT_EQ(filled[b], bsp.cells[b].volume) << "bsp cell " << b;
}

TEST(Partition, BspCoarsensExhaustive) {
  for (std::uint64_t seed : {11u, 12u, 13u}) expect_bsp_coarsens_exhaustive(random_polygons(seed, 10));
  std::vector<ConvexPolygon> cube;
  for (int axis = 0; axis < 3; ++axis)
    for (double v : {0.25, 0.75}) cube.push_back(axis_polygon(static_cast<int>(cube.size()), axis, v, 0.25, 0.75));
  expect_bsp_coarsens_exhaustive(cube);
}

TEST(Partition, RepeatedCoplanarPolygonDoesNotResplit) {
  // The same polygon inserted twice (and a smaller one inside it) gives the complex of one polygon.
  auto base = random_polygons(21, 8);
  auto repeated = base;
  ConvexPolygon copy = base[0];
  copy.plane_id = 50;
  repeated.push_back(copy);
  ConvexPolygon inner = base[0];
  inner.plane_id = 51;
  Vec3 c = Vec3::Zero();
  for (const Vec3& v : inner.vertices) c += v;
  c /= static_cast<double>(inner.vertices.size());
  for (Vec3& v : inner.vertices) v = c + 0.5 * (v - c);
  repeated.push_back(inner);
  const CellComplex a = partition(base, Partitioner::Bsp), b = partition(repeated, Partitioner::Bsp);
  EXPECT_EQ(a.cells.size(), b.cells.size());
  EXPECT_EQ(a.facets.size(), b.facets.size());
  EXPECT_TRUE(validate(b, &repeated).ok) << describe(validate(b, &repeated));
}

TEST(Partition, ParallelPlanes) {
  std::vector<ConvexPolygon> polys;
  const Vec3 n(1, 2, 3);
  for (int i = 0; i < 6; ++i) polys.push_back(plane_polygon(i, n, Vec3::Constant(0.1 + 0.15 * i)));
  auto [ex, bsp] = check_both(polys);
  EXPECT_EQ(ex, 7u);
  EXPECT_EQ(bsp, 7u);
}

TEST(Partition, CoplanarDuplicatesAreMergedIntoOneSupportPlane) {
  // Three polygons on x = 0.5 (one with the opposite normal), disjoint or overlapping, and a crossing plane.
  std::vector<ConvexPolygon> polys = {axis_polygon(0, 0, 0.5, 0.0, 0.4), axis_polygon(1, 0, 0.5, 0.3, 0.9),
                                      axis_polygon(2, 0, 0.5, 0.6, 1.0), axis_polygon(3, 1, 0.5)};
  polys[2].plane.normal = -polys[2].plane.normal;
  polys[2].plane.offset = -polys[2].plane.offset;
  auto [ex, bsp] = check_both(polys);
  EXPECT_EQ(ex, 4u);
  CellComplex cx = partition(polys, Partitioner::Bsp);
  EXPECT_EQ(cx.planes.size(), 6u + 2u);  // box sides + x = 0.5 + y = 0.5
  EXPECT_EQ(cx.planes[6].input_planes, (std::vector<int>{0, 1, 2}));
  EXPECT_LE(bsp, 4u);
}

TEST(Partition, ThreeAndFourPlanesThroughOneLine) {
  // Planes containing the vertical line x = y = 1/2: k planes make 2k wedges.
  for (int k : {3, 4}) {
    std::vector<Vec3> normals = k == 3 ? std::vector<Vec3>{{1, 0, 0}, {1, 1, 0}, {1, -2, 0}}
                                       : std::vector<Vec3>{{1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, -1, 0}};
    std::vector<ConvexPolygon> polys;
    for (const Vec3& n : normals)
      polys.push_back(exact_plane_polygon(static_cast<int>(polys.size()), n, -0.5 * (n.x() + n.y())));
    auto [ex, bsp] = check_both(polys);
    EXPECT_EQ(ex, static_cast<std::size_t>(2 * k)) << k;
    EXPECT_EQ(bsp, static_cast<std::size_t>(2 * k)) << k;
  }
}

TEST(Partition, FourPlanesThroughOnePoint) {
  // x, y, z = 1/2 make 8 octants; x + y + z = 3/2 also passes through the centre and crosses the
  // interior of 6 of them (not the (+,+,+) and (-,-,-) octants): 14 cells.
  std::vector<ConvexPolygon> polys = {axis_polygon(0, 0, 0.5), axis_polygon(1, 1, 0.5), axis_polygon(2, 2, 0.5)};
  polys.push_back(exact_plane_polygon(3, Vec3(1, 1, 1), -1.5));
  auto [ex, bsp] = check_both(polys);
  EXPECT_EQ(ex, 14u);
  EXPECT_EQ(bsp, 14u);
}

TEST(Partition, PlanesTouchingOrCoincidingWithTheBox) {
  // No margin: the box is exactly [0,1]^3. Polygons on two box sides, a plane touching the box along an
  // edge (x + y = 0), one touching a corner (x + y + z = 3), and one real cut.
  std::vector<ConvexPolygon> polys = {axis_polygon(0, 0, 0.0), axis_polygon(1, 2, 1.0)};
  polys.push_back(exact_plane_polygon(2, Vec3(1, 1, 0), 0.0));
  polys.push_back(exact_plane_polygon(3, Vec3(1, 1, 1), -3.0));
  {
    auto [ex, bsp] = check_both(polys, 0.0);
    EXPECT_EQ(ex, 1u);
    EXPECT_EQ(bsp, 1u);
    CellComplex cx = partition(polys, Partitioner::Exhaustive, 0.0);
    EXPECT_EQ(cx.planes[0].input_planes, std::vector<int>{0});  // x = 0 is the low x side
    EXPECT_EQ(cx.planes[5].input_planes, std::vector<int>{1});  // z = 1 is the high z side
  }
  polys.push_back(axis_polygon(4, 1, 0.5));
  auto [ex, bsp] = check_both(polys, 0.0);
  EXPECT_EQ(ex, 2u);
  EXPECT_EQ(bsp, 2u);
}

TEST(Partition, NearlyCoincidentPlanesAreDistinctExactly) {
  // z = 1/2 and z = 1/2 + 2^-40: two planes, a slab of thickness 2^-40 between them.
  std::vector<ConvexPolygon> slab = {axis_polygon(0, 2, 0.5), axis_polygon(1, 2, 0.5 + std::ldexp(1.0, -40))};
  auto [ex, bsp] = check_both(slab);
  EXPECT_EQ(ex, 3u);
  EXPECT_EQ(bsp, 3u);
  CellComplex cx = partition(slab, Partitioner::Exhaustive);
  Rational thinnest = box_volume(cx);
  for (const Cell& c : cx.cells) thinnest = std::min(thinnest, c.volume);
  EXPECT_EQ(thinnest, (cx.box_max.x - cx.box_min.x) * (cx.box_max.y - cx.box_min.y) * Rational(1, 1099511627776));
  // z = 1/2 and a plane tilted by 1e-9 rad about the line x = 1/2 in it: four thin wedges.
  std::vector<ConvexPolygon> wedge = {axis_polygon(0, 2, 0.5),
                                      exact_plane_polygon(1, Vec3(1e-9, 0, 1), -0.5 - 0.5e-9)};
  auto [ex2, bsp2] = check_both(wedge);
  EXPECT_EQ(ex2, 4u);
  EXPECT_EQ(bsp2, 4u);
}

TEST(Partition, FarFromTheOrigin) {
  // A box far from the origin (georeferenced data not shifted): exactness does not depend on magnitude.
  BBox far;
  far.extend(Vec3(4e6, 5e6, 100));
  far.extend(Vec3(4e6 + 50, 5e6 + 30, 120));
  std::vector<ConvexPolygon> polys;
  std::mt19937_64 rng(9);
  for (int i = 0; i < 8; ++i) {
    Vec3 n(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    n.normalize();
    const Vec3 c = far.min + Vec3(uniform(rng, 0, 50), uniform(rng, 0, 30), uniform(rng, 0, 20));
    const Vec3 u = n.unitOrthogonal(), v = n.cross(u);
    polys.push_back(rectangle(i, c, u, v, uniform(rng, 2, 20), uniform(rng, 2, 20)));
  }
  auto [ex, bsp] = check_both(polys, 0.05, far);
  EXPECT_GT(ex, 8u);
  EXPECT_GT(bsp, 1u);
}

TEST(Partition, AxisAlignedGrid) {
  // 3 planes per axis: 4^3 cells; partial polygons in bsp (each covering half a slab) give fewer.
  std::vector<ConvexPolygon> full;
  for (int axis = 0; axis < 3; ++axis)
    for (double v : {0.25, 0.5, 0.75}) full.push_back(axis_polygon(static_cast<int>(full.size()), axis, v));
  auto [ex, bsp] = check_both(full);
  EXPECT_EQ(ex, 64u);
  EXPECT_EQ(bsp, 64u);
  std::vector<ConvexPolygon> partial;
  for (int axis = 0; axis < 3; ++axis)
    for (double v : {0.25, 0.5, 0.75})
      partial.push_back(axis_polygon(static_cast<int>(partial.size()), axis, v, 0.1, 0.45));
  auto [ex2, bsp2] = check_both(partial);
  EXPECT_EQ(ex2, 64u);
  EXPECT_LT(bsp2, 64u);
}

TEST(Partition, GridWithDiagonalPlanesThroughItsVertices) {
  // Diagonal planes through grid vertices and edges: many vertices exactly on the cutting planes.
  std::vector<ConvexPolygon> polys;
  for (int axis = 0; axis < 3; ++axis)
    for (double v : {0.25, 0.5, 0.75}) polys.push_back(axis_polygon(static_cast<int>(polys.size()), axis, v));
  for (auto [n, d] : {std::pair{Vec3(1, -1, 0), 0.0}, {Vec3(1, 1, 0), -1.0}, {Vec3(1, 1, 1), -1.5},
                      {Vec3(0, 1, -1), -0.25}}) {
    ConvexPolygon p = exact_plane_polygon(static_cast<int>(polys.size()), n, d);
    polys.push_back(p);
  }
  check_both(polys);
}

TEST(Partition, BspIsCoarserWithSmallPolygons) {
  // Small polygons deep inside: bsp splits only what they cross.
  std::vector<ConvexPolygon> polys = {axis_polygon(0, 0, 0.3, 0.1, 0.2), axis_polygon(1, 1, 0.7, 0.6, 0.7),
                                      axis_polygon(2, 2, 0.5, 0.8, 0.9)};
  auto [ex, bsp] = check_both(polys);
  EXPECT_EQ(ex, 8u);
  EXPECT_EQ(bsp, 4u);
}

// bsp extends a polygon to its bounds: A (x = 1/2, y and z in [0.4, 0.6]) is adjacent to B (full z = 0.8),
// whose line bounds A at z <= 0.8; C (full y = 0.2) is not adjacent. B and C make 4 cells. As is, A's
// fragment crosses only the cell y > 0.2, z < 0.8 (5 cells); extended to the section z <= 0.8 it also
// splits y < 0.2, z < 0.8 (6 cells), and its facets reach B and the box side y = 0 exactly.
TEST(Partition, BspExtendsPolygonsToTheirBounds) {
  const std::vector<ConvexPolygon> polys = {axis_polygon(0, 0, 0.5, 0.4, 0.6), axis_polygon(1, 2, 0.8),
                                            axis_polygon(2, 1, 0.2)};
  for (bool extend : {false, true}) {
    PartitionParams params;
    params.method = Partitioner::Bsp;
    params.bbox_margin = 0;
    params.bsp_extend = extend;
    CellComplex cx = run_partition({polys, unit_box(), {{0, 1}}}, params);
    ValidationReport r = validate(cx, &polys);
    EXPECT_TRUE(r.ok) << describe(r);
    EXPECT_EQ(cx.cells.size(), extend ? 6u : 5u);
    Rational y_lo = 1, z_hi = 0;
    for (const Facet& f : cx.facets) {
      const ExactPlane& p = cx.planes[f.plane].exact;
      if (!(p.a == 1 && p.b == 0 && p.c == 0 && p.d == Rational(-1, 2))) continue;
      for (auto v : f.vertices) {
        y_lo = std::min(y_lo, cx.vertices[v].y);
        z_hi = std::max(z_hi, cx.vertices[v].z);
      }
    }
    EXPECT_EQ(y_lo, extend ? Rational(0) : Rational(0.2));  // the doubles 0.2 and 0.8, read exactly
    EXPECT_EQ(z_hi, Rational(0.8));
  }
}

// Without exact volumes (the pipeline's setting) the complex is the same, validate() still recomputes and
// sums the exact volumes, and volume_approx agrees with the exact volume.
TEST(Partition, WithoutExactVolumes) {
  const auto polys = random_polygons(21, 12);
  for (Partitioner m : {Partitioner::Bsp, Partitioner::Hierarchical}) {
    PartitionParams params;
    params.method = m;
    const CellComplex exact = run_partition({polys, unit_box()}, params);
    params.exact_volumes = false;
    const CellComplex fast = run_partition({polys, unit_box()}, params);
    ValidationReport r = validate(fast, &polys);
    EXPECT_TRUE(r.ok) << describe(r);
    ASSERT_EQ(fast.cells.size(), exact.cells.size());
    EXPECT_EQ(fast.facets.size(), exact.facets.size());
    for (std::size_t c = 0; c < fast.cells.size(); ++c) {
      EXPECT_EQ(fast.cells[c].volume, 0);
      EXPECT_NEAR(fast.cells[c].volume_approx, exact.cells[c].volume.get_d(), 1e-12) << "cell " << c;
    }
    // A broken complex is still caught: drop a cell's facet.
    CellComplex broken = fast;
    broken.cells[0].facets.pop_back();
    EXPECT_FALSE(validate(broken, &polys).ok);
  }
}

TEST(Partition, Deterministic) {
  auto polys = random_polygons(77, 15);
  for (Partitioner m : {Partitioner::Exhaustive, Partitioner::Bsp}) {
    CellComplex a = partition(polys, m), b = partition(polys, m);
    ASSERT_EQ(a.vertices.size(), b.vertices.size());
    for (std::size_t i = 0; i < a.vertices.size(); ++i) EXPECT_TRUE(a.vertices[i] == b.vertices[i]);
    ASSERT_EQ(a.facets.size(), b.facets.size());
    for (std::size_t i = 0; i < a.facets.size(); ++i) {
      EXPECT_EQ(a.facets[i].vertices, b.facets[i].vertices);
      EXPECT_EQ(a.facets[i].cells, b.facets[i].cells);
    }
  }
}

// validate() itself: each kind of corruption is reported.
class BrokenComplex : public ::testing::Test {
 protected:
  void SetUp() override {
    polys = random_polygons(5, 6);
    good = partition(polys, Partitioner::Bsp);
    ASSERT_TRUE(validate(good, &polys).ok) << describe(validate(good, &polys));
    ASSERT_GT(good.cells.size(), 2u);
  }
  int interior_facet() const {
    for (std::size_t f = 0; f < good.facets.size(); ++f)
      if (good.planes[good.facets[f].plane].kind == SupportPlane::Kind::Input) return static_cast<int>(f);
    return -1;
  }
  std::vector<ConvexPolygon> polys;
  CellComplex good;
};

TEST_F(BrokenComplex, RemovedFacetFromACell) {
  CellComplex cx = good;
  cx.cells[0].facets.pop_back();
  EXPECT_FALSE(validate(cx).ok);
}

TEST_F(BrokenComplex, PerturbedVertex) {
  CellComplex cx = good;
  const auto v = cx.facets[interior_facet()].vertices[0];
  cx.vertices[v].x += Rational(1, 1000000);
  cx.vertices_approx[v].x() += 1e-6;
  EXPECT_FALSE(validate(cx).ok);
}

TEST_F(BrokenComplex, ReversedFacetLoop) {
  CellComplex cx = good;
  auto& loop = cx.facets[interior_facet()].vertices;
  std::reverse(loop.begin(), loop.end());
  EXPECT_FALSE(validate(cx).ok);
}

TEST_F(BrokenComplex, SwappedFacetSides) {
  CellComplex cx = good;
  auto& cells = cx.facets[interior_facet()].cells;
  std::swap(cells[0], cells[1]);
  EXPECT_FALSE(validate(cx).ok);
}

TEST_F(BrokenComplex, TJunction) {
  // Drop a flat vertex from the two facets of one cell that carry it: that cell stays closed, convex and
  // of the same volume, but other facets around the edge keep the vertex: the T-junction check fires
  // (the neighbours sharing those facets also stop being closed).
  bool broken = false;
  for (std::size_t c = 0; c < good.cells.size() && !broken; ++c) {
    std::map<std::uint32_t, std::vector<std::uint32_t>> flat_in;  // vertex -> facets of c where it is flat
    std::map<std::uint32_t, int> uses;
    for (auto f : good.cells[c].facets) {
      const auto& loop = good.facets[f].vertices;
      const std::size_t n = loop.size();
      for (std::size_t i = 0; i < n; ++i) {
        const Vec3 a = good.vertices_approx[loop[(i + n - 1) % n]], b = good.vertices_approx[loop[i]],
                   d = good.vertices_approx[loop[(i + 1) % n]];
        ++uses[loop[i]];
        if ((b - a).cross(d - b).norm() < 1e-12) flat_in[loop[i]].push_back(f);
      }
    }
    for (const auto& [v, fs] : flat_in) {
      if (fs.size() != 2 || uses[v] != 2) continue;
      CellComplex cx = good;
      for (auto f : fs) {
        auto& loop = cx.facets[f].vertices;
        loop.erase(std::find(loop.begin(), loop.end(), v));
      }
      ValidationReport r = validate(cx);
      EXPECT_FALSE(r.ok);
      bool t_junction = false;
      for (const auto& p : r.problems) t_junction |= p.find("T-junction") != std::string::npos;
      EXPECT_TRUE(t_junction) << describe(r);
      broken = true;
      break;
    }
  }
  EXPECT_TRUE(broken) << "no flat vertex found to remove";
}

TEST_F(BrokenComplex, WrongVolume) {
  CellComplex cx = good;
  cx.cells[1].volume += Rational(1, 1000000007);
  EXPECT_FALSE(validate(cx).ok);
}

TEST_F(BrokenComplex, DuplicateVertex) {
  CellComplex cx = good;
  cx.vertices.push_back(cx.vertices[0]);
  cx.vertices_approx.push_back(cx.vertices_approx[0]);
  EXPECT_FALSE(validate(cx).ok);
}

TEST_F(BrokenComplex, DroppedCell) {
  // Removing the last cell (and every facet reference to it) breaks the volume sum and the two-cell rule.
  CellComplex cx = good;
  const int last = static_cast<int>(cx.cells.size()) - 1;
  cx.cells.pop_back();
  for (auto& f : cx.facets)
    for (auto& c : f.cells)
      if (c == last) c = -1;
  EXPECT_FALSE(validate(cx).ok);
}

TEST_F(BrokenComplex, OverlappingFacetsOnOnePlane) {
  // A copy of an interior facet shared by the same two cells: closedness and overlap both fail.
  CellComplex cx = good;
  const int f = interior_facet();
  cx.facets.push_back(cx.facets[f]);
  const auto nf = static_cast<std::uint32_t>(cx.facets.size() - 1);
  for (int c : cx.facets[f].cells) cx.cells[c].facets.push_back(nf);
  ValidationReport r = validate(cx);
  EXPECT_FALSE(r.ok);
  bool overlap_reported = false;
  for (const auto& p : r.problems) overlap_reported |= p.find("overlap") != std::string::npos;
  EXPECT_TRUE(overlap_reported) << describe(r);
}

TEST_F(BrokenComplex, UncoveredInputPolygon) {
  // A polygon on the plane of an inserted one but elsewhere: bsp never inserted it, coverage must fail
  // (unless its plane happens to be fully cut, which the assertion on the exhaustive complex rules out).
  std::vector<ConvexPolygon> more = polys;
  ConvexPolygon extra = polys[0];
  extra.plane_id = 100;
  // Use a tiny polygon near the far box corner, on the same plane.
  const Vec3 n = polys[0].plane.normal;
  Vec3 u = n.unitOrthogonal(), v = n.cross(u);
  Vec3 far = Vec3(1.04, 1.04, 1.04);
  Vec3 c = far - n * (n.dot(far) + polys[0].plane.offset);
  extra.vertices = {c - 0.01 * u - 0.01 * v, c + 0.01 * u - 0.01 * v, c + 0.01 * u + 0.01 * v, c - 0.01 * u + 0.01 * v};
  more.push_back(extra);
  // The exhaustive complex covers it (whole plane cut), the bsp one built without it does not.
  CellComplex full = partition(more, Partitioner::Exhaustive);
  EXPECT_TRUE(validate(full, &more).ok) << describe(validate(full, &more));
  EXPECT_FALSE(validate(good, &more).ok);
}

TEST(Partition, DegeneratePolygons) {
  // A polygon whose vertices are collinear on its plane: bsp ignores it, exhaustive still cuts with its
  // plane; both stay valid. A zero normal is a user error.
  std::vector<ConvexPolygon> polys = {axis_polygon(0, 0, 0.5)};
  ConvexPolygon line = axis_polygon(1, 1, 0.3);
  line.vertices = {Vec3(0.1, 0.3, 0.1), Vec3(0.5, 0.3, 0.5), Vec3(0.9, 0.3, 0.9)};
  polys.push_back(line);
  auto [ex, bsp] = check_both(polys);
  EXPECT_EQ(ex, 4u);
  EXPECT_EQ(bsp, 2u);
  polys[1].plane.normal = Vec3::Zero();
  EXPECT_EQ(test::status_of([&] { partition(polys, Partitioner::Bsp); }), Status::BadInput);
}

TEST(Partition, Names) {
  for (Partitioner p : {Partitioner::Exhaustive, Partitioner::Bsp, Partitioner::Kinetic, Partitioner::Hierarchical})
    EXPECT_EQ(parse_partitioner(partitioner_name(p)), p);
  try {
    parse_partitioner("octree");
    FAIL() << "no throw";
  } catch (const Error& e) {
    EXPECT_EQ(e.status(), Status::BadInput);
    EXPECT_NE(std::string(e.what()).find("octree"), std::string::npos);
  }
}

TEST(Partition, BadInput) {
  PartitionInput in{random_polygons(1, 3), unit_box()};
  PartitionParams params;
  params.method = Partitioner::Kinetic;
  params.kinetic_k = 0;
  EXPECT_EQ(test::status_of([&] { run_partition(in, params); }), Status::BadInput);
  params.kinetic_k = 1;
  params.method = Partitioner::Bsp;
  in.points_bbox = BBox();
  EXPECT_EQ(test::status_of([&] { run_partition(in, params); }), Status::BadInput);
  // A flat bbox with no margin has no volume.
  in.points_bbox = unit_box();
  in.points_bbox.max.z() = 0;
  params.bbox_margin = 0;
  EXPECT_EQ(test::status_of([&] { run_partition(in, params); }), Status::DegenerateInput);
}

TEST(Partition, DumpWritesEveryFacet) {
  auto polys = random_polygons(3, 5);
  CellComplex cx = partition(polys, Partitioner::Bsp);
  std::filesystem::create_directories(HSR_TEST_TMP_DIR);
  const std::string path = std::string(HSR_TEST_TMP_DIR) + "/dump.ply";
  write_partition_dump(cx, path);
  std::ifstream in(path);
  std::string line;
  std::size_t nv = 0, nf = 0;
  while (std::getline(in, line) && line != "end_header") {
    if (line.rfind("element vertex ", 0) == 0) nv = std::stoul(line.substr(15));
    if (line.rfind("element face ", 0) == 0) nf = std::stoul(line.substr(13));
  }
  EXPECT_EQ(nv, cx.vertices.size());
  EXPECT_EQ(nf, cx.facets.size());
  std::size_t body = 0;
  while (std::getline(in, line)) ++body;
  EXPECT_EQ(body, nv + nf);
}

}  // namespace
}  // namespace hsr
