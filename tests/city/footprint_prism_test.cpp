// The footprint as a hard bound of the solid (partition/footprint_prism.h and its use in the pipeline):
// the walls cut every cell they cross, the kept cells fill exactly the prism, and a building run with a
// footprint stays inside it, so two halves of one scan given neighbouring footprints meet on their shared
// wall without overlapping.
#include "partition/footprint_prism.h"
#include "partition/partition.h"
#include "pipeline/pipeline.h"
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

// footprint_wall_points: a point on no plane near an edge votes for that edge's wall (its id in
// footprint_wall_polygons' order, the edge's outward normal); a point on a plane of the complex, one at the
// ground, one beyond `distance` and one past an edge's end keep what they had.
TEST(FootprintPrism, FacadePointsOnNoPlaneVoteForTheirEdgesWall) {
  const Footprint f = l_with_hole();
  const int first_id = 7;
  const std::vector<ConvexPolygon> walls = footprint_wall_polygons(f, 0.0, 3.0, first_id);
  ASSERT_EQ(walls.size(), 10u);  // six outer edges, four of the hole
  const std::vector<Vec3> points = {
      {3.0, -0.05, 1.0},   // 0: outside the first edge (0,0)->(4,0): its wall, id 7, normal -y
      {4.05, 1.0, 1.0},    // 1: outside the second edge (4,0)->(4,2): id 8, normal +x
      {1.0, 1.45, 1.0},    // 2: inside the hole, near its edge (0.5,1.5)->(1.5,1.5): the hole's second edge, id 14, normal -y
      {3.0, 0.05, 1.0},    // 3: on plane 2, which the complex holds: kept
      {3.0, 0.05, 0.05},   // 4: at the ground: kept
      {3.0, 0.5, 1.0},     // 5: farther than the distance from every edge: kept
      {4.05, -0.05, 1.0},  // 6: beyond the ends of both edges at the corner: kept
  };
  std::vector<int> plane = {-1, -1, -1, 2, -1, -1, -1};
  std::vector<Vec3> normals(points.size(), Vec3::UnitZ());
  const std::vector<bool> in_complex = {false, false, true};
  const std::size_t given = footprint_wall_points(points, f, first_id, in_complex, 0.1, 0.0, plane, normals);
  EXPECT_EQ(given, 3u);
  EXPECT_EQ(plane, (std::vector<int>{7, 8, 14, 2, -1, -1, -1}));
  EXPECT_TRUE(normals[0].isApprox(Vec3(0, -1, 0)));
  EXPECT_TRUE(normals[1].isApprox(Vec3(1, 0, 0)));
  EXPECT_TRUE(normals[2].isApprox(Vec3(0, -1, 0)));  // out of the footprint: into the hole
  EXPECT_EQ(normals[3], Vec3::UnitZ());
  // the wall each id names is the edge's: its plane passes through the point's projection
  EXPECT_NEAR(walls[0].plane.signed_distance(Vec3(3.0, 0.0, 1.0)), 0.0, 1e-12);
  EXPECT_NEAR(walls[7].plane.signed_distance(Vec3(1.0, 1.5, 1.0)), 0.0, 1e-12);
  // a point on a plane the complex does not hold (a wall that gave way to the footprint) votes too
  plane[3] = 2;
  const std::size_t again = footprint_wall_points(points, f, first_id, {false, false, false}, 0.1, 0.0, plane, normals);
  EXPECT_EQ(again, 4u);
  EXPECT_EQ(plane[3], 7);
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

/// A vertical plane x = x0 across the box [-1, 5] x [-1, 5] x [0, 3].
ConvexPolygon upright_x(double x0, int id) {
  ConvexPolygon p;
  p.plane_id = id;
  p.plane.normal = Vec3::UnitX();
  p.plane.offset = -x0;
  p.vertices = {{x0, -1, 0}, {x0, 5, 0}, {x0, 5, 3}, {x0, -1, 3}};
  return p;
}

// keep_cells_in_prism decides most cells in doubles (cell_inside_footprint, DECISIONS #164): the cells it keeps
// are exactly those whose exact vertex average is inside, also for slivers one ulp wide on either side of the
// L's edge x = 4, whose doubles' average lies on the edge.
TEST(FootprintPrism, CellsKeptInDoublesAreTheExactAveragesCells) {
  PartitionInput in;
  in.polygons = {horizontal(1.0), upright_x(std::nextafter(4.0, 0.0), 1), upright_x(std::nextafter(4.0, 5.0), 2),
                 upright_x(2.5, 3)};
  in.points_bbox.extend({-1, -1, 0});
  in.points_bbox.extend({5, 5, 3});
  const Footprint f = l_with_hole();
  in.cuts = footprint_wall_polygons(f, -10, 10, 4);
  PartitionParams pp;
  pp.method = Partitioner::Bsp;
  const CellComplex cx = run_partition(in, pp);
  std::vector<int> exact_inside;  // the cells whose exact vertex average is inside, in order
  std::size_t slivers = 0;
  for (std::size_t c = 0; c < cx.cells.size(); ++c) {
    std::vector<std::uint32_t> ids;
    for (std::uint32_t fa : cx.cells[c].facets)
      for (std::uint32_t v : cx.facets[fa].vertices) ids.push_back(v);
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    Rational x = 0, y = 0;
    double lo = INFINITY, hi = -INFINITY;
    for (std::uint32_t v : ids) {
      x += cx.vertices[v].x;
      y += cx.vertices[v].y;
      lo = std::min(lo, cx.vertices_approx[v].x());
      hi = std::max(hi, cx.vertices_approx[v].x());
    }
    x /= static_cast<long>(ids.size());
    y /= static_cast<long>(ids.size());
    slivers += hi - lo < 1e-12;
    if (inside_footprint(x, y, f)) exact_inside.push_back(static_cast<int>(c));
  }
  ASSERT_GE(slivers, 2u) << "the slivers along x = 4 are not cells of the complex: the test shows nothing";
  std::size_t removed = 0;
  const CellComplex kept = keep_cells_in_prism(cx, f, &removed);
  ASSERT_EQ(kept.cells.size(), exact_inside.size());
  for (std::size_t k = 0; k < exact_inside.size(); ++k) {
    EXPECT_EQ(kept.cells[k].centroid, cx.cells[static_cast<std::size_t>(exact_inside[k])].centroid);
    EXPECT_EQ(kept.cells[k].facets.size(), cx.cells[static_cast<std::size_t>(exact_inside[k])].facets.size());
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

namespace {

/// A vertical wall polygon on the line x = x0, over y in [0, 6], z in [0, 5].
ConvexPolygon wall_at_x(double x0, double turn = 0.0) {
  ConvexPolygon p;
  p.plane_id = 1;
  const Vec2 n(std::cos(turn), std::sin(turn));
  p.plane.normal = Vec3(n.x(), n.y(), 0.0);
  p.plane.offset = -x0 * n.x();
  const Vec2 d(-n.y(), n.x());
  for (double z : {0.0, 5.0})
    for (double t : {0.0, 6.0}) p.vertices.emplace_back(x0 + t * d.x(), t * d.y(), z);
  std::swap(p.vertices[2], p.vertices[3]);
  return p;
}

TEST(FootprintWalls, AWallNearAnEdgeWithNothingBetweenStandsForIt) {
  const Footprint square{{{{-0.5, -0.5}, {10.5, -0.5}, {10.5, 6.5}, {-0.5, 6.5}}, {}}};
  std::vector<Vec2> roof;  // a roof over [0, 10] x [0, 6], spacing 0.25
  for (double x = 0; x <= 10; x += 0.25)
    for (double y = 0; y <= 6; y += 0.25) roof.emplace_back(x, y);
  const auto stands = [&](const ConvexPolygon& w, const std::vector<Vec2>& pts) -> bool {
    return walls_standing_for_footprint({w}, square, pts, 1.0, 10.0, 0.25, 13)[0];
  };
  EXPECT_TRUE(stands(wall_at_x(10.0), roof));        // 0.5 inside the east edge, nothing between
  EXPECT_TRUE(stands(wall_at_x(0.0), roof));         // the west edge, the other side of the wall
  EXPECT_TRUE(stands(wall_at_x(10.7), roof));        // just outside the edge
  EXPECT_FALSE(stands(wall_at_x(5.0), roof));        // far from every edge
  EXPECT_FALSE(stands(wall_at_x(10.0, 0.3), roof));  // turned 17 degrees from the edge
  ConvexPolygon flat = wall_at_x(10.0);
  flat.plane.normal = Vec3::UnitZ();
  EXPECT_FALSE(stands(flat, roof));  // not a wall
  // A lower roof 0.5 wide between the wall and the edge: the wall is a step between two roofs.
  std::vector<Vec2> annex = roof;
  for (double x = 10.25; x <= 10.5; x += 0.25)
    for (double y = 0; y <= 6; y += 0.25) annex.emplace_back(x + 0.1, y);
  EXPECT_FALSE(stands(wall_at_x(10.0), annex));
  // Turned off: nothing stands.
  const std::vector<bool> off = walls_standing_for_footprint({wall_at_x(10.0)}, square, roof, 0.0, 10.0, 0.25, 13);
  EXPECT_FALSE(off[0]);
}

/// Area of the mesh's faces that face down (its plan, for a solid without overhangs).
double plan_area(const PolygonMesh& m) {
  double area = 0;
  for (const auto& f : m.faces) {
    Vec3 n = Vec3::Zero();
    for (std::size_t i = 0; i < f.size(); ++i) n += m.vertices[f[i]].cross(m.vertices[f[(i + 1) % f.size()]]);
    if (n.z() < 0 && std::abs(n.z()) > 0.999 * n.norm()) area += -0.5 * n.z();
  }
  return area;
}

/// An airborne scan of a flat-roofed box [0, 10] x [0, 6] x [0, 6]: its roof on a 0.25 grid, its walls on a 0.5
/// grid (a steep view sees a little of them), every point moved by a small deterministic jitter.
PointCloud flat_box_scan() {
  PointCloud c;
  std::uint64_t k = 0;
  auto jitter = [&] { return 0.01 * std::sin(1.7 * static_cast<double>(++k)); };
  for (double x = 0.125; x < 10; x += 0.25)
    for (double y = 0.125; y < 6; y += 0.25) c.points.emplace_back(x + jitter(), y + jitter(), 6.0 + jitter());
  for (double z = 0.5; z < 6; z += 0.5) {
    for (double x = 0.25; x < 10; x += 0.5) {
      c.points.emplace_back(x, 0.0 + jitter(), z);
      c.points.emplace_back(x, 6.0 + jitter(), z);
    }
    for (double y = 0.25; y < 6; y += 0.5) {
      c.points.emplace_back(0.0 + jitter(), y, z);
      c.points.emplace_back(10.0 + jitter(), y, z);
    }
  }
  return c;
}

/// A cadastre and a scan differ by decimetres: with a footprint 0.3 beyond the walls on every side, the model
/// fills it to the bit of the exact prism; the rule off, the scan's walls stand 0.3 inside it.
TEST(FootprintWalls, TheModelFillsItsFootprintWhereTheWallsStandForItsEdges) {
  const PointCloud scan = flat_box_scan();
  PipelineParams pp;
  pp.scene.mode = SceneMode::Building;
  pp.scene.building.ground_z = 0.0;
  pp.footprint = {{{{-0.3, -0.3}, {10.3, -0.3}, {10.3, 6.3}, {-0.3, 6.3}}, {}}};
  const PipelineResult filled = run_pipeline(scan, pp);
  ASSERT_TRUE(filled.eval.validity.valid()) << filled.eval.validity.summary();
  EXPECT_NEAR(plan_area(filled.mesh), 10.6 * 6.6, 1e-6);
  EXPECT_GT(filled.report["counts"]["walls_left_to_footprint"].get<int>(), 0);
  pp.partition.footprint_wall_offset = 0.0;
  const PipelineResult cut = run_pipeline(scan, pp);
  ASSERT_TRUE(cut.eval.validity.valid()) << cut.eval.validity.summary();
  EXPECT_LT(plan_area(cut.mesh), 10.4 * 6.4);
}

}  // namespace
