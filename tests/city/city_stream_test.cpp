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

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <random>

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

/// A survey of 3 x 3 tiles cut from a synthetic tile of 12 buildings (through whatever buildings the lines
/// cross), its footprints in the tiles' CRS.
std::vector<std::string> three_by_three(const fs::path& dir, FootprintSet& footprints) {
  SynthCityParams p;
  p.buildings = 12;
  p.seed = 2;
  p.tiles = 3;
  write_synth_city(run_synth_city(p), dir.string());
  std::vector<std::string> tiles;
  for (const auto& e : fs::directory_iterator(dir / "tiles")) tiles.push_back(e.path().string());
  std::sort(tiles.begin(), tiles.end());
  FootprintReadParams rp;
  rp.id_field = "id";
  rp.points_crs = read_points(tiles.front()).crs;
  footprints = read_footprints((dir / "footprints.geojson").string(), rp);
  return tiles;
}

/// How many kept points lie farther than `reach` + a mask cell's diagonal (KeepMask::mark_near marks a cell whose
/// centre is within reach + half a diagonal; its points lie within another half) from every footprint the tile
/// plans.
std::size_t kept_far_from_planned(const city::RegionReader& reader, const PointCloud& kept, const FootprintSet& footprints,
                                  double reach) {
  std::vector<const Footprint*> planned;
  for (const FootprintFeature& f : footprints.features)
    if (reader.plans(f.footprint)) planned.push_back(&f.footprint);
  const double near = reach + std::sqrt(2.0) * city::RegionReader::kCell;
  std::size_t far = 0;
  for (std::size_t i = 0; i < kept.size(); ++i) {
    const Vec3 q = kept.points[i] + kept.origin;
    const bool close = std::any_of(planned.begin(), planned.end(), [&](const Footprint* f) {
      return inside_footprint(q.x(), q.y(), *f) || distance_to_footprint(q.head<2>(), *f) <= near + 1e-6;
    });
    far += !close;
  }
  return far;
}

// Issue 40 item 2 (DECISIONS #103): a tile of a survey keeps, of its neighbours' margins and of its own points,
// only the ground and building points near the footprints it plans; the points near a neighbour's footprint
// are that neighbour's to read. And the plan on those points is the plan on every point of the region.
TEST(CityStream, ATileOfASurveyKeepsOnlyThePointsNearTheFootprintsItPlans) {
  const fs::path dir = fs::path(HSR_TEST_TMP_DIR) / "stream_survey";
  fs::remove_all(dir);
  FootprintSet footprints;
  const std::vector<std::string> tiles = three_by_three(dir, footprints);
  ASSERT_EQ(tiles.size(), 9u);
  const CityParams params;
  const double reach = std::max(params.ring_outer, params.buffer) + city::RegionReader::kSlack;
  const int centre = 4;  // r1c1: a neighbour on every side
  city::RegionReader reader(tiles, centre);
  reader.add_neighbours(params.tile_margin);
  ASSERT_TRUE(reader.classified(params.classes));
  std::size_t planned = 0;
  for (const FootprintFeature& f : footprints.features) planned += reader.plans(f.footprint);
  ASSERT_GT(planned, 0u);
  ASSERT_LT(planned, footprints.features.size());

  SurveyRegion region;
  const city::KeepMask mask = city::first_keep_mask(reader, &footprints.features, params);
  const PointCloud kept = reader.read(&mask, region);
  EXPECT_EQ(kept_far_from_planned(reader, kept, footprints, reach), 0u);
  // As before: every footprint of the region marked, the points near the neighbours' footprints kept too.
  city::KeepMask every(reader.area(), city::RegionReader::kCell);
  for (const FootprintFeature& f : footprints.features) every.mark_near(f.footprint, reach);
  SurveyRegion before_region;
  const PointCloud before = reader.read(&every, before_region);
  EXPECT_GT(kept_far_from_planned(reader, before, footprints, reach), 1000u);
  EXPECT_LT(kept.size(), before.size());

  // The plan on the kept points is the plan on every point of the region, tile by tile.
  city::CityOptions o;
  o.tiles = tiles;
  o.footprints = (dir / "footprints.geojson").string();
  o.id_field = "id";
  o.output = (dir / "out").string();
  const std::vector<city::TileFiles> files = city::tile_files(o);
  city::RunFootprints run(o);
  std::size_t buildings = 0;
  for (int t = 0; t < static_cast<int>(tiles.size()); ++t) {
    SCOPED_TRACE(tiles[static_cast<std::size_t>(t)]);
    city::RegionReader all(tiles, t);
    all.add_neighbours(params.tile_margin);
    SurveyRegion whole_region;
    const PointCloud whole = all.read(nullptr, whole_region);
    const CityTile want = run_city_tile(whole, &footprints.features, params, whole_region);
    const city::TilePlan plan = city::plan_tile(o, files[static_cast<std::size_t>(t)], t % 2 ? &run : nullptr);
    EXPECT_EQ(plan.classes, want.classes);
    EXPECT_EQ(plan.unused_building_points, want.unused_building_points);
    EXPECT_EQ(plan.footprints_off_tile, want.footprints_elsewhere);
    ASSERT_EQ(plan.buildings.size(), want.buildings.size());
    for (std::size_t k = 0; k < want.buildings.size(); ++k) {
      EXPECT_EQ(plan.buildings[k].id, want.buildings[k].id);
      EXPECT_EQ(plan.buildings[k].points, want.buildings[k].points.size());
      EXPECT_TRUE(same_double(plan.buildings[k].ground_z, want.buildings[k].ground_z)) << want.buildings[k].id;
      EXPECT_EQ(plan.buildings[k].ground_source, want.buildings[k].ground_source);
      EXPECT_EQ(plan.buildings[k].failure, want.buildings[k].failure);
    }
    buildings += plan.buildings.size();
  }
  EXPECT_EQ(buildings, footprints.features.size());  // each footprint planned once
  EXPECT_EQ(run.reads(), 1u);
}

