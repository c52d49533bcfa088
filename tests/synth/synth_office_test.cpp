// Tests of the office model (synth office, issue 41 item 1): the truth is a closed, oriented, valid solid for
// 1 to 6 rooms; every truth face belongs to the room (walls, floor, ceilings), a partition, or exactly one
// listed piece, and the pieces listed are the counts asked for; a floor point hidden behind a pillar from
// the station is absent from the scan; the same seed gives the same bytes.
#include "eval/eval.h"
#include "synth/synth.h"

#include "common/test_util.h"
#include "core/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace hsr {
namespace {

SynthScan office(int rooms, std::uint64_t seed, double density, int scanners = 2) {
  SynthParams p;
  p.seed = seed;
  p.noise = 0.0;
  p.density = density;
  p.office.rooms = rooms;
  p.office.scanners = scanners;
  return run_synth("office", p);
}

/// Every directed edge once, its reverse once: closed, 2-manifold along edges, consistently oriented.
std::size_t unmatched_edges(const PolygonMesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& f : m.faces)
    for (std::size_t i = 0; i < f.size(); ++i) ++directed[{f[i], f[(i + 1) % f.size()]}];
  std::size_t bad = 0;
  for (const auto& [e, n] : directed)
    if (n != 1 || !directed.count({e.second, e.first})) ++bad;
  return bad;
}

/// The world point p in the block's own frame.
Vec3 in_own_frame(const SynthBlock& b, const Vec3& p) {
  const double c = std::cos(b.angle), s = std::sin(b.angle);
  const Vec3 d = p - b.origin;
  return {c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z()};
}

bool holds(const SynthBlock& b, const Vec3& p, double tol) {
  const Vec3 q = in_own_frame(b, p);
  return (q.array() >= b.own.min.array() - tol).all() && (q.array() <= b.own.max.array() + tol).all();
}

TEST(SynthOffice, TruthsAreValidClosedSolidsFromOneToSixRooms) {
  for (int rooms : {1, 3, 6}) {
    SCOPED_TRACE(rooms);
    const SynthScan s = office(rooms, 3, 2.0);
    EXPECT_TRUE(s.indoor);
    EXPECT_EQ(unmatched_edges(s.truth), 0u);
    const Validity v = check_validity(s.truth, /*check_self_intersections=*/true);
    EXPECT_TRUE(v.valid()) << v.summary();
    EXPECT_EQ(s.scanners.size(), 2u * rooms);
  }
}

TEST(SynthOffice, EveryFaceIsTheRoomsAPartitionsOrOnePiecesAndTheCountsAreTheOptions) {
  for (int rooms : {2, 5}) {
    SCOPED_TRACE(rooms);
    const SynthScan s = office(rooms, 7, 1.0);
    const SynthOfficeParams o;
    std::map<std::string, int> kinds;
    for (const SynthBlock& b : s.blocks) ++kinds[b.kind];
    const int rows = rooms >= 4 ? 2 : 1, second = rooms - (rooms + rows - 1) / rows;
    EXPECT_EQ(kinds["table"], o.tables * rooms);
    EXPECT_EQ(kinds["chair"], o.chairs * rooms);
    EXPECT_EQ(kinds["desk"], o.desks * rooms);
    EXPECT_EQ(kinds["cabinet"], o.cabinets * rooms);
    EXPECT_EQ(kinds["shelf"], o.shelves * rooms);
    EXPECT_EQ(kinds["pillar"], o.pillars * rooms);
    EXPECT_EQ(kinds["partition"], rooms - rows + (rows - 1));  // one between neighbours in a row, one between rows
    EXPECT_EQ(kinds["doorway"], rooms - rows + second);
    // Each truth face off the floor, the ceiling and the outer walls lies in a partition or in exactly one
    // piece; each piece holds faces (it is in the truth, not only in the list).
    const BBox box = bounding_box(s.truth.vertices);
    std::vector<int> faces_of(s.blocks.size(), 0);
    for (const auto& f : s.truth.faces) {
      auto all = [&](auto&& pred) { return std::all_of(f.begin(), f.end(), [&](std::uint32_t v) { return pred(s.truth.vertices[v]); }); };
      bool room = false;
      for (int a = 0; a < 3; ++a)
        room = room || all([&](const Vec3& p) { return p[a] == box.min[a]; }) || all([&](const Vec3& p) { return p[a] == box.max[a]; });
      if (room) continue;
      int pieces = 0, partitions = 0;
      for (std::size_t b = 0; b < s.blocks.size(); ++b) {
        if (!all([&](const Vec3& p) { return holds(s.blocks[b], p, 1e-9); })) continue;
        if (s.blocks[b].kind == "partition") ++partitions;
        else if (s.blocks[b].kind != "doorway") ++pieces, ++faces_of[b];
      }
      EXPECT_EQ(pieces + (partitions > 0 ? 1 : 0), 1) << "a face in " << pieces << " pieces, " << partitions << " partitions";
    }
    for (std::size_t b = 0; b < s.blocks.size(); ++b)
      if (s.blocks[b].kind != "doorway" && s.blocks[b].kind != "partition")
        EXPECT_GE(faces_of[b], s.blocks[b].kind == "cabinet" ? 5 : 6) << s.blocks[b].kind;
  }
}

