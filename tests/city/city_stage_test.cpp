// The tile stage of `hsr city` (src/city/city.h) on small hand-made tiles with known answers: the
// classification split, SMRF and the building rule without classes, footprints with holes and multipolygons,
// the buffer and a shared wall, the ground ring (median, widening, none), groups in plan, the failure reason;
// and the footprints through GDAL (GeoJSON, GeoPackage, Shapefile; CRS check and reprojection; ids).
#include "city/child_call.h"
#include "city/city.h"
#include "city/footprints.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <signal.h>

#include <cmath>
#include <random>

using namespace hsr;
using namespace hsr::test;

namespace {

std::vector<Vec2> rect(double x0, double y0, double x1, double y1) { return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}; }

/// A tile: a level ground grid (class 2) at z_ground over [0, 60]², and each roof a grid of class-6 points
/// at height h over its rectangle (the ground under it removed).
struct TileMaker {
  PointCloud cloud;
  void ground(double z, double step = 0.5) {
    for (double x = 0; x <= 60; x += step)
      for (double y = 0; y <= 60; y += step) add({x, y, z}, 2);
  }
  void roof(const std::vector<Vec2>& r, double h, double step = 0.3) {
    for (double x = r[0].x() + 0.1; x < r[2].x(); x += step)
      for (double y = r[0].y() + 0.1; y < r[2].y(); y += step) add({x, y, h}, 6);
  }
  void add(const Vec3& p, std::uint8_t cls, std::uint8_t returns = 1) {
    cloud.points.push_back(p);
    cloud.attributes.classification.push_back(cls);
    cloud.attributes.return_number.push_back(1);
    cloud.attributes.number_of_returns.push_back(returns);
  }
  /// Removes the ground points inside the rectangles (under the roofs).
  void clear_under(const std::vector<std::vector<Vec2>>& roofs) {
    PointCloud kept;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      bool under = false;
      for (const auto& r : roofs)
        under = under || (cloud.attributes.classification[i] == 2 && cloud.points[i].x() > r[0].x() &&
                          cloud.points[i].x() < r[2].x() && cloud.points[i].y() > r[0].y() && cloud.points[i].y() < r[2].y());
      if (under) continue;
      kept.points.push_back(cloud.points[i]);
      kept.attributes.classification.push_back(cloud.attributes.classification[i]);
      kept.attributes.return_number.push_back(cloud.attributes.return_number[i]);
      kept.attributes.number_of_returns.push_back(cloud.attributes.number_of_returns[i]);
    }
    cloud = kept;
  }
};

FootprintFeature feature(const std::string& id, Footprint f) {
  FootprintFeature out;
  out.id = id;
  out.footprint = std::move(f);
  return out;
}

TEST(CityClasses, TheFileSaysGroundIsTwoAndBuildingSix) {
  TileMaker t;
  t.ground(1.0);
  t.roof(rect(10, 10, 20, 20), 7.0);
  t.add({30, 30, 5}, 5);  // vegetation: left out
  t.add({31, 30, 1}, 1);  // unclassified: left out
  CityTile out;
  split_classes(t.cloud, CityParams{}, out);
  for (std::size_t i = 0; i < t.cloud.size(); ++i) {
    EXPECT_EQ(out.ground[i] != 0, t.cloud.attributes.classification[i] == 2) << i;
    EXPECT_EQ(out.building[i] != 0, t.cloud.attributes.classification[i] == 6) << i;
  }
  EXPECT_NE(out.classes.find("building = LAS class 6"), std::string::npos) << out.classes;
  EXPECT_NE(out.classes.find("2 other points left out"), std::string::npos) << out.classes;
}

TEST(CityClasses, FileClassesAskedForButAbsentIsAnError) {
  TileMaker t;
  t.ground(1.0);
  for (auto& c : t.cloud.attributes.classification) c = 1;
  CityParams p;
  p.classes = ClassSource::File;
  CityTile out;
  EXPECT_EQ(status_of([&] { split_classes(t.cloud, p, out); }), Status::BadInput);
}