// A survey's run reads its footprints once and drops each tile's plan once the tile is written: it holds one
// tile's planned buildings at a time, not the survey's (DECISIONS #103).
TEST(CityStream, ASurveyRunReadsItsFootprintsOnceAndHoldsOneTilesPlan) {
  const fs::path dir = fs::path(HSR_TEST_TMP_DIR) / "stream_survey_run";
  fs::remove_all(dir);
  FootprintSet footprints;
  const std::vector<std::string> tiles = three_by_three(dir, footprints);
  city::CityOptions o;
  o.tiles = tiles;
  o.footprints = (dir / "footprints.geojson").string();
  o.id_field = "id";
  o.output = (dir / "out").string();
  o.hsr_cli = "/bin/true";  // the buildings' runs are not what is measured: each ends at once, without output
  o.jobs = 2;
  std::size_t most = 0;
  for (const city::TileFiles& f : city::tile_files(o)) most = std::max(most, city::plan_tile(o, f).buildings.size());
  city::CityRunStats stats;
  city::run_city(o, &stats);
  EXPECT_EQ(stats.footprint_reads, 1u);
  EXPECT_EQ(stats.most_buildings_held, most);
  EXPECT_LT(most, footprints.features.size());
}

// The footprints meeting a rectangle, by the grid, are those a test of every box finds.
TEST(CitySurvey, TheFootprintGridGivesTheFootprintsMeetingARectangle) {
  FootprintSet set;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> at(-300.0, 700.0), side(1.0, 150.0);
  for (int f = 0; f < 300; ++f) {
    const double x = at(rng), y = at(rng), w = side(rng), h = side(rng);
    FootprintPolygon poly;
    poly.outer = {Vec2(x, y), Vec2(x + w, y), Vec2(x + w, y + h), Vec2(x, y + h)};
    set.features.push_back({std::to_string(f), {poly}, nlohmann::json::object()});
  }
  const FootprintGrid grid(set);
  for (int q = 0; q < 200; ++q) {
    BBox rect;
    rect.extend(Vec3(at(rng), at(rng), 0));
    rect.extend(Vec3(at(rng), at(rng), 0));
    std::vector<std::size_t> want;
    for (std::size_t f = 0; f < set.features.size(); ++f) {
      const auto& r = set.features[f].footprint[0].outer;
      if (r[0].x() <= rect.max.x() && rect.min.x() <= r[1].x() && r[0].y() <= rect.max.y() && rect.min.y() <= r[2].y()) want.push_back(f);
    }
    EXPECT_EQ(grid.meeting(rect), want);
  }
}

