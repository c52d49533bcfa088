// Tests of the indoor synth models (hall, meeting_room): the truth is the room's air minus every piece of
// furniture (closed, oriented, valid, the volume and face count the construction gives), the pieces are
// clear of each other, of the walls and of the scanners, the points lie on the truth, the plane target is
// met from 100 to 2,000 planes, and the same seed gives the same bytes.
#include "eval/eval.h"
#include "io/io.h"
#include "synth/synth.h"

#include "core/error.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace hsr {
namespace {

SynthScan scan_of(const std::string& model, int blocks, double density, double noise = 0.0, std::uint64_t seed = 5) {
  SynthParams p;
  p.seed = seed;
  p.noise = noise;
  p.blocks = blocks;
  p.density = density;
  return run_synth(model, p);
}

const SynthScan& hall() {
  static const SynthScan s = scan_of("hall", 40, 20.0);
  return s;
}
const SynthScan& meeting_room() {
  static const SynthScan s = scan_of("meeting_room", 12, 60.0);
  return s;
}

double signed_volume(const PolygonMesh& m) {
  double v = 0;
  for (const auto& f : m.faces)
    for (std::size_t i = 1; i + 1 < f.size(); ++i)
      v += m.vertices[f[0]].dot(m.vertices[f[i]].cross(m.vertices[f[i + 1]])) / 6.0;
  return v;
}

/// Every directed edge once, its reverse once: closed, 2-manifold along edges, consistently oriented.
void expect_closed_and_oriented(const PolygonMesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& f : m.faces)
    for (std::size_t i = 0; i < f.size(); ++i) ++directed[{f[i], f[(i + 1) % f.size()]}];
  std::size_t bad = 0;
  for (const auto& [e, n] : directed)
    if (n != 1 || !directed.count({e.second, e.first})) ++bad;
  EXPECT_EQ(bad, 0u) << "edges used twice in one direction or not matched by their reverse";
}

TEST(SynthIndoor, NamesAndUnknownModel) {
  EXPECT_EQ(synth_indoor_model_names(), (std::vector<std::string>{"hall", "meeting_room", "office"}));
  try {
    run_synth("ballroom");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("meeting_room"), std::string::npos) << e.what();
  }
  SynthParams bad;
  bad.blocks = -1;
  EXPECT_THROW(run_synth("hall", bad), Error);
}

TEST(SynthIndoor, TruthsAreValidClosedSolids) {
  for (const SynthScan* s : {&hall(), &meeting_room()}) {
    SCOPED_TRACE(s->model);
    EXPECT_TRUE(s->indoor);
    expect_closed_and_oriented(s->truth);
    const Validity v = check_validity(s->truth, /*check_self_intersections=*/true);
    EXPECT_TRUE(v.valid()) << v.summary();
    // The air: less than the room, more than the room less the pieces' bounding boxes.
    const BBox room = bounding_box(s->truth.vertices);
    double bounds = 0;
    for (const SynthBlock& b : s->blocks) bounds += b.box.size().prod();
    EXPECT_LT(signed_volume(s->truth), room.size().prod());
    EXPECT_GE(signed_volume(s->truth), room.size().prod() - bounds - 1e-9);
    EXPECT_GT(signed_volume(s->truth), 0.8 * room.size().prod());
  }
}

TEST(SynthIndoor, HallVolumeIsTheRoomLessItsBoxesExactly) {
  // An axis-aligned block's volume is its bounding box's: take a small hall without a turned block.
  for (std::uint64_t seed = 1; seed < 40; ++seed) {
    const SynthScan s = scan_of("hall", 6, 0.5, 0.0, seed);
    if (std::any_of(s.blocks.begin(), s.blocks.end(), [](const SynthBlock& b) { return b.angle != 0; })) continue;
    double furniture = 0;
    for (const SynthBlock& b : s.blocks) furniture += b.box.size().prod();
    const BBox room = bounding_box(s.truth.vertices);
    EXPECT_NEAR(signed_volume(s.truth), room.size().prod() - furniture, 1e-9 * room.size().prod());
    return;
  }
  FAIL() << "no seed without a turned block";
}

TEST(SynthIndoor, HallFaceCountIsSixPerBlockPlusTheRoom) {
  // Each block, a box clear of everything: 5 faces (a pillar 4) and one hole in the floor (a pillar also
  // one in the ceiling); the room 6 faces.
  const SynthScan& s = hall();
  EXPECT_EQ(s.polygon_faces, 6 + 6 * s.blocks.size());
  EXPECT_EQ(s.blocks.size(), 40u);
  std::set<std::string> kinds;
  for (const SynthBlock& b : s.blocks) kinds.insert(b.kind);
  EXPECT_EQ(kinds, (std::set<std::string>{"cabinet", "crate", "desk", "pillar", "shelf"}));
}

