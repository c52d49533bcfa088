// Issue 41's three tests through the pipeline with its defaults, on small `synth office` scenes whose answers
// are known from the generator's truth: a 12 cm partition with a doorway survives (a slab where it stands, air
// through the doorway), a yawed desk keeps its shape (its box at its own angle, not the world's axes), a round
// pillar is not a pit (solid from floor to ceiling, its seen side where the points are). The model of a room is
// its air: a point is air where the model's winding number is 1, solid where it is 0.
#include "eval/eval.h"
#include "pipeline/pipeline.h"
#include "synth/synth.h"
#include "winding_number.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

namespace hsr {
namespace {

using test::winding_number;

/// The model in the scan's coordinates.
PolygonMesh in_scan_frame(const SynthScan& scan, const PipelineResult& r) {
  PolygonMesh mesh = r.mesh;
  for (Vec3& v : mesh.vertices) v += r.mesh.origin - scan.cloud.origin;
  return mesh;
}

/// Whether the model makes `p` (scan coordinates) air.
bool is_air(const PolygonMesh& mesh, const Vec3& p) { return std::abs(winding_number(mesh, p) - 1.0) < 0.5; }

/// A point given in a piece's own frame, in the world (SynthBlock: w = origin + R(angle) q).
Vec3 from_own_frame(const SynthBlock& b, const Vec3& q) {
  const double c = std::cos(b.angle), s = std::sin(b.angle);
  return b.origin + Vec3(c * q.x() - s * q.y(), s * q.x() + c * q.y(), q.z());
}

/// `hsr synth office` of `rooms` rooms with the generator's own furniture (SynthOfficeParams' defaults), seed `seed`.
SynthScan furnished_office(int rooms, std::uint64_t seed) {
  SynthParams p;
  p.seed = seed;
  p.office.rooms = rooms;
  return run_synth("office", p);
}

/// An office of `rooms` rooms with no furniture but what `furnish` asks for.
SynthScan office(int rooms, std::uint64_t seed, const std::function<void(SynthOfficeParams&)>& furnish) {
  SynthParams p;
  p.seed = seed;
  p.office.rooms = rooms;
  p.office.tables = p.office.chairs = p.office.desks = p.office.cabinets = p.office.shelves = p.office.pillars = 0;
  furnish(p.office);
  return run_synth("office", p);
}

const SynthBlock& the_block(const SynthScan& scan, const std::string& kind) {
  for (const SynthBlock& b : scan.blocks)
    if (b.kind == kind) return b;
  throw std::runtime_error("no " + kind + " in the scene");
}

/// At the nine places (0.3, 0.5, 0.7 of its length by its width) under a table's top, how many have their first air
/// going down in `step`s within `within` of `depth` under the top (the truth's underside).
int undersides_near(const PolygonMesh& mesh, const SynthBlock& table, double depth, double within, double step) {
  const Vec3 hi = table.own.max;
  int near = 0;
  for (double fx : {0.3, 0.5, 0.7})
    for (double fy : {0.3, 0.5, 0.7})
      for (double d = step; d < 0.2; d += step)
        if (is_air(mesh, from_own_frame(table, Vec3(fx * hi.x(), fy * hi.y(), hi.z() - d)))) {
          near += std::abs(d - depth) <= within;
          break;
        }
  return near;
}

// Issue 41 item 2 and 5: two rooms behind a 12 cm partition (thinner than the inlier distance, 2 r = 0.22 m at
// 80 points/m²) with a 0.9 m doorway. Every sample in the partition's middle, along its whole length beside the
// doorway and from the floor to the ceiling, is solid; every sample across the doorway (below the lintel) is air,
// so the free space of the two rooms is connected and no block stands across it. Without two-faced slabs
// (RoomParams::two_faced_slabs off) the two faces are grown into one plane through the middle and the slab is lost;
// without the doorway's head (RoomParams::opening_heads off) a 12 cm block closes the doorway: the test sees both
// rules.
TEST(Office, ATwelveCentimetrePartitionWithADoorwaySurvives) {
  const SynthScan scan = office(2, 1, [](SynthOfficeParams&) {});
  const SynthBlock& wall = the_block(scan, "partition");
  const SynthBlock& door = the_block(scan, "doorway");
  const auto solid_share = [&](const PipelineResult& r, int* door_air, int* door_samples) {
    const PolygonMesh mesh = in_scan_frame(scan, r);
    const Vec3 lo = wall.box.min, hi = wall.box.max, mid = wall.box.center();
    const bool along_x = hi.x() - lo.x() > hi.y() - lo.y();
    int solid = 0, samples = 0;
    for (double t = 0.05; t < 1.0; t += 0.1)
      for (double z : {0.3, 1.2, 2.0, hi.z() - 0.3}) {
        const Vec3 p = along_x ? Vec3(lo.x() + t * (hi.x() - lo.x()), mid.y(), z) : Vec3(mid.x(), lo.y() + t * (hi.y() - lo.y()), z);
        const bool in_door = (p.array() >= door.box.min.array() - 0.1).all() && (p.array() <= door.box.max.array() + 0.1).all();
        if (in_door) continue;
        ++samples;
        solid += !is_air(mesh, p);
      }
    *door_air = *door_samples = 0;
    for (double z : {0.3, 1.0, 1.8})
      for (double across : {-0.5, 0.0, 0.5}) {  // through the doorway, from one room into the other
        Vec3 p = door.box.center();
        p.z() = z;
        (along_x ? p.y() : p.x()) += across;
        ++*door_samples;
        *door_air += is_air(mesh, p);
      }
    return static_cast<double>(solid) / samples;
  };
  const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  int air = 0, through = 0;
  EXPECT_EQ(solid_share(r, &air, &through), 1.0) << "the partition has a gap";
  EXPECT_EQ(air, through) << "a block across the doorway";
  PipelineParams one_face;
  one_face.scene.room.two_faced_slabs = false;
  const PipelineResult o = run_pipeline(scan.cloud, one_face);
  int air_o = 0, through_o = 0;
  EXPECT_LT(solid_share(o, &air_o, &through_o), 0.5) << "without two-faced slabs the partition stood too: the test shows nothing";
  PipelineParams no_head;  // without the doorway's head the slab's cell runs from the floor up through the lintel
  no_head.scene.room.opening_heads = false;
  const PipelineResult h = run_pipeline(scan.cloud, no_head);
  int air_h = 0, through_h = 0;
  solid_share(h, &air_h, &through_h);
  EXPECT_LT(air_h, through_h) << "without opening heads the doorway was open too: the test shows nothing";
}

// Issue 41 item 3: an L-shaped desk turned by 37 degrees keeps its shape. Its top is solid at points of both arms;
// points just outside its own box (10 cm beyond each side, under the top's height) are air although they lie
// within its box along the world's axes, so its box follows its own frame; and the model stays within 5 cm of the
// truth on the desk's seen top.
TEST(Office, AYawedDeskKeepsItsShape) {
  const SynthScan scan = office(1, 1, [](SynthOfficeParams& o) {
    o.desks = 1;
    o.angle_deg = 37.0;
  });
  const SynthBlock& desk = the_block(scan, "desk");
  ASSERT_NEAR(desk.angle, 37.0 * M_PI / 180.0, 1e-12);
  const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  const PolygonMesh mesh = in_scan_frame(scan, r);
  const Vec3 lo = desk.own.min, hi = desk.own.max;
  const double top = hi.z() - 0.015;  // inside the 3 cm top
  // The top: near the corner, and out along both arms (the L: x up to its length at small y, y at small x).
  for (const Vec3& q : {Vec3(0.2, 0.2, top), Vec3(hi.x() - 0.2, 0.2, top), Vec3(0.2, hi.y() - 0.2, top)})
    EXPECT_FALSE(is_air(mesh, from_own_frame(desk, q))) << "top at " << q.transpose();
  // Beyond each side of its own box, at half its height: air, though inside its world box.
  int beyond = 0, inside_world_box = 0;
  const double z = 0.5 * hi.z(), gap = 0.1;
  for (double t : {0.25, 0.5, 0.75}) {
    const double x = lo.x() + t * (hi.x() - lo.x()), y = lo.y() + t * (hi.y() - lo.y());
    for (const Vec3& q : {Vec3(x, lo.y() - gap, z), Vec3(x, hi.y() + gap, z), Vec3(lo.x() - gap, y, z), Vec3(hi.x() + gap, y, z)}) {
      const Vec3 w = from_own_frame(desk, q);
      if (!(w.array() >= desk.box.min.array()).all() || !(w.array() <= desk.box.max.array()).all()) continue;
      ++inside_world_box;
      beyond += is_air(mesh, w);
    }
  }
  ASSERT_GE(inside_world_box, 4) << "the desk is not turned enough for the test";
  EXPECT_EQ(beyond, inside_world_box) << "the desk's box follows the world's axes";
}

// Issue 41 item 4: a round pillar (a 24-sided prism from floor to ceiling) is solid along its axis from near the
// floor to just under the ceiling (no pit in the ceiling, no air inside it), air 15 cm beside it on every side
// a station sees, and its seen side within 5 cm of the model (no bulge, no flat cut where the points are).
TEST(Office, APillarIsNotAPit) {
  const SynthScan scan = office(1, 1, [](SynthOfficeParams& o) { o.pillars = 1; });
  const SynthBlock& pillar = the_block(scan, "pillar");
  const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  const PolygonMesh mesh = in_scan_frame(scan, r);
  const Vec3 c = pillar.box.center();
  const double radius = 0.5 * (pillar.box.max.x() - pillar.box.min.x()), ceiling = pillar.box.max.z();
  for (double z : {0.1, 1.0, 2.0, ceiling - 0.1, ceiling - 0.03})
    EXPECT_FALSE(is_air(mesh, Vec3(c.x(), c.y(), z))) << "air inside the pillar at z " << z;
  int air = 0, around = 0;
  for (int k = 0; k < 8; ++k) {
    const double a = 2 * M_PI * k / 8;
    for (double z : {0.5, 1.5, ceiling - 0.2}) {
      ++around;
      air += is_air(mesh, Vec3(c.x() + (radius + 0.15) * std::cos(a), c.y() + (radius + 0.15) * std::sin(a), z));
    }
  }
  EXPECT_EQ(air, around) << "a block beside the pillar";
  // Its seen side: the scan's points on it lie within 5 cm of the model.
  std::vector<Vec3> on_pillar;
  for (std::size_t i = 0; i < scan.cloud.size(); ++i) {
    const Vec3& p = scan.cloud.points[i];
    if (std::hypot(p.x() - c.x(), p.y() - c.y()) < radius + 0.03 && p.z() > 0.05 && p.z() < ceiling - 0.05) on_pillar.push_back(p);
  }
  ASSERT_GT(on_pillar.size(), 50u);
  PolygonMesh model = r.mesh;
  for (Vec3& p : on_pillar) p += scan.cloud.origin - r.mesh.origin;
  EXPECT_EQ(count_farther(on_pillar, model, 0.05), 0u) << "of " << on_pillar.size() << " points on the pillar";
}

// Issue 41 item 2: a table on four legs leaves the free space under its top. Its top is solid (1 cm under its
// surface, in the middle), and under it, at the middle of its own box and half way to each corner, 0.2 and 0.4 m
// above the floor, is air (the scan holds the floor there, seen between the legs). Without
// RoomParams::free_under_tops the top's sides and the piece's box reach down to the floor, the floor's points
// inside that block vote it air, and the whole table is lost (the model is the room's six faces): the test sees
// the rule.
TEST(Office, ATableOnLegsLeavesTheSpaceUnderItsTop) {
  const SynthScan scan = office(1, 1, [](SynthOfficeParams& o) { o.tables = 1; });
  const SynthBlock& table = the_block(scan, "table");
  const Vec3 hi = table.own.max;
  const auto kept = [&](const PipelineResult& r, std::string* why) {
    const PolygonMesh mesh = in_scan_frame(scan, r);
    if (is_air(mesh, from_own_frame(table, Vec3(0.5 * hi.x(), 0.5 * hi.y(), hi.z() - 0.01)))) {
      *why = "the top is lost";
      return false;
    }
    for (double fx : {0.3, 0.5, 0.7})
      for (double fy : {0.3, 0.5, 0.7})
        for (double z : {0.2, 0.4})
          if (!is_air(mesh, from_own_frame(table, Vec3(fx * hi.x(), fy * hi.y(), z)))) {
            *why = "a block under the top";
            return false;
          }
    return true;
  };
  const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  std::string why;
  EXPECT_TRUE(kept(r, &why)) << why;
  PipelineParams to_the_floor;
  to_the_floor.scene.room.free_under_tops = false;
  EXPECT_FALSE(kept(run_pipeline(scan.cloud, to_the_floor), &why)) << "without free_under_tops the table was kept too: the test shows nothing";
}

/// The doorways of `scan` open in the model of `r` (its centre in plan, the partition's middle, air at 0.3, 1.0 and
/// 1.8 m, as office_pieces counts them); `doorways` their number.
int open_doorways(const SynthScan& scan, const PipelineResult& r, int* doorways) {
  const PolygonMesh mesh = in_scan_frame(scan, r);
  int open = 0;
  *doorways = 0;
  for (const SynthBlock& b : scan.blocks) {
    if (b.kind != "doorway") continue;
    ++*doorways;
    bool air = true;
    for (double z : {0.3, 1.0, 1.8}) air = air && is_air(mesh, Vec3(b.box.center().x(), b.box.center().y(), b.box.min.z() + z));
    open += air;
  }
  return open;
}

// Issue 41 item 5: the free space stays connected through each doorway of a furnished office (3 rooms, seeds 1 and
// 3: the generator's default furniture). A doorway is open when its centre in plan (the partition's middle) is air
// at 0.3, 1.0 and 1.8 m. Two rules of the openings' recovery are seen, each on the scene it was made for:
// - seed 3: a jamb was found 6 cm inside the opening's edge, so the edge's own rows of points, down to 0.2 m, lay
//   between the jambs; the lowest of them was taken for the lintel's underside and the opening, reaching down to
//   the floor, got no head (a 12 cm block across it). RecoveryParams::lintel_gap takes the rows hanging from the
//   top without a gap; with it 0 (the lowest point, DECISIONS #97) that doorway is closed again.
// - seed 1: one face's segment along a jamb, fitted to the few points of the opening's edge, stood 14 degrees off
//   vertical, so no jamb was found there and the opening was not recovered. RecoveryParams::jamb_angle_deg (20)
//   takes it; with r_a's 10 degrees that doorway is closed again.
TEST(Office, EveryDoorwayOfAFurnishedOfficeIsOpen) {
  for (const std::uint64_t seed : {3, 1}) {
    const SynthScan scan = furnished_office(3, seed);
    const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
    ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
    int doorways = 0;
    EXPECT_EQ(open_doorways(scan, r, &doorways), doorways) << "a block across a doorway, seed " << seed;
    EXPECT_EQ(doorways, 2);
    PipelineParams without;
    if (seed == 3) without.recovery.lintel_gap = 0;  // the head at the lowest inlier between the jambs (#97)
    else without.recovery.jamb_angle_deg = without.recovery.angle_deg;  // jambs within r_a of vertical (#98)
    EXPECT_LT(open_doorways(scan, run_pipeline(scan.cloud, without), &doorways), doorways)
        << "without the rule every doorway was open too at seed " << seed << ": the test shows nothing";
  }
}

// Issue 41 (valid): the office of 4 rooms (seed 2) with defaults held a face whose corners round to one point (a
// sub-precision cell of the exact complex where a turned piece's nearly parallel planes meet): a face of zero area,
// and the model was not valid (self-intersecting). With those edges collapsed in the output
// (collapse_sub_precision_edges, DECISIONS #158) it is valid; the count says the collapse was needed. (The offices
// of 5 rooms, seeds 1 and 2, have such edges too; what else kept them invalid is the next test's.)
TEST(Office, FacesShorterThanTheDoublesPrecisionAreCollapsed) {
  const PipelineResult r = run_pipeline(furnished_office(4, 2).cloud, PipelineParams{});
  EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  // Since DECISIONS #179 the sub-precision cells are not made: they lay between a post's side and its box's side at
  // one coordinate, their planes ulps apart (2 such pairs here before #179). No edge needs the collapse now; #158
  // has no input showing it left (DECISIONS #179, Left).
  EXPECT_EQ(r.report["counts"]["sub_precision_edges"].get<std::size_t>(), 0u) << "a sub-precision cell again";
}

// Issue 41 (valid): the office of 5 rooms (seed 1) with defaults held a chair seat's face whose two halves the exact
// complex joins by a strip about 1e-15 m wide, where a turned chair's nearly parallel planes meet: exact and simple,
// but once rounded two of its corners lie on, and across, its own edge, and the model was not valid
// (self-intersecting). No edge is short there, so the collapse of #158 did not help. With those corners zipped into
// the edge (zip_sub_precision_necks, DECISIONS #161: the face split in two at them, the face across the edge given
// the corners) it is valid; the count says the zip was needed.
TEST(Office, NecksNarrowerThanTheDoublesPrecisionAreZipped) {
  const PipelineResult r = run_pipeline(furnished_office(5, 1).cloud, PipelineParams{});
  EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  // Since DECISIONS #179 no neck is made here (the strip lay between planes ulps apart, as in the test above); #161
  // has no input showing it left (DECISIONS #179, Left).
  EXPECT_EQ(r.report["counts"]["sub_precision_necks"].get<std::size_t>(), 0u) << "a sub-precision neck again";
}

// Issue 41 item 5: a doorway's jambs stand at its edges (6 rooms, seed 1, the defaults: all seven doorways open). A
// jamb's segments, fitted to the edge's boundary points, lie about half a spacing inside the wall; with the jamb's
// plane there (RecoveryParams::jamb_at_edge false, DECISIONS #98) the faces' points between it and the true edge lay
// on the doorway's facets facing out of it, and with a chair seat's plane cutting the doorway at 0.46 m the cell
// above it was labelled solid: one doorway air at 0.3 m only (DECISIONS #138). The test sees the rule.
TEST(Office, ADoorwaysJambsStandAtItsEdges) {
  const SynthScan scan = furnished_office(6, 1);
  const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  int doorways = 0;
  EXPECT_EQ(open_doorways(scan, r, &doorways), doorways) << "a block across a doorway";
  EXPECT_EQ(doorways, 7);
  PipelineParams without;
  without.recovery.jamb_at_edge = false;  // the jamb's plane through its segments' mean (#98)
  EXPECT_LT(open_doorways(scan, run_pipeline(scan.cloud, without), &doorways), doorways)
      << "without jamb_at_edge every doorway was open too: the test shows nothing";
}

// Issue 41 item 2: every chair on one post keeps its seat and its back (1 room, seed 1, four chairs and nothing
// else). A chair's seat is solid somewhere on the vertical through its own (0.22, 0.22) between 0.40 and 0.56 m
// (the seat's top lies at 0.48-0.54 m), its back somewhere on the line across it at own x 0.22 and 0.70 m high,
// own y from 0.40 to 0.55 m (the 4 cm back stands at y 0.40-0.50). The back's plane lies on the side of the chair's
// box (RecoveryParams::piece_boxes) but holds points above the seat only; with box_side_gap 0 it stood for the
// whole side, the side under it was dropped, and one chair's back was lost (DECISIONS #120): the test sees the rule.
TEST(Office, EveryChairKeepsItsSeatAndItsBack) {
  const SynthScan scan = office(1, 1, [](SynthOfficeParams& o) { o.chairs = 4; });
  const auto whole_chairs = [&](const PipelineResult& r) {
    const PolygonMesh mesh = in_scan_frame(scan, r);
    int whole = 0;
    for (const SynthBlock& b : scan.blocks) {
      if (b.kind != "chair") continue;
      bool seat = false, back = false;
      for (int cm = 40; cm <= 56 && !seat; ++cm) seat = !is_air(mesh, from_own_frame(b, Vec3(0.22, 0.22, 0.01 * cm)));
      for (int cm = 40; cm <= 55 && !back; ++cm) back = !is_air(mesh, from_own_frame(b, Vec3(0.22, 0.01 * cm, 0.70)));
      whole += seat && back;
    }
    return whole;
  };
  const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_EQ(whole_chairs(r), 4);
  PipelineParams whole_side;
  whole_side.recovery.box_side_gap = 0;  // a covering plane stands for the whole side (#70)
  whole_side.recovery.step_min_free = 0;  // and the box one block (#70; with #141's step the seat's side is not the back's)
  whole_side.recovery.inner_face_depth = 0;  // and a plane seen from inside covers a side (#70; #154 keeps the side)
  EXPECT_LT(whole_chairs(run_pipeline(scan.cloud, whole_side)), 4)
      << "without box_side_gap every chair was whole too: the test shows nothing";
}

// Issue 41 "every table and chair present": a chair's box steps at its seat (DECISIONS #141). Chairs alone (1 room,
// 4 chairs, seeds 1-3: 12 chairs): a chair has its back when the model is solid somewhere 0.70 m up across the back
// (0.40-0.55 m from the seat's front edge, as in EveryChairKeepsItsSeatAndItsBack). With the step every chair has its
// back; without it (step_min_free 0: one block from the floor to the back's top over the whole seat) the chair at
// seed 3 facing -x was air across its back (its seat too: 0.19 of its seen surface within 5 cm, 0.67 with the step).
// Both runs with the raised top at r_d, as #141 was made: with #168's 2 r the chair at seed 2 (7.48, 4.42) loses its
// back (11 of 12, one of the 6 chairs #168 loses on the office; AChairsSeatIsARaisedTop tests #168's defaults).
TEST(Office, AChairsBoxStepsAtItsSeat) {
  int chairs = 0, backs = 0, backs_without = 0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const SynthScan scan = office(1, seed, [](SynthOfficeParams& o) { o.chairs = 4; });
    PipelineParams with_step;
    with_step.recovery.piece_top_height = 0;  // r_d, as before #168
    const PipelineResult r = run_pipeline(scan.cloud, with_step);
    ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
    PipelineParams one_block = with_step;
    one_block.recovery.step_min_free = 0;  // one block (#70)
    const PolygonMesh mesh = in_scan_frame(scan, r), mesh0 = in_scan_frame(scan, run_pipeline(scan.cloud, one_block));
    const auto has_back = [&](const PolygonMesh& m, const SynthBlock& b) {
      for (int cm = 40; cm <= 55; ++cm)
        if (!is_air(m, from_own_frame(b, Vec3(0.22, 0.01 * cm, 0.70)))) return true;
      return false;
    };
    for (const SynthBlock& b : scan.blocks) {
      if (b.kind != "chair") continue;
      ++chairs;
      const bool with = has_back(mesh, b), without = has_back(mesh0, b);
      EXPECT_TRUE(with || !without) << "seed " << seed << ": the chair at " << b.origin.transpose() << " lost its back to the step";
      backs += with;
      backs_without += without;
    }
  }
  EXPECT_EQ(chairs, 12);
  EXPECT_EQ(backs, chairs);
  EXPECT_LT(backs_without, backs) << "without the step every chair had its back too: the test shows nothing";
}

// Issue 41 item 2: a lone table on four legs is kept whatever the seed (1 room, one table, seeds 1-6): its top is
// solid (1 cm under its surface, in the middle) and the middle under it, 0.3 m above the floor, air. Its box's
// bottom lies one spacing (top_thickness) under the top, and the top's own plane, within a spacing of it, was read
// as covering it or not by the rounding of the fit: without the bottom the cell under the top ran down to the
// floor and the table was voted air at seeds 2-4 (DECISIONS #129).
TEST(Office, ALoneTableOnLegsIsKeptAtEverySeed) {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const SynthScan scan = office(1, seed, [](SynthOfficeParams& o) { o.tables = 1; });
    const SynthBlock& table = the_block(scan, "table");
    const Vec3 hi = table.own.max;
    const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
    ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
    const PolygonMesh mesh = in_scan_frame(scan, r);
    EXPECT_FALSE(is_air(mesh, from_own_frame(table, Vec3(0.5 * hi.x(), 0.5 * hi.y(), hi.z() - 0.01))))
        << "the top is lost at seed " << seed;
    EXPECT_TRUE(is_air(mesh, from_own_frame(table, Vec3(0.5 * hi.x(), 0.5 * hi.y(), 0.3))))
        << "a block under the top at seed " << seed;
  }
}