/// Without classes: sloping ground (5 %), a 12 x 12 m flat roof 6 m up, a sloped 30-degree roof, a tree (points
/// with two returns), a scattered bush of single returns. SMRF finds the ground; the rule keeps the roofs.
TEST(CityClasses, WithoutClassesSmrfAndTheBuildingRule) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  TileMaker t;
  auto ground_z = [](double x, double y) { return 0.05 * x + 0.02 * y; };
  for (double x = 0; x <= 60; x += 0.5)
    for (double y = 0; y <= 60; y += 0.5) {
      const bool under_roof = (x > 10 && x < 22 && y > 10 && y < 22) || (x > 35 && x < 47 && y > 10 && y < 20);
      if (!under_roof) t.add({x + 0.1 * u(rng), y + 0.1 * u(rng), ground_z(x, y) + 0.03 * u(rng)}, 0);
    }
  const std::size_t ground_count = t.cloud.size();
  std::vector<std::size_t> roof_points, tree_points, bush_points;
  for (double x = 10.2; x < 22; x += 0.3)
    for (double y = 10.2; y < 22; y += 0.3) {
      roof_points.push_back(t.cloud.size());
      t.add({x, y, ground_z(16, 16) + 6.0 + 0.02 * u(rng)}, 0);
    }
  for (double x = 35.2; x < 47; x += 0.3)
    for (double y = 10.2; y < 20; y += 0.3) {
      roof_points.push_back(t.cloud.size());
      t.add({x, y, ground_z(41, 15) + 5.0 + std::tan(30 * M_PI / 180) * (y - 10) + 0.02 * u(rng)}, 0);
    }
  for (int k = 0; k < 400; ++k) {  // a crown, 4 m wide, 5-8 m up, two returns
    tree_points.push_back(t.cloud.size());
    t.add({45 + 2 * u(rng), 45 + 2 * u(rng), ground_z(45, 45) + 6.5 + 3 * u(rng)}, 0, 2);
  }
  for (int k = 0; k < 300; ++k) {  // scattered, single returns: no plane
    bush_points.push_back(t.cloud.size());
    t.add({15 + 2 * u(rng), 45 + 2 * u(rng), ground_z(15, 45) + 4 + 3 * u(rng)}, 0, 1);
  }
  CityParams p;
  CityTile out;
  split_classes(t.cloud, p, out);
  std::size_t ground_found = 0;
  for (std::size_t i = 0; i < ground_count; ++i) ground_found += out.ground[i];
  EXPECT_GE(ground_found, ground_count * 99 / 100);
  std::size_t roof_building = 0, roof_ground = 0;
  for (std::size_t i : roof_points) {
    roof_building += out.building[i];
    roof_ground += out.ground[i];
  }
  EXPECT_EQ(roof_ground, 0u);
  EXPECT_GE(roof_building, roof_points.size() * 97 / 100);
  for (std::size_t i : tree_points) EXPECT_FALSE(out.building[i]) << "tree point " << i;
  std::size_t bush_building = 0;
  for (std::size_t i : bush_points) bush_building += out.building[i];
  EXPECT_LE(bush_building, bush_points.size() / 20);
  EXPECT_NE(out.classes.find("SMRF"), std::string::npos) << out.classes;
}

TEST(CityRing, MedianOfTheRingWidenedWhenEmptyAndNoneFarAway) {
  const Footprint f{{rect(0, 0, 10, 10), {}}};
  CityParams p;
  std::vector<Vec3> ground;
  for (int k = 0; k < 40; ++k) ground.push_back({-1.0 - 0.04 * k, 5, 3.0 + (k % 2 ? 0.01 : -0.01)});  // 1-2.6 m out
  for (int k = 0; k < 20; ++k) ground.push_back({12 + 0.5 * k, 5, 9.0});                               // 2-11.5 m out
  ground.push_back({5, 5, -20});  // inside the footprint: never ground of the ring
  TileBuilding b;
  ring_ground_height(ground, f, p, b);
  EXPECT_NEAR(b.ground_z, 3.0, 0.011);
  EXPECT_EQ(b.ring_outer, 3.0);
  EXPECT_EQ(b.ground_points, 43u);  // 40 west, the 3 east ones within 3 m (at 2, 2.5 and 3 m)
  // Nothing within 3 m: doubled to 6, then 12.
  std::vector<Vec3> far;
  for (int k = 0; k < 12; ++k) far.push_back({20, 2.0 + 0.5 * k, 4.0});  // 10 m out
  TileBuilding w;
  ring_ground_height(far, f, p, w);
  EXPECT_NEAR(w.ground_z, 4.0, 1e-12);
  EXPECT_EQ(w.ring_outer, 12.0);
  EXPECT_NE(w.ground_source.find("0.5-12 m"), std::string::npos) << w.ground_source;
  std::vector<Vec3> none{{60, 5, 1}};
  TileBuilding n;
  ring_ground_height(none, f, p, n);
  EXPECT_TRUE(std::isnan(n.ground_z));
  EXPECT_NE(n.ground_source.find("lowest point"), std::string::npos) << n.ground_source;
}

