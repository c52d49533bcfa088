// src/city/lods.h: the LoD 1.2 / 1.3 solids and the attributes of a feature, on solids whose answers are known:
// a box (LoD 1.2 volume = footprint area x height), two boxes of different heights side by side (LoD 1.3 has
// both levels, its volume their sum), a gable roof of known pitch (slope and azimuth of each roof surface),
// the roof type, the --lod list.
#include "city/lods.h"

#include "core/error.h"
#include "eval/eval.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace hsr;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// A closed solid from plan rings: `bottom` (counter-clockwise from above) at z0, and the faces given.
struct Builder {
  PolygonMesh m;
  std::uint32_t v(double x, double y, double z) {
    for (std::uint32_t i = 0; i < m.vertices.size(); ++i)
      if (m.vertices[i] == Vec3(x, y, z)) return i;
    m.vertices.emplace_back(x, y, z);
    return static_cast<std::uint32_t>(m.vertices.size() - 1);
  }
  void face(std::vector<std::uint32_t> f, FaceClass c) {
    m.faces.push_back(std::move(f));
    m.face_class.push_back(c);
  }
};

/// An axis-aligned box [0, w] x [0, d] x [z0, z1] with ground, walls and a flat roof.
PolygonMesh box(double w, double d, double z0, double z1) {
  Builder b;
  const auto g = [&](double x, double y) { return b.v(x, y, z0); };
  const auto t = [&](double x, double y) { return b.v(x, y, z1); };
  b.face({g(0, 0), g(0, d), g(w, d), g(w, 0)}, FaceClass::Ground);
  b.face({t(0, 0), t(w, 0), t(w, d), t(0, d)}, FaceClass::Roof);
  b.face({g(0, 0), g(w, 0), t(w, 0), t(0, 0)}, FaceClass::Wall);
  b.face({g(w, 0), g(w, d), t(w, d), t(w, 0)}, FaceClass::Wall);
  b.face({g(w, d), g(0, d), t(0, d), t(w, d)}, FaceClass::Wall);
  b.face({g(0, d), g(0, 0), t(0, 0), t(0, d)}, FaceClass::Wall);
  return b.m;
}

/// Two flat-roofed blocks side by side: [0, s] x [0, 8] at height h1, [s, w] x [0, 8] at h2 < h1 (s = 10,
/// w = 16 unless given); one ground face, the step wall between the roofs.
PolygonMesh two_levels(double h1, double h2, double s = 10, double w = 16) {
  Builder b;
  const auto p = [&](double x, double y, double z) { return b.v(x, y, z); };
  b.face({p(0, 0, 0), p(0, 8, 0), p(s, 8, 0), p(w, 8, 0), p(w, 0, 0), p(s, 0, 0)}, FaceClass::Ground);
  b.face({p(0, 0, h1), p(s, 0, h1), p(s, 8, h1), p(0, 8, h1)}, FaceClass::Roof);
  b.face({p(s, 0, h2), p(w, 0, h2), p(w, 8, h2), p(s, 8, h2)}, FaceClass::Roof);
  b.face({p(0, 0, 0), p(s, 0, 0), p(s, 0, h2), p(s, 0, h1), p(0, 0, h1)}, FaceClass::Wall);  // south, high
  b.face({p(s, 0, 0), p(w, 0, 0), p(w, 0, h2), p(s, 0, h2)}, FaceClass::Wall);                // south, low
  b.face({p(w, 0, 0), p(w, 8, 0), p(w, 8, h2), p(w, 0, h2)}, FaceClass::Wall);                // east
  b.face({p(w, 8, 0), p(s, 8, 0), p(s, 8, h2), p(w, 8, h2)}, FaceClass::Wall);                // north, low
  b.face({p(s, 8, 0), p(0, 8, 0), p(0, 8, h1), p(s, 8, h1), p(s, 8, h2)}, FaceClass::Wall);  // north, high
  b.face({p(0, 8, 0), p(0, 0, 0), p(0, 0, h1), p(0, 8, h1)}, FaceClass::Wall);                    // west
  b.face({p(s, 0, h2), p(s, 8, h2), p(s, 8, h1), p(s, 0, h1)}, FaceClass::Wall);              // the step
  return b.m;
}

