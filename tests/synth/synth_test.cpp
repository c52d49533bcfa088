// Tests of the synth stage: the truth meshes are valid closed solids with known volumes, the scans are
// exact samples of the truth seen from the scanners (occlusion, orientation, missing bottoms), and the
// whole thing is deterministic for a seed.
#include "synth/synth.h"

#include "core/error.h"
#include "io/io.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace hsr {
namespace {

const std::vector<std::string> kModels = {"box", "house", "dormer_house", "bracket", "room", "courtyard"};

struct Tri {
  Vec3 a, b, c;
};

std::vector<Tri> fan_triangles(const PolygonMesh& m) {
  std::vector<Tri> tris;
  for (const auto& f : m.faces)
    for (std::size_t i = 1; i + 1 < f.size(); ++i) tris.push_back({m.vertices[f[0]], m.vertices[f[i]], m.vertices[f[i + 1]]});
  return tris;
}

double signed_volume(const PolygonMesh& m) {
  double v = 0;
  for (const Tri& t : fan_triangles(m)) v += t.a.dot(t.b.cross(t.c)) / 6.0;
  return v;
}

/// Generalised winding number of a closed mesh at p (1 inside, 0 outside), from triangle solid angles.
double winding_number(const PolygonMesh& m, const Vec3& p) {
  double total = 0;
  for (const Tri& t : fan_triangles(m)) {
    const Vec3 a = t.a - p, b = t.b - p, c = t.c - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double num = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    total += 2.0 * std::atan2(num, den);
  }
  return total / (4.0 * M_PI);
}

/// Möller–Trumbore: parameter t of the hit of origin + t * dir with the triangle, or -1.
double ray_triangle(const Vec3& o, const Vec3& d, const Tri& t) {
  const Vec3 e1 = t.b - t.a, e2 = t.c - t.a, pv = d.cross(e2);
  const double det = e1.dot(pv);
  if (std::abs(det) < 1e-14) return -1;
  const Vec3 tv = o - t.a;
  const double u = tv.dot(pv) / det;
  if (u < 0 || u > 1) return -1;
  const Vec3 qv = tv.cross(e1);
  const double v = d.dot(qv) / det;
  if (v < 0 || u + v > 1) return -1;
  return e2.dot(qv) / det;
}

/// Distance from p to a convex planar polygon (exact for points whose projection is inside, else to edges).
double point_polygon_distance(const PolygonMesh& m, const std::vector<std::uint32_t>& f, const Vec3& p) {
  Vec3 n = Vec3::Zero();
  for (std::size_t i = 0; i < f.size(); ++i) n += m.vertices[f[i]].cross(m.vertices[f[(i + 1) % f.size()]]);
  n.normalize();
  const double sd = n.dot(p - m.vertices[f[0]]);
  const Vec3 q = p - sd * n;
  bool inside = true;
  double edge_dist = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < f.size(); ++i) {
    const Vec3& a = m.vertices[f[i]];
    const Vec3& b = m.vertices[f[(i + 1) % f.size()]];
    if ((b - a).cross(q - a).dot(n) < 0) inside = false;
    const double s = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    edge_dist = std::min(edge_dist, (p - (a + s * (b - a))).norm());
  }
  return inside ? std::abs(sd) : edge_dist;
}

/// One noise-free scan per model, shared by the tests (the scans are the expensive part).
const SynthScan& exact_scan(const std::string& model) {
  static std::map<std::string, SynthScan> cache;
  auto it = cache.find(model);
  if (it == cache.end()) {
    SynthParams p;
    p.noise = 0;
    p.target_points = 12000;
    p.seed = 3;
    it = cache.emplace(model, run_synth(model, p)).first;
  }
  return it->second;
}

std::string read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(Synth, ModelNamesInFixedOrder) { EXPECT_EQ(synth_model_names(), kModels); }

TEST(Synth, UnknownModelThrowsBadInputListingValidNames) {
  try {
    run_synth("castle");
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_EQ(e.status(), Status::BadInput);
    EXPECT_NE(std::string(e.what()).find("dormer_house"), std::string::npos) << e.what();
  }
  SynthParams bad;
  bad.noise = -1;
  EXPECT_THROW(run_synth("box", bad), Error);
}

class SynthModel : public ::testing::TestWithParam<std::string> {};

