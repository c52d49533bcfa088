// Stage 3 tests: the singular-segment rule on a hand-made structure (exact thresholds), and on a scanned
// box with missing faces: exactly the edges around each hole are singular, and the faces come back.
#include "core/error.h"
#include "hulls/hulls.h"
#include "recovery/recovery.h"
#include "structure/structure.h"
#include "synth/synth.h"
#include "test_scenes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace hsr {
namespace {

/// Plane 0: z = 0 with one segment along x at y = 0 (support points on it); plane 1: y = offset tilted
/// by `tilt_deg` about z, so the line 0 ∩ 1 is at distance |offset| from the segment and `tilt_deg` off.
SceneStructure one_segment_scene(double offset, double tilt_deg, PointCloud& cloud) {
  cloud.points.clear();
  for (int i = 0; i <= 10; ++i) cloud.points.emplace_back(i * 0.1, 0, 0);
  SceneStructure s;
  s.spacing = 0.1;
  s.planes.resize(2);
  s.planes[0].plane.normal = Vec3::UnitZ();
  for (int i = 0; i <= 10; ++i) s.planes[0].inliers.push_back(i);
  BoundarySegment seg;
  seg.a = Vec3(0, 0, 0);
  seg.b = Vec3(1, 0, 0);
  seg.normal = -Vec3::UnitY();
  seg.plane = 0;
  for (int i = 0; i <= 10; ++i) seg.support.push_back(i);
  s.planes[0].segments.push_back(seg);
  s.adjacency = {{1}, {0}};
  s.second_order = {{}, {}};
  const double t = tilt_deg * M_PI / 180.0;
  IntersectionLine line;
  line.plane_a = 0;
  line.plane_b = 1;
  line.direction = Vec3(std::cos(t), std::sin(t), 0);
  line.point = Vec3(0.5, offset, 0);  // passes at |offset| (times cos t) from the centroid (0.5, 0, 0)
  line.adjacent = true;
  s.lines.push_back(line);
  return s;
}

TEST(Singular, ThresholdsOnDistanceAndAngle) {
  PointCloud cloud;
  RecoveryParams p;  // r_a = 10 deg, r_d = 5 r = 0.5
  EXPECT_FALSE(run_recovery(cloud, one_segment_scene(0.4, 0, cloud), p).singular[0][0]);
  EXPECT_TRUE(run_recovery(cloud, one_segment_scene(0.6, 0, cloud), p).singular[0][0]);
  EXPECT_FALSE(run_recovery(cloud, one_segment_scene(0.0, 8, cloud), p).singular[0][0]);
  EXPECT_TRUE(run_recovery(cloud, one_segment_scene(0.0, 12, cloud), p).singular[0][0]);
  const RecoveryResult r = run_recovery(cloud, one_segment_scene(0.1, 3, cloud), p);
  EXPECT_EQ(r.partner[0][0], 1);
  EXPECT_EQ(r.partner[1].size(), 0u);
  EXPECT_TRUE(r.recovered.empty());  // one singular segment at most: nothing to recover
}

TEST(Singular, ABuildingRoofsEdgeIsNotExplainedByALineInsideTheRoof) {
  // Building mode (DECISIONS #177): plane 1 is an upright wall y = offset whose boundary reaches the segment. At
  // offset 0.4 (4 r, within r_d = 5 r) its line runs inside the roof, behind the segment (whose outward normal is
  // -y): the roof's far side, not this edge, which stays singular and gets its own wall. A line at the edge, or
  // beyond it, still explains the segment.
  PointCloud cloud;
  const auto scene = [&cloud](double offset) {
    SceneStructure s = one_segment_scene(offset, 0, cloud);
    s.planes[1].plane.normal = Vec3::UnitY();
    s.planes[1].plane.offset = -offset;
    s.planes[1].boundary_points = {Vec3(0.5, offset, 0), Vec3(0.5, offset, -1)};
    return s;
  };
  RecoveryParams p;
  p.vertical = true;
  EXPECT_TRUE(run_recovery(cloud, scene(0.4), p).singular[0][0]) << "the line 4 r inside the roof";
  EXPECT_TRUE(run_recovery(cloud, scene(0.25), p).singular[0][0]) << "2.5 r inside";
  EXPECT_FALSE(run_recovery(cloud, scene(0.15), p).singular[0][0]) << "1.5 r inside: the roof's edge";
  EXPECT_FALSE(run_recovery(cloud, scene(-0.4), p).singular[0][0]) << "beyond the segment";
  EXPECT_EQ(run_recovery(cloud, scene(-0.4), p).partner[0][0], 1);
  p.partner_max_behind = -1;  // not tested: r_d alone (before #177)
  EXPECT_FALSE(run_recovery(cloud, scene(0.4), p).singular[0][0]);
  p.vertical = false;  // other scenes: r_d alone
  p.partner_max_behind = 2;
  EXPECT_FALSE(run_recovery(cloud, scene(0.4), p).singular[0][0]);
}

double angle_deg(const Vec3& a, const Vec3& b) {
  return std::acos(std::min(1.0, std::abs(a.dot(b)))) * 180.0 / M_PI;
}

/// The synth box (4 x 3 x 2 on z = 0, bottom never scanned), optionally without the points of the top.
struct BoxRun {
  SynthScan scan;
  PointCloud cloud;
  SceneStructure s;
  RecoveryResult rec;
};

BoxRun run_box(bool remove_top) {
  BoxRun b;
  SynthParams sp;
  sp.noise = 0.0005;
  b.scan = run_synth("box", sp);
  b.cloud.origin = b.scan.cloud.origin;
  for (std::size_t i = 0; i < b.scan.cloud.size(); ++i) {
    const Plane& truth = b.scan.planes[static_cast<std::size_t>(b.scan.point_plane[i])].plane;
    if (remove_top && truth.normal.z() > 0.9) continue;
    b.cloud.points.push_back(b.scan.cloud.points[i]);
    b.cloud.normals.push_back(b.scan.cloud.normals[i]);
  }
  StructureParams p;
  p.scanners = b.scan.scanners;
  b.s = run_structure(b.cloud, p);
  b.rec = run_recovery(b.cloud, b.s, {});
  return b;
}

TEST(Singular, BoxWithoutBottomExactlyTheFourBottomEdges) {
  const BoxRun b = run_box(false);
  ASSERT_EQ(b.s.planes.size(), 5u);  // four walls and the top
  int singular = 0;
  for (std::size_t i = 0; i < b.s.planes.size(); ++i)
    for (std::size_t j = 0; j < b.s.planes[i].segments.size(); ++j) {
      const BoundarySegment& seg = b.s.planes[i].segments[j];
      const bool on_hole = std::abs(seg.a.z()) < 3 * b.s.spacing && std::abs(seg.b.z()) < 3 * b.s.spacing;
      EXPECT_EQ(b.rec.singular[i][j], on_hole) << "plane " << i << " segment " << j << " z " << seg.a.z() << " "
                                               << seg.b.z();
      singular += b.rec.singular[i][j];
    }
  EXPECT_EQ(singular, 4);
}

TEST(Recovery, BoxGetsItsBottomBack) {
  const BoxRun b = run_box(false);
  ASSERT_EQ(b.rec.recovered.size(), 1u);
  const RecoveredPlane& rp = b.rec.recovered[0];
  EXPECT_LT(angle_deg(rp.plane.normal, Vec3::UnitZ()), 3.0);
  EXPECT_LT(std::abs(rp.plane.offset), 2 * b.s.spacing);  // z = 0
  EXPECT_EQ(rp.segments.size(), 4u);
  EXPECT_FALSE(rp.support.empty());
}

TEST(Recovery, BoxWithoutTopAndBottomGetsBothBack) {
  const BoxRun b = run_box(true);
  ASSERT_EQ(b.s.planes.size(), 4u);
  // Singular exactly on the top and bottom edges (an edge may come in more than one segment).
  for (std::size_t i = 0; i < b.s.planes.size(); ++i)
    for (std::size_t j = 0; j < b.s.planes[i].segments.size(); ++j) {
      const BoundarySegment& seg = b.s.planes[i].segments[j];
      auto at = [&](double z) {
        return std::abs(seg.a.z() - z) < 3 * b.s.spacing && std::abs(seg.b.z() - z) < 3 * b.s.spacing;
      };
      EXPECT_EQ(b.rec.singular[i][j], at(0) || at(2)) << "plane " << i << " segment " << j;
    }
  EXPECT_GE(b.rec.num_singular(), 8u);
  ASSERT_EQ(b.rec.recovered.size(), 2u);
  bool top = false, bottom = false;
  for (const RecoveredPlane& rp : b.rec.recovered) {
    EXPECT_LT(angle_deg(rp.plane.normal, Vec3::UnitZ()), 3.0);
    const double z = -rp.plane.offset / rp.plane.normal.z();
    top |= std::abs(z - 2.0) < 2 * b.s.spacing;
    bottom |= std::abs(z) < 2 * b.s.spacing;
  }
  EXPECT_TRUE(top);
  EXPECT_TRUE(bottom);
}

/// Recovery of a hand-made room: nothing with the defaults (a room's rules are off), then with `rule` on.
RecoveryResult recovered_with(const RectScene& sc, bool RecoveryParams::*rule) {
  RecoveryParams p;
  EXPECT_TRUE(run_recovery(sc.cloud, sc.s, p).recovered.empty());  // off by default
  p.*rule = true;
  return run_recovery(sc.cloud, sc.s, p);
}

TEST(Recovery, ARoomGetsALevelTopOverFurnitureWhoseTopNoScannerSaw) {
  RectScene sc;
  sc.s.spacing = 0.05;  // r_d = 0.25
  const int floor = sc.add({0, 0, 0}, {10, 10, 0}, Vec3::UnitZ());
  // A box 1 x 1, 0.8 high, its four sides scanned, its top not.
  std::vector<int> box{sc.add({1, 1, 0}, {2, 1, 0.8}, -Vec3::UnitY()), sc.add({2, 1, 0}, {2, 2, 0.8}, Vec3::UnitX()),
                       sc.add({1, 2, 0}, {2, 2, 0.8}, Vec3::UnitY()), sc.add({1, 1, 0}, {1, 2, 0.8}, -Vec3::UnitX())};
  // A cabinet 1.2 high whose top was scanned: nothing to add.
  const int cab_side = sc.add({5, 5, 0}, {6, 5, 1.2}, -Vec3::UnitY());
  const int cab_top = sc.add({5, 5, 1.2}, {6, 6, 1.2}, Vec3::UnitZ());
  // Two adjacent panels whose tops are 0.5 apart (more than r_d): two caps, not one.
  const int low = sc.add({8, 1, 0}, {9, 1, 0.5}, -Vec3::UnitY());
  const int high = sc.add({9, 1, 0}, {9, 2, 1.0}, Vec3::UnitX());
  for (std::size_t i = 0; i < box.size(); ++i) {
    sc.link(floor, box[i]);
    sc.link(box[i], box[(i + 1) % box.size()]);
  }
  sc.link(floor, cab_side);
  sc.link(cab_side, cab_top);
  sc.link(floor, low);
  sc.link(floor, high);
  sc.link(low, high);
  sc.s.second_order.assign(sc.s.planes.size(), {});

  const RecoveryResult r = recovered_with(sc, &RecoveryParams::level_caps);
  ASSERT_EQ(r.recovered.size(), 3u);
  std::vector<int> box_sorted = box;
  std::sort(box_sorted.begin(), box_sorted.end());
  const std::vector<std::vector<int>> want_caps{box_sorted, {low}, {high}};
  const double want_z[] = {0.8, 0.5, 1.0};
  for (std::size_t c = 0; c < 3; ++c) {
    const RecoveredPlane& cap = r.recovered[c];
    EXPECT_EQ(cap.caps, want_caps[c]) << "cap " << c;
    EXPECT_EQ(cap.plane.normal, Vec3::UnitZ());
    EXPECT_NEAR(-cap.plane.offset, want_z[c], 1e-12) << "cap " << c;
    EXPECT_TRUE(cap.segments.empty());
    ASSERT_FALSE(cap.support.empty());
    EXPECT_TRUE(std::is_sorted(cap.support.begin(), cap.support.end()));
    for (int i : cap.support) EXPECT_NEAR(sc.cloud.points[static_cast<std::size_t>(i)].z(), want_z[c], sc.s.spacing);
  }
  // The box's cap is supported by the top rows of all four sides: it spans the box.
  double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
  for (int i : r.recovered[0].support) {
    const Vec3& q = sc.cloud.points[static_cast<std::size_t>(i)];
    x0 = std::min(x0, q.x()), x1 = std::max(x1, q.x()), y0 = std::min(y0, q.y()), y1 = std::max(y1, q.y());
  }
  EXPECT_DOUBLE_EQ(x0, 1.0);
  EXPECT_DOUBLE_EQ(x1, 2.0);
  EXPECT_DOUBLE_EQ(y0, 1.0);
  EXPECT_DOUBLE_EQ(y1, 2.0);
}

TEST(Recovery, ARoomGetsAnUprightSideUnderATopsUnseenEdge) {
  RectScene sc;
  sc.s.spacing = 0.05;  // r_d = 0.25, min_wall_length 4 r = 0.2
  sc.add({0, 0, 0}, {10, 10, 0}, Vec3::UnitZ());                   // the floor: not raised, its edges nothing
  const int table = sc.add({5, 7, 0.7}, {7, 8, 0.7}, Vec3::UnitZ());  // a desk's top; its side at y = 7 unseen
  DetectedPlane& top = sc.s.planes[static_cast<std::size_t>(table)];
  BoundarySegment edge, stub;
  edge.a = Vec3(5, 7, 0.7), edge.b = Vec3(7, 7, 0.7), edge.normal = -Vec3::UnitY(), edge.plane = table;
  for (int i : top.inliers)
    if (sc.cloud.points[static_cast<std::size_t>(i)].y() == 7.0) edge.support.push_back(i);
  stub = edge;  // an edge shorter than min_wall_length: no side
  stub.a = Vec3(7, 7.9, 0.7), stub.b = Vec3(7, 8.0, 0.7), stub.normal = Vec3::UnitX();
  top.segments = {edge, stub};
  sc.s.adjacency.assign(sc.s.planes.size(), {});
  sc.s.second_order.assign(sc.s.planes.size(), {});

  const RecoveryResult r = recovered_with(sc, &RecoveryParams::level_sides);
  ASSERT_EQ(r.recovered.size(), 1u);
  const RecoveredPlane& side = r.recovered[0];
  EXPECT_NEAR(side.plane.normal.dot(-Vec3::UnitY()), 1.0, 1e-12);  // facing out of the desk, upright
  EXPECT_NEAR(side.plane.offset, 7.0, 1e-9);                       // y = 7
  EXPECT_EQ(side.segments, (std::vector<SegmentRef>{{table, 0}}));
  EXPECT_EQ(side.support, edge.support);
  ASSERT_EQ(side.reach.size(), 4u);  // the edge's ends, at the top and on the floor
  double z0 = 1e9, z1 = -1e9, x0 = 1e9, x1 = -1e9;
  for (const Vec3& q : side.reach) {
    EXPECT_NEAR(q.y(), 7.0, 1e-9);
    z0 = std::min(z0, q.z()), z1 = std::max(z1, q.z()), x0 = std::min(x0, q.x()), x1 = std::max(x1, q.x());
  }
  EXPECT_DOUBLE_EQ(z0, 0.0);
  EXPECT_DOUBLE_EQ(z1, 0.7);
  EXPECT_DOUBLE_EQ(x0, 5.0);
  EXPECT_DOUBLE_EQ(x1, 7.0);
}

// A room's pieces get their boxes where no plane covers a face: a crate no plane holds all five faces, a desk
// top seen alone its four sides (one of its inliers lying far off); a plane reaching beyond its piece with a
// plane's worth of points, a handful of stray points and the enclosure's own points get none.
/// A room of a hand-made scene whose planes have no adjacency: `floor` its enclosure (run_recovery's `enclosure`).
std::vector<bool> room_of(RectScene& sc, int floor) {
  sc.s.adjacency.assign(sc.s.planes.size(), {});
  sc.s.second_order.assign(sc.s.planes.size(), {});
  std::vector<bool> enclosure(sc.s.planes.size(), false);
  enclosure[static_cast<std::size_t>(floor)] = true;
  return enclosure;
}

TEST(Recovery, ARoomsPiecesGetTheirBoxesWhereNoPlaneCoversAFace) {
  RectScene sc;
  sc.s.spacing = 0.05;  // r_d = 0.25; alpha radius 3 r
  sc.s.alpha_radius = 0.15;
  const int floor = sc.add({0, 0, 0}, {10, 10, 0}, Vec3::UnitZ());
  const int desk = sc.add({5, 5, 0.7}, {6, 6, 0.7}, Vec3::UnitZ());  // a desk's top, alone
  const int panel = sc.add({8, 5, 0}, {8, 5.5, 0.5}, Vec3::UnitX());  // a panel, its plane also 2 m away
  auto loose = [&](Vec3 q, Vec3 n, int plane = -1) {  // a point on `plane` (-1: none)
    sc.cloud.points.push_back(q);
    sc.cloud.normals.push_back(n);
    sc.s.point_plane.push_back(plane);
    if (plane >= 0) sc.s.planes[static_cast<std::size_t>(plane)].inliers.push_back(static_cast<int>(sc.cloud.points.size()) - 1);
    return static_cast<int>(sc.cloud.points.size()) - 1;
  };
  for (int j = 0; j <= 10; ++j)
    for (int k = 0; k <= 10; ++k) loose(Vec3(8, 7.5 + 0.05 * j, 0.05 * k), Vec3::UnitX(), panel);
  // The crate: 0.4 x 0.3 in plan, 0.35 high, turned 30 degrees; its top and two sides scanned, from z = 0.05.
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  const Vec3 u(c, s, 0), v(-s, c, 0), origin(2, 2, 0);
  std::vector<int> crate;
  for (int i = 0; i <= 8; ++i)
    for (int j = 0; j <= 6; ++j) crate.push_back(loose(origin + 0.05 * i * u + 0.05 * j * v + Vec3(0, 0, 0.35), Vec3::UnitZ()));
  for (int i = 0; i <= 8; ++i)
    for (int k = 1; k <= 6; ++k) crate.push_back(loose(origin + 0.05 * i * u + Vec3(0, 0, 0.05 * k), -v));
  for (int j = 0; j <= 6; ++j)
    for (int k = 1; k <= 6; ++k) crate.push_back(loose(origin + 0.4 * u + 0.05 * j * v + Vec3(0, 0, 0.05 * k), u));
  std::vector<int> under_desk;  // under the desk's edge down to near the floor, on no plane: it stands there
  for (int k = 1; k <= 13; ++k) under_desk.push_back(loose(Vec3(5.5, 4.95, 0.7 - 0.05 * k), -Vec3::UnitY()));
  for (int k = 0; k < 5; ++k) loose(Vec3(1, 8, 0.1 + 0.05 * k), Vec3::UnitX());  // a few stray points
  loose(Vec3(9, 1, 0.7), Vec3::UnitZ(), desk);  // one inlier of the desk's top far off: no surface there (#74)
  const std::vector<bool> enclosure = room_of(sc, floor);

  RecoveryParams p;
  p.piece_boxes = true;
  EXPECT_TRUE(run_recovery(sc.cloud, sc.s, RecoveryParams{}, enclosure).recovered.empty());  // off by default
  const RecoveryResult r = run_recovery(sc.cloud, sc.s, p, enclosure);
  ASSERT_EQ(r.recovered.size(), 9u);  // the desk's four sides, the crate's top and four sides; no bottoms
  std::vector<int> crate_support;
  int tops = 0;
  for (std::size_t q = 0; q < r.recovered.size(); ++q) {
    const RecoveredPlane& face = r.recovered[q];
    const bool of_desk = q < 4;  // pieces in order of their smallest point: the desk's plane comes first
    EXPECT_EQ(face.piece, of_desk ? 0 : 1);
    EXPECT_EQ(face.caps, of_desk ? std::vector<int>{desk} : std::vector<int>{});
    EXPECT_TRUE(face.segments.empty());
    ASSERT_EQ(face.reach.size(), 4u);
    double z0 = 1e9, z1 = -1e9;
    for (const Vec3& corner : face.reach) {
      EXPECT_NEAR(face.plane.signed_distance(corner), 0.0, 1e-12);
      z0 = std::min(z0, corner.z()), z1 = std::max(z1, corner.z());
    }
    EXPECT_TRUE(std::is_sorted(face.support.begin(), face.support.end()));
    EXPECT_NEAR(z0, face.plane.normal.z() > 0.5 ? 0.35 : 0.0, 1e-12);  // sides down to the floor, not to z = 0.05
    EXPECT_NEAR(z1, of_desk ? 0.7 : 0.35, 1e-12);
    if (of_desk) {  // sides along the desk's extent, the one over the loose points at y = 4.95 holding them
      EXPECT_NEAR(face.plane.normal.z(), 0.0, 1e-12);
      EXPECT_EQ(face.support, face.plane.normal.y() < -0.5 ? under_desk : std::vector<int>{});
      continue;
    }
    crate_support.insert(crate_support.end(), face.support.begin(), face.support.end());
    if (face.plane.normal.z() > 0.5) {
      ++tops;
      continue;
    }
    // Each side is one of the crate's: along u or v, at its extent, facing out of it.
    const Vec3 mid = 0.25 * (face.reach[0] + face.reach[1] + face.reach[2] + face.reach[3]);
    const Vec3 centre = origin + 0.2 * u + 0.15 * v + Vec3(0, 0, mid.z());
    EXPECT_GT(face.plane.normal.dot(mid - centre), 0.14);
    EXPECT_GT(std::max(std::abs(face.plane.normal.dot(u)), std::abs(face.plane.normal.dot(v))), 1 - 1e-9);
    EXPECT_NEAR(std::abs(face.plane.signed_distance(centre)), std::abs(face.plane.normal.dot(u)) > 0.5 ? 0.2 : 0.15, 1e-9);
  }
  EXPECT_EQ(tops, 1);
  std::sort(crate_support.begin(), crate_support.end());
  EXPECT_EQ(crate_support, crate);  // every crate point votes on one face
  // The faces of a box are adjacent to each other and to the piece's planes (the partition stops each at the
  // others' lines): the desk's 4 faces 6 pairs and 4 with its top, the crate's 5 faces 10 pairs.
  const int first = static_cast<int>(sc.s.planes.size());
  const std::vector<std::pair<int, int>> pairs = polygon_adjacency(sc.s, r);
  EXPECT_EQ(pairs.size(), 20u);
  for (const auto& [a, b] : pairs) EXPECT_TRUE(a == desk ? b >= first && b < first + 4 : a >= first) << a << " " << b;
  // Fewer points than min_piece_points: no box (the crate's); the desk keeps its sides.
  p.min_piece_points = static_cast<int>(crate.size()) + 1;
  const RecoveryResult fewer = run_recovery(sc.cloud, sc.s, p, enclosure);
  ASSERT_EQ(fewer.recovered.size(), 4u);
  for (std::size_t q = 0; q < 4; ++q) EXPECT_EQ(fewer.recovered[q].plane.normal, r.recovered[q].plane.normal);
}

// An open shelf's board seen edge-on (RecoveryParams::edge_boards, DECISIONS #217): a 1 m shelf, its back's inner face
// (facing its open front) and a side panel its planes; a row of three points facing the front at 1.17 m along its
// front edge, 0.36 m before the back and farther than the alpha radius from every other point (in no piece of its
// own size): a board there, two level faces of the shelf's piece half a board_thickness over and under the row,
// from the front back to the box's back. A lone point at 1.5 m, a row of three one above the other at 0.6 m (a side
// panel's edge) and a row facing the front a spacing before the back (no board's depth) make none; nor does the
// row with the rule off.
TEST(Recovery, AnOpenShelfsBoardSeenEdgeOnGetsItsSlab) {
  RectScene sc;
  sc.s.spacing = 0.05;  // r; alpha radius 3 r
  sc.s.alpha_radius = 0.15;
  const int floor = sc.add({0, 0, 0}, {10, 10, 0}, Vec3::UnitZ());
  sc.add({2, 2.36, 0.1}, {3, 2.36, 1.8}, -Vec3::UnitY());  // the back's inner face, seen through the front
  sc.add({2, 2.0, 0}, {2, 2.36, 1.8}, -Vec3::UnitX());    // a side panel, seen from outside: the front is y = 2
  auto loose = [&](Vec3 q) {
    sc.cloud.points.push_back(q);
    sc.cloud.normals.push_back(-Vec3::UnitY());
    sc.s.point_plane.push_back(-1);
  };
  for (const double x : {2.3, 2.55, 2.8}) loose(Vec3(x, 2.0, 1.17 + 0.002 * (x - 2.3)));  // the board's front edge
  loose(Vec3(2.5, 2.0, 1.5));                                                          // one point: no row
  for (const double z : {0.58, 0.6, 0.62}) loose(Vec3(2.98, 2.0, z));                  // one place along it: no row
  for (const double x : {2.3, 2.55, 2.8}) loose(Vec3(x, 2.33, 0.9));                   // 3 cm before the back
  const std::vector<bool> enclosure = room_of(sc, floor);
  RecoveryParams p;
  p.piece_boxes = true;
  const auto boards = [&](const RecoveryResult& r) {  // the level faces of a piece between the floor and its top
    std::vector<const RecoveredPlane*> out;
    for (const RecoveredPlane& f : r.recovered)
      if (f.piece >= 0 && std::abs(f.plane.normal.z()) == 1.0 && std::abs(f.plane.offset) > 0.05 && std::abs(f.plane.offset) < 1.7)
        out.push_back(&f);
    return out;
  };
  EXPECT_TRUE(boards(run_recovery(sc.cloud, sc.s, p, enclosure)).empty()) << "off: no board";
  p.edge_boards = true;
  const RecoveryResult r = run_recovery(sc.cloud, sc.s, p, enclosure);
  const std::vector<const RecoveredPlane*> b = boards(r);
  ASSERT_EQ(b.size(), 2u);
  const double z = (3 * 1.17 + 0.002 * 0.75) / 3, half = 0.5 * p.board_thickness * sc.s.spacing;
  for (const RecoveredPlane* f : b) {
    EXPECT_NEAR(f->plane.normal.z() > 0 ? -f->plane.offset : f->plane.offset, f->plane.normal.z() > 0 ? z + half : z - half, 1e-9);
    double y0 = 1e9, y1 = -1e9, x0 = 1e9, x1 = -1e9;
    for (const Vec3& c : f->reach) y0 = std::min(y0, c.y()), y1 = std::max(y1, c.y()), x0 = std::min(x0, c.x()), x1 = std::max(x1, c.x());
    EXPECT_NEAR(y0, 2.0, 1e-9) << "from the front";
    EXPECT_GE(y1, 2.36 - 1e-9) << "to the back";
    EXPECT_NEAR(x0, 2.0, 1e-9) << "across the shelf";
    EXPECT_NEAR(x1, 3.0, 1e-9);
  }
  EXPECT_EQ(b[0]->piece, b[1]->piece);
  p.edge_board_min_points = 4;
  EXPECT_TRUE(boards(run_recovery(sc.cloud, sc.s, p, enclosure)).empty()) << "three points are no row of four";
}

// A boxed piece's box stands for the planes its own segments would recover: one grown across the corner of its
// alpha shapes (facing along none of the box's faces) is left out, one along a face is kept.
TEST(Recovery, APlaneAcrossABoxedPiecesCornerIsLeftOut) {
  RectScene sc;
  sc.s.spacing = 0.05;  // r_d = 0.25
  sc.s.alpha_radius = 0.15;
  const int floor = sc.add({0, 0, 0}, {10, 10, 0}, Vec3::UnitZ());
  const int top = sc.add({2, 2, 0.6}, {3, 3, 0.6}, Vec3::UnitZ());  // a cabinet's top and front
  const int front = sc.add({2, 2, 0}, {3, 2, 0.6}, -Vec3::UnitY());
  sc.link(top, front);
  sc.s.second_order.assign(sc.s.planes.size(), {});
  // Singular segments: at the corner (3, 2) a short diagonal cut on each plane, and along y = 2.9 on the top and
  // near the same line on the front's end (both facing +y, as a missing back would).
  auto segment = [&](int plane, Vec3 a, Vec3 b, Vec3 normal) {
    BoundarySegment seg;
    seg.a = a, seg.b = b, seg.normal = normal.normalized(), seg.plane = plane;
    for (int i : sc.s.planes[static_cast<std::size_t>(plane)].inliers)
      if ((sc.cloud.points[static_cast<std::size_t>(i)] - 0.5 * (a + b)).norm() < 0.08) seg.support.push_back(i);
    sc.s.planes[static_cast<std::size_t>(plane)].segments.push_back(seg);
  };
  segment(top, {2.9, 2.0, 0.6}, {3.0, 2.1, 0.6}, {1, -1, 0});
  segment(front, {2.95, 2.0, 0.1}, {2.95, 2.0, 0.5}, {1, -1, 0});
  std::vector<bool> enclosure(sc.s.planes.size(), false);
  enclosure[static_cast<std::size_t>(floor)] = true;

  RecoveryParams p;
  const RecoveryResult grown = run_recovery(sc.cloud, sc.s, p, enclosure);
  ASSERT_EQ(grown.recovered.size(), 1u);  // the paper's rule: two segments of two planes make a plane
  EXPECT_LT(std::abs(grown.recovered[0].plane.normal.dot(Vec3::UnitX())), 0.8);  // across the corner
  p.piece_boxes = true;
  const RecoveryResult boxed = run_recovery(sc.cloud, sc.s, p, enclosure);
  for (const RecoveredPlane& rp : boxed.recovered) EXPECT_GE(rp.piece, 0) << "the corner's plane is left out";
  EXPECT_EQ(boxed.recovered.size(), 3u);  // the box's back and two ends; its top and front are the planes'
}

// One surface, one plane: a level cap within a spacing of a detected plane, over that plane's extent, is left
// out; a cap farther than a spacing from such a plane, or beside its extent, stays.
TEST(Recovery, ARecoveredPlaneOnASurfaceAPlaneStandsForIsLeftOut) {
  RectScene sc;
  sc.s.spacing = 0.05;  // r = 0.05, r_d = 0.25
  const int floor = sc.add({0, 0, 0}, {10, 10, 0}, Vec3::UnitZ());
  // Three boxes 1 x 1, 0.8 high, four sides scanned; a level plane (its top rows, not adjacent to them) found
  // 3 cm under the first's top, 20 cm under the second's, and 3 cm under a top beside the third.
  const double x0[] = {1, 4, 7};
  const double plane_z[] = {0.77, 0.6, 0.77};
  const double plane_x[] = {1.2, 4.2, 8.5};  // the third's lies beside its box (x 7 to 8)
  for (int b = 0; b < 3; ++b) {
    const double x = x0[b];
    const std::vector<int> box{sc.add({x, 1, 0}, {x + 1, 1, 0.8}, -Vec3::UnitY()), sc.add({x + 1, 1, 0}, {x + 1, 2, 0.8}, Vec3::UnitX()),
                               sc.add({x, 2, 0}, {x + 1, 2, 0.8}, Vec3::UnitY()), sc.add({x, 1, 0}, {x, 2, 0.8}, -Vec3::UnitX())};
    for (std::size_t i = 0; i < box.size(); ++i) {
      sc.link(floor, box[i]);
      sc.link(box[i], box[(i + 1) % box.size()]);
    }
    sc.add({plane_x[b], 1.2, plane_z[b]}, {plane_x[b] + 0.6, 1.8, plane_z[b]}, Vec3::UnitZ());
  }
  sc.s.second_order.assign(sc.s.planes.size(), {});
  sc.s.adjacency.resize(sc.s.planes.size());

  RecoveryParams p;
  p.level_caps = true;
  const RecoveryResult caps = run_recovery(sc.cloud, sc.s, p);
  ASSERT_EQ(caps.recovered.size(), 3u);  // a cap at 0.8 over each box
  EXPECT_EQ(caps.covered, 0u);
  p.one_plane_per_surface = true;
  const RecoveryResult one = run_recovery(sc.cloud, sc.s, p);
  EXPECT_EQ(one.covered, 1u);
  ASSERT_EQ(one.recovered.size(), 2u);  // the second's and the third's
  EXPECT_EQ(one.recovered[0].caps, caps.recovered[1].caps);
  EXPECT_EQ(one.recovered[1].caps, caps.recovered[2].caps);
}

// Walls around a roof the model left out (run_recovery's walls_around_roofs, DECISIONS #159): a flat roof with a
// 2 x 2.5 m part on it sloping 0.2 m a metre, turned 20 degrees, no boundary segment anywhere. Without the rule no
// wall; with it four, the sides of the part's rectangle: upright, facing out, each through the outermost inlier on
// its side with every inlier inside, adjacent to the part (caps), reaching a spacing above its highest corner.
// Turned onto the main direction when within snap_deg of it.
TEST(Recovery, ARoofTheModelLeftOutGetsFourWallsAroundIt) {
  PointCloud cloud;
  SceneStructure s;
  s.spacing = 0.25;
  s.planes.resize(2);
  for (int i = 0; i <= 40; ++i)
    for (int j = 0; j <= 40; ++j) {
      s.planes[0].inliers.push_back(static_cast<int>(cloud.size()));
      cloud.points.emplace_back(i * 0.25, j * 0.25, 5.0);
    }
  s.planes[0].plane.normal = Vec3::UnitZ();
  s.planes[0].plane.offset = -5.0;
  const double turn = 20.0 * M_PI / 180.0;
  const Vec2 e0(std::cos(turn), std::sin(turn)), e1(-e0.y(), e0.x()), c(4.0, 4.0);
  for (int i = 0; i <= 8; ++i)
    for (int j = 0; j <= 10; ++j) {
      const double u = -1.0 + i * 0.25, v = -1.25 + j * 0.25;
      const Vec2 xy = c + u * e0 + v * e1;
      s.planes[1].inliers.push_back(static_cast<int>(cloud.size()));
      cloud.points.emplace_back(xy.x(), xy.y(), 6.0 + 0.2 * u);
    }
  // z = 6 + 0.2 (xy - c).e0: normal along (-0.2 e0, 1)
  const Vec3 n = Vec3(-0.2 * e0.x(), -0.2 * e0.y(), 1.0).normalized();
  s.planes[1].plane.normal = n;
  s.planes[1].plane.offset = -n.dot(Vec3(c.x(), c.y(), 6.0));
  s.adjacency = {{1}, {0}};
  s.second_order = {{}, {}};
  s.point_plane.assign(cloud.size(), 0);
  for (int i : s.planes[1].inliers) s.point_plane[static_cast<std::size_t>(i)] = 1;

  RecoveryParams p;
  p.vertical = true;
  EXPECT_TRUE(run_recovery(cloud, s, p).recovered.empty());
  const RecoveryResult res = run_recovery(cloud, s, p, {}, {1});
  ASSERT_EQ(res.recovered.size(), 4u);
  int along_e0 = 0;
  for (const RecoveredPlane& w : res.recovered) {
    EXPECT_EQ(w.plane.normal.z(), 0.0);
    EXPECT_NEAR(w.plane.normal.norm(), 1.0, 1e-12);
    const Vec2 wn = w.plane.normal.head<2>();
    EXPECT_NEAR(std::abs(wn.dot(e0)) + std::abs(wn.dot(e1)), 1.0, 1e-6) << "a side of the turned rectangle";
    along_e0 += std::abs(wn.dot(e0)) > 0.5;
    EXPECT_EQ(w.caps, std::vector<int>{1});
    ASSERT_EQ(w.support.size(), 1u);
    EXPECT_NEAR(w.plane.signed_distance(cloud.points[static_cast<std::size_t>(w.support[0])]), 0.0, 1e-9);
    for (int i : s.planes[1].inliers) EXPECT_LT(w.plane.signed_distance(cloud.points[static_cast<std::size_t>(i)]), 1e-9);
    ASSERT_EQ(w.reach.size(), 2u);
    for (const Vec3& q : w.reach) {
      EXPECT_NEAR(q.z(), 6.2 + 0.25, 1e-6) << "a spacing above the highest corner";
      EXPECT_NEAR(w.plane.signed_distance(q), 0.0, 1e-9);
    }
  }
  EXPECT_EQ(along_e0, 2);
  p.main_direction = 18.0 * M_PI / 180.0;  // within snap_deg (5): the walls turn onto it
  for (const RecoveredPlane& w : run_recovery(cloud, s, p, {}, {1}).recovered) {
    const double a = std::atan2(w.plane.normal.y(), w.plane.normal.x());
    EXPECT_NEAR(std::remainder(a - p.main_direction, M_PI / 2.0), 0.0, 1e-9);
  }
  EXPECT_THROW(run_recovery(cloud, s, p, {}, {2}), Error);
}

// A side of a roof's rectangle on the plane of a wall already there takes that wall's plane
// (RecoveryParams::around_side_same_wall, DECISIONS #191): three flat roof parts in a row at three heights, walls
// around each. The second's westmost points lie on the first's eastmost line but for a rounding error (1e-12 m):
// its west side takes the first's east plane exactly (coefficients negated: it faces the other way), one plane in
// the partition and no slab 1e-12 m thin. The third's west side is 10 cm from the second's east side: its own.
// With the rule off (-1) the second's west side keeps its own plane; at 0.1 r (2.5 cm) a side 2 cm off is taken.
TEST(Recovery, ARoofsSideOnAWallAlreadyThereTakesItsPlane) {
  const auto scene = [](double second_x0, PointCloud& cloud, SceneStructure& s) {
    s.spacing = 0.25;
    const double x0[] = {0.0, second_x0, 3.6};  // the parts' westmost points; 8 points 0.25 m apart: 1.75 m wide
    for (int part = 0; part < 3; ++part) {
      DetectedPlane pl;
      pl.plane.normal = Vec3::UnitZ();
      pl.plane.offset = -5.0 - part;
      for (int i = 0; i < 8; ++i)
        for (int j = 0; j <= 8; ++j) {
          pl.inliers.push_back(static_cast<int>(cloud.size()));
          cloud.points.emplace_back(x0[part] + i * 0.25, j * 0.25, 5.0 + part);
        }
      s.planes.push_back(pl);
    }
    s.adjacency.assign(3, {});
    s.second_order.assign(3, {});
    s.point_plane.assign(cloud.size(), 0);
    for (int k = 0; k < 3; ++k)
      for (int i : s.planes[static_cast<std::size_t>(k)].inliers) s.point_plane[static_cast<std::size_t>(i)] = k;
  };
  // the side of part k facing +x (east) or -x (west)
  const auto side = [](const RecoveryResult& res, int k, double facing) -> const RecoveredPlane& {
    for (const RecoveredPlane& w : res.recovered)
      if (w.caps == std::vector<int>{k} && w.plane.normal.x() * facing > 0.5) return w;
    throw std::runtime_error("no such side");
  };
  PointCloud cloud;
  SceneStructure s;
  scene(1.75 + 1e-12, cloud, s);
  RecoveryParams p;
  p.vertical = true;
  const RecoveryResult res = run_recovery(cloud, s, p, {}, {0, 1, 2});
  ASSERT_EQ(res.recovered.size(), 12u);
  EXPECT_EQ(side(res, 1, -1).plane.normal, Vec3(-side(res, 0, 1).plane.normal)) << "the first's east plane";
  EXPECT_EQ(side(res, 1, -1).plane.offset, -side(res, 0, 1).plane.offset);
  EXPECT_NEAR(side(res, 2, -1).plane.signed_distance(Vec3(3.6, 1, 7)), 0.0, 1e-9) << "10 cm off: its own";
  EXPECT_NEAR(side(res, 1, 1).plane.signed_distance(Vec3(3.5, 1, 6)), 0.0, 1e-9);
  p.around_side_same_wall = -1;
  const RecoveryResult off = run_recovery(cloud, s, p, {}, {0, 1, 2});
  ASSERT_EQ(off.recovered.size(), 12u);
  EXPECT_NE(side(off, 1, -1).plane.offset, -side(off, 0, 1).plane.offset) << "the test no longer shows the cause";
  PointCloud cloud2;
  SceneStructure s2;
  scene(1.77, cloud2, s2);
  p.around_side_same_wall = 0.1;
  const RecoveryResult wide = run_recovery(cloud2, s2, p, {}, {0, 1, 2});
  EXPECT_EQ(side(wide, 1, -1).plane.offset, -side(wide, 0, 1).plane.offset) << "2 cm, under 0.1 r";
  EXPECT_NE(side(wide, 2, -1).plane.offset, -side(wide, 1, 1).plane.offset) << "8 cm, over 0.1 r";
  p.around_side_same_wall = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(run_recovery(cloud, s, p, {}, {0}), Error);
}

}  // namespace
}  // namespace hsr