/// A gable house [0, 12] x [0, 8], eaves at 3 m, the ridge along x at y = 4, pitch `deg`.
PolygonMesh gable(double deg) {
  Builder b;
  const double ridge = 3 + 4 * std::tan(deg * kPi / 180);
  const auto p = [&](double x, double y, double z) { return b.v(x, y, z); };
  b.face({p(0, 0, 0), p(0, 8, 0), p(12, 8, 0), p(12, 0, 0)}, FaceClass::Ground);
  b.face({p(0, 0, 3), p(12, 0, 3), p(12, 4, ridge), p(0, 4, ridge)}, FaceClass::Roof);  // south slope
  b.face({p(12, 8, 3), p(0, 8, 3), p(0, 4, ridge), p(12, 4, ridge)}, FaceClass::Roof);  // north slope
  b.face({p(0, 0, 0), p(12, 0, 0), p(12, 0, 3), p(0, 0, 3)}, FaceClass::Wall);
  b.face({p(12, 8, 0), p(0, 8, 0), p(0, 8, 3), p(12, 8, 3)}, FaceClass::Wall);
  b.face({p(12, 0, 0), p(12, 8, 0), p(12, 8, 3), p(12, 4, ridge), p(12, 0, 3)}, FaceClass::Wall);
  b.face({p(0, 8, 0), p(0, 0, 0), p(0, 0, 3), p(0, 4, ridge), p(0, 8, 3)}, FaceClass::Wall);
  return b.m;
}

const CityJsonGeometry* lod(const BuildingLods& l, const std::string& name) {
  for (const auto& g : l.solids)
    if (g.lod == name) return &g;
  return nullptr;
}

}  // namespace

TEST(Lods, TheTestSolidsAreValid) {
  for (const PolygonMesh& m : {box(10, 6, 2, 9), two_levels(9, 4), gable(35)})
    EXPECT_TRUE(check_validity(m).valid()) << check_validity(m).summary();
}

TEST(Lods, Lod12OfABoxIsItsFootprintTimesItsHeight) {
  // 10 x 6 m at 2..9 m: every roof cell at 9 m, so the 70th percentile is 9 and the volume 10 x 6 x 7.
  const PolygonMesh m = box(10, 6, 2, 9);
  const BuildingLods l = building_lods(m, {}, nlohmann::json::object(), LodParams{});
  const CityJsonGeometry* g12 = lod(l, "1.2");
  ASSERT_NE(g12, nullptr);
  const Validity v = check_validity(g12->mesh);
  EXPECT_TRUE(v.valid()) << v.summary();
  EXPECT_NEAR(v.volume, 10 * 6 * 7.0, 1e-6);  // the grid (1 mm) holds every coordinate exactly
  EXPECT_NEAR(l.attributes["b3_volume_lod12"].get<double>(), 420, 1e-6);
  EXPECT_NEAR(l.attributes["b3_volume_lod22"].get<double>(), 420, 1e-6);
  EXPECT_NEAR(l.attributes["b3_h_maaiveld"].get<double>(), 2, 1e-12);
  for (const char* k : {"b3_h_dak_min", "b3_h_dak_50p", "b3_h_dak_70p", "b3_h_dak_max"})
    EXPECT_NEAR(l.attributes[k].get<double>(), 9, 1e-9) << k;
  EXPECT_EQ(l.attributes["b3_dak_type"], "horizontal");
  EXPECT_EQ(l.attributes["hsr_validity_lod12"], "valid");
  EXPECT_EQ(l.attributes["hsr_lod13_parts"], 1);
  ASSERT_NE(lod(l, "1.3"), nullptr);  // one level: the block
  EXPECT_NEAR(check_validity(lod(l, "1.3")->mesh).volume, 420, 1e-6);
}

TEST(Lods, HeightsAreTheWorldsNotTheMeshsLocalOnes) {
  // The same box with its vertices local to an origin 50 m up (as a tile's building is): the heights are the
  // world's, 52 and 59 m, the volume the same.
  PolygonMesh m = box(10, 6, 2, 9);
  m.origin = Vec3(155000, 463000, 50);
  const BuildingLods l = building_lods(m, {}, nlohmann::json::object(), LodParams{});
  EXPECT_NEAR(l.attributes["b3_h_maaiveld"].get<double>(), 52, 1e-9);
  for (const char* k : {"b3_h_dak_min", "b3_h_dak_50p", "b3_h_dak_70p", "b3_h_dak_max"})
    EXPECT_NEAR(l.attributes[k].get<double>(), 59, 1e-9) << k;
  EXPECT_NEAR(l.attributes["b3_volume_lod12"].get<double>(), 420, 1e-6);
}