// Issue 41 "truth -> mesh <= 0.02 %": a table's top ends where its rim ends (RecoveryParams::rim_underside,
// DECISIONS #229). A lone table on four legs (1 room, seeds 1-6; the generator's top is 4 cm thick): at nine
// places under its top (a 3 x 3 grid at 0.3, 0.5 and 0.7 of its own box), going down from 5 mm under its surface
// in 5 mm steps, the model's underside is the first height that is air. With the rule it lies within 1.5 cm of
// the truth's at 27 of the 54 places (asked: 24); without it (top_thickness, one spacing: 0.11 m under the top) at
// none, the slab reaching 7 cm too deep. The other places are a sliver of the top over air, the min-cut's choice
// with the rule and without it (#229's Left).
TEST(Office, ATablesTopEndsWhereItsRimEnds) {
  constexpr double kTop = 0.04, kWithin = 0.015, kStep = 0.005;  // the generator's top (office.cpp office_table)
  int places = 0, near = 0, near_without = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const SynthScan scan = office(1, seed, [](SynthOfficeParams& o) { o.tables = 1; });
    const SynthBlock& table = the_block(scan, "table");
    const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
    ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
    PipelineParams without;
    without.recovery.rim_underside = false;
    const PolygonMesh mesh = in_scan_frame(scan, r), mesh0 = in_scan_frame(scan, run_pipeline(scan.cloud, without));
    places += 9;
    near += undersides_near(mesh, table, kTop, kWithin, kStep);
    near_without += undersides_near(mesh0, table, kTop, kWithin, kStep);
  }
  std::printf("%d places under the top: the underside within %.3f m of the truth's at %d, without the rule at %d\n", places,
              kWithin, near, near_without);
  EXPECT_GE(near, 24);
  EXPECT_LT(near_without, near) << "without the rule as many were near: the test shows nothing";
}

