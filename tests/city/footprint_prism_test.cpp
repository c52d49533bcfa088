// The footprint as a hard bound of the solid (partition/footprint_prism.h and its use in the pipeline):
// the walls cut every cell they cross, the kept cells fill exactly the prism, and a building run with a
// footprint stays inside it, so two halves of one scan given neighbouring footprints meet on their shared
// wall without overlapping.
#include "partition/footprint_prism.h"
#include "partition/partition.h"
#include "pipeline.h"
#include "synth/synth.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace hsr;

namespace {

/// An L: [0, 4] x [0, 2] plus [0, 2] x [2, 4] (area 12), with a 1 x 1 hole at [0.5, 1.5]² — inside the box
/// [-1, 5] x [-1, 5] x [0, 3].
Footprint l_with_hole() {
  return {{{{0, 0}, {4, 0}, {4, 2}, {2, 2}, {2, 4}, {0, 4}}, {{{0.5, 0.5}, {0.5, 1.5}, {1.5, 1.5}, {1.5, 0.5}}}}};
}

ConvexPolygon horizontal(double z) {
  ConvexPolygon p;
  p.plane_id = 0;
  p.plane.normal = Vec3::UnitZ();
  p.plane.offset = -z;
  p.vertices = {{-1, -1, z}, {5, -1, z}, {5, 5, z}, {-1, 5, z}};
  return p;
}

TEST(FootprintPrism, InsideTest) {
  const Footprint f = l_with_hole();
  EXPECT_TRUE(inside_footprint(3.0, 1.0, f));
  EXPECT_FALSE(inside_footprint(3.0, 3.0, f));   // the L's notch
  EXPECT_FALSE(inside_footprint(1.0, 1.0, f));   // the hole
  EXPECT_TRUE(inside_footprint(Rational(1, 4), Rational(3), f));
  EXPECT_FALSE(inside_footprint(Rational(5, 2), Rational(5, 2), f));
}

TEST(FootprintPrism, CollinearEdgesShareOnePlaneExactly) {
  // A U turned by 30 degrees near (155000, 463000): the ends of its two arms lie on one line (as an aerial
  // footprint's aligned wings do; a 3e-9 m sliver between the two edges' planes made B0043 of the synthetic
  // tile of seed 2 impossible to round to any CityJSON grid).
  const std::vector<Vec2> local = {{0, 0}, {12.3, 0}, {12.3, 9.6}, {8.1, 9.6}, {8.1, 4.9}, {3.7, 4.9}, {3.7, 9.6}, {0, 9.6}};
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  FootprintPolygon poly;
  for (const Vec2& q : local) poly.outer.push_back(Vec2(155000.1, 463000.7) + Vec2(c * q.x() - s * q.y(), s * q.x() + c * q.y()));
  const auto walls = footprint_wall_polygons({poly}, 0, 10, 0);
  ASSERT_EQ(walls.size(), 8u);
  EXPECT_TRUE(walls[2].plane.normal == walls[6].plane.normal && walls[2].plane.offset == walls[6].plane.offset);
  // Edge by edge the two planes are not the same doubles (what the test guards against).
  auto naive = [&](int e) {
    const Vec2 a = poly.outer[e], b = poly.outer[(e + 1) % 8];
    const bool flip = b.x() < a.x() || (b.x() == a.x() && b.y() < a.y());
    const Vec2 p = flip ? b : a, d = ((flip ? a : b) - p).normalized();
    return Plane{Vec3(d.y(), -d.x(), 0), -(d.y() * p.x() - d.x() * p.y())};
  };
  const Plane p2 = naive(2), p6 = naive(6);
  EXPECT_FALSE(p2.normal == p6.normal && p2.offset == p6.offset);
  EXPECT_NE(walls[3].plane.offset, walls[7].plane.offset);  // parallel but not collinear: their own planes
}

TEST(FootprintPrism, KeptCellsFillThePrismExactly) {
  for (Partitioner method : {Partitioner::Bsp, Partitioner::Kinetic, Partitioner::Hierarchical, Partitioner::Exhaustive}) {
    SCOPED_TRACE(partitioner_name(method));
    PartitionInput in;
    in.polygons = {horizontal(1.0), horizontal(2.2)};
    in.polygons[1].plane_id = 1;
    in.points_bbox.extend({-1, -1, 0});
    in.points_bbox.extend({5, 5, 3});
    const Footprint f = l_with_hole();
    in.cuts = footprint_wall_polygons(f, -10, 10, 2);
    ASSERT_EQ(in.cuts.size(), 10u);  // 6 + 4 edges
    PartitionParams pp;
    pp.method = method;
    const CellComplex cx = run_partition(in, pp);
    std::vector<ConvexPolygon> all = in.polygons;
    all.insert(all.end(), in.cuts.begin(), in.cuts.end());
    ASSERT_TRUE(validate(cx, &all).ok);  // the walls are covered by facets
    std::size_t removed = 0;
    const CellComplex kept = keep_cells_in_prism(cx, f, &removed);
    EXPECT_EQ(kept.cells.size() + removed, cx.cells.size());
    double volume = 0;
    for (const Cell& c : kept.cells) {
      volume += c.volume_approx;
      EXPECT_TRUE(inside_footprint(c.centroid.x(), c.centroid.y(), f));
    }
    const double height = cx.box.max.z() - cx.box.min.z();
    EXPECT_NEAR(volume, 11.0 * height, 1e-9 * height);  // (12 - 1) x the box's height
    for (const Facet& fa : kept.facets) {
      EXPECT_FALSE(fa.cells[0] < 0 && fa.cells[1] < 0);
      for (int c : fa.cells) EXPECT_LT(c, static_cast<int>(kept.cells.size()));
    }
  }
}

/// Vertices of the mesh, in the cloud's frame, whose xy lie farther than `tol` outside the footprint.
std::size_t vertices_outside(const PolygonMesh& m, const Footprint& f, double tol) {
  std::size_t n = 0;
  for (const Vec3& v : m.vertices) {
    if (inside_footprint(v.x(), v.y(), f)) continue;
    double d = INFINITY;
    for (const auto& p : f) {
      const auto& r = p.outer;
      for (std::size_t i = 0, j = r.size() - 1; i < r.size(); j = i++) {
        const Vec2 a = r[j], b = r[i], q = v.head<2>();
        const double t = std::clamp((q - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
        d = std::min(d, (q - (a + t * (b - a))).norm());
      }
    }
    n += d > tol;
  }
  return n;
}

/// One aerial scan cut in two along a line across it: each half's model stays on its side of the line.
TEST(FootprintPrism, TwoNeighboursShareAWallAndDoNotOverlap) {
  SynthParams sp;
  sp.seed = 3;
  sp.aerial_ground = 0;
  sp.aerial_trees = 0;
  const SynthScan scan = run_synth("aerial_flat", sp);
  const BBox box = bounding_box(scan.cloud.points);
  const Vec3 c = box.center();
  const double r = box.diagonal();
  // A line through the centre at 20 degrees; each side's footprint a big quadrilateral ending on it.
  const Vec2 d(std::cos(0.35), std::sin(0.35)), n(-d.y(), d.x());
  const Vec2 o = c.head<2>();
  const Footprint left{{{o - r * d, o + r * d, o + r * d + r * n, o - r * d + r * n}, {}}};
  const Footprint right{{{o - r * d - r * n, o + r * d - r * n, o + r * d, o - r * d}, {}}};
  PipelineParams pp;
  pp.scene.mode = SceneMode::Building;
  PipelineResult whole = run_pipeline(scan.cloud, pp);
  pp.footprint = left;
  PipelineResult a = run_pipeline(scan.cloud, pp);
  pp.footprint = right;
  PipelineResult b = run_pipeline(scan.cloud, pp);
  for (const PipelineResult* res : {&whole, &a, &b}) EXPECT_TRUE(res->eval.validity.valid()) << res->eval.validity.summary();
  EXPECT_EQ(vertices_outside(a.mesh, left, 1e-9), 0u);
  EXPECT_EQ(vertices_outside(b.mesh, right, 1e-9), 0u);
  EXPECT_GT(vertices_outside(whole.mesh, left, 1e-3), 0u);  // the whole model does cross the line
  // The two halves together are the whole building's volume, near enough (the cut adds walls only).
  const double va = a.eval.validity.volume, vb = b.eval.validity.volume, vw = whole.eval.validity.volume;
  EXPECT_GT(va, 0.2 * vw);
  EXPECT_GT(vb, 0.2 * vw);
  EXPECT_NEAR(va + vb, vw, 0.05 * vw);
  EXPECT_EQ(a.report["counts"]["cells_outside_footprint"].get<std::size_t>() > 0, true);
}

}  // namespace

namespace {

/// `hsr city` passes each building its ring's ground with --trust-ground-z (SceneParams::given_ground_wins):
/// a plane at the bottom of the points is then not taken for the ground.
TEST(GivenGround, WinsOverADetectedPlaneWhenTrusted) {
  SynthParams sp;
  sp.seed = 1;
  sp.aerial_ground = 1;  // ground points around the building: a ground plane is detected
  sp.aerial_trees = 0;
  const SynthScan scan = run_synth("aerial_gable", sp);
  const SceneStructure s = run_structure(scan.cloud, StructureParams{});
  SceneParams p;
  p.mode = SceneMode::Building;
  p.building.ground_z = -0.75;
  // The given height wins either way; untrusted, the ground plane is still found and left out of the model.
  const SceneResult plane = run_scene(scan.cloud, s, p);
  ASSERT_EQ(plane.ground_source, GroundSource::Given);
  EXPECT_EQ(plane.ground_z, -0.75);
  EXPECT_FALSE(plane.ground_planes.empty());
  p.building.given_ground_wins = true;
  const SceneResult given = run_scene(scan.cloud, s, p);
  EXPECT_EQ(given.ground_source, GroundSource::Given);
  EXPECT_EQ(given.ground_z, -0.75);
  EXPECT_TRUE(given.ground_planes.empty());
}

}  // namespace