TEST(Lods, RoofMinAndMaxAreThe2ndAnd99thPercentileAsRoofersAre) {
  // 40 x 8 m, 5,120 cells of 0.25 m. A lower strip 0.25 m wide at the east end (32 cells, 0.6 %) is under the
  // 2nd percentile, a higher one at the west end above the 99th: neither makes b3_h_dak_min / _max (roofer
  // writes those percentiles of its roof points, DECISIONS #146); the 50th and 70th are the main roof's.
  const BuildingLods low = building_lods(two_levels(9, 4, 39.75, 40), {}, nlohmann::json::object(), LodParams{});
  EXPECT_NEAR(low.attributes["b3_h_dak_min"].get<double>(), 9, 1e-9);
  EXPECT_NEAR(low.attributes["b3_h_dak_max"].get<double>(), 9, 1e-9);
  const BuildingLods high = building_lods(two_levels(12, 9, 0.25, 40), {}, nlohmann::json::object(), LodParams{});
  EXPECT_NEAR(high.attributes["b3_h_dak_min"].get<double>(), 9, 1e-9);
  EXPECT_NEAR(high.attributes["b3_h_dak_50p"].get<double>(), 9, 1e-9);
  EXPECT_NEAR(high.attributes["b3_h_dak_max"].get<double>(), 9, 1e-9);
  // Half and half: the extremes are each level's.
  const BuildingLods half = building_lods(two_levels(12, 9, 20, 40), {}, nlohmann::json::object(), LodParams{});
  EXPECT_NEAR(half.attributes["b3_h_dak_min"].get<double>(), 9, 1e-9);
  EXPECT_NEAR(half.attributes["b3_h_dak_max"].get<double>(), 12, 1e-9);
  // With the extremes (0th, 100th) the strips are the min and the max.
  LodParams extremes;
  extremes.roof_min_percentile = 0;
  extremes.roof_max_percentile = 100;
  EXPECT_NEAR(building_lods(two_levels(9, 4, 39.75, 40), {}, nlohmann::json::object(), extremes).attributes["b3_h_dak_min"].get<double>(), 4, 1e-9);
  EXPECT_NEAR(building_lods(two_levels(12, 9, 0.25, 40), {}, nlohmann::json::object(), extremes).attributes["b3_h_dak_max"].get<double>(), 12, 1e-9);
}

TEST(Lods, DensityAndNoDataAreOverTheFootprintWhenThereIsOne) {
  // A 10 x 6 m box with 4 points a m² on its roof; its footprint 12 x 6 m (the model 2 m short of it, as
  // AHN3_08831's plan was 23 m² short of its footprint): over the footprint 240 / 72 points a m² and the 2 m strip
  // without points (about a sixth of its cells) is no data; without the footprint, over the plan: 4 and none.
  const PolygonMesh m = box(10, 6, 0, 5);
  std::vector<Vec3> points;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 12; ++j) points.emplace_back((i + 0.5) * 0.5, (j + 0.5) * 0.5, 5.0);
  const BuildingLods plan = building_lods(m, points, nlohmann::json::object(), LodParams{});
  EXPECT_NEAR(plan.attributes["b3_puntdichtheid"].get<double>(), 4.0, 1e-9);
  EXPECT_NEAR(plan.attributes["b3_nodata_fractie"].get<double>(), 0.0, 1e-9);
  const Footprint fp{{{Vec2(0, 0), Vec2(12, 0), Vec2(12, 6), Vec2(0, 6)}, {}}};
  const BuildingLods over = building_lods(m, points, nlohmann::json::object(), LodParams{}, fp);
  EXPECT_NEAR(over.attributes["b3_puntdichtheid"].get<double>(), 240.0 / 72.0, 1e-9);
  EXPECT_GT(over.attributes["b3_nodata_fractie"].get<double>(), 0.1);
  EXPECT_LT(over.attributes["b3_nodata_fractie"].get<double>(), 0.25);
  // The heights and volumes stay the model's.
  EXPECT_EQ(over.attributes["b3_volume_lod22"], plan.attributes["b3_volume_lod22"]);
  EXPECT_EQ(over.attributes["b3_h_dak_70p"], plan.attributes["b3_h_dak_70p"]);
}