TEST_P(SynthModel, TruthIsClosedManifoldAndConsistentlyOriented) {
  const PolygonMesh& m = exact_scan(GetParam()).truth;
  ASSERT_GT(m.num_faces(), 0u);
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& f : m.faces) {
    ASSERT_GE(f.size(), 3u);
    std::vector<std::uint32_t> s = f;
    std::sort(s.begin(), s.end());
    ASSERT_EQ(std::adjacent_find(s.begin(), s.end()), s.end()) << "repeated vertex in a face";
    for (std::size_t i = 0; i < f.size(); ++i) {
      ASSERT_LT(f[i], m.num_vertices());
      ++directed[{f[i], f[(i + 1) % f.size()]}];
    }
  }
  for (const auto& [e, count] : directed) {
    EXPECT_EQ(count, 1) << "directed edge used twice: " << e.first << "-" << e.second;
    auto rev = directed.find({e.second, e.first});
    ASSERT_NE(rev, directed.end()) << "border edge " << e.first << "-" << e.second;
    EXPECT_EQ(rev->second, 1);
  }
}

TEST_P(SynthModel, FacesArePlanarAndConvex) {
  const PolygonMesh& m = exact_scan(GetParam()).truth;
  for (const auto& f : m.faces) {
    Vec3 n = Vec3::Zero();
    for (std::size_t i = 0; i < f.size(); ++i) n += m.vertices[f[i]].cross(m.vertices[f[(i + 1) % f.size()]]);
    n.normalize();
    for (std::size_t i = 0; i < f.size(); ++i) {
      const Vec3& a = m.vertices[f[i]];
      const Vec3& b = m.vertices[f[(i + 1) % f.size()]];
      const Vec3& c = m.vertices[f[(i + 2) % f.size()]];
      EXPECT_NEAR(n.dot(a - m.vertices[f[0]]), 0.0, 1e-9);
      EXPECT_GE((b - a).cross(c - b).dot(n), -1e-9) << "reflex corner";
    }
    // Vertex 0 is a strict corner, so the fan's first triangle has area.
    EXPECT_GT((m.vertices[f[1]] - m.vertices[f[0]]).cross(m.vertices[f.back()] - m.vertices[f[0]]).dot(n), 1e-9);
  }
}

TEST_P(SynthModel, VolumeMatchesTheConstruction) {
  // Hand-computed volumes of the CSG recipes (see models.cpp); e.g. house = two 27 m^2-profile wings
  // (10 m + 8 m long) plus the 9 m^3 where the side wing's roof rises above the main roof in the valley.
  const std::map<std::string, double> expected = {
      {"box", 24.0},         {"house", 270.0 + 216.0 + 9.0},        {"dormer_house", 480.0 + 1.856 + 3.5},
      {"bracket", 74.76},    {"room", 144.0 - 0.216 - 0.018432 - 0.75}, {"courtyard", 1092.0 + 1170.0}};
  EXPECT_NEAR(signed_volume(exact_scan(GetParam()).truth), expected.at(GetParam()), 1e-9 * expected.at(GetParam()));
}

TEST_P(SynthModel, PlanesPartitionTheFacesAndAreasAddUp) {
  const SynthScan& s = exact_scan(GetParam());
  ASSERT_EQ(s.face_plane.size(), s.truth.num_faces());
  std::vector<double> area(s.planes.size(), 0.0);
  double total = 0;
  for (std::size_t f = 0; f < s.truth.num_faces(); ++f) {
    const auto& loop = s.truth.faces[f];
    Vec3 newell = Vec3::Zero();
    for (std::size_t i = 0; i < loop.size(); ++i)
      newell += s.truth.vertices[loop[i]].cross(s.truth.vertices[loop[(i + 1) % loop.size()]]);
    const Plane& p = s.planes.at(s.face_plane[f]).plane;
    EXPECT_GT(newell.normalized().dot(p.normal), 1 - 1e-9) << "face normal differs from its plane's";
    for (auto v : loop) EXPECT_NEAR(p.signed_distance(s.truth.vertices[v]), 0.0, 1e-9);
    area[s.face_plane[f]] += 0.5 * newell.norm();
    total += 0.5 * newell.norm();
  }
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    EXPECT_NEAR(s.planes[k].area, area[k], 1e-9 * total);
    EXPECT_NEAR(s.planes[k].plane.normal.norm(), 1.0, 1e-12);
    for (std::size_t j = 0; j < k; ++j)  // distinct planes
      EXPECT_FALSE(s.planes[j].plane.normal.dot(s.planes[k].plane.normal) > 1 - 1e-9 &&
                   std::abs(s.planes[j].plane.offset - s.planes[k].plane.offset) < 1e-9);
  }
}