TEST(CityFootprints, HolesMultipolygonsBufferAndASharedWall) {
  TileMaker t;
  t.ground(0.0);
  // A: a courtyard block (20 x 20 with an 8 x 8 hole) whose roof covers the hole too (a glass roof, class 6);
  // B: two separate parts; C shares A's east wall x = 30.
  const auto a_outer = rect(10, 10, 30, 30), a_hole = rect(16, 16, 24, 24);
  t.roof(a_outer, 8.0);
  t.roof(rect(40, 10, 45, 15), 5.0);
  t.roof(rect(50, 10, 55, 15), 5.0);
  t.roof(rect(45, 10, 50, 15), 3.0);  // between B's two parts: B's neither (beyond the buffer)
  t.roof(rect(30, 12, 36, 28), 6.0);
  t.clear_under({a_outer, rect(40, 10, 56, 15), rect(30, 12, 36, 28)});
  std::vector<FootprintFeature> fs = {feature("A", {{a_outer, {a_hole}}}),
                                      feature("B", {{rect(40, 10, 45, 15), {}}, {rect(50, 10, 55, 15), {}}}),
                                      feature("C", {{rect(30, 12, 36, 28), {}}}),
                                      feature("far", {{rect(200, 200, 210, 210), {}}})};
  fs[0].attributes = {{"name", "courtyard"}};
  const CityTile out = run_city_tile(t.cloud, &fs, CityParams{});
  ASSERT_EQ(out.buildings.size(), 3u);
  EXPECT_EQ(out.footprints_elsewhere, 1u);
  const TileBuilding &a = out.buildings[0], &b = out.buildings[1], &c = out.buildings[2];
  EXPECT_EQ(a.id, "A");
  EXPECT_EQ(a.attributes["name"], "courtyard");
  EXPECT_NEAR(a.area, 400 - 64, 1e-9);
  for (std::size_t i : a.points) {
    const Vec3& q = t.cloud.points[i];
    EXPECT_FALSE(q.x() > 16.5 && q.x() < 23.5 && q.y() > 16.5 && q.y() < 23.5) << "point in the hole";
    EXPECT_FALSE(q.x() > 30 && q.y() > 12 && q.y() < 28) << "C's point taken by A";
    EXPECT_LE(q.x(), 30.5);
  }
  for (std::size_t i : c.points) EXPECT_GT(t.cloud.points[i].x(), 29.5);  // A's roof is A's
  std::size_t b_mid = 0;
  for (std::size_t i : b.points) b_mid += t.cloud.points[i].x() > 45.5 && t.cloud.points[i].x() < 49.5;
  EXPECT_EQ(b_mid, 0u);
  EXPECT_GT(b.points.size(), 400u);  // both parts
  // Ground: all at 0 around A.
  EXPECT_NEAR(a.ground_z, 0.0, 1e-12);
  EXPECT_TRUE(a.failure.empty());
}

TEST(CityFootprints, TooFewPointsMakeTheFootprintPrismNoneMakeNoModel) {
  // DECISIONS #165: under min_building_points the footprint prism, under min_prism_points no model; no failure.
  TileMaker t;
  t.ground(0.0);
  t.roof(rect(10, 10, 11, 11), 5.0);  // 16 points
  t.roof(rect(30, 30, 30.3, 30.3), 5.0);  // 1 point
  std::vector<FootprintFeature> fs = {feature("small", {{rect(10, 10, 11, 11), {}}}),
                                      feature("bare", {{rect(30, 30, 30.3, 30.3), {}}})};
  const CityTile out = run_city_tile(t.cloud, &fs, CityParams{});
  ASSERT_EQ(out.buildings.size(), 2u);
  EXPECT_TRUE(out.buildings[0].failure.empty()) << out.buildings[0].failure;
  EXPECT_TRUE(out.buildings[0].footprint_prism);
  EXPECT_TRUE(out.buildings[0].no_points.empty());
  EXPECT_TRUE(out.buildings[1].failure.empty()) << out.buildings[1].failure;
  EXPECT_FALSE(out.buildings[1].footprint_prism);
  EXPECT_NE(out.buildings[1].no_points.find("fewer than min_prism_points 3"), std::string::npos) << out.buildings[1].no_points;
}

TEST(CityGroups, ConnectedGroupsInPlanWithStableIds) {
  TileMaker t;
  t.ground(2.0);
  t.roof(rect(40, 40, 50, 52), 8.0);   // second in raster order (further north)
  t.roof(rect(5, 5, 15, 12), 6.0);     // first
  t.roof(rect(15, 5, 20, 12), 4.0);    // touches the first: one group (the documented limit)
  t.roof(rect(30, 5, 32, 7), 4.0);     // 4 m²: under min_building_area, left out
  t.clear_under({rect(40, 40, 50, 52), rect(5, 5, 20, 12), rect(30, 5, 32, 7)});
  const CityTile out = run_city_tile(t.cloud, nullptr, CityParams{});
  ASSERT_EQ(out.buildings.size(), 2u);
  EXPECT_EQ(out.buildings[0].id, "b0001");
  EXPECT_EQ(out.buildings[1].id, "b0002");
  for (std::size_t i : out.buildings[0].points) EXPECT_LT(t.cloud.points[i].y(), 13);
  for (std::size_t i : out.buildings[1].points) EXPECT_GT(t.cloud.points[i].y(), 39);
  EXPECT_GT(out.unused_building_points, 0u);
  EXPECT_NEAR(out.buildings[0].ground_z, 2.0, 1e-12);
  EXPECT_NEAR(out.buildings[1].ground_z, 2.0, 1e-12);
}