// Issue 41 "truth -> mesh <= 0.02 %": a table's top is solid down to the underside its rim measured though another
// top's plane runs through it (RecoveryParams::solid_slabs, ExtractionParams::slab_facet_weight; DECISIONS #230).
// The offices of 1 room, seeds 1-3, all their furniture (two tables each, their tops at 0.72-0.76 m, level planes
// millimetres apart that cross each other's slab): at nine places under each table's top (as
// ATablesTopEndsWhereItsRimEnds, in 2.5 mm steps), the first air going down lies within 1.5 cm of the truth's
// underside at 18 of the 54 places with the rule (asked: 16) and at 1 without it (the cells under the crossing
// plane air: a sliver of the top a few millimetres thick).
TEST(Office, ATablesTopIsSolidToItsUndersideThoughAnotherTopsPlaneCrossesIt) {
  constexpr double kTop = 0.04, kWithin = 0.015, kStep = 0.0025;  // the generator's top (office.cpp office_table)
  int places = 0, near = 0, near_without = 0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const SynthScan scan = furnished_office(1, seed);
    const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
    ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
    PipelineParams without;
    without.recovery.solid_slabs = false;
    const PolygonMesh mesh = in_scan_frame(scan, r), mesh0 = in_scan_frame(scan, run_pipeline(scan.cloud, without));
    for (const SynthBlock& table : scan.blocks) {
      if (table.kind != "table") continue;
      places += 9;
      near += undersides_near(mesh, table, kTop, kWithin, kStep);
      near_without += undersides_near(mesh0, table, kTop, kWithin, kStep);
    }
  }
  std::printf("%d places under the tables' tops: the underside within %.3f m of the truth's at %d, without the rule at %d\n",
              places, kWithin, near, near_without);
  EXPECT_EQ(places, 54);
  EXPECT_GE(near, 16);
  EXPECT_LT(near_without, near) << "without the rule as many were near: the test shows nothing";
}

