// `hsr city` reads a classified tile streamed and keeps only the points its plan reads (DECISIONS #96,
// src/driver/city_survey.h): the plan on the kept points is the plan on the whole tile, exactly: the same
// buildings, the same points of each (its NAME.ply, to the bit), the same ground heights (to the bit), counts
// and reasons; with footprints and with groups; a building whose first ground ring holds no ground point (its
// surroundings read again) included; and the reader does leave points out.
#include "city/city.h"
#include "city/footprints.h"
#include "driver/city_run.h"
#include "driver/city_survey.h"
#include "io/io.h"
#include "io/las_writer.h"
#include "synth/city_synth.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>

namespace fs = std::filesystem;

namespace hsr {
namespace {

bool same_double(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// A synthetic tile whose first building's ground within 5 m of its footprint's box is class 1 (not ground),
/// so that its ground ring must widen past what the reader keeps at first.
fs::path tile_with_a_bare_ring(const fs::path& dir, SynthCity& city) {
  SynthCityParams p;
  p.buildings = 6;
  p.seed = 3;
  city = run_synth_city(p);
  write_synth_city(city, dir.string());
  BBox box;
  for (const FootprintPolygon& poly : city.buildings[0].footprint)
    for (const Vec2& q : poly.outer) box.extend(Vec3(q.x(), q.y(), 0));
  auto& cls = city.cloud.attributes.classification;
  std::size_t moved = 0;
  for (std::size_t i = 0; i < city.cloud.size(); ++i) {
    const Vec3& q = city.cloud.points[i];
    if (cls[i] == 2 && q.x() > box.min.x() - 5 && q.x() < box.max.x() + 5 && q.y() > box.min.y() - 5 && q.y() < box.max.y() + 5) {
      cls[i] = 1;
      ++moved;
    }
  }
  EXPECT_GT(moved, 100u);
  const fs::path tile = dir / "bare_ring.las";
  write_las(tile.string(), city.cloud);
  return tile;
}

void expect_plan_is_the_whole_tiles(const fs::path& tile, const fs::path& footprints, const fs::path& out) {
  SCOPED_TRACE(footprints.empty() ? "groups" : "footprints");
  const PointCloud whole = read_points(tile.string());
  std::unique_ptr<FootprintSet> set;
  if (!footprints.empty()) {
    FootprintReadParams rp;
    rp.id_field = "id";
    rp.points_crs = whole.crs;
    set = std::make_unique<FootprintSet>(read_footprints(footprints.string(), rp));
  }
  const CityTile want = run_city_tile(whole, set ? &set->features : nullptr, CityParams{});

  city::CityOptions o;
  o.tiles = {tile.string()};
  o.footprints = footprints.string();
  o.id_field = footprints.empty() ? "" : "id";
  o.output = (out / "run.city.jsonl").string();
  const city::TilePlan plan = city::plan_tile(o, city::tile_files(o).front());

  EXPECT_EQ(plan.classes, want.classes);
  EXPECT_EQ(plan.unused_building_points, want.unused_building_points);
  ASSERT_EQ(plan.buildings.size(), want.buildings.size());
  ASSERT_FALSE(want.buildings.empty());
  for (std::size_t k = 0; k < want.buildings.size(); ++k) {
    const TileBuilding& w = want.buildings[k];
    const city::PlannedBuilding& g = plan.buildings[k];
    SCOPED_TRACE(w.id);
    EXPECT_EQ(g.id, w.id);
    EXPECT_EQ(g.points, w.points.size());
    EXPECT_TRUE(same_double(g.ground_z, w.ground_z)) << g.ground_z << " vs " << w.ground_z;
    EXPECT_EQ(g.ground_points, w.ground_points);
    EXPECT_EQ(g.ground_source, w.ground_source);
    EXPECT_EQ(g.failure, w.failure);
    EXPECT_EQ(g.not_building, w.not_building);
    if (!g.failure.empty() || !g.not_building.empty()) continue;
    const PointCloud ply = read_points(g.item.input);
    ASSERT_EQ(ply.size(), w.points.size());
    std::size_t different = 0;
    for (std::size_t i = 0; i < ply.size(); ++i) {
      const Vec3 a = ply.points[i] + ply.origin, b = whole.points[w.points[i]] + whole.origin;
      different += !(a.x() == b.x() && a.y() == b.y() && a.z() == b.z());
    }
    EXPECT_EQ(different, 0u);
  }
}

TEST(CityStream, ThePlanOnTheKeptPointsIsThePlanOnTheWholeTile) {
  const fs::path dir = fs::path(HSR_TEST_TMP_DIR) / "stream";
  fs::remove_all(dir);
  SynthCity city;
  const fs::path tile = tile_with_a_bare_ring(dir, city);

  // The reader leaves points out of this tile: its file gives both classes.
  city::RegionReader reader({tile.string()}, 0);
  EXPECT_TRUE(reader.classified(ClassSource::Auto));
  EXPECT_FALSE(reader.classified(ClassSource::Filter));
  {
    city::KeepMask keep(reader.area(), city::RegionReader::kCell);
    keep.mark_around(reader.building_cells(), 1.0);
    SurveyRegion region;
    const PointCloud kept = reader.read(&keep, region);
    EXPECT_GT(region.left_out.ground, 0u);
    EXPECT_GT(region.left_out.other, 0u);  // trees, and the bare ring
    EXPECT_EQ(kept.size() + region.left_out.ground + region.left_out.building + region.left_out.other, city.cloud.size());
  }

  // The first building's ring widens (the whole tile's plan says so), and the plans agree all the same.
  PointCloud whole = read_points(tile.string());
  FootprintReadParams rp;
  rp.id_field = "id";
  rp.points_crs = whole.crs;
  const FootprintSet set = read_footprints((dir / "footprints.geojson").string(), rp);
  const CityTile want = run_city_tile(whole, &set.features, CityParams{});
  ASSERT_FALSE(want.buildings.empty());
  EXPECT_GT(want.buildings[0].ring_outer, CityParams{}.ring_outer);

  expect_plan_is_the_whole_tiles(tile, dir / "footprints.geojson", dir / "with_footprints");
  expect_plan_is_the_whole_tiles(tile, "", dir / "groups");
  expect_plan_is_the_whole_tiles(dir / "tile_unclassified.las", dir / "footprints.geojson", dir / "unclassified");
}

}  // namespace
}  // namespace hsr