TEST(CityGroups, AThinLinkJoinsNoTwoBuildings) {
  TileMaker t;
  t.ground(0.0);
  t.roof(rect(5, 20, 20, 35), 7.0);
  t.roof(rect(30, 20, 45, 35), 7.0);
  for (double x = 20.1; x < 30; x += 0.3) t.add({x, 27.5, 3.0}, 6);  // a fence of "building" points between them
  t.clear_under({rect(5, 20, 45, 35)});
  const CityTile out = run_city_tile(t.cloud, nullptr, CityParams{});
  ASSERT_EQ(out.buildings.size(), 2u);
  EXPECT_EQ(out.buildings[0].points.size() + out.buildings[1].points.size() + out.unused_building_points,
            out.building_points);  // the fence's points went to a building or to none, never both
}

/// An unclassified tile: level ground, a flat roof (12 x 12 m at 6 m) and a gable roof (12 x 10 m, 30 degrees),
/// both at 0.3 m spacing with 2 cm of noise, and a crown: single returns over a dome 8 m wide (3.5 m high,
/// 5 m up), jittered by +-0.4 m as leaves are, so that part of its points look flat enough to pass the
/// building rule one by one.
PointCloud tile_with_a_crown(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  TileMaker t;
  for (double x = 0; x <= 60; x += 0.5)
    for (double y = 0; y <= 60; y += 0.5) {
      const bool under = (x > 10 && x < 22 && y > 10 && y < 22) || (x > 35 && x < 47 && y > 10 && y < 20);
      if (!under) t.add({x + 0.1 * u(rng), y + 0.1 * u(rng), 0.03 * u(rng)}, 0);
    }
  for (double x = 10.2; x < 22; x += 0.3)
    for (double y = 10.2; y < 22; y += 0.3) t.add({x, y, 6.0 + 0.04 * u(rng)}, 0);
  for (double x = 35.2; x < 47; x += 0.3)
    for (double y = 10.2; y < 20; y += 0.3)
      t.add({x, y, 5.0 + std::tan(30 * M_PI / 180) * (5 - std::abs(y - 15)) + 0.04 * u(rng)}, 0);
  for (double x = 26; x <= 34; x += 0.3)
    for (double y = 36; y <= 44; y += 0.3) {
      const double r2 = (x - 30) * (x - 30) + (y - 40) * (y - 40);
      if (r2 > 16) continue;
      t.add({x + 0.2 * u(rng), y + 0.2 * u(rng), 5.0 + 3.5 * std::sqrt(1 - r2 / 16) + 0.8 * u(rng)}, 0);
    }
  return t.cloud;
}

TEST(CityGroups, ACrownIsListedAsVegetationRoofsAreBuildings) {
  for (std::uint64_t seed : {1, 2, 3}) {
    const PointCloud cloud = tile_with_a_crown(seed);
    const CityTile out = run_city_tile(cloud, nullptr, CityParams{});
    ASSERT_EQ(out.buildings.size(), 3u) << "seed " << seed;
    std::size_t vegetation = 0;
    for (const TileBuilding& b : out.buildings) {
      Vec3 c = Vec3::Zero();
      for (std::size_t i : b.points) c += cloud.points[i];
      c /= static_cast<double>(b.points.size());
      const bool crown = c.y() > 30;
      EXPECT_EQ(!b.not_building.empty(), crown) << b.id << " at " << c.transpose() << ": " << b.not_building;
      if (crown) EXPECT_EQ(b.not_building.rfind("vegetation: the median surface variation", 0), 0u) << b.not_building;
      EXPECT_TRUE(b.failure.empty());
      vegetation += !b.not_building.empty();
    }
    EXPECT_EQ(out.vegetation_groups, vegetation);
    EXPECT_EQ(vegetation, 1u);
    // The bound is the rule: above every group's median, none is vegetation; at 0, every one is.
    CityParams loose, strict;
    loose.max_group_variation = 1.0;
    strict.max_group_variation = 0.0;
    EXPECT_EQ(run_city_tile(cloud, nullptr, loose).vegetation_groups, 0u);
    EXPECT_EQ(run_city_tile(cloud, nullptr, strict).vegetation_groups, 3u);
  }
}