// Issue 41 item 2: an open shelf seen from its front only is a solid where it stands (6 rooms seed 2, the defaults).
// The shelf at (9.0, 2.5) is seen from its front alone: its boards' edges and its back panel lie within a spacing of
// one plane, whose box's back then lay within r of that plane and was taken as covered, so the box was open and the
// shelf air; min_piece_depth gives such a box two spacings behind its seen face (DECISIONS #130). A shelf is solid
// when its middle, half its depth behind its front and 1 m up, is; no shelf solid without the rule is air with it.
TEST(Office, AShelfSeenFromItsFrontIsSolid) {
  const SynthScan scan = furnished_office(6, 2);
  const auto solid_shelves = [&](const PipelineResult& r) {
    const PolygonMesh mesh = in_scan_frame(scan, r);
    std::vector<bool> solid;
    for (const SynthBlock& b : scan.blocks)
      if (b.kind == "shelf") solid.push_back(!is_air(mesh, from_own_frame(b, Vec3(0.5 * b.own.max.x(), 0.5 * b.own.max.y(), 1.0))));
    return solid;
  };
  int seen_from_front = -1, shelf = 0;  // the index among the shelves of the one at (9.0, 2.5)
  for (const SynthBlock& b : scan.blocks) {
    if (b.kind != "shelf") continue;
    const Vec3 c = from_own_frame(b, 0.5 * b.own.max);
    if (std::hypot(c.x() - 9.0, c.y() - 2.5) < 0.5) seen_from_front = shelf;
    ++shelf;
  }
  const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  const std::vector<bool> with = solid_shelves(r);
  ASSERT_EQ(with.size(), 6u);
  ASSERT_GE(seen_from_front, 0) << "no shelf at (9.0, 2.5)";
  EXPECT_TRUE(with[static_cast<std::size_t>(seen_from_front)]) << "the shelf seen from its front is air";
  PipelineParams without;
  without.recovery.min_piece_depth = 0;  // the box spans the points only (#70)
  const std::vector<bool> before = solid_shelves(run_pipeline(scan.cloud, without));
  EXPECT_FALSE(before[static_cast<std::size_t>(seen_from_front)]) << "without min_piece_depth it was solid too: the test shows nothing";
  for (std::size_t k = 0; k < with.size(); ++k) EXPECT_TRUE(with[k] || !before[k]) << "shelf " << k << " lost";
}