TEST_P(SynthModel, NoiseFreePointsLieOnTheTruthOnTheirPlane) {
  const SynthScan& s = exact_scan(GetParam());
  const double diag = bounding_box(s.truth.vertices).diagonal();
  ASSERT_EQ(s.point_plane.size(), s.cloud.size());
  ASSERT_EQ(s.point_scanner.size(), s.cloud.size());
  ASSERT_TRUE(s.cloud.has_normals());
  std::vector<std::vector<std::size_t>> faces_of_plane(s.planes.size());
  for (std::size_t f = 0; f < s.face_plane.size(); ++f) faces_of_plane[s.face_plane[f]].push_back(f);
  std::size_t off_truth = 0;
  for (std::size_t i = 0; i < s.cloud.size(); ++i) {
    const int k = s.point_plane[i];
    ASSERT_GE(k, 0);
    ASSERT_LT(k, static_cast<int>(s.planes.size()));
    EXPECT_LE(std::abs(s.planes[k].plane.signed_distance(s.cloud.points[i])), 1e-6 * diag);
    double d = std::numeric_limits<double>::infinity();
    for (std::size_t f : faces_of_plane[k]) d = std::min(d, point_polygon_distance(s.truth, s.truth.faces[f], s.cloud.points[i]));
    if (d > 1e-6 * diag) ++off_truth;
  }
  EXPECT_EQ(off_truth, 0u) << "points outside the faces of their plane";
}

TEST_P(SynthModel, NormalsAreThePlaneNormalTurnedTowardsTheScanner) {
  const SynthScan& s = exact_scan(GetParam());
  for (std::size_t i = 0; i < s.cloud.size(); ++i) {
    const Vec3& n = s.cloud.normals[i];
    EXPECT_NEAR(n.norm(), 1.0, 1e-12);
    const Vec3 to_scanner = s.scanners.at(s.point_scanner[i]) - s.cloud.points[i];
    EXPECT_GT(n.dot(to_scanner), 0.0);
    // Outdoor: the scanners see the outside of the solid; the room's scanners are inside its air volume.
    const double agree = n.dot(s.planes[s.point_plane[i]].plane.normal);
    EXPECT_NEAR(agree, s.indoor ? -1.0 : 1.0, 1e-12);
  }
}

TEST_P(SynthModel, EveryPointIsTheFirstHitFromItsScanner) {
  const SynthScan& s = exact_scan(GetParam());
  const std::vector<Tri> tris = fan_triangles(s.truth);
  const double diag = bounding_box(s.truth.vertices).diagonal();
  std::size_t occluded = 0, checked = 0;
  for (std::size_t i = 0; i < s.cloud.size(); i += 37) {
    const Vec3 o = s.scanners[s.point_scanner[i]];
    const Vec3 d = (s.cloud.points[i] - o).normalized();
    const double range = (s.cloud.points[i] - o).norm();
    for (const Tri& t : tris) {
      const double h = ray_triangle(o, d, t);
      if (h > 0 && h < range - 1e-6 * diag) { ++occluded; break; }
    }
    ++checked;
  }
  EXPECT_GT(checked, 100u);
  EXPECT_EQ(occluded, 0u);
}

TEST_P(SynthModel, PointCountNearTargetAndPlaneCountsConsistent) {
  const SynthScan& s = exact_scan(GetParam());
  EXPECT_NEAR(static_cast<double>(s.cloud.size()), 12000.0, 0.15 * 12000.0);
  std::vector<std::size_t> count(s.planes.size(), 0);
  for (int k : s.point_plane) ++count[k];
  for (std::size_t k = 0; k < s.planes.size(); ++k) EXPECT_EQ(s.planes[k].points, count[k]);
}