/// Every file of a plan's work folder (plan.json, NAME.ply, NAME.footprint.geojson), by name, as bytes.
std::map<std::string, std::string> work_files(const fs::path& work) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::directory_iterator(work)) {
    std::ifstream in(e.path(), std::ios::binary);
    out[e.path().filename().string()] = std::string(std::istreambuf_iterator<char>(in), {});
  }
  return out;
}

/// Plans tile t of `o` whole (block 0) and in blocks of `block` m into the same work folder, one after the other;
/// expects the same files to the byte. Returns the number of blocks the tile's footprints fell into.
int expect_blocks_plan_the_whole_plan(city::CityOptions o, int t, double block) {
  const city::TileFiles files = city::tile_files(o)[static_cast<std::size_t>(t)];
  SCOPED_TRACE(files.tile);
  o.block = 0;
  o.every_part = true;  // the reference: every part of every file decoded (DECISIONS #133)
  fs::remove_all(files.work);
  const city::TilePlan whole = city::plan_tile(o, files);
  const std::map<std::string, std::string> want = work_files(files.work);
  // Whole with only the parts it keeps points of decoded, then in blocks likewise.
  o.every_part = false;
  for (const double side : {0.0, block}) {
    SCOPED_TRACE("blocks of " + std::to_string(side));
    o.block = side;
    fs::remove_all(files.work);
    const city::TilePlan plan = city::plan_tile(o, files);
    const std::map<std::string, std::string> got = work_files(files.work);
    EXPECT_EQ(city::to_json(plan).dump(), city::to_json(whole).dump());
    EXPECT_EQ(got.size(), want.size());
    std::size_t different = 0;
    for (const auto& [name, bytes] : want) {
      const auto it = got.find(name);
      different += it == got.end() || it->second != bytes;
    }
    EXPECT_EQ(different, 0u);
  }
  EXPECT_GT(whole.buildings.size(), 0u);
  // Which blocks the tile's footprints fell into (the grid of make_plan_in_blocks).
  city::RegionReader reader(o.tiles, t, false);
  const TileBlocks grid = TileBlocks::over(reader.own_box(), block);
  std::set<int> used;
  FootprintReadParams rp;
  rp.id_field = "id";
  rp.points_crs = reader.crs();
  for (const FootprintFeature& f : read_footprints(o.footprints, rp).features)
    if (reader.plans(f.footprint)) used.insert(grid.of(footprint_plan_centre(f.footprint, reader.origin())));
  return static_cast<int>(used.size());
}

// Issue 40 item 2 (DECISIONS #124): one large tile is planned block by block, each block reading only the points
// near the buildings whose centre it owns, and the plan is the whole tile's to the byte: plan.json (ids, point
// counts, ground heights, the unused building points, the footprints off the tile) and every building's
// NAME.ply and footprint; a tile alone (a building whose ring widens past what was kept first included) and the
// tiles of a survey (blocks of a tile with its neighbours' margins).
TEST(CityStream, ATilePlannedInBlocksIsPlannedAsAWhole) {
  const fs::path dir = fs::path(HSR_TEST_TMP_DIR) / "stream_blocks";
  fs::remove_all(dir);
  SynthCity bare;
  const fs::path tile = tile_with_a_bare_ring(dir / "bare", bare);
  city::CityOptions o;
  o.tiles = {tile.string()};
  o.footprints = (dir / "bare" / "footprints.geojson").string();
  o.id_field = "id";
  o.output = (dir / "bare" / "out.city.jsonl").string();
  EXPECT_GE(expect_blocks_plan_the_whole_plan(o, 0, 25.0), 3);

  SynthCityParams p;
  p.buildings = 30;
  p.seed = 1;
  write_synth_city(run_synth_city(p), (dir / "thirty").string());
  o.tiles = {(dir / "thirty" / "tile.las").string()};
  o.footprints = (dir / "thirty" / "footprints.geojson").string();
  o.output = (dir / "thirty" / "out.city.jsonl").string();
  EXPECT_GE(expect_blocks_plan_the_whole_plan(o, 0, 40.0), 6);

  FootprintSet footprints;
  o.tiles = three_by_three(dir / "survey", footprints);
  o.footprints = (dir / "survey" / "footprints.geojson").string();
  o.output = (dir / "survey" / "out").string();
  int blocks = 0;
  for (int t = 0; t < 9; ++t) blocks += expect_blocks_plan_the_whole_plan(o, t, 20.0);
  EXPECT_GT(blocks, 9);
}