// Issue 41 "every table and chair present": a table stands on its legs (DECISIONS #139). A lone table on four legs
// (1 room, seeds 1-6, 24 legs): each leg whose 5 cm square holds at least 5 of the scan's points is solid at its
// middle in plan, 0.3 m up (14 legs), and so are at least 18 of the 22 legs with 3 or more (a leg of 3-4 points may
// lose some to the top's piece or to the min-cut: 4 do today); the space between the legs stays air (the middle of
// the top's box, 0.3 m up). Without posts (post_min_points 0) the legs were air (the model had the top alone: a
// table's legs are 17-38 % of its seen surface, and office_pieces counted 18 of 60 tables present): no leg is solid.
TEST(Office, ATableStandsOnItsLegs) {
  int seen_legs = 0, solid_legs = 0, solid_without = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const SynthScan scan = office(1, seed, [](SynthOfficeParams& o) { o.tables = 1; });
    const SynthBlock& table = the_block(scan, "table");
    const Vec3 hi = table.own.max;
    const double inset = 0.05, leg = 0.05;  // the generator's (office.cpp office_table)
    std::vector<Vec3> legs;  // each leg's middle in its own frame, 0.3 m up
    for (double x : {inset + 0.5 * leg, hi.x() - inset - 0.5 * leg})
      for (double y : {inset + 0.5 * leg, hi.y() - inset - 0.5 * leg}) legs.emplace_back(x, y, 0.3);
    const double c = std::cos(table.angle), s = std::sin(table.angle);
    std::vector<int> points(legs.size(), 0);
    for (const Vec3& w : scan.cloud.points) {
      const Vec3 d = w + scan.cloud.origin - table.origin, q(c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z());
      for (std::size_t k = 0; k < legs.size(); ++k)
        if (std::abs(q.x() - legs[k].x()) < 0.5 * leg + 0.02 && std::abs(q.y() - legs[k].y()) < 0.5 * leg + 0.02 &&
            q.z() > 0.05 && q.z() < hi.z() - 0.1)
          ++points[k];
    }
    const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
    ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
    const PolygonMesh mesh = in_scan_frame(scan, r);
    PipelineParams no_posts;
    no_posts.recovery.post_min_points = 0;
    const PipelineResult r0 = run_pipeline(scan.cloud, no_posts);
    const PolygonMesh mesh0 = in_scan_frame(scan, r0);
    EXPECT_TRUE(is_air(mesh, from_own_frame(table, Vec3(0.5 * hi.x(), 0.5 * hi.y(), 0.3)))) << "a block under the top at seed " << seed;
    for (std::size_t k = 0; k < legs.size(); ++k) {
      const bool solid = !is_air(mesh, from_own_frame(table, legs[k]));
      if (points[k] < 3) continue;
      ++seen_legs;
      solid_legs += solid;
      if (points[k] >= 5) EXPECT_TRUE(solid) << "seed " << seed << ": leg " << k << " of " << points[k] << " points is air";
      solid_without += !is_air(mesh0, from_own_frame(table, legs[k]));
    }
  }
  EXPECT_EQ(seen_legs, 22);
  EXPECT_GE(solid_legs, 18) << "of " << seen_legs << " legs of 3 points or more";
  EXPECT_EQ(solid_without, 0) << "without posts a leg was solid too: the test shows nothing";
}

// Issue 41 item 2: an open shelf's boards and panels seen from inside it only stand behind what was seen
// (DECISIONS #154). One room with two shelves, seeds 1-4 (8 shelves): a shelf's top board (its middle, 1 cm under
// its top) and its side panels (each 1 cm inside its outer face, half its depth, 1 m up) are samples of its
// material; with the defaults at least as many are solid as with inner_face_depth 0 and none solid there is air,
// and more are solid (2026-12-05: 17 against 11). Without the rule the top board seen from below (the scanners stand 1.5 m up) and a side panel
// seen through the open front had their inner face only, which covered the box's side: one plane, no thickness.
TEST(Office, AnOpenShelfsBoardsSeenFromInsideStandBehindIt) {
  int solid = 0, solid_without = 0, samples = 0;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const SynthScan scan = office(1, seed, [](SynthOfficeParams& o) { o.shelves = 2; });
    const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
    ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
    PipelineParams without;
    without.recovery.inner_face_depth = 0;  // a plane covers a side from either side (#70)
    const PolygonMesh mesh = in_scan_frame(scan, r), mesh0 = in_scan_frame(scan, run_pipeline(scan.cloud, without));
    for (const SynthBlock& b : scan.blocks) {
      if (b.kind != "shelf") continue;
      const Vec3 hi = b.own.max;
      for (const Vec3& q : {Vec3(0.5 * hi.x(), 0.5 * hi.y(), hi.z() - 0.01), Vec3(0.01, 0.5 * hi.y(), 1.0),
                            Vec3(hi.x() - 0.01, 0.5 * hi.y(), 1.0)}) {
        const Vec3 w = from_own_frame(b, q);
        const bool with = !is_air(mesh, w), with0 = !is_air(mesh0, w);
        EXPECT_TRUE(with || !with0) << "seed " << seed << ": the shelf at " << b.origin.transpose() << " lost " << q.transpose();
        ++samples, solid += with, solid_without += with0;
      }
    }
  }
  EXPECT_EQ(samples, 24);
  EXPECT_GE(solid, 17);  // 17 of 24 on 2026-12-05
  EXPECT_GT(solid, solid_without) << "without the rule as many were solid (" << solid_without << "): the test shows nothing";
}

/// The boards and compartments of the shelves of 1 room with `shelves` shelves at seeds 1-`seeds`, counted right with
/// the defaults (`right`) and with `without` changing them (`right_without`), of `samples`: the middle of each board
/// and of the top board (1 cm inside it: the generator's 2 cm boards, office.cpp office_shelf) is a sample of its
/// material, the middle of each compartment between two boards a sample of air; a sample is right when the model
/// says so. `lost`: boards solid without the change and air with the defaults.
void count_shelf_samples(int shelves, std::uint64_t seeds, const std::function<void(PipelineParams&)>& without,
                         int& samples, int& right, int& right_without, int& lost) {
  for (std::uint64_t seed = 1; seed <= seeds; ++seed) {
    const SynthScan scan = office(1, seed, [&](SynthOfficeParams& o) { o.shelves = shelves; });
    const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
    ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
    PipelineParams changed;
    without(changed);
    const PolygonMesh mesh = in_scan_frame(scan, r), mesh0 = in_scan_frame(scan, run_pipeline(scan.cloud, changed));
    for (const SynthBlock& b : scan.blocks) {
      if (b.kind != "shelf") continue;
      const Vec3 hi = b.own.max;
      const double t = 0.02, plinth = 0.08, pitch = 0.35;  // office_shelf's
      const int boards = std::max(0, static_cast<int>((hi.z() - plinth - t) / pitch) - 1);
      std::vector<double> tops = {plinth};  // the top of the plinth, of each board, of the top board
      for (int i = 1; i <= boards; ++i)
        tops.push_back(std::round(100.0 * (plinth + i * (hi.z() - plinth - t) / (boards + 1))) / 100.0 + t);
      tops.push_back(hi.z());
      for (std::size_t i = 1; i < tops.size(); ++i) {
        for (const bool board : {true, false}) {
          const double z = board ? tops[i] - 0.5 * t : 0.5 * (tops[i - 1] + tops[i] - t);
          const Vec3 w = from_own_frame(b, Vec3(0.5 * hi.x(), 0.5 * hi.y(), z));
          const bool ok = is_air(mesh, w) != board, ok0 = is_air(mesh0, w) != board;
          if (board && ok0 && !ok)
            std::printf("seed %d: the shelf at %.2f %.2f lost its board at %.2f\n", static_cast<int>(seed), b.origin.x(), b.origin.y(), z);
          ++samples, right += ok, right_without += ok0, lost += board && ok0 && !ok;
        }
      }
    }
  }
}

// Issue 41 item 2: an open shelf's boards are slabs (DECISIONS #186). One room with two shelves, seeds 1-8 (16
// shelves), count_shelf_samples: with the defaults more are right than with board_thickness 0, and every board the
// rule's run has solid there. Without the rule a board seen from one side was one plane with the compartments the
// scanners looked into on both its sides: either the min-cut made them air and the board was nothing, or the shelf
// stayed a solid box with its compartments inside.
TEST(Office, AnOpenShelfsBoardsAreSlabs) {
  int samples = 0, right = 0, right_without = 0, lost = 0;
  count_shelf_samples(2, 8, [](PipelineParams& p) { p.recovery.board_thickness = 0; }, samples, right, right_without, lost);
  std::printf("%d samples: %d right, %d without the rule, %d boards lost\n", samples, right, right_without, lost);
  EXPECT_EQ(samples, 130);
  EXPECT_EQ(lost, 0);
  EXPECT_GE(right, 88);  // 80 of 130 on 2026-12-06 (88 with #198), 76 without the rule: boards at the scanners' height hold no point
  EXPECT_GE(right, right_without + 4) << "without the rule nearly as many were right: the test shows nothing";
}