TEST(Lods, Lod13KeepsEachRoofLevel) {
  const PolygonMesh m = two_levels(9, 4);
  const BuildingLods l = building_lods(m, {}, nlohmann::json::object(), LodParams{});
  const CityJsonGeometry* g13 = lod(l, "1.3");
  ASSERT_NE(g13, nullptr);
  const Validity v = check_validity(g13->mesh);
  EXPECT_TRUE(v.valid()) << v.summary();
  EXPECT_EQ(l.attributes["hsr_lod13_parts"], 2);
  EXPECT_FALSE(l.attributes.contains("hsr_lod13_note"));
  EXPECT_NEAR(v.volume, 10 * 8 * 9.0 + 6 * 8 * 4.0, 1e-6);  // each part at its own level: the LoD 2.2's volume
  EXPECT_NEAR(v.volume, check_validity(m).volume, 1e-6);
  EXPECT_EQ(l.attributes["b3_dak_type"], "multiple horizontal");
  // LoD 1.2: the whole plan at the 70th percentile of the heights (62.5 % of the plan is at 9 m).
  EXPECT_NEAR(check_validity(lod(l, "1.2")->mesh).volume, 16 * 8 * 9.0, 1e-6);
  // A step below lod13_min_step joins the parts.
  LodParams p;
  p.lod13_min_step = 6;
  EXPECT_EQ(building_lods(m, {}, nlohmann::json::object(), p).attributes["hsr_lod13_parts"], 1);
}

TEST(Lods, RoofSurfacesSlopeAndAzimuthAreThePitchAndTheCompassBearing) {
  const PolygonMesh m = gable(35);
  const nlohmann::json south = roof_surface_attributes(m, 1), north = roof_surface_attributes(m, 2);
  EXPECT_NEAR(south["b3_hellingshoek"].get<double>(), 35, 1e-9);
  EXPECT_NEAR(north["b3_hellingshoek"].get<double>(), 35, 1e-9);
  EXPECT_NEAR(south["b3_azimut"].get<double>(), 180, 1e-9);  // faces south (-y)
  EXPECT_NEAR(north["b3_azimut"].get<double>(), 0, 1e-9);
  EXPECT_NEAR(south["b3_opp"].get<double>(), 12 * 4 / std::cos(35 * kPi / 180), 1e-9);
  EXPECT_TRUE(roof_surface_attributes(m, 0).is_null());  // the ground is no roof
  const nlohmann::json flat = roof_surface_attributes(box(4, 4, 0, 3), 1);
  EXPECT_NEAR(flat["b3_hellingshoek"].get<double>(), 0, 1e-12);
  EXPECT_TRUE(flat["b3_azimut"].is_null());  // a horizontal face has no bearing
  EXPECT_EQ(building_lods(m, {}, nlohmann::json::object(), LodParams{}).attributes["b3_dak_type"], "slanted");
}

TEST(Lods, PointsGiveRmseDensityAndGaps) {
  // Points on the roof of the box over half its plan: RMSE 0 to LoD 1.2 (roof at 9), half the plan empty.
  const PolygonMesh m = box(10, 6, 2, 9);
  std::vector<Vec3> points;
  for (double x = 0.05; x < 5; x += 0.1)
    for (double y = 0.05; y < 6; y += 0.1) points.emplace_back(x, y, 9);
  nlohmann::json run = {{"hsr_points_unexplained_share", 0.2}};
  const BuildingLods l = building_lods(m, points, run, LodParams{});
  EXPECT_NEAR(l.attributes["b3_rmse_lod12"].get<double>(), 0, 1e-9);
  EXPECT_NEAR(l.attributes["b3_puntdichtheid"].get<double>(), static_cast<double>(points.size()) / 60, 1e-9);
  EXPECT_NEAR(l.attributes["b3_nodata_fractie"].get<double>(), 0.5, 0.05);
  EXPECT_EQ(l.attributes["b3_reconstructie_onvolledig"], true);  // 20 % unexplained, above the 5 % warning
  run["hsr_points_unexplained_share"] = 0.01;
  EXPECT_EQ(building_lods(m, points, run, LodParams{}).attributes["b3_reconstructie_onvolledig"], false);
}

TEST(Lods, TheLodListChoosesAndABadOneIsOneLine) {
  LodParams p;
  parse_lod_list("2.2,1.2", p);
  EXPECT_TRUE(p.lod12);
  EXPECT_FALSE(p.lod13);
  EXPECT_TRUE(p.lod22);
  EXPECT_EQ(lod_list(p), "1.2,2.2");
  const BuildingLods l = building_lods(box(4, 4, 0, 3), {}, nlohmann::json::object(), p);
  ASSERT_EQ(l.solids.size(), 1u);
  EXPECT_EQ(l.solids[0].lod, "1.2");
  for (const char* bad : {"", "1.4", "1.2,1.2", "1.2,", "lod2"}) {
    try {
      parse_lod_list(bad, p);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const Error& e) {
      EXPECT_EQ(e.status(), Status::BadInput);
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
      EXPECT_NE(std::string(e.what()).find("--lod"), std::string::npos);
    }
  }
}