TEST(CityGroups, TheFilesBuildingClassIsTrusted) {
  TileMaker t;
  t.ground(0.0);
  t.roof(rect(10, 10, 22, 22), 6.0);
  t.clear_under({rect(10, 10, 22, 22)});
  CityParams p;
  p.max_group_variation = 0.0;  // every group of the rule's points would be vegetation
  const CityTile out = run_city_tile(t.cloud, nullptr, p);
  ASSERT_EQ(out.buildings.size(), 1u);
  EXPECT_TRUE(out.buildings[0].not_building.empty());
  EXPECT_TRUE(out.variation.empty());
}

TEST(CityUnits, LengthsInFeet) {
  const CityParams p = in_tile_units(CityParams{}, 0.3048, "ft");
  EXPECT_NEAR(p.buffer, 0.5 / 0.3048, 1e-12);
  EXPECT_NEAR(p.ring_outer, 3.0 / 0.3048, 1e-12);
  EXPECT_NEAR(p.smrf.cell, 1.0 / 0.3048, 1e-12);
  EXPECT_NEAR(p.min_building_area, 10.0 / (0.3048 * 0.3048), 1e-9);
  EXPECT_EQ(p.smrf.slope, CityParams{}.smrf.slope);  // dimensionless
  EXPECT_EQ(p.length_unit, "ft");
  EXPECT_NEAR(crs_metres_per_unit("EPSG:2994"), 0.3048, 1e-6);  // NAD83(HARN) / Oregon GIC Lambert (ft)
  EXPECT_EQ(crs_metres_per_unit("EPSG:28992"), 1.0);
}

// ------------------------------------------------------------------------------------------ GDAL

std::vector<FootprintFeature> sample_features() {
  std::vector<FootprintFeature> fs;
  fs.push_back(feature("1001", {{rect(155010.125, 463010.5, 155030.25, 463030.75), {rect(155016, 463016, 155024, 463024)}}}));
  fs.back().attributes = {{"storeys", 3}, {"name", "courtyard"}, {"height", 9.5}};
  fs.push_back(feature("1002", {{rect(155040, 463010, 155045, 463015), {}}, {rect(155050, 463010, 155055, 463015), {}}}));
  fs.back().attributes = {{"storeys", 1}, {"name", "pair"}, {"height", 4.25}};
  return fs;
}

void expect_same(const std::vector<FootprintFeature>& got, const std::vector<FootprintFeature>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t f = 0; f < want.size(); ++f) {
    ASSERT_EQ(got[f].footprint.size(), want[f].footprint.size());
    for (std::size_t p = 0; p < want[f].footprint.size(); ++p) {
      const auto &g = got[f].footprint[p], &w = want[f].footprint[p];
      ASSERT_EQ(g.holes.size(), w.holes.size());
      // The same ring, perhaps starting elsewhere or turning the other way (Shapefile turns outer rings clockwise).
      auto same_ring = [](std::vector<Vec2> a, std::vector<Vec2> b) {
        if (a.size() != b.size()) return false;
        for (int turn = 0; turn < 2; ++turn, std::reverse(b.begin(), b.end()))
          for (std::size_t s = 0; s < a.size(); ++s) {
            bool all = true;
            for (std::size_t i = 0; i < a.size() && all; ++i) all = a[i] == b[(i + s) % b.size()];
            if (all) return true;
          }
        return false;
      };
      EXPECT_TRUE(same_ring(g.outer, w.outer)) << f << "/" << p;
      for (std::size_t h = 0; h < w.holes.size(); ++h) EXPECT_TRUE(same_ring(g.holes[h], w.holes[h]));
    }
    EXPECT_EQ(got[f].attributes["storeys"], want[f].attributes["storeys"]);
    EXPECT_EQ(got[f].attributes["name"], want[f].attributes["name"]);
    EXPECT_EQ(got[f].attributes["height"], want[f].attributes["height"]);
  }
}

TEST(CityGdal, FootprintsRoundTripThroughGeoJsonGeoPackageAndShapefile) {
  const auto dir = scratch_dir("formats");
  const auto fs = sample_features();
  for (const std::string name : {"f.geojson", "f.gpkg", "f.shp"}) {
    SCOPED_TRACE(name);
    write_footprints((dir / name).string(), fs, "EPSG:28992");
    FootprintReadParams rp;
    rp.id_field = "id";
    rp.points_crs = "EPSG:28992";
    const FootprintSet got = read_footprints((dir / name).string(), rp);
    expect_same(got.features, fs);
    EXPECT_EQ(got.features[0].id, "1001");
    EXPECT_EQ(got.features[1].id, "1002");
    EXPECT_NE(got.crs_note.find("same CRS"), std::string::npos) << got.crs_note;
  }
}