TEST_P(SynthModel, ScannersAreInsideOnlyForTheRoom) {
  const SynthScan& s = exact_scan(GetParam());
  for (const Vec3& p : s.scanners) {
    const double w = winding_number(s.truth, p);
    if (GetParam() == "room") {
      EXPECT_NEAR(w, 1.0, 1e-6) << "room scanner not inside the room's air";
    } else {
      EXPECT_NEAR(w, 0.0, 1e-6) << "scanner inside the model";
    }
  }
  EXPECT_EQ(s.indoor, GetParam() == "room");
}

TEST_P(SynthModel, BottomFacesOfOutdoorModelsHaveNoPoints) {
  const SynthScan& s = exact_scan(GetParam());
  int bottom = -1;
  for (std::size_t k = 0; k < s.planes.size(); ++k)
    if (s.planes[k].plane.normal.z() < -1 + 1e-9 && std::abs(s.planes[k].plane.offset) < 1e-9) bottom = static_cast<int>(k);
  if (GetParam() == "room") {
    // The room's floor bounds its air from below: its truth normal points down (out of the air), and the
    // scanners inside see it.
    ASSERT_GE(bottom, 0);
    EXPECT_GT(s.planes[bottom].points, 0u);
    return;
  }
  ASSERT_GE(bottom, 0) << "no bottom plane z = 0";
  EXPECT_EQ(std::count(s.point_plane.begin(), s.point_plane.end(), bottom), 0);
  for (const Vec3& p : s.cloud.points) EXPECT_GT(p.z(), -1e-9);
}

INSTANTIATE_TEST_SUITE_P(AllModels, SynthModel, ::testing::ValuesIn(kModels));

TEST(Synth, BoxHasSixPlanesAndOnlyTheBottomIsMissing) {
  const SynthScan& s = exact_scan("box");
  ASSERT_EQ(s.planes.size(), 6u);
  double area = 0;
  for (const SynthPlane& p : s.planes) {
    area += p.area;
    const bool is_bottom = p.plane.normal.z() < -0.5;
    EXPECT_EQ(p.points == 0, is_bottom);
  }
  EXPECT_NEAR(area, 2 * (4 * 3 + 4 * 2 + 3 * 2), 1e-12);
}

TEST(Synth, HousePlanes) {
  // ground, walls x=0, x=4, x=10 (gable + side-wing wall), y=0, y=6, y=14, four roof slopes.
  const SynthScan& s = exact_scan("house");
  EXPECT_EQ(s.planes.size(), 11u);
  int slopes = 0;
  for (const SynthPlane& p : s.planes)
    if (std::abs(std::abs(p.plane.normal.z()) - std::sqrt(0.5)) < 1e-9) {
      ++slopes;
      EXPECT_GT(p.points, 0u) << "roof slope not seen by the aerial scanner";
    }
  EXPECT_EQ(slopes, 4);
}

TEST(Synth, DefaultNoiseIsRangeNoiseOfTheGivenSigma) {
  SynthParams p;
  p.target_points = 20000;
  const SynthScan s = run_synth("house", p);
  const double sigma = p.noise * bounding_box(s.truth.vertices).diagonal();
  double sum2 = 0;
  for (std::size_t i = 0; i < s.cloud.size(); ++i) {
    const double d = s.planes[s.point_plane[i]].plane.signed_distance(s.cloud.points[i]);
    EXPECT_LE(std::abs(d), 6 * sigma);
    sum2 += d * d;
  }
  // Distance to the plane = range error * |cos(incidence)|, so the RMS is a fraction of sigma.
  const double rms = std::sqrt(sum2 / static_cast<double>(s.cloud.size()));
  EXPECT_GT(rms, 0.2 * sigma);
  EXPECT_LT(rms, 1.0 * sigma);
}

TEST(Synth, CustomScannersAreUsed) {
  SynthParams p;
  p.noise = 0;
  p.target_points = 3000;
  p.scanners = {Vec3(2, 1.5, 20)};  // straight above the box: only the top is visible
  const SynthScan s = run_synth("box", p);
  ASSERT_EQ(s.scanners.size(), 1u);
  ASSERT_FALSE(s.cloud.empty());
  for (const Vec3& q : s.cloud.points) EXPECT_NEAR(q.z(), 2.0, 1e-9);
}