// DECISIONS #133: a read with a mask decodes only the parts of the file (io.h point_parts: here 65,536 LAS records)
// holding a class 2 or 6 point in a part cell with a marked cell, and reads the same cloud, in the same order,
// with the same counts left out and the same ranks of the building points as a read decoding every part; a
// mask marking nothing decodes no part.
TEST(CityStream, AReadDecodesOnlyThePartsMeetingItsMaskAndReadsTheSameCloud) {
  const fs::path dir = fs::path(HSR_TEST_TMP_DIR) / "stream_parts";
  fs::remove_all(dir);
  SynthCityParams p;
  p.buildings = 30;
  p.seed = 1;
  write_synth_city(run_synth_city(p), dir.string());
  const std::string tile = (dir / "tile.las").string();
  ASSERT_GT(point_parts(tile).size(), 8u);
  city::RegionReader reader({tile}, 0);
  ASSERT_TRUE(reader.classified(ClassSource::Auto));
  const BBox area = reader.area();
  // A corner of the tile, and its buildings' cells around the middle: two masks.
  city::KeepMask corner(area, city::RegionReader::kCell);
  corner.mark(area.min.x(), area.min.y(), area.min.x() + 30, area.min.y() + 30);
  city::KeepMask middle(area, city::RegionReader::kCell);
  const Vec3 c = 0.5 * (area.min + area.max);
  middle.mark(c.x() - 40, c.y() - 40, c.x() + 40, c.y() + 40);
  for (const city::KeepMask* keep : {&corner, &middle}) {
    SurveyRegion all_region, some_region;
    std::vector<std::uint32_t> all_rank, some_rank;
    reader.set_every_part(true);
    std::size_t before = reader.parts_read(), total = reader.parts_total();
    const PointCloud all = reader.read(keep, all_region, &all_rank);
    EXPECT_EQ(reader.parts_read() - before, reader.parts_total() - total);
    reader.set_every_part(false);
    before = reader.parts_read();
    total = reader.parts_total();
    const PointCloud some = reader.read(keep, some_region, &some_rank);
    const std::size_t read = reader.parts_read() - before, parts = reader.parts_total() - total;
    EXPECT_GT(read, 0u);
    EXPECT_LT(read, parts);  // parts skipped
    ASSERT_EQ(some.size(), all.size());
    EXPECT_GT(some.size(), 0u);
    EXPECT_TRUE(some.points == all.points);
    EXPECT_EQ(some.attributes.classification, all.attributes.classification);
    EXPECT_EQ(some_rank, all_rank);
    EXPECT_EQ(some_region.left_out.ground, all_region.left_out.ground);
    EXPECT_EQ(some_region.left_out.building, all_region.left_out.building);
    EXPECT_EQ(some_region.left_out.other, all_region.left_out.other);
    EXPECT_EQ(some_region.left_out.own_building, all_region.left_out.own_building);
    EXPECT_EQ(some_region.own_points, all_region.own_points);
  }
  city::KeepMask none(area, city::RegionReader::kCell);
  SurveyRegion region;
  const std::size_t before = reader.parts_read();
  EXPECT_EQ(reader.read(&none, region).size(), 0u);
  EXPECT_EQ(reader.parts_read(), before);
}

/// Two tiles cut from a synthetic tile at the median x, each written in x order (as a tiler may write them), so
/// that a file's parts (65,536 LAS records) are strips across x and the 50 m margin meets only some of them.
std::vector<std::string> two_tiles_in_x_order(const fs::path& dir) {
  SynthCityParams p;
  p.buildings = 30;
  p.seed = 1;
  write_synth_city(run_synth_city(p), dir.string());
  const PointCloud cloud = read_points((dir / "tile.las").string());
  std::vector<std::size_t> order(cloud.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return cloud.points[a].x() < cloud.points[b].x(); });
  const std::size_t half = order.size() / 2;
  const std::vector<std::size_t> west(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(half));
  const std::vector<std::size_t> east(order.begin() + static_cast<std::ptrdiff_t>(half), order.end());
  const std::vector<std::string> tiles = {(dir / "west.las").string(), (dir / "east.las").string()};
  write_las(tiles[0], select_points(cloud, west));
  write_las(tiles[1], select_points(cloud, east));
  return tiles;
}