TEST(CityGdal, ReprojectedIntoThePointsCrs) {
  const auto dir = scratch_dir("reproject");
  write_footprints((dir / "f.geojson").string(), sample_features(), "EPSG:28992");
  FootprintReadParams rp;
  rp.points_crs = "EPSG:4326";
  const FootprintSet got = read_footprints((dir / "f.geojson").string(), rp);
  EXPECT_NE(got.crs_note.find("reprojected"), std::string::npos) << got.crs_note;
  // RD New (155000, 463000) is Amersfoort's neighbourhood: about 5.39 E, 52.16 N.
  const Vec2 p = got.features[0].footprint[0].outer[0];
  EXPECT_NEAR(p.x(), 5.3875, 0.01);
  EXPECT_NEAR(p.y(), 52.155, 0.01);
  rp.points_crs = "";
  EXPECT_NE(read_footprints((dir / "f.geojson").string(), rp).crs_note.find("not checked"), std::string::npos);
}

TEST(CityGdal, IdsMustBeUniqueAndTheIdFieldMustExist) {
  const auto dir = scratch_dir("ids");
  auto fs = sample_features();
  fs[1].attributes["name"] = "courtyard";
  write_footprints((dir / "f.geojson").string(), fs, "EPSG:28992");
  FootprintReadParams rp;
  rp.id_field = "name";
  EXPECT_EQ(status_of([&] { read_footprints((dir / "f.geojson").string(), rp); }), Status::BadFormat);
  rp.id_field = "nope";
  EXPECT_EQ(status_of([&] { read_footprints((dir / "f.geojson").string(), rp); }), Status::BadFormat);
  EXPECT_EQ(status_of([&] { read_footprints((dir / "missing.gpkg").string()); }), Status::FileNotFound);
  write_file(dir / "junk.geojson", "{ not json");
  EXPECT_EQ(status_of([&] { read_footprints((dir / "junk.geojson").string()); }), Status::BadFormat);
}

TEST(CityGdal, HsrsOwnFootprintFileIsReadWithoutGdalToTheBitAsGdalReadsIt) {
  // What hsr city hands each building: footprint_geojson's file. Read without GDAL (the note says so), its
  // polygons must be GDAL's to the bit: the same doubles, a repeated corner and the closing one dropped, a hole of
  // two distinct corners dropped, a polygon of two left out, the rings in their order and turn.
  const auto dir = scratch_dir("own");
  FootprintFeature f;
  f.id = "B0007";
  FootprintPolygon first;
  first.outer = {{155010.1234567891, 463010.9876543219}, {155030.3, 463010.1}, {155030.3, 463010.1},
                 {155031.70000000001, 463030.25}, {155010.5, 463029.99999999994}};
  first.holes = {rect(155016, 463016, 155024, 463024), {{155026, 463026}, {155027, 463027}, {155026, 463026}}};
  FootprintPolygon two;  // two distinct corners
  two.outer = {{155040, 463010}, {155041, 463011}, {155040, 463010}};
  FootprintPolygon clockwise;
  clockwise.outer = {{155050.5, 463010.25}, {155050.5, 463015}, {155055, 463015}, {155055, 463010.25}};
  f.footprint = {first, two, clockwise};
  f.attributes = {{"storeys", 2}, {"name", "own"}};
  const nlohmann::json j = footprint_geojson(f);
  ASSERT_EQ(j.value("hsr_footprint", 0), 1);
  write_file(dir / "own.geojson", j.dump(1));
  nlohmann::json plain = j;
  plain.erase("hsr_footprint");
  write_file(dir / "plain.geojson", plain.dump(1));
  const FootprintSet own = read_footprints((dir / "own.geojson").string());
  const FootprintSet gdal = read_footprints((dir / "plain.geojson").string());
  EXPECT_NE(own.crs_note.find("hsr's own"), std::string::npos) << own.crs_note;
  EXPECT_EQ(gdal.crs_note.find("hsr's own"), std::string::npos) << gdal.crs_note;
  ASSERT_EQ(own.features.size(), 1u);
  ASSERT_EQ(gdal.features.size(), 1u);
  EXPECT_EQ(own.features[0].id, "B0007");
  EXPECT_EQ(own.features[0].attributes, f.attributes);
  const Footprint &a = own.features[0].footprint, &b = gdal.features[0].footprint;
  ASSERT_EQ(a.size(), 2u);  // the polygon of two distinct corners is left out
  ASSERT_EQ(b.size(), a.size());
  for (std::size_t p = 0; p < a.size(); ++p) {
    EXPECT_EQ(a[p].outer, b[p].outer) << p;  // exact doubles, same start, same turn
    EXPECT_EQ(a[p].holes, b[p].holes) << p;
  }
  EXPECT_EQ(a[0].outer.size(), 4u);  // the repeated corner dropped
  EXPECT_EQ(a[0].outer[0], Vec2(155010.1234567891, 463010.9876543219));
  EXPECT_EQ(a[0].holes.size(), 1u);  // the hole of two distinct corners dropped
  EXPECT_EQ(a[1].outer, f.footprint[2].outer);
  // With --id-field: the property's value; a missing field, a broken file and duplicate ids are errors, as with GDAL.
  FootprintReadParams rp;
  rp.id_field = "name";
  EXPECT_EQ(read_footprints((dir / "own.geojson").string(), rp).features[0].id, "own");
  rp.id_field = "nope";
  EXPECT_EQ(status_of([&] { read_footprints((dir / "own.geojson").string(), rp); }), Status::BadFormat);
  nlohmann::json broken = j;
  broken["features"][0]["geometry"]["coordinates"] = 7;
  write_file(dir / "broken.geojson", broken.dump());
  EXPECT_EQ(status_of([&] { read_footprints((dir / "broken.geojson").string()); }), Status::BadFormat);
  nlohmann::json twice = j;
  twice["features"].push_back(j["features"][0]);
  write_file(dir / "twice.geojson", twice.dump());
  EXPECT_EQ(status_of([&] { read_footprints((dir / "twice.geojson").string()); }), Status::BadFormat);
}