TEST(SynthOffice, PiecesAreTurnedAtAnyAngleAndThePillarsAreRound) {
  const SynthScan s = office(3, 2, 1.0);
  int turned = 0, pillars = 0;
  for (const SynthBlock& b : s.blocks) {
    if (b.kind == "pillar") {
      ++pillars;
      continue;
    }
    if (std::fmod(b.angle, 0.5 * M_PI) > 0.01) ++turned;
  }
  EXPECT_GE(turned, 20);
  EXPECT_EQ(pillars, 3);
  // 24 sides per pillar: 24 distinct vertical planes through no other face.
  std::size_t vertical = 0;
  for (const SynthPlane& p : s.planes)
    if (std::abs(p.plane.normal.z()) < 1e-9 && std::abs(p.plane.normal.x()) > 1e-6 && std::abs(p.plane.normal.y()) > 1e-6) ++vertical;
  EXPECT_GE(vertical, 3u * 24u);
}

TEST(SynthOffice, AFloorPointBehindAPillarFromTheStationIsAbsent) {
  // One station per room: the pillar's shadow on the floor is the set of floor points whose sight line to
  // the station passes through the pillar (its inscribed circle, less 2 cm).
  const SynthScan s = office(1, 4, 400.0, /*scanners=*/1);
  ASSERT_EQ(s.scanners.size(), 1u);
  const Vec3 st = s.scanners[0];
  const SynthBlock* pillar = nullptr;
  for (const SynthBlock& b : s.blocks)
    if (b.kind == "pillar") pillar = &b;
  ASSERT_NE(pillar, nullptr);
  const Vec3 c = pillar->box.center();
  const double r = 0.5 * pillar->box.size().x() * std::cos(M_PI / 24) - 0.02;
  auto shadowed = [&](const Vec3& q) {
    // The segment station -> q (in plan) passes within r of the pillar's axis, beyond it.
    const Eigen::Vector2d a = st.head<2>(), b = q.head<2>(), o = c.head<2>();
    const double t = std::clamp((o - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    return t < 1.0 && (a + t * (b - a) - o).norm() < r && (b - o).norm() > r + 0.05;
  };
  // Floor in the shadow (a 5 cm grid, off the furniture): enough for many points at 400 per m².
  const BBox room = bounding_box(s.truth.vertices);
  int shadow_cells = 0;
  for (double x = room.min.x() + 0.025; x < room.max.x(); x += 0.05)
    for (double y = room.min.y() + 0.025; y < room.max.y(); y += 0.05) {
      const Vec3 q(x, y, 0);
      bool under = false;
      for (const SynthBlock& b : s.blocks) under = under || (b.kind != "pillar" && holds(b, q, 0.05));
      if (!under && shadowed(q)) ++shadow_cells;
    }
  EXPECT_GT(shadow_cells * 0.0025, 0.2) << "the pillar casts too small a shadow to test";
  int in_shadow = 0, on_floor = 0;
  for (const Vec3& p : s.cloud.points)
    if (std::abs(p.z()) < 1e-9) {
      ++on_floor;
      if (shadowed(p)) ++in_shadow;
    }
  EXPECT_GT(on_floor, 1000);
  EXPECT_EQ(in_shadow, 0);
}

std::string read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(SynthOffice, SameSeedSameBytesOtherSeedOtherOffice) {
  const std::filesystem::path tmp = test::scratch_dir("synth_office_bytes");
  SynthParams p;
  p.office.rooms = 3;
  p.density = 10;
  write_synth(run_synth("office", p), (tmp / "a").string());
  write_synth(run_synth("office", p), (tmp / "b").string());
  p.seed = 2;
  write_synth(run_synth("office", p), (tmp / "c").string());
  for (const char* f : {"points.ply", "truth.obj", "planes.json"}) {
    EXPECT_EQ(read_bytes(tmp / "a" / f), read_bytes(tmp / "b" / f)) << f;
    EXPECT_NE(read_bytes(tmp / "a" / f), read_bytes(tmp / "c" / f)) << f;
  }
}

TEST(SynthOffice, BadOptionsAreOneError) {
  SynthParams p;
  p.office.rooms = 7;
  EXPECT_THROW(run_synth("office", p), Error);
  p.office.rooms = 2;
  p.office.partition = 0.0;
  EXPECT_THROW(run_synth("office", p), Error);
  p.office.partition = 0.12;
  p.office.chairs = 40;  // no room for 40 chairs: one error, no endless search
  EXPECT_THROW(run_synth("office", p), Error);
}

}  // namespace
}  // namespace hsr