// Issue 41 item 2: a shelf's boards over the one its box hangs from are boards (DECISIONS #198). The plinth's top,
// 8 cm up, is the floor seen under each board, so each board was a top with free space under it (#100, #180); the
// box hung under the lowest, and those above, inside the box, got no slab (board_slabs skipped every such top): the
// compartments on both sides of each were air and so was the board. One room with three shelves, seeds 1-8,
// count_shelf_samples against boards_over_underside false.
TEST(Office, AShelfsBoardsOverItsLowestAreBoards) {
  int samples = 0, right = 0, right_without = 0, lost = 0;
  count_shelf_samples(3, 8, [](PipelineParams& p) { p.recovery.boards_over_underside = false; }, samples, right, right_without, lost);
  std::printf("%d samples: %d right, %d without the rule, %d boards lost\n", samples, right, right_without, lost);
  EXPECT_EQ(samples, 200);
  EXPECT_EQ(lost, 0);
  EXPECT_GE(right, 145);  // 145 of 200 on 2026-12-06, 134 without the rule
  EXPECT_GE(right, right_without + 8) << "without the rule nearly as many were right: the test shows nothing";
}

// Issue 41 item 4: a round pillar's back, which no scanner sees, is no chord (DECISIONS #240). Office 1 room seed 1
// with one pillar (a 24-sided prism): the scanners see its front arc, and its box's back side stood on its outermost
// seen points, a chord up to a third of its radius inside it; round (RecoveryParams::round_sides), its sides are a
// prism around the circle its points show. 48 samples 4 cm inside its surface, all round it, at three heights:
// all solid with the rule, some air without it.
TEST(Office, ARoundPillarsUnseenBackIsNoChord) {
  const SynthScan scan = office(1, 1, [](SynthOfficeParams& o) { o.pillars = 1; });
  const SynthBlock& pillar = the_block(scan, "pillar");
  const Vec3 c = pillar.box.center();
  const double radius = 0.5 * (pillar.box.max.x() - pillar.box.min.x());
  const auto air_inside = [&](const PipelineResult& r) {
    const PolygonMesh mesh = in_scan_frame(scan, r);
    int air = 0;
    for (int k = 0; k < 16; ++k) {
      const double a = 2 * M_PI * k / 16;
      for (double z : {0.5, 1.5, 2.5})
        air += is_air(mesh, Vec3(c.x() + (radius - 0.04) * std::cos(a), c.y() + (radius - 0.04) * std::sin(a), z));
    }
    return air;
  };
  const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  PipelineParams without;
  without.recovery.round_sides = 0;  // the box's rectangle always (before #240)
  const int with = air_inside(r), with0 = air_inside(run_pipeline(scan.cloud, without));
  std::printf("48 samples inside the pillar: %d air, %d without the rule\n", with, with0);
  EXPECT_EQ(with, 0) << "air inside the pillar's unseen back";
  EXPECT_GT(with0, 0) << "without the rule the pillar was whole too: the test shows nothing";
}

// Issue 41 item 2: a piece seen from one side only reaches min_piece_depth behind its seen face, though something of
// it beside that face stands in front of it (DECISIONS #206). Office 1 room seed 3, the defaults: the shelf there
// faces the wall, and the scanners see its back alone; the round pillar 0.2 m beside it is in one piece with it and
// stands 0.37 m before the back, so the box reached only two spacings behind the pillar's front, 0.11 m behind the
// back (room_rules.cpp seen_face_front), and the shelf's body was air. 25 samples 0.15 m behind the back (inside
// the 0.22 m min_piece_depth), across the shelf and from 0.3 to 1.9 m up: most solid with the rule, few without.
// Since #209 the shelf and the pillar are two pieces with the defaults (the shelf's box then reaches behind its back
// whatever this rule says); with piece_split_link 0 they are one piece again, the case this rule is for.
TEST(Office, AShelfSeenOnlyFromBehindReachesBehindItsBack) {
  const SynthScan scan = furnished_office(1, 3);
  const SynthBlock& shelf = the_block(scan, "shelf");
  const auto solid = [&](const PipelineResult& r) {
    const PolygonMesh mesh = in_scan_frame(scan, r);
    int n = 0;
    for (double x = 0.15; x < shelf.own.max.x(); x += 0.25)
      for (double z = 0.3; z < 2.0; z += 0.4) n += !is_air(mesh, from_own_frame(shelf, Vec3(x, shelf.own.max.y() - 0.15, z)));
    return n;
  };
  PipelineParams one_piece;
  one_piece.recovery.piece_split_link = 0;  // the shelf and the pillar one piece (#70)
  const PipelineResult r = run_pipeline(scan.cloud, one_piece);
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  PipelineParams without = one_piece;
  without.recovery.depth_from_seen_face = false;  // the box reaches behind the piece's front only (#130)
  const int with = solid(r), with0 = solid(run_pipeline(scan.cloud, without));
  const int defaults = solid(run_pipeline(scan.cloud, PipelineParams{}));
  std::printf("25 samples: %d solid, %d without the rule, %d with the defaults (two pieces)\n", with, with0, defaults);
  EXPECT_GE(with, 20);
  EXPECT_GE(defaults, 20);
  EXPECT_LE(with0, 5) << "without the rule the shelf's body was solid too: the test shows nothing";
}

/// The chairs of 1 room with 4 chairs at seeds 1-6 (24 chairs) counted whole with the defaults (`whole`) and with
/// `without` changing them (`whole_without`). A chair is whole when its seat is solid (somewhere 0.40-0.56 m up at
/// its middle, as in EveryChairKeepsItsSeatAndItsBack), its back solid (0.70 m up across it) and the space under its
/// seat's front corners air (0.25 m up, 0.1 m in from both edges: the post and its cross base stand in the middle).
void count_whole_chairs(const std::function<void(PipelineParams&)>& without, int& chairs, int& whole, int& whole_without) {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const SynthScan scan = office(1, seed, [](SynthOfficeParams& o) { o.chairs = 4; });
    const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
    ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
    PipelineParams changed;
    without(changed);
    const PolygonMesh mesh = in_scan_frame(scan, r), mesh0 = in_scan_frame(scan, run_pipeline(scan.cloud, changed));
    const auto is_whole = [&](const PolygonMesh& m, const SynthBlock& b) {
      const double w = 2.0 * (b.own.max.x() - 0.30), d = 2.0 * (b.own.max.y() - 0.30);  // the seat (the base: 0.30 m)
      bool seat = false, back = false;
      for (int cm = 40; cm <= 56 && !seat; ++cm) seat = !is_air(m, from_own_frame(b, Vec3(0.5 * w, 0.5 * d, 0.01 * cm)));
      for (int cm = 40; cm <= 55 && !back; ++cm) back = !is_air(m, from_own_frame(b, Vec3(0.5 * w, 0.01 * cm, 0.70)));
      const bool under = is_air(m, from_own_frame(b, Vec3(0.1, 0.1, 0.25))) && is_air(m, from_own_frame(b, Vec3(w - 0.1, 0.1, 0.25)));
      return seat && back && under;
    };
    for (const SynthBlock& b : scan.blocks) {
      if (b.kind != "chair") continue;
      ++chairs;
      const bool with = is_whole(mesh, b), without_rule = is_whole(mesh0, b);
      std::printf("seed %d chair at %.2f %.2f: whole %d, without the rule %d\n", static_cast<int>(seed), b.origin.x(),
                  b.origin.y(), with, without_rule);
      whole += with;
      whole_without += without_rule;
    }
  }
}

// Issue 41 "every table and chair present": a chair's seat is a raised top however low it stands (DECISIONS #168).
// With piece_top_height at r_d (5 r, 0.55 m) a seat 0.48-0.54 m up was no top: no step at it, and the chair's box
// stood on the floor up to its back's top with the seat inside, air or a block.
TEST(Office, AChairsSeatIsARaisedTop) {
  int chairs = 0, whole = 0, whole_without = 0;
  count_whole_chairs([](PipelineParams& p) { p.recovery.piece_top_height = 0; }, chairs, whole, whole_without);  // r_d, as before #168
  EXPECT_EQ(chairs, 24);
  EXPECT_GE(whole, 15);  // 15 of 24 on 2026-12-06, 11 without the rule; 19 and 12 with free_under_seats on (#179)
  EXPECT_GT(whole, whole_without) << "without the rule as many chairs were whole (" << whole_without << "): the test shows nothing";
}