TEST(CityGdal, EpsgCodesOfWktAndCodes) {
  EXPECT_EQ(crs_epsg_code("EPSG:28992"), "EPSG:28992");
  EXPECT_EQ(crs_epsg_code("EPSG:7415"), "EPSG:7415");
  EXPECT_EQ(crs_epsg_code(""), "");
  EXPECT_EQ(crs_epsg_code("not a crs"), "");
}

/// True when this process maps GDAL's module or GDAL itself.
bool maps_gdal() {
  const std::string maps = read_file("/proc/self/maps");
  return maps.find("libhsr_gdal") != std::string::npos || maps.find("libgdal") != std::string::npos;
}

TEST(CityGdal, ReadingFootprintsAndAskingOfACrsLeaveGdalOutOfThisProcess) {
  // The reads and the CRS questions go through GDAL in a child process (DECISIONS #245): the ~100 libraries
  // GDAL maps never weigh on the process that asks (hsr city's driver), and the answers are GDAL's.
  const auto dir = scratch_dir("child");
  write_file(dir / "plain.geojson",
             R"({"type": "FeatureCollection", "crs": {"type": "name", "properties": {"name": "EPSG:28992"}},)"
             R"( "features": [{"type": "Feature", "properties": {"id": "a", "storeys": 3, "height": 9.5},)"
             R"( "geometry": {"type": "Polygon", "coordinates": [[[155000.1, 463000.3], [155010.7, 463000.3],)"
             R"( [155010.7, 463010.123456789], [155000.1, 463000.3]]]}}]})");
  FootprintReadParams rp;
  rp.id_field = "id";
  rp.points_crs = "EPSG:28992";
  const FootprintSet set = read_footprints((dir / "plain.geojson").string(), rp);
  ASSERT_EQ(set.features.size(), 1u);
  EXPECT_EQ(set.features[0].id, "a");
  EXPECT_EQ(set.features[0].attributes, nlohmann::json({{"id", "a"}, {"storeys", 3}, {"height", 9.5}}));
  EXPECT_EQ(set.features[0].footprint[0].outer,
            (std::vector<Vec2>{{155000.1, 463000.3}, {155010.7, 463000.3}, {155010.7, 463010.123456789}}));
  EXPECT_TRUE(set.crs_compared) << set.crs_note;
  EXPECT_EQ(crs_epsg_code("EPSG:7415"), "EPSG:7415");
  bool projected = false;
  std::string unit;
  EXPECT_NEAR(crs_metres_per_unit("EPSG:2994", &projected, &unit), 0.3048, 1e-6);
  EXPECT_TRUE(projected);
  EXPECT_EQ(unit, "foot");
  EXPECT_EQ(status_of([&] { read_footprints((dir / "plain.geojson").string(), FootprintReadParams{"", "nope", ""}); }),
            Status::BadFormat);
  EXPECT_FALSE(maps_gdal());
}

TEST(CityGdal, ACallInAChildGivesItsAnswerToTheBitItsErrorAsItselfAndACrashAsOneLine) {
  const double third = 1.0 / 3.0;
  EXPECT_EQ(call_in_child("a sum", [&] { return nlohmann::json({{"x", third}, {"n", -7}}); }),
            nlohmann::json({{"x", third}, {"n", -7}}));
  try {
    call_in_child("a bad file", []() -> nlohmann::json { throw Error(Status::BadFormat, "city", "footprints: 'f' is bad"); });
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.status(), Status::BadFormat);
    EXPECT_EQ(e.one_line(), "city: footprints: 'f' is bad");
  }
  try {
    call_in_child("a crash", []() -> nlohmann::json {
      ::raise(SIGKILL);
      return {};
    });
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.status(), Status::Internal);
    EXPECT_EQ(e.one_line(), "city: a crash: its child process ended by signal 9 (Killed) without an answer");
  }
}

}  // namespace