TEST(Synth, DistantScannerStillReachesTheTarget) {
  // From 300 m the 4 x 3 x 2 box covers ~1e-5 of the sphere: the pilot must grow to find it.
  SynthParams p;
  p.noise = 0;
  p.target_points = 2000;
  p.scanners = {Vec3(300, 200, 150)};
  const SynthScan s = run_synth("box", p);
  EXPECT_NEAR(static_cast<double>(s.cloud.size()), 2000.0, 0.2 * 2000.0);
  // Only faces looking towards +x, +y, +z are visible from there.
  for (std::size_t i = 0; i < s.cloud.size(); ++i) EXPECT_GT(s.planes[s.point_plane[i]].plane.normal.sum(), 0.5);
}

TEST(Synth, DeterministicForASeedAndDifferentAcrossSeeds) {
  SynthParams p;
  p.seed = 7;
  p.target_points = 5000;
  const SynthScan a = run_synth("dormer_house", p), b = run_synth("dormer_house", p);
  ASSERT_EQ(a.cloud.size(), b.cloud.size());
  EXPECT_TRUE(a.cloud.points == b.cloud.points);
  EXPECT_TRUE(a.cloud.normals == b.cloud.normals);
  EXPECT_EQ(a.point_plane, b.point_plane);
  p.seed = 8;
  const SynthScan c = run_synth("dormer_house", p);
  EXPECT_FALSE(c.cloud.points == a.cloud.points);

  const std::filesystem::path tmp = std::filesystem::path(HSR_TEST_TMP_DIR) / "determinism";
  std::filesystem::remove_all(tmp);
  write_synth(a, (tmp / "a").string());
  write_synth(b, (tmp / "b").string());
  for (const char* name : {"points.ply", "truth.obj", "planes.json"}) {
    const std::string fa = read_bytes(tmp / "a" / name), fb = read_bytes(tmp / "b" / name);
    EXPECT_FALSE(fa.empty()) << name;
    EXPECT_EQ(fa, fb) << name << " differs between two runs with the same seed";
  }
}

TEST(Synth, WrittenFilesRoundTrip) {
  SynthParams p;
  p.target_points = 4000;
  const SynthScan s = run_synth("bracket", p);
  const std::filesystem::path dir = std::filesystem::path(HSR_TEST_TMP_DIR) / "roundtrip";
  std::filesystem::remove_all(dir);
  write_synth(s, dir.string());
  for (const auto& e : std::filesystem::directory_iterator(dir))
    EXPECT_EQ(e.path().string().find(".tmp-"), std::string::npos) << "leftover temporary " << e.path();

  std::ifstream in(dir / "planes.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("model"), "bracket");
  EXPECT_EQ(j.at("seed").get<std::uint64_t>(), p.seed);
  EXPECT_DOUBLE_EQ(j.at("noise").get<double>(), p.noise);
  EXPECT_EQ(j.at("scanners").size(), s.scanners.size());
  ASSERT_EQ(j.at("planes").size(), s.planes.size());
  std::size_t total = 0;
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    const auto& jp = j["planes"][k];
    EXPECT_DOUBLE_EQ(jp.at("offset").get<double>(), s.planes[k].plane.offset);
    EXPECT_DOUBLE_EQ(jp.at("area").get<double>(), s.planes[k].area);
    total += jp.at("points").get<std::size_t>();
  }
  EXPECT_EQ(total, s.cloud.size());

  const PointCloud pts = read_points((dir / "points.ply").string());
  ASSERT_EQ(pts.size(), s.cloud.size());
  EXPECT_TRUE(pts.has_normals());
  for (std::size_t i = 0; i < pts.size(); i += 97) {
    EXPECT_LT((pts.points[i] + pts.origin - s.cloud.points[i]).norm(), 1e-5);
    EXPECT_LT((pts.normals[i] - s.cloud.normals[i]).norm(), 1e-5);
  }
  const PolygonMesh truth = read_mesh((dir / "truth.obj").string());
  EXPECT_EQ(truth.num_faces(), s.truth.num_faces());
  EXPECT_EQ(truth.num_vertices(), s.truth.num_vertices());
}

TEST(Synth, DefaultParamsGiveAboutFortyThousandPoints) {
  for (const std::string& model : kModels) {
    const SynthScan s = run_synth(model);
    EXPECT_NEAR(static_cast<double>(s.cloud.size()), 40000.0, 0.15 * 40000.0) << model;
  }
}

}  // namespace
}  // namespace hsr