// Issue 41 "every table and chair present": a seat's free space without the floor seen under it (DECISIONS #179,
// after #169). The floor is not seen under a 0.46 m seat from scanners 1.5 m up, so without free_under_seats the
// box under the seat stood from the floor to it, and the rays under the seat voted it air, seat and all, or left
// it a block.
TEST(Office, AChairsSeatKeepsTheFreeSpaceUnderIt) {
  int chairs = 0, whole = 0, whole_without = 0;
  count_whole_chairs([](PipelineParams& p) { p.recovery.free_under_seats = false; }, chairs, whole, whole_without);
  EXPECT_EQ(chairs, 24);
  EXPECT_GE(whole, 19);  // 19 of 24 on 2026-12-06, 16 without the rule
  EXPECT_GT(whole, whole_without) << "without the rule as many chairs were whole (" << whole_without << "): the test shows nothing";
}

// Issue 41 "every table and chair present": a seat no plane holds is a seat (DECISIONS #194). A chair's seat holds
// 15-18 points at 80 points/m², often fewer than the room's smallest plane, and its piece's one plane was then its
// back's: no top, no step, its box stood from the floor to the back's top over the seat, and the min-cut made it
// air, seat, post and all (28 of the offices' 46 missing chairs). seat_level takes the level of its points facing up
// (1 room, 4 chairs, seeds 1-6, count_whole_chairs).
TEST(Office, AChairsSeatWithNoPlaneIsASeat) {
  int chairs = 0, whole = 0, whole_without = 0;
  count_whole_chairs([](PipelineParams& p) { p.recovery.seat_min_points = 0; }, chairs, whole, whole_without);
  EXPECT_EQ(chairs, 24);
  EXPECT_GE(whole, 21);  // 21 of 24 on 2026-12-06, 19 without the rule (seed 2: the chairs at (7.48, 4.42) and (1.41, 3.71))
  EXPECT_GT(whole, whole_without) << "without the rule as many chairs were whole (" << whole_without << "): the test shows nothing";
}

// A post's side where its box's side stands is that side's plane to the last bit (DECISIONS #179). A chair's
// cross base reaches as far as its seat, so the post made from the points under the seat (#139) and the box over
// it (#141) have a side at one coordinate; their planes' offsets, each taken from one of its corners, lay 2e-16 to
// 2e-15 m apart, and the partition cut cells thinner than the doubles' precision between them: with
// free_under_seats, office 4 rooms seeds 1 and 3 came out not oriented and self-intersecting. Each face's offset is
// now its coordinate, and both models are valid.
TEST(Office, APostAtItsBoxsSideLeavesNoSliverBetweenThem) {
  for (std::uint64_t seed : {1, 3}) {
    const SynthScan scan = furnished_office(4, seed);
    const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
    EXPECT_TRUE(r.eval.validity.valid()) << "seed " << seed << ": " << r.eval.validity.summary();
  }
}

// Issue 41 "every table present", and item 2 (a top on legs leaves the free space under it): an L-shaped desk's
// top over its two 2 cm panels and its drawer pedestal keeps the free space under its arms (DECISIONS #180). One
// room with one desk, seeds 1-6: the desk is whole when its top is solid (1.5 cm under it, near the corner and
// out along both arms) and the space under each arm's middle is air (0.35 m up, away from the panels and the
// pedestal). The panels' planes reach under the top, so without panels_as_posts the desk's box stood from the floor
// to its top, and the floor points seen under it voted it air, top and all, or left it a block.
TEST(Office, ADesksTopOverItsPanelsKeepsTheFreeSpaceUnderIt) {
  int whole = 0, whole_without = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const SynthScan scan = office(1, seed, [](SynthOfficeParams& o) { o.desks = 1; });
    const SynthBlock& desk = the_block(scan, "desk");
    const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
    ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
    PipelineParams without;
    without.recovery.panels_as_posts = false;
    const PolygonMesh mesh = in_scan_frame(scan, r), mesh0 = in_scan_frame(scan, run_pipeline(scan.cloud, without));
    // The generator's desk (office.cpp office_desk): arms [0, a] x [0, da] and [0, db] x [0, b], da and db 0.6-0.8 m;
    // the pedestal under the corner up to 0.45 x 0.50 m, a panel 5-7 cm in from each arm's end.
    const Vec3 hi = desk.own.max;
    const double top = hi.z() - 0.015;
    const auto is_whole = [&](const PolygonMesh& m) {
      for (const Vec3& q : {Vec3(0.2, 0.2, top), Vec3(hi.x() - 0.2, 0.2, top), Vec3(0.2, hi.y() - 0.2, top)})
        if (is_air(m, from_own_frame(desk, q))) return false;
      for (const Vec3& q : {Vec3(0.5 * (0.5 + hi.x() - 0.1), 0.25, 0.35), Vec3(0.25, 0.5 * (0.55 + hi.y() - 0.1), 0.35)})
        if (!is_air(m, from_own_frame(desk, q))) return false;
      return true;
    };
    const bool with = is_whole(mesh), with0 = is_whole(mesh0);
    std::printf("seed %d desk at %.2f %.2f: whole %d, without the rule %d\n", static_cast<int>(seed), desk.origin.x(),
                desk.origin.y(), with, with0);
    whole += with, whole_without += with0;
  }
  EXPECT_GE(whole, 4);  // 4 of 6 on 2026-12-06, 0 without the rule
  EXPECT_GT(whole, whole_without) << "without the rule as many desks were whole (" << whole_without << "): the test shows nothing";
}

/// An office scan (`seed`, `rooms`) reconstructed with a room rule (a RecoveryParams switch) on and off: the
/// validity of the model with it, and both models in the scan's frame.
struct RuleOnAndOff {
  SynthScan scan;
  Validity validity;      ///< of the model with the rule
  PolygonMesh with, without;
};
RuleOnAndOff office_rule_on_and_off(std::uint64_t seed, int rooms, bool RecoveryParams::*rule) {
  SynthParams p;
  p.seed = seed;
  p.office.rooms = rooms;
  RuleOnAndOff o;
  o.scan = run_synth("office", p);
  PipelineParams on, off;
  on.recovery.*rule = true;
  off.recovery.*rule = false;
  const PipelineResult r = run_pipeline(o.scan.cloud, on);
  o.validity = r.eval.validity;
  o.with = in_scan_frame(o.scan, r);
  o.without = in_scan_frame(o.scan, run_pipeline(o.scan.cloud, off));
  return o;
}

// Issue 41: with piece_split_across_planes (not the default, DECISIONS #210) a detected plane grown across the
// coplanar faces of two things holds them together no more. Office 2 rooms seed 3: the shelf at (5.72, 4.46),
// linked to a pillar and a cabinet by two such planes (49 + 70 and 33 + 40 inliers), is one piece with them by
// default, its box's frame and bottom theirs: samples over the
// shelf's box and 0.3 m around it (every 5 cm) agree with the truth (air or solid) more often with the rule than
// with piece_split_across_planes false (one piece again).
TEST(Office, AShelfAndThePillarBesideItOnOnePlaneAreTwoPieces) {
  const RuleOnAndOff o = office_rule_on_and_off(3, 2, &RecoveryParams::piece_split_across_planes);  // not the default (#210)
  ASSERT_TRUE(o.validity.valid()) << o.validity.summary();
  const SynthScan& scan = o.scan;
  const PolygonMesh &mesh = o.with, &mesh0 = o.without;
  PolygonMesh truth = scan.truth;  // the interior air
  for (Vec3& v : truth.vertices) v += scan.truth.origin - scan.cloud.origin;
  int samples = 0, right = 0, right_without = 0;
  for (const SynthBlock& b : scan.blocks) {
    if (b.kind != "shelf" || (b.origin - Vec3(5.72, 4.46, 0)).norm() > 0.05) continue;
    const Vec3 hi = b.own.max;
    for (double x = -0.3; x < hi.x() + 0.3; x += 0.05)
      for (double y = -0.3; y < hi.y() + 0.3; y += 0.05)
        for (double z = 0.025; z < hi.z(); z += 0.05) {
          const Vec3 w = from_own_frame(b, Vec3(x, y, z));
          const bool air = is_air(truth, w);
          ++samples, right += is_air(mesh, w) == air, right_without += is_air(mesh0, w) == air;
        }
  }
  std::printf("%d samples in and around the shelf's box: %d as the truth, %d without the rule\n", samples, right, right_without);
  ASSERT_GT(samples, 0) << "no shelf there";
  EXPECT_GT(right, right_without) << "without the rule as many were right: the test shows nothing";
}