TEST(SynthIndoor, PiecesAreClearOfEachOtherTheWallsAndTheScanners) {
  for (const SynthScan* s : {&hall(), &meeting_room()}) {
    SCOPED_TRACE(s->model);
    const BBox room = bounding_box(s->truth.vertices);
    const double clearance = s->model == "hall" ? 0.4 : 0.1;
    for (std::size_t i = 0; i < s->blocks.size(); ++i) {
      const BBox& a = s->blocks[i].box;
      EXPECT_GE(a.min.z(), 0.0);
      EXPECT_GT(a.min.x(), room.min.x());
      EXPECT_GT(a.min.y(), room.min.y());
      EXPECT_LT(a.max.x(), room.max.x());
      EXPECT_LT(a.max.y(), room.max.y());
      for (std::size_t j = 0; j < i; ++j) {
        const BBox& b = s->blocks[j].box;
        const double gap = std::max({a.min.x() - b.max.x(), b.min.x() - a.max.x(), a.min.y() - b.max.y(), b.min.y() - a.max.y()});
        EXPECT_GE(gap, clearance - 1e-9) << i << " and " << j;
      }
      for (const Vec3& sc : s->scanners)
        EXPECT_FALSE(sc.x() > a.min.x() && sc.x() < a.max.x() && sc.y() > a.min.y() && sc.y() < a.max.y() &&
                     sc.z() < a.max.z());
    }
    EXPECT_GE(s->scanners.size(), 3u);
  }
}

TEST(SynthIndoor, NoiseFreePointsLieOnTheTruthAndFaceTheirScanner) {
  for (const SynthScan* s : {&hall(), &meeting_room()}) {
    SCOPED_TRACE(s->model);
    EvalParams ep;
    ep.mesh_samples = 20000;
    const EvalResult r = run_eval(s->cloud, s->truth, &s->truth, ep);
    EXPECT_LE(r.accuracy.p2m_max, 1e-9);
    for (std::size_t i = 0; i < s->cloud.size(); i += 97) {
      const Vec3 to_scanner = s->scanners.at(s->point_scanner[i]) - s->cloud.points[i];
      EXPECT_GT(s->cloud.normals[i].dot(to_scanner), 0.0);
      EXPECT_NEAR(s->cloud.normals[i].dot(s->planes[s->point_plane[i]].plane.normal), -1.0, 1e-12);
    }
  }
}

TEST(SynthIndoor, DensityIsPointsPerSquareMetreOfTheTruth) {
  double area = 0;
  for (const SynthPlane& p : hall().planes) area += p.area;
  EXPECT_NEAR(static_cast<double>(hall().cloud.size()), 20.0 * area, 0.1 * 20.0 * area);
  // Default density: 60 points/m² for the hall.
  SynthParams p;
  p.blocks = 10;
  const SynthScan s = run_synth("hall", p);
  double a = 0;
  for (const SynthPlane& q : s.planes) a += q.area;
  EXPECT_NEAR(static_cast<double>(s.cloud.size()), 60.0 * a, 0.1 * 60.0 * a);
  EXPECT_EQ(s.target_points, static_cast<std::size_t>(std::llround(60.0 * a)));
}

TEST(SynthIndoor, PlaneTargetFromOneHundredToTwoThousand) {
  for (int target : {100, 500, 1000, 2000}) {
    SynthParams p;
    p.planes = target;
    p.density = 0.2;  // few points: only the truth is looked at
    const SynthScan s = run_synth("hall", p);
    EXPECT_GE(static_cast<double>(s.planes.size()), 0.95 * target) << target;
    EXPECT_LE(static_cast<double>(s.planes.size()), 1.05 * target) << target;
    expect_closed_and_oriented(s.truth);
    if (target == 2000) {
      const BBox room = bounding_box(s.truth.vertices);
      EXPECT_GT(room.size().x(), 40.0);  // the hall grows beyond 250 blocks
    }
  }
}

TEST(SynthIndoor, MeetingRoomHasItsChairsTableAndCabinets) {
  const SynthScan& s = meeting_room();
  std::map<std::string, int> kinds;
  for (const SynthBlock& b : s.blocks) ++kinds[b.kind];
  EXPECT_EQ(kinds["table"], 1);
  EXPECT_GE(kinds["chair"], 10);  // a chair that touches its neighbour is left out
  EXPECT_LE(kinds["chair"], 12);
  EXPECT_GE(kinds["cabinet"], 2);
  // Every chair is turned (a little, or half a turn plus a little) and has its own planes.
  for (const SynthBlock& b : s.blocks)
    if (b.kind == "chair") EXPECT_NE(b.angle, 0.0);
  EXPECT_GT(s.planes.size(), 6 + 5 * static_cast<std::size_t>(kinds["chair"]));
}

std::string read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(SynthIndoor, SameSeedSameBytesOtherSeedOtherHall) {
  const std::filesystem::path tmp = std::filesystem::path(HSR_TEST_TMP_DIR) / "synth_indoor";
  std::filesystem::remove_all(tmp);
  SynthParams p;
  p.blocks = 25;
  p.density = 10;
  write_synth(run_synth("hall", p), (tmp / "a").string());
  write_synth(run_synth("hall", p), (tmp / "b").string());
  p.seed = 2;
  write_synth(run_synth("hall", p), (tmp / "c").string());
  for (const char* f : {"points.ply", "truth.obj", "planes.json"}) {
    EXPECT_EQ(read_bytes(tmp / "a" / f), read_bytes(tmp / "b" / f)) << f;
    EXPECT_NE(read_bytes(tmp / "a" / f), read_bytes(tmp / "c" / f)) << f;
  }
  const nlohmann::json j = nlohmann::json::parse(read_bytes(tmp / "a" / "planes.json"));
  EXPECT_EQ(j["blocks"].size(), 25u);
  EXPECT_EQ(j["polygon_faces"].get<std::size_t>(), 6u + 6u * 25u);
  EXPECT_NEAR(j["noise_sigma"].get<double>(), 0.01, 1e-12);  // 0.001 of 10 m, whatever the hall's size
}

}  // namespace
}  // namespace hsr