namespace {

hsr::BBox plan_rect(double x0, double y0, double x1, double y1) {
  hsr::BBox b;
  b.extend(hsr::Vec3(x0, y0, 0));
  b.extend(hsr::Vec3(x1, y1, 10));
  return b;
}

}  // namespace

TEST(CitySurvey, EveryPositionHasOneOwnerAcrossGapsAndOverlaps) {
  using hsr::Vec2;
  // Two tiles 0.3 apart (the gap a grid leaves between the last point of one and the first of the next), a
  // third overlapping the second by 2 (tiles published with buffers).
  const std::vector<hsr::BBox> tiles = {plan_rect(0, 0, 99.85, 100), plan_rect(100.15, 0, 200, 100), plan_rect(198, 0, 300, 100)};
  EXPECT_EQ(hsr::owning_tile(Vec2(50, 50), tiles, 1.0), 0);
  EXPECT_EQ(hsr::owning_tile(Vec2(99.95, 50), tiles, 1.0), 0);   // in the gap, nearer the first
  EXPECT_EQ(hsr::owning_tile(Vec2(100.05, 50), tiles, 1.0), 1);  // in the gap, nearer the second
  EXPECT_EQ(hsr::owning_tile(Vec2(199, 50), tiles, 1.0), 1);     // in both: the first of them
  EXPECT_EQ(hsr::owning_tile(Vec2(250, 50), tiles, 1.0), 2);
  EXPECT_EQ(hsr::owning_tile(Vec2(350, 50), tiles, 1.0), -1);    // off the survey
  EXPECT_EQ(hsr::owning_tile(Vec2(300.5, 50), tiles, 1.0), 2);   // within the tolerance of its edge
  EXPECT_EQ(hsr::tiles_meeting(plan_rect(-10, -10, 110, 110), tiles, 0), std::vector<int>({1}));
  EXPECT_TRUE(hsr::survey_beyond(plan_rect(-10, -10, 110, 110), 1, 2.0, tiles));   // east: the second tile goes on
  EXPECT_FALSE(hsr::survey_beyond(plan_rect(-10, -10, 110, 110), 0, 2.0, tiles));  // west: nothing
}

TEST(CitySurvey, AGroupOnTwoTilesIsPlannedByTheTileThatOwnsItsCentre) {
  // A flat roof 20 x 10 m of building points (class 6) with ground around, across the line x = 16 between two
  // tiles; each tile plans it with the other's points (its region): only the west tile, which owns the
  // centre x = 10, plans it, with all its points; the east one lists it as elsewhere.
  hsr::PointCloud cloud;
  for (double x = -20; x <= 40; x += 0.5)
    for (double y = -20; y <= 30; y += 0.5) {
      const bool roof = x >= 0 && x <= 20 && y >= 0 && y <= 10;
      cloud.points.emplace_back(x, y, roof ? 6.0 : 0.0);
      cloud.attributes.classification.push_back(roof ? 6 : 2);
    }
  hsr::SurveyRegion region;
  region.extents = {plan_rect(-20, -20, 15.9, 30), plan_rect(16, -20, 40, 30)};
  region.loaded = plan_rect(-70, -70, 90, 80);
  region.own_points = cloud.size();  // which are whose does not matter here
  std::size_t roof = 0;
  for (auto c : cloud.attributes.classification) roof += c == 6;
  region.self = 0;
  const hsr::CityTile west = hsr::run_city_tile(cloud, nullptr, hsr::CityParams{}, region);
  ASSERT_EQ(west.buildings.size(), 1u);
  EXPECT_EQ(west.buildings[0].points.size(), roof);
  EXPECT_TRUE(west.buildings[0].failure.empty()) << west.buildings[0].failure;
  region.self = 1;
  const hsr::CityTile east = hsr::run_city_tile(cloud, nullptr, hsr::CityParams{}, region);
  EXPECT_TRUE(east.buildings.empty());
  EXPECT_EQ(east.groups_elsewhere, 1u);
  // Loaded only up to x = 18 with the survey going on: the group reaches the side, listed as cut.
  region.self = 0;
  region.loaded = plan_rect(-70, -70, 18, 80);
  hsr::PointCloud cut;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (cloud.points[i].x() <= 18) {
      cut.points.push_back(cloud.points[i]);
      cut.attributes.classification.push_back(cloud.attributes.classification[i]);
    }
  region.own_points = cut.size();
  const hsr::CityTile partial = hsr::run_city_tile(cut, nullptr, hsr::CityParams{}, region);
  ASSERT_EQ(partial.buildings.size(), 1u);
  EXPECT_NE(partial.buildings[0].failure.find("--tile-margin"), std::string::npos) << partial.buildings[0].failure;
}