// Issue 41 "every table and chair present" and #162's desk: the points linked within the alpha radius (3 r, about
// 0.33 m) were one piece with one box whatever stood 0.15-0.3 m apart, and office 3 rooms seed 2's L-shaped desk at
// (16.6, 3.3), one piece with the chair tucked at it, lost its top (its box from the seat's underside up over both;
// DECISIONS #209). Each desk of that office is whole when its top is solid 1.5 cm under it near the corner and out
// along both arms (as in ADesksTopOverItsPanelsKeepsTheFreeSpaceUnderIt). With piece_split_link 0 the desk and the
// chair are one piece again.
TEST(Office, ADeskAndTheChairTuckedAtItAreTwoPieces) {
  const SynthScan scan = furnished_office(3, 2);
  const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  // Since #229 (rim_underside) the desk's top survives in one piece with the chair as well: the rule is seen
  // with the underside one spacing under the top, as it was made.
  PipelineParams with_spacing, without;
  with_spacing.recovery.rim_underside = without.recovery.rim_underside = false;
  without.recovery.piece_split_link = 0;  // a piece is what the alpha radius links (#70)
  const PipelineResult r1 = run_pipeline(scan.cloud, with_spacing), r0 = run_pipeline(scan.cloud, without);
  const PolygonMesh defaults = in_scan_frame(scan, r), mesh = in_scan_frame(scan, r1), mesh0 = in_scan_frame(scan, r0);
  int desks = 0, whole = 0, whole_without = 0, whole_defaults = 0;
  for (const SynthBlock& desk : scan.blocks) {
    if (desk.kind != "desk") continue;
    const Vec3 hi = desk.own.max;
    const double top = hi.z() - 0.015;
    const auto top_solid = [&](const PolygonMesh& m) {
      for (const Vec3& q : {Vec3(0.2, 0.2, top), Vec3(hi.x() - 0.2, 0.2, top), Vec3(0.2, hi.y() - 0.2, top)})
        if (is_air(m, from_own_frame(desk, q))) return false;
      return true;
    };
    const bool with = top_solid(mesh), with0 = top_solid(mesh0);
    std::printf("desk at %.2f %.2f: top solid %d, without the rule %d\n", desk.origin.x(), desk.origin.y(), with, with0);
    ++desks, whole += with, whole_without += with0, whole_defaults += top_solid(defaults);
  }
  EXPECT_EQ(whole_defaults, desks);
  EXPECT_EQ(whole, desks);
  EXPECT_LT(whole_without, desks) << "without the rule every desk's top was solid too: the test shows nothing";
}

// A chair's seat over free space in `m`: solid at the seat's middle somewhere 0.40–0.56 m up, air under its two
// front corners at 0.25 m (the chair's own frame; its base 0.30 m wide). What the seat tests of #211 and #241 ask.
bool seat_over_free_space(const PolygonMesh& m, const SynthBlock& b) {
  const double w = 2.0 * (b.own.max.x() - 0.30), d = 2.0 * (b.own.max.y() - 0.30);  // the seat (the base: 0.30 m)
  bool seat = false;
  for (int cm = 40; cm <= 56 && !seat; ++cm) seat = !is_air(m, from_own_frame(b, Vec3(0.5 * w, 0.5 * d, 0.01 * cm)));
  return seat && is_air(m, from_own_frame(b, Vec3(0.1, 0.1, 0.25))) && is_air(m, from_own_frame(b, Vec3(w - 0.1, 0.1, 0.25)));
}

// Issue 41 "every table and chair present": a seat that nothing of its piece stands on is a seat (DECISIONS #211).
// Office 2 rooms seed 2's chair at (0.84, 3.74) was seen from its front: its seat a plane of 17 inliers at 0.53 m,
// its back one point. No back, no step (#141), so no seat's free space (#179): its box stood from the floor to its
// highest point (0.83 m) with the floor unseen under the seat, and the min-cut made the whole chair air. With
// free_under_lone_tops (the default) the seat keeps the free space under it: solid at its middle and air under its
// front corners (as count_whole_chairs asks), not without the rule.
TEST(Office, ASeatWithNothingOnItKeepsTheFreeSpaceUnderIt) {
  const RuleOnAndOff o = office_rule_on_and_off(2, 2, &RecoveryParams::free_under_lone_tops);
  ASSERT_TRUE(o.validity.valid()) << o.validity.summary();
  const SynthScan& scan = o.scan;
  const PolygonMesh &mesh = o.with, &mesh0 = o.without;
  int found = 0;
  for (const SynthBlock& b : scan.blocks) {
    if (b.kind != "chair" || (b.origin - Vec3(0.84, 3.74, 0)).norm() > 0.05) continue;
    ++found;
    const auto whole = [&](const PolygonMesh& m) { return seat_over_free_space(m, b); };
    const bool with_rule = whole(mesh), without_rule = whole(mesh0);
    std::printf("chair at %.2f %.2f: seat over free space %d, without the rule %d\n", b.origin.x(), b.origin.y(), with_rule, without_rule);
    EXPECT_TRUE(with_rule);
    EXPECT_FALSE(without_rule) << "without the rule the seat stood over free space too: the test shows nothing";
  }
  EXPECT_EQ(found, 1) << "no chair there";
}

// Issue 41, DECISIONS #241: an upright plane stands under a raised top only with at least
// RecoveryParams::upright_min_inliers (3) of its inliers under it. Office 2 rooms seed 1, the chair at (5.39, 0.84):
// its seat's plane holds 14 inliers, its back's plane one point of the post 0.27 m up (the post's rear face lies
// within the inlier distance of the back's); with any inlier enough (1, as before) that point denied the seat its
// free space, the seat stood on a block down to the floor and the min-cut made the block air, seat and all. With
// the rule the seat is solid at its middle and its front corners have air under them.
TEST(Office, APostsPointInTheBacksPlaneLeavesTheSeatItsFreeSpace) {
  const SynthScan scan = furnished_office(2, 1);
  PipelineParams one;
  one.recovery.upright_min_inliers = 1;
  const PipelineResult r = run_pipeline(scan.cloud, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  const PolygonMesh mesh = in_scan_frame(scan, r), mesh1 = in_scan_frame(scan, run_pipeline(scan.cloud, one));
  int found = 0;
  for (const SynthBlock& b : scan.blocks) {
    if (b.kind != "chair" || (b.origin - Vec3(5.39, 0.84, 0)).norm() > 0.05) continue;
    ++found;
    const auto whole = [&](const PolygonMesh& m) { return seat_over_free_space(m, b); };
    const bool with_rule = whole(mesh), any_inlier = whole(mesh1);
    std::printf("chair at %.2f %.2f: seat over free space %d, with any inlier under it enough %d\n", b.origin.x(), b.origin.y(),
                with_rule, any_inlier);
    EXPECT_TRUE(with_rule);
    EXPECT_FALSE(any_inlier) << "with any inlier enough the seat stood over free space too: the test shows nothing";
  }
  EXPECT_EQ(found, 1) << "no chair there";
}

}  // namespace
}  // namespace hsr