// DECISIONS #142: a neighbour decoded whole once in a run (SurveyIndex) is decoded again only in the parts with a
// point in a cell meeting the margin, and the region read is the same: the same census (area, boxes, origin,
// classes, building cells) and the same clouds, whole and through the first mask, with the same counts left out;
// the index drops a file once no tile still to plan reads it.
TEST(CityStream, ASurveyIndexDecodesANeighbourOnlyWhereItMeetsTheMarginAndReadsTheSameRegion) {
  const fs::path dir = fs::path(HSR_TEST_TMP_DIR) / "stream_index";
  fs::remove_all(dir);
  const std::vector<std::string> tiles = two_tiles_in_x_order(dir);
  ASSERT_GT(point_parts(tiles[0]).size(), 4u);
  const CityParams params;
  city::SurveyIndex index;
  for (int t = 0; t < 2; ++t) {
    SCOPED_TRACE(tiles[static_cast<std::size_t>(t)]);
    city::RegionReader plain(tiles, t);
    plain.add_neighbours(params.tile_margin);
    city::RegionReader indexed(tiles, t, true, &index);
    indexed.add_neighbours(params.tile_margin);
    const std::size_t parts = point_parts(tiles[0]).size() + point_parts(tiles[1]).size();
    EXPECT_EQ(plain.census_parts_read(), parts);
    EXPECT_EQ(indexed.census_parts_total(), parts);
    if (t == 0) {
      EXPECT_EQ(indexed.census_parts_read(), parts);  // neither file seen before: both decoded whole, remembered
    } else {
      // The west tile is known: of its strips (about 165 m wide in all) only those within 50 m (and a 25 m cell)
      // of the east tile.
      const std::size_t own = point_parts(tiles[1]).size(), west = point_parts(tiles[0]).size();
      EXPECT_GT(indexed.census_parts_read(), own);
      EXPECT_LE(indexed.census_parts_read(), own + (3 * west) / 4) << own << " own parts, " << west << " west parts";
      EXPECT_LT(indexed.census_points_decoded(), plain.census_points_decoded());
    }
    ASSERT_TRUE(indexed.classified(params.classes));
    EXPECT_EQ(indexed.crs(), plain.crs());
    EXPECT_TRUE(indexed.origin() == plain.origin());
    EXPECT_TRUE(indexed.own_box().min == plain.own_box().min && indexed.own_box().max == plain.own_box().max);
    EXPECT_TRUE(indexed.area().min == plain.area().min && indexed.area().max == plain.area().max);
    EXPECT_EQ(indexed.building_cells(), plain.building_cells());
    EXPECT_EQ(indexed.own_building_points(), plain.own_building_points());
    SurveyRegion a, b;
    const PointCloud all_plain = plain.read(nullptr, a);
    const PointCloud all_indexed = indexed.read(nullptr, b);
    ASSERT_EQ(all_indexed.size(), all_plain.size());
    EXPECT_TRUE(all_indexed.points == all_plain.points);
    EXPECT_EQ(all_indexed.attributes.classification, all_plain.attributes.classification);
    EXPECT_EQ(all_indexed.attributes.number_of_returns, all_plain.attributes.number_of_returns);
    EXPECT_EQ(b.own_points, a.own_points);
    const city::KeepMask mask_plain = city::first_keep_mask(plain, nullptr, params);
    const city::KeepMask mask_indexed = city::first_keep_mask(indexed, nullptr, params);
    const PointCloud kept_plain = plain.read(&mask_plain, a);
    const PointCloud kept_indexed = indexed.read(&mask_indexed, b);
    ASSERT_GT(kept_plain.size(), 0u);
    ASSERT_EQ(kept_indexed.size(), kept_plain.size());
    EXPECT_TRUE(kept_indexed.points == kept_plain.points);
    EXPECT_EQ(b.left_out.ground, a.left_out.ground);
    EXPECT_EQ(b.left_out.building, a.left_out.building);
    EXPECT_EQ(b.left_out.other, a.left_out.other);
    EXPECT_EQ(b.own_points, a.own_points);
  }
  EXPECT_EQ(index.files(), 2u);
  EXPECT_GT(index.bytes(), 0u);
  index.forget_after(0);
  EXPECT_EQ(index.files(), 2u);  // tile 1 reads both files
  index.forget_after(1);
  EXPECT_EQ(index.files(), 0u);
}

