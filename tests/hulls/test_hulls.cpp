// Stage 4 tests: speeds, levels and plane ids on a hand-made structure, the expanded hull (a partner
// segment's supporting points extend the partner plane), and the recovered bottom of the scanned box
// spanning its hole; the dump files and JSON fields.
#include "hulls/hulls.h"
#include "structure/structure.h"
#include "synth/synth.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

namespace hsr {
namespace {

double polygon_area(const ConvexPolygon& p) {
  Vec3 s = Vec3::Zero();
  for (std::size_t i = 0; i < p.vertices.size(); ++i) s += p.vertices[i].cross(p.vertices[(i + 1) % p.vertices.size()]);
  return 0.5 * std::abs(s.dot(p.plane.normal));
}

TEST(Hulls, SpeedsMapRatiosLinearly) {
  const auto s = speeds_from_ratios({0.2, 0.6, 1.0});
  ASSERT_EQ(s.size(), 3u);
  EXPECT_DOUBLE_EQ(s[0], 0.5);
  EXPECT_DOUBLE_EQ(s[1], 0.75);
  EXPECT_DOUBLE_EQ(s[2], 1.0);
  EXPECT_EQ(speeds_from_ratios({0.3, 0.3}), (std::vector<double>{1.0, 1.0}));
  EXPECT_EQ(speeds_from_ratios({0.7}), (std::vector<double>{1.0}));
}

/// Three unit squares: plane 0 z = 0 on [0,1]^2, plane 1 z = 1 on [0,1]^2, plane 2 x = 2 on y,z in [0,1]
/// (points 0..8, 9..17, 18..26 on 3x3 grids), and point 27 at (3, 0.5, 1.02): the support of a segment of
/// plane 2 whose partner is plane 1, so plane 1's expanded hull reaches (3, 0.5, 1).
struct Scene {
  PointCloud cloud;
  SceneStructure s;
};

Scene three_planes() {
  Scene sc;
  auto grid = [&](auto f) {
    std::vector<int> idx;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        idx.push_back(static_cast<int>(sc.cloud.points.size()));
        sc.cloud.points.push_back(f(0.5 * i, 0.5 * j));
      }
    return idx;
  };
  sc.s.spacing = 0.5;
  sc.s.planes.resize(3);
  sc.s.planes[0].plane = {Vec3::UnitZ(), 0.0};
  sc.s.planes[0].inliers = grid([](double a, double b) { return Vec3(a, b, 0); });
  sc.s.planes[1].plane = {Vec3::UnitZ(), -1.0};
  sc.s.planes[1].inliers = grid([](double a, double b) { return Vec3(a, b, 1); });
  sc.s.planes[2].plane = {Vec3::UnitX(), -2.0};
  sc.s.planes[2].inliers = grid([](double a, double b) { return Vec3(2, a, b); });
  sc.cloud.points.emplace_back(3, 0.5, 1.02);  // point 27
  BoundarySegment seg;
  seg.plane = 2;
  seg.support = {27};
  sc.s.planes[2].segments.push_back(seg);
  sc.s.adjacency = {{}, {}, {}};
  sc.s.second_order = {{}, {}, {}};
  return sc;
}

/// three_planes' visibility: planes 0 and 1 highly visible, 2 not.
VisibilityResult three_planes_visibility() {
  VisibilityResult vis;
  vis.ratio = {0.9, 0.7, 0.1};
  vis.ratio_sphere = vis.ratio;
  vis.highly = {true, true, false};
  vis.outward_normal = {Vec3::UnitZ(), Vec3::UnitZ(), Vec3::UnitX()};
  return vis;
}

/// three_planes' recovery: plane 2's one segment has plane 1 as its partner.
RecoveryResult three_planes_recovery() {
  RecoveryResult rec;
  rec.singular = {{}, {}, {false}};
  rec.partner = {{}, {}, {1}};
  return rec;
}

TEST(Hulls, LevelsSpeedsIdsAndExpansion) {
  const Scene sc = three_planes();
  const VisibilityResult vis = three_planes_visibility();
  RecoveryResult rec = three_planes_recovery();
  RecoveredPlane rp;  // plane y = 0 through points 0, 1, 2, 9, 10, 11 (x = 0 .. 1, z = 0 and 1)
  rp.plane = {-Vec3::UnitY(), 0.0};
  rp.support = {0, 3, 6, 9, 12, 15};
  rec.recovered.push_back(rp);

  const std::vector<ConvexPolygon> polys = run_hulls(sc.cloud, sc.s, vis, rec, {});
  ASSERT_EQ(polys.size(), 4u);
  EXPECT_EQ(polys[0].plane_id, 0);
  EXPECT_EQ(polys[0].level, 1);
  EXPECT_DOUBLE_EQ(polys[0].speed, 1.0);   // most visible of level 1
  EXPECT_DOUBLE_EQ(polys[1].speed, 0.5);   // least visible of level 1
  EXPECT_EQ(polys[2].level, 2);
  EXPECT_DOUBLE_EQ(polys[2].speed, 1.0);   // alone in level 2
  EXPECT_EQ(polys[3].plane_id, 3);         // structure.planes.size() + 0
  EXPECT_EQ(polys[3].level, 3);
  EXPECT_DOUBLE_EQ(polys[3].speed, 1.0);
  EXPECT_NEAR(polygon_area(polys[0]), 1.0, 1e-9);
  // Plane 1 expanded to x = 3 by the partner segment's support: [0,3] x [0,1] minus the corner triangles.
  double max_x = -1;
  for (const Vec3& v : polys[1].vertices) {
    max_x = std::max(max_x, v.x());
    EXPECT_NEAR(v.z(), 1.0, 1e-12);  // projected on its plane
  }
  EXPECT_NEAR(max_x, 3.0, 1e-12);
  EXPECT_NEAR(polygon_area(polys[1]), 2.0, 1e-9);  // square [0,1]^2 plus triangle to (3, 0.5)
  // Recovered plane: hull of its support (x in [0, 1], z in {0, 1}) on y = 0.
  EXPECT_NEAR(polygon_area(polys[3]), 1.0, 1e-9);
  for (const Vec3& v : polys[3].vertices) EXPECT_NEAR(v.y(), 0.0, 1e-12);

  HullsParams no_expand;
  no_expand.expand = false;
  no_expand.recovered_planes = false;
  const auto plain = run_hulls(sc.cloud, sc.s, vis, rec, no_expand);
  ASSERT_EQ(plain.size(), 3u);
  EXPECT_NEAR(polygon_area(plain[1]), 1.0, 1e-9);
}

// A room (HullsParams::expand_reach): a partner segment's points extend the partner's hull only when its boundary
// comes that near them; the paper's expansion (0) reaches any distance.
TEST(Hulls, APartnerElsewhereIsNotStretchedToASegment) {
  Scene sc = three_planes();
  for (int i : sc.s.planes[1].inliers) {  // plane 1's boundary: its grid's rim; point 27 is 2.0 from (1, 0.5, 1)
    const Vec3& q = sc.cloud.points[static_cast<std::size_t>(i)];
    if (q.x() != 0.5 || q.y() != 0.5) sc.s.planes[1].boundary_points.push_back(q);
  }
  const VisibilityResult vis = three_planes_visibility();
  RecoveryResult rec = three_planes_recovery();
  HullsParams p;
  EXPECT_NEAR(polygon_area(run_hulls(sc.cloud, sc.s, vis, rec, p)[1]), 2.0, 1e-9);  // the paper: stretched to x = 3
  p.expand_reach = 5;                                                               // 2.5 (spacing 0.5): near enough
  EXPECT_NEAR(polygon_area(run_hulls(sc.cloud, sc.s, vis, rec, p)[1]), 2.0, 1e-9);
  p.expand_reach = 3;  // 1.5: the partner is elsewhere, its hull its own points'
  EXPECT_NEAR(polygon_area(run_hulls(sc.cloud, sc.s, vis, rec, p)[1]), 1.0, 1e-9);
}

TEST(Hulls, ScannedBoxRecoveredBottomSpansTheHole) {
  const SynthScan scan = run_synth("box", {});
  StructureParams sp;
  sp.scanners = scan.scanners;
  const SceneStructure s = run_structure(scan.cloud, sp);
  const VisibilityResult vis = run_visibility(scan.cloud, s, {});
  const RecoveryResult rec = run_recovery(scan.cloud, s, {});
  const auto polys = run_hulls(scan.cloud, s, vis, rec, {});
  int level3 = 0;
  for (const ConvexPolygon& p : polys) {
    if (p.plane_id < static_cast<int>(s.planes.size())) {
      EXPECT_EQ(p.level, 1) << "box faces seen from outside are highly visible";
      continue;
    }
    ++level3;
    EXPECT_EQ(p.level, 3);
    EXPECT_GT(polygon_area(p), 0.9 * 12.0);  // the 4 x 3 bottom
    EXPECT_LT(polygon_area(p), 1.1 * 12.0);
  }
  EXPECT_EQ(level3, 1);

  const auto dir = test::scratch_dir("dump");
  write_hulls_dump(scan.cloud, s, vis, rec, polys, dir.string());
  for (const char* f : {"visibility.ply", "levels.ply", "recovered.ply"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  const std::string rec_ply = test::read_file(dir / "recovered.ply");
  EXPECT_NE(rec_ply.find("element face 1\n"), std::string::npos);
  nlohmann::json planes;
  const nlohmann::json recj = add_hulls_fields(planes, s, vis, rec, polys);
  ASSERT_EQ(planes.size(), s.planes.size());
  EXPECT_EQ(planes[0]["level"], 1);
  std::size_t singular = 0;
  for (const auto& p : planes) singular += p["singular_segments"].get<std::size_t>();
  EXPECT_EQ(singular, rec.num_singular());
  ASSERT_EQ(recj.size(), 1u);
  EXPECT_EQ(recj[0]["plane_id"], s.planes.size());
}

}  // namespace
}  // namespace hsr