// DECISIONS #142: a survey's run (with its SurveyIndex) plans every tile as a tile planned alone (every file decoded
// whole): plan.json and every work file the same bytes; the index never holds every file of the 3 x 3 survey.
TEST(CityStream, ASurveyRunWithItsIndexPlansEveryTileAsAlone) {
  const fs::path dir = fs::path(HSR_TEST_TMP_DIR) / "stream_index_run";
  fs::remove_all(dir);
  FootprintSet footprints;
  city::CityOptions o;
  o.tiles = three_by_three(dir, footprints);
  o.footprints = (dir / "footprints.geojson").string();
  o.id_field = "id";
  o.output = (dir / "out").string();
  o.hsr_cli = "/bin/true";  // the plans are what is compared
  o.jobs = 1;
  city::CityRunStats stats;
  city::run_city(o, &stats);
  EXPECT_GT(stats.most_index_files, 0u);
  EXPECT_LT(stats.most_index_files, o.tiles.size());
  for (const city::TileFiles& files : city::tile_files(o)) {
    SCOPED_TRACE(files.tile);
    const std::map<std::string, std::string> run = work_files(files.work);
    ASSERT_GT(run.size(), 1u);
    fs::remove_all(files.work);
    city::plan_tile(o, files);  // no index: every file decoded whole
    const std::map<std::string, std::string> alone = work_files(files.work);  // plan.json, NAME.ply, footprints
    ASSERT_GT(alone.size(), 1u);
    std::size_t different = 0;
    for (const auto& [name, bytes] : alone) {
      const auto it = run.find(name);
      different += it == run.end() || it->second != bytes;
    }
    EXPECT_EQ(different, 0u);
  }
}

// Issue 40 item 1 ("takes tiles (files, folders, globs)"): a folder given as a tile is its LAS/LAZ files (COPC's
// .copc.laz among them) in name order, not its other files or subfolders; a file stays as given; a folder without
// such a file is refused.
TEST(CitySurvey, AFolderOfTilesIsItsLasAndLazFilesInNameOrder) {
  const fs::path dir = fs::path(HSR_TEST_TMP_DIR) / "tile_folder";
  fs::remove_all(dir);
  fs::create_directories(dir / "tiles" / "sub");
  fs::create_directories(dir / "empty");
  for (const char* name : {"r1c0.laz", "r0c1.las", "r0c0.copc.laz", "notes.txt", "sub/r9c9.las"}) std::ofstream(dir / "tiles" / name) << "x";
  std::ofstream(dir / "empty" / "readme.md") << "x";
  const std::string t = (dir / "tiles").string();
  const std::vector<std::string> got = city::expand_tile_folders({t, "/elsewhere/one.las"});
  const std::vector<std::string> want = {(dir / "tiles" / "r0c0.copc.laz").string(), (dir / "tiles" / "r0c1.las").string(),
                                         (dir / "tiles" / "r1c0.laz").string(), "/elsewhere/one.las"};
  EXPECT_EQ(got, want);
  EXPECT_THROW(city::expand_tile_folders({(dir / "empty").string()}), Error);
}

// The grid of blocks: a side of about 1.4 blocks stays one block, of 1.6 two; every position has one block,
// positions off the grid the nearest.
TEST(CitySurvey, BlocksOfATileGiveEveryPositionOneBlock) {
  BBox box;
  box.extend(Vec3(100, 200, 0));
  box.extend(Vec3(1500, 1800, 0));  // 1,400 x 1,600
  const TileBlocks b = TileBlocks::over(box, 1000);
  EXPECT_EQ(b.nx, 1);
  EXPECT_EQ(b.ny, 2);
  EXPECT_EQ(TileBlocks::over(box, 0).count(), 1);
  EXPECT_EQ(b.of(Vec2(800, 999)), 0);
  EXPECT_EQ(b.of(Vec2(800, 1000)), 1);  // the south side is the block's own
  EXPECT_EQ(b.of(Vec2(-50, -50)), 0);
  EXPECT_EQ(b.of(Vec2(5000, 5000)), 1);
  const TileBlocks c = TileBlocks::over(box, 300);  // 5 x 5 of 280 x 320
  EXPECT_EQ(c.count(), 25);
  EXPECT_EQ(c.of(Vec2(1499.9, 1799.9)), 24);
  EXPECT_EQ(c.of(Vec2(100 + 280 * 2 + 1, 200 + 320 * 3 + 1)), 2 + 5 * 3);
}

}  // namespace
}  // namespace hsr
