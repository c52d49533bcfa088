// `hsr city` as a user runs it, on a small synthetic tile (`hsr synth city`: 4 buildings, one of them a
// terraced neighbour sharing a wall, sloping ground, trees): one valid solid per building standing on its true
// ground, inside its footprint, neighbours not overlapping; the same bytes whatever --jobs and from run to
// run; --resume; a footprint with few points modelled as its prism, one with none listed (DECISIONS #165); a
// building that fails listed with its reason, exit 1; the tile without
// classes and without footprints; the exit codes (groups that are not buildings are no failure); footprints
// that lie on no tile (another CRS, or none to compare) refused with one line naming --crs; bad input refused
// with one line and no output; tiles cut through a building are one survey; a kill and --resume.
#include "city/footprints.h"
#include "core/error.h"
#include "io/io.h"
#include "eval/eval.h"
#include "io/cityjson.h"
#include "io/las_writer.h"
#include "test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <thread>

namespace fs = std::filesystem;
using namespace hsr;
using namespace hsr::test;

namespace {

class City : public ::testing::Test {
 protected:
  static fs::path data;
  static void SetUpTestSuite() {
    data = fs::path(HSR_TEST_TMP_DIR) / "tile";
    if (fs::exists(data / "truth.json")) return;
    const CommandResult r = run_cli("synth city --buildings 4 --terraced 1 --seed 2 -o '" + data.string() + "' -q");
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  static std::string q(const fs::path& p) { return "'" + p.string() + "'"; }
  static nlohmann::json truth() {
    std::ifstream in(data / "truth.json");
    return nlohmann::json::parse(in);
  }
  static std::map<std::string, Footprint> footprints() {
    FootprintReadParams rp;
    rp.id_field = "id";
    std::map<std::string, Footprint> out;
    for (const auto& f : read_footprints((data / "footprints.geojson").string(), rp).features) out[f.id] = f.footprint;
    return out;
  }
};
fs::path City::data;

double outside_distance(const Vec2& p, const Footprint& f) {
  if (inside_footprint(p.x(), p.y(), f)) return 0;
  double d = INFINITY;
  for (const auto& poly : f)
    for (std::size_t i = 0, j = poly.outer.size() - 1; i < poly.outer.size(); j = i++) {
      const Vec2 a = poly.outer[j], b = poly.outer[i];
      const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      d = std::min(d, (p - (a + t * (b - a))).norm());
    }
  return d;
}

/// Depth of p inside the footprint (0 outside): its distance to the boundary when inside.
double inside_depth(const Vec2& p, const Footprint& f) {
  if (!inside_footprint(p.x(), p.y(), f)) return 0;
  double d = INFINITY;
  for (const auto& poly : f)
    for (std::size_t i = 0, j = poly.outer.size() - 1; i < poly.outer.size(); j = i++) {
      const Vec2 a = poly.outer[j], b = poly.outer[i];
      const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      d = std::min(d, (p - (a + t * (b - a))).norm());
    }
  return d;
}

std::vector<std::vector<std::string>> read_csv(const fs::path& p) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(read_file(p));
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::string cell;
    bool quoted = false;
    for (char c : line) {
      if (c == '"') quoted = !quoted;
      else if (c == ',' && !quoted) cells.push_back(std::exchange(cell, ""));
      else cell += c;
    }
    cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

TEST_F(City, EveryBuildingAValidSolidOnItsGroundInsideItsFootprint) {
  const fs::path out = scratch_dir("classes_footprints");
  const CommandResult r = run_cli("city " + q(data / "tile.las") + " -o " + q(out / "a.city.jsonl") + " --footprints " +
                                  q(data / "footprints.geojson") + " --id-field id -j 2");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("building = LAS class 6"), std::string::npos) << r.output;
  const CityModel model = read_cityjson((out / "a.city.jsonl").string());
  EXPECT_EQ(model.reference_system, "https://www.opengis.net/def/crs/EPSG/0/28992");
  ASSERT_EQ(model.buildings.size(), 4u);
  const nlohmann::json t = truth();
  const auto fps = footprints();
  std::map<std::string, PolygonMesh> global;
  for (std::size_t k = 0; k < 4; ++k) {
    const CityBuilding& b = model.buildings[k];
    EXPECT_EQ(b.id, t["building"][k]["id"].get<std::string>());
    const Validity v = check_validity(b.mesh);
    EXPECT_TRUE(v.valid()) << b.id << ": " << v.summary();
    EXPECT_EQ(b.attributes["family"], t["building"][k]["family"]);
    EXPECT_TRUE(b.attributes.contains("hsr_ground_z"));
    EXPECT_FALSE(b.attributes.contains("hsr_seconds"));  // no timing: the same bytes every run
    PolygonMesh g = b.mesh;
    for (Vec3& p : g.vertices) p += g.origin;
    double lowest = INFINITY, worst_outside = 0;
    for (const Vec3& p : g.vertices) {
      lowest = std::min(lowest, p.z());
      worst_outside = std::max(worst_outside, outside_distance(p.head<2>(), fps.at(b.id)));
    }
    EXPECT_NEAR(lowest, t["building"][k]["ground_z"].get<double>(), 0.1) << b.id;  // its ground face
    EXPECT_LE(worst_outside, 0.002) << b.id;  // inside its prism (within the 1 mm grid)
    global[b.id] = g;
  }
  // The terraced neighbour and its host share a wall and do not overlap.
  const std::string block = t["building"][3]["id"], host = t["building"][3]["attached_to"];
  ASSERT_FALSE(host.empty());
  double a_in_b = 0, b_in_a = 0;
  for (const Vec3& p : global[host].vertices) a_in_b = std::max(a_in_b, inside_depth(p.head<2>(), fps.at(block)));
  for (const Vec3& p : global[block].vertices) b_in_a = std::max(b_in_a, inside_depth(p.head<2>(), fps.at(host)));
  EXPECT_LE(a_in_b, 0.002);
  EXPECT_LE(b_in_a, 0.002);
  const auto rows = read_csv(out / "a.summary.csv");
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[0][7], "building");
  for (std::size_t i = 1; i < rows.size(); ++i) EXPECT_EQ(rows[i][1], "ok") << rows[i][6];
}

TEST_F(City, SameBytesWhateverTheJobsOrProcessesAndResumeRedoesOnlyWhatIsMissing) {
  const fs::path out = scratch_dir("jobs");
  const std::string common = " --footprints " + q(data / "footprints.geojson") + " --id-field id";
  ASSERT_EQ(run_cli("city " + q(data / "tile.las") + " -o " + q(out / "one.city.jsonl") + common + " -j 1 -q").exit_code, 0);
  ASSERT_EQ(run_cli("city " + q(data / "tile.las") + " -o " + q(out / "two.city.jsonl") + common + " -j 2 -q").exit_code, 0);
  ASSERT_EQ(run_cli("city " + q(data / "tile.las") + " -o " + q(out / "fresh.city.jsonl") + common + " -j 2 -q --fresh-processes").exit_code, 0);
  ASSERT_EQ(run_cli("city " + q(data / "tile.las") + " -o " + q(out / "serial.city.jsonl") + common + " -j 1 -q --one-at-a-time").exit_code, 0);
  const std::string one = read_file(out / "one.city.jsonl");
  EXPECT_EQ(one, read_file(out / "two.city.jsonl"));
  EXPECT_EQ(one, read_file(out / "fresh.city.jsonl"));  // workers (the default) and a process per building
  // by turns (the default: the next building's first runs beside the last's step 7, DECISIONS #235) and not
  if (std::thread::hardware_concurrency() >= 2) EXPECT_TRUE(fs::exists(out / "one.work" / ".turn.0"));
  EXPECT_FALSE(fs::exists(out / "two.work" / ".turn.0") && std::thread::hardware_concurrency() == 2);
  EXPECT_FALSE(fs::exists(out / "serial.work" / ".turn.0"));
  EXPECT_EQ(one, read_file(out / "serial.city.jsonl"));
  fs::remove(out / "one.work" / "B0002.city.json");
  const CommandResult r = run_cli("city " + q(data / "tile.las") + " -o " + q(out / "one.city.jsonl") + common + " --resume");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("plan of 4 buildings reused"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("3 of 4 buildings already done"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("city: 4/4 done"), std::string::npos) << r.output;
  EXPECT_EQ(read_file(out / "one.city.jsonl"), one);
}

TEST_F(City, AFootprintWithFewPointsIsItsPrismOneWithNoneIsListedAndExitZero) {
  // DECISIONS #165: a footprint with fewer points than a run needs (a 1 m square on a roof: about 10-20 points,
  // under min_building_points 50) is modelled as its footprint prism; one holding no point (an empty lot) is
  // listed as no-points. Neither is a failure: exit 0. Before, both failed and the run exited 1.
  const fs::path out = scratch_dir("few_points");
  FootprintReadParams rp;
  rp.id_field = "id";
  FootprintSet set = read_footprints((data / "footprints.geojson").string(), rp);
  const Footprint& host = set.features[0].footprint;
  Vec2 c(NAN, NAN);  // a point 1.5 m inside the first building's footprint
  BBox box;
  for (const Vec2& v : host.front().outer) box.extend(Vec3(v.x(), v.y(), 0));
  for (double x = box.min.x(); x <= box.max.x() && std::isnan(c.x()); x += 0.25)
    for (double y = box.min.y(); y <= box.max.y() && std::isnan(c.x()); y += 0.25)
      if (inside_depth(Vec2(x, y), host) >= 1.5) c = Vec2(x, y);
  ASSERT_FALSE(std::isnan(c.x()));
  FootprintFeature shed, empty;
  shed.id = "shed";
  shed.footprint = {{{c + Vec2(-0.5, -0.5), c + Vec2(0.5, -0.5), c + Vec2(0.5, 0.5), c + Vec2(-0.5, 0.5)}, {}}};
  shed.attributes = set.features[0].attributes;
  empty.id = "empty-lot";
  const nlohmann::json origin = truth()["origin"];
  const Vec2 corner(origin[0].get<double>() + 1, origin[1].get<double>() + 1);  // the tile's south-west corner: no building
  empty.footprint = {{{corner, corner + Vec2(2, 0), corner + Vec2(2, 2), corner + Vec2(0, 2)}, {}}};
  empty.attributes = set.features[0].attributes;
  set.features.push_back(shed);
  set.features.push_back(empty);
  write_footprints((out / "more.gpkg").string(), set.features, "EPSG:28992");
  const CommandResult r = run_cli("city " + q(data / "tile.las") + " -o " + q(out / "f.city.jsonl") + " --footprints " +
                                  q(out / "more.gpkg") + " --id-field id -j 2");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const CityModel model = read_cityjson((out / "f.city.jsonl").string());
  ASSERT_EQ(model.buildings.size(), 5u);
  const CityBuilding& b = model.buildings[4];
  EXPECT_EQ(b.id, "shed");
  EXPECT_TRUE(check_validity(b.mesh).valid());
  EXPECT_EQ(b.attributes.value("hsr_fallback", ""), "footprint prism");
  EXPECT_EQ(b.lods.size(), 3u);
  EXPECT_EQ(b.mesh.faces.size(), 6u);  // roof, 4 walls, bottom: the square extruded
  for (const Vec3& v : b.mesh.vertices) {
    const Vec2 g = (v + model.translate).head<2>();
    EXPECT_NEAR(std::abs(g.x() - c.x()), 0.5, 0.002);  // on the footprint's corners
    EXPECT_NEAR(std::abs(g.y() - c.y()), 0.5, 0.002);
  }
  const auto rows = read_csv(out / "f.summary.csv");
  ASSERT_EQ(rows.size(), 7u);
  EXPECT_EQ(rows[5][7], "shed");
  EXPECT_EQ(rows[5][1], "ok") << rows[5][6];
  const std::size_t shed_points = std::stoul(rows[5][8]);
  EXPECT_GE(shed_points, 3u);
  EXPECT_LT(shed_points, 50u);
  EXPECT_EQ(rows[6][7], "empty-lot");
  EXPECT_EQ(rows[6][1], "no-points");
  EXPECT_NE(rows[6][6].find("0 building points"), std::string::npos) << rows[6][6];
  EXPECT_FALSE(fs::exists(out / "f.work" / "empty-lot.ply"));  // not run
}

TEST_F(City, AFailedBuildingIsListedWithItsReasonAndExitsOne) {
  const fs::path out = scratch_dir("failure");
  // A time budget no run meets: every building fails, each listed with its reason, and the run exits 1.
  const CommandResult r = run_cli("city " + q(data / "tile.las") + " -o " + q(out / "f.city.jsonl") + " --footprints " +
                                  q(data / "footprints.geojson") + " --id-field id -j 2 -- --max-seconds 0.000001");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(read_cityjson((out / "f.city.jsonl").string()).buildings.empty());
  const auto rows = read_csv(out / "f.summary.csv");
  ASSERT_EQ(rows.size(), 5u);
  for (std::size_t i = 1; i < rows.size(); ++i) {
    EXPECT_NE(rows[i][1], "ok");
    EXPECT_FALSE(rows[i][6].empty());
  }
}

TEST_F(City, WithoutClassesAndWithoutFootprints) {
  const fs::path out = scratch_dir("neither");
  const CommandResult r = run_cli("city " + q(data / "tile_unclassified.las") + " -o " + q(out / "n.city.jsonl") + " -j 2");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("SMRF"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("connected groups"), std::string::npos) << r.output;
  const CityModel model = read_cityjson((out / "n.city.jsonl").string());
  // The terraced pair touches: one group (the documented limit of groups in plan), so 3 of the 4.
  ASSERT_EQ(model.buildings.size(), 3u);
  for (const CityBuilding& b : model.buildings) EXPECT_TRUE(check_validity(b.mesh).valid()) << b.id;
  EXPECT_EQ(model.buildings[0].id, "b0001");
}

TEST_F(City, GroupsThatAreNotBuildingsAreListedAndExitZero) {
  const fs::path out = scratch_dir("not_buildings");
  // At 0 every group is vegetation: nothing is modelled, nothing failed.
  const CommandResult r = run_cli("city " + q(data / "tile_unclassified.las") + " -o " + q(out / "v.city.jsonl") +
                                  " --max-group-variation 0 -j 2");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("not-a-building"), std::string::npos) << r.output;
  const auto rows = read_csv(out / "v.summary.csv");
  ASSERT_EQ(rows.size(), 4u);  // header + the 3 groups
  for (std::size_t i = 1; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i][1], "not-a-building");
    EXPECT_EQ(rows[i][6].rfind("vegetation: ", 0), 0u) << rows[i][6];
    EXPECT_FALSE(fs::exists(out / "v.work" / (rows[i][7] + ".ply")));  // not run
  }
  EXPECT_TRUE(read_cityjson((out / "v.city.jsonl").string()).buildings.empty());
}

/// The tile's footprints moved 100 km east, in `crs` ("" none), written to `path`.
void far_footprints(const fs::path& footprints, const fs::path& path, const std::string& crs) {
  FootprintReadParams rp;
  rp.id_field = "id";
  FootprintSet set = read_footprints(footprints.string(), rp);
  for (FootprintFeature& f : set.features)
    for (FootprintPolygon& p : f.footprint)
      for (Vec2& v : p.outer) v.x() += 1e5;
  write_footprints(path.string(), set.features, crs);
}

TEST_F(City, FootprintsOnNoTileAreOneLineNamingCrs) {
  const fs::path out = scratch_dir("no_footprint");
  const int bad_input = exit_code(Status::BadInput);
  far_footprints(data / "footprints.geojson", out / "far.gpkg", "EPSG:28992");
  // Both CRSs known (the tile's EPSG:28992): the footprints are elsewhere.
  CommandResult r = run_cli("city " + q(data / "tile.las") + " -o " + q(out / "a.city.jsonl") + " --footprints " +
                            q(out / "far.gpkg") + " --id-field id");
  EXPECT_EQ(r.exit_code, bad_input) << r.output;
  EXPECT_NE(r.output.find("hsr: city: none of the 4 footprints of "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("a wrong --crs"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out / "a.city.jsonl"));
  EXPECT_FALSE(fs::exists(out / "a.work"));
  // Points that name no CRS (a PLY of the tile's points) and footprints in one: not compared, so the line
  // asks for the points' CRS.
  PointCloud points = read_points((data / "tile.las").string());
  points.crs.clear();
  write_points((out / "nocrs.ply").string(), points);
  r = run_cli("city " + q(out / "nocrs.ply") + " -o " + q(out / "b.city.jsonl") + " --footprints " + q(out / "far.gpkg") +
              " --id-field id");
  EXPECT_EQ(r.exit_code, bad_input) << r.output;
  EXPECT_NE(r.output.find("the points name no CRS"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("give the points' CRS with --crs EPSG:N"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out / "b.city.jsonl"));
  // Several tiles: refused once every tile is planned, when none holds a footprint.
  r = run_cli("city " + q(data / "tile.las") + " " + q(data / "tile_unclassified.las") + " -o " + q(out / "dir") +
              " --footprints " + q(out / "far.gpkg") + " --id-field id -q");
  EXPECT_EQ(r.exit_code, bad_input) << r.output;
  EXPECT_NE(r.output.find("lies on any of the 2 tiles"), std::string::npos) << r.output;
  // The same points with --crs: compared, the footprints are on the tile and all 4 run.
  r = run_cli("city " + q(out / "nocrs.ply") + " -o " + q(out / "c.city.jsonl") + " --footprints " +
              q(data / "footprints.geojson") + " --id-field id --crs EPSG:28992 -j 2");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("--crs EPSG:N"), std::string::npos) << r.output;
  EXPECT_EQ(read_cityjson((out / "c.city.jsonl").string()).buildings.size(), 4u);
}

/// The tile cut into two at x = `cut` (file coordinates), as a survey is published: DIR/west.las, DIR/east.las.
void cut_tile(const fs::path& tile, double cut, const fs::path& dir) {
  const PointCloud cloud = read_points(tile.string());
  std::vector<std::size_t> west, east;
  for (std::size_t i = 0; i < cloud.size(); ++i) (cloud.points[i].x() + cloud.origin.x() < cut ? west : east).push_back(i);
  write_las((dir / "west.las").string(), select_points(cloud, west));
  write_las((dir / "east.las").string(), select_points(cloud, east));
}

/// building id -> its summary row.
std::map<std::string, std::vector<std::string>> rows_by_building(const std::vector<fs::path>& summaries) {
  std::map<std::string, std::vector<std::string>> out;
  for (const fs::path& s : summaries) {
    const auto rows = read_csv(s);
    for (std::size_t i = 1; i < rows.size(); ++i) EXPECT_TRUE(out.emplace(rows[i][7], rows[i]).second) << rows[i][7] << " twice";
  }
  return out;
}

TEST_F(City, TilesCutThroughABuildingAreOneSurvey) {
  const fs::path out = scratch_dir("survey");
  // Cut through the middle of the first building's footprint.
  const nlohmann::json ring = truth()["building"][0]["footprint"]["coordinates"][0][0];
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& v : ring) {
    lo = std::min(lo, v[0].get<double>());
    hi = std::max(hi, v[0].get<double>());
  }
  cut_tile(data / "tile.las", 0.5 * (lo + hi), out);
  const std::string fp = " --footprints " + q(data / "footprints.geojson") + " --id-field id -j 2 -q";
  ASSERT_EQ(run_cli("city " + q(data / "tile.las") + " -o " + q(out / "whole.city.jsonl") + fp).exit_code, 0);
  const CommandResult r = run_cli("city " + q(out / "west.las") + " " + q(out / "east.las") + " -o " + q(out / "tiles") + fp);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto whole = rows_by_building({out / "whole.summary.csv"});
  const auto split = rows_by_building({out / "tiles" / "west.summary.csv", out / "tiles" / "east.summary.csv"});
  ASSERT_EQ(split.size(), 4u);  // each building planned by one tile only
  for (const auto& [id, row] : whole) {
    ASSERT_TRUE(split.count(id)) << id;
    EXPECT_EQ(split.at(id)[1], "ok") << id << ": " << split.at(id)[6];
    EXPECT_EQ(split.at(id)[8], row[8]) << id << ": every point of the building, from both tiles";
    EXPECT_EQ(split.at(id)[11], row[11]) << id << ": the same ground ring";
  }
  std::size_t features = 0;
  for (const char* name : {"west", "east"})
    for (const CityBuilding& b : read_cityjson((out / "tiles" / (std::string(name) + ".city.jsonl")).string()).buildings) {
      EXPECT_TRUE(check_validity(b.mesh).valid()) << b.id;
      ++features;
    }
  EXPECT_EQ(features, 4u);
  // Without footprints: the groups across the edge are joined, each planned once.
  const CommandResult g = run_cli("city " + q(out / "west.las") + " " + q(out / "east.las") + " -o " + q(out / "groups") + " -j 2 -q");
  ASSERT_EQ(g.exit_code, 0) << g.output;
  const auto groups = rows_by_building({out / "groups" / "west.summary.csv"});
  const auto groups_east = rows_by_building({out / "groups" / "east.summary.csv"});
  EXPECT_EQ(groups.size() + groups_east.size(), 3u);  // as the whole tile: the terraced pair is one group
}

TEST_F(City, ASurveyReportsItsProgressWithAnEtaAndQuietSaysNothing) {
  const fs::path out = scratch_dir("progress");
  const nlohmann::json ring = truth()["building"][0]["footprint"]["coordinates"][0][0];
  cut_tile(data / "tile.las", ring[0][0].get<double>(), out);
  const std::string tiles = q(out / "west.las") + " " + q(out / "east.las");
  const std::string fp = " --footprints " + q(data / "footprints.geojson") + " --id-field id -j 2";
  const CommandResult r = run_cli("city " + tiles + " -o " + q(out / "loud") + fp);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // Per building, the tile named; after each tile, the survey's buildings, rate and time left.
  EXPECT_TRUE(std::regex_search(r.output, std::regex("city: tile [12] of 2: 1/[0-9]+ done \\([0-9]+ ok, 0 failed\\), "
                                                      "[0-9.]+ inputs/min, (ETA [0-9]+ (s|min)|done)")))
      << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("city: tile 1 of 2 done \\(west\\.las\\): [0-9]+ buildings in [0-9.]+ (s|min), "
                                                      "[0-9]+ buildings/min, ETA [0-9]+ (s|min) \\(1 tile\\)")))
      << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("city: tile 2 of 2 done \\(east\\.las\\): 4 buildings in [0-9.]+ (s|min), "
                                                      "[0-9]+ buildings/min, done")))
      << r.output;
  const CommandResult quiet = run_cli("city " + tiles + " -o " + q(out / "quiet") + fp + " -q");
  ASSERT_EQ(quiet.exit_code, 0) << quiet.output;
  EXPECT_EQ(quiet.output, "");
}

TEST_F(City, AKillAndResumeLoseNothingAndRunNothingTwice) {
  const fs::path out = scratch_dir("kill");
  const std::string common = " --footprints " + q(data / "footprints.geojson") + " --id-field id -j 1 -q";
  ASSERT_EQ(run_cli("city " + q(data / "tile.las") + " -o " + q(out / "ref.city.jsonl") + common).exit_code, 0);
  // A stand-in for hsr that hangs on the third building it is given, whichever the run's order makes it, until `go`
  // exists: the run is killed there, after two were done, whatever the machine's speed.
  const fs::path slow = out / "slow.sh", go = out / "go", calls = out / "calls";
  fs::create_directories(calls);
  {
    std::ofstream s(slow);
    s << "#!/bin/sh\nn=0\nwhile ! mkdir '" << calls.string() << "/'$n 2>/dev/null; do n=$((n+1)); done\n"
      << "if [ $n -eq 2 ]; then while [ ! -e '" << go.string() << "' ]; do sleep 0.1; done; fi\nexec '" << HSR_CLI_PATH
      << "' \"$@\"\n";
  }
  fs::permissions(slow, fs::perms::owner_all);
  const std::string run = "city " + q(data / "tile.las") + " -o " + q(out / "k.city.jsonl") + common + " --hsr " + q(slow);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::setpgid(0, 0);
    ::execl("/bin/sh", "sh", "-c", (std::string(HSR_CLI_PATH) + " " + run + " > /dev/null 2>&1").c_str(), static_cast<char*>(nullptr));
    std::_Exit(127);
  }
  ::setpgid(pid, pid);
  const auto done_files = [&] {
    std::vector<fs::path> files;
    if (fs::exists(out / "k.work"))
      for (const auto& e : fs::directory_iterator(out / "k.work"))
        if (const std::string f = e.path().filename().string();
            f.size() > 10 && f.compare(f.size() - 10, 10, ".city.json") == 0)
          files.push_back(e.path());
    std::sort(files.begin(), files.end());
    return files;
  };
  for (int i = 0; i < 1200 && done_files().size() < 2; ++i) ::usleep(50000);
  ::usleep(200000);
  ::kill(-pid, SIGKILL);  // the whole group, as Ctrl-C or a batch system's kill does
  int status = 0;
  ::waitpid(pid, &status, 0);
  const std::vector<fs::path> done = done_files();
  ASSERT_EQ(done.size(), 2u) << "two buildings done, the third hanging, in 60 s";
  EXPECT_FALSE(fs::exists(out / "k.city.jsonl"));  // killed before the sequence was written
  const auto first_time = fs::last_write_time(done[0]), second_time = fs::last_write_time(done[1]);
  std::ofstream(go).put('\n');
  const CommandResult r = run_cli(run + " --resume");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(fs::last_write_time(done[0]), first_time);  // not run again
  EXPECT_EQ(fs::last_write_time(done[1]), second_time);
  EXPECT_EQ(read_file(out / "k.city.jsonl"), read_file(out / "ref.city.jsonl"));  // nothing lost, nothing twice
}

TEST_F(City, BadInputOneLineAndNoOutput) {
  const fs::path out = scratch_dir("bad");
  CommandResult r = run_cli("city " + q(data / "tile_unclassified.las") + " -o " + q(out / "x.city.jsonl") + " --classes file");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("hsr: city: "), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out / "x.city.jsonl"));
  r = run_cli("city " + q(data / "tile.las") + " -o " + q(out / "y.city.jsonl") + " --footprints " + q(out / "none.gpkg"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("not found"), std::string::npos) << r.output;
  r = run_cli("city " + q(data / "tile.las") + " " + q(data / "tile_unclassified.las") + " -o " + q(out / "z.city.jsonl"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_FALSE(fs::exists(out / "y.city.jsonl"));
  EXPECT_FALSE(fs::exists(out / "z.city.jsonl"));
}

/// Runs `hsr city` with `args` and polls its process's memory map until it ends: whether the driver ever mapped
/// GDAL (its module, or libgdal), and its exit code. GDAL once loaded stays until the process ends, so a map read
/// every millisecond of a run of seconds cannot miss it.
std::pair<bool, int> driver_maps_gdal(const std::vector<std::string>& args) {
  std::vector<std::string> argv = {HSR_CLI_PATH, "city"};
  argv.insert(argv.end(), args.begin(), args.end());
  std::vector<char*> cargv;
  for (std::string& a : argv) cargv.push_back(a.data());
  cargv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::execv(cargv[0], cargv.data());
    ::_exit(127);
  }
  const std::string maps = "/proc/" + std::to_string(pid) + "/maps";
  bool mapped = false;
  int status = 0;
  for (;;) {
    const std::string m = read_file(maps);
    mapped = mapped || m.find("libhsr_gdal") != std::string::npos || m.find("libgdal") != std::string::npos;
    if (::waitpid(pid, &status, WNOHANG) == pid) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return {mapped, WIFEXITED(status) ? WEXITSTATUS(status) : -1};
}

TEST_F(City, TheDriverNeverMapsGdalAndABadFootprintFileIsStillOneLine) {
  // The footprints and the CRS questions go through GDAL in a short-lived child (DECISIONS #245): the driver,
  // which lives the whole run, never maps GDAL's ~100 libraries (about 30 MB of `hsr city -j 1`'s memory).
  const fs::path out = scratch_dir("no_gdal");
  const auto [mapped, code] = driver_maps_gdal({(data / "tile.las").string(), "-o", (out / "a.city.jsonl").string(), "--footprints",
                                                (data / "footprints.geojson").string(), "--id-field", "id", "-j", "1", "-q"});
  EXPECT_EQ(code, 0);
  EXPECT_FALSE(mapped);
  // GDAL's errors, thrown in the child, reach the user as before: one line, the same exit code.
  write_file(out / "junk.geojson", "not json");
  const CommandResult r = run_cli("city " + q(data / "tile.las") + " -o " + q(out / "b.city.jsonl") + " --footprints " +
                                  q(out / "junk.geojson"));
  EXPECT_EQ(r.exit_code, exit_code(Status::BadFormat));
  EXPECT_EQ(r.output, "hsr: city: footprints: '" + (out / "junk.geojson").string() + "' is not a vector file GDAL can read\n");
}

/// Newell vector of face f (normal x twice its area).
Vec3 face_newell(const PolygonMesh& m, std::size_t f) {
  Vec3 n = Vec3::Zero();
  const auto& r = m.faces[f];
  for (std::size_t i = 0; i < r.size(); ++i) n += m.vertices[r[i]].cross(m.vertices[r[(i + 1) % r.size()]]);
  return n;
}

bool inside_face_plan(const PolygonMesh& m, std::size_t f, double x, double y) {
  bool in = false;
  const auto& r = m.faces[f];
  for (std::size_t i = 0, j = r.size() - 1; i < r.size(); j = i++) {
    const Vec3 &a = m.vertices[r[i]], &b = m.vertices[r[j]];
    if ((a.y() > y) != (b.y() > y) && x < (b.x() - a.x()) * (y - a.y()) / (b.y() - a.y()) + a.x()) in = !in;
  }
  return in;
}

TEST_F(City, EveryFeatureCarriesThreeValidLodsAndItsRoofSlopesAreTheTruths) {
  const fs::path out = scratch_dir("lods");
  const CommandResult r = run_cli("city " + q(data / "tile.las") + " -o " + q(out / "a.city.jsonl") + " --footprints " +
                                  q(data / "footprints.geojson") + " --id-field id -j 2");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const CityModel model = read_cityjson((out / "a.city.jsonl").string());
  ASSERT_EQ(model.buildings.size(), 4u);
  // The features' JSON, for the roof surfaces' semantic attributes (in the order of the solid's faces).
  std::istringstream lines(read_file(out / "a.city.jsonl"));
  std::string line;
  std::getline(lines, line);
  std::size_t roofs_checked = 0;
  for (const CityBuilding& b : model.buildings) {
    ASSERT_EQ(b.lods.size(), 3u) << b.id;
    EXPECT_EQ(b.lods[0].lod, "2.2");  // geometry[0] stays the LoD 2.2
    EXPECT_EQ(b.lods[1].lod, "1.2");
    EXPECT_EQ(b.lods[2].lod, "1.3");
    for (const auto& g : b.lods) {
      const Validity v = check_validity(g.mesh);
      EXPECT_TRUE(v.valid()) << b.id << " LoD " << g.lod << ": " << v.summary();
      const std::string key = "b3_volume_lod" + g.lod.substr(0, 1) + g.lod.substr(2);
      EXPECT_NEAR(b.attributes[key].get<double>(), v.volume, 1e-6 * v.volume) << b.id << " " << key;
    }
    for (const char* k : {"b3_h_maaiveld", "b3_h_dak_min", "b3_h_dak_50p", "b3_h_dak_70p", "b3_h_dak_max", "b3_dak_type",
                          "b3_rmse_lod12", "b3_rmse_lod13", "b3_rmse_lod22", "b3_puntdichtheid", "b3_nodata_fractie",
                          "b3_reconstructie_onvolledig", "hsr_validity_lod12", "hsr_validity_lod13", "hsr_validity_lod22"})
      EXPECT_TRUE(b.attributes.contains(k)) << b.id << " lacks " << k;
    EXPECT_LE(b.attributes["b3_h_dak_min"].get<double>(), b.attributes["b3_h_dak_70p"].get<double>());
    EXPECT_LE(b.attributes["b3_h_dak_70p"].get<double>(), b.attributes["b3_h_dak_max"].get<double>());
    EXPECT_LT(b.attributes["b3_rmse_lod22"].get<double>(), b.attributes["b3_rmse_lod12"].get<double>()) << b.id;
    // Roof slopes and azimuths against the generator's truth: the truth's roof face under each roof
    // surface's plan centre (surfaces of 10 m² and more: small ones are dormer cheeks and slivers).
    std::getline(lines, line);
    const nlohmann::json f = nlohmann::json::parse(line);
    const nlohmann::json& sem = f["CityObjects"][b.id]["geometry"][0]["semantics"];
    PolygonMesh truth = read_mesh((data / "truth" / (b.id + ".obj")).string());
    for (Vec3& v : truth.vertices) v += truth.origin - b.mesh.origin;
    for (std::size_t face = 0; face < b.mesh.faces.size(); ++face) {
      const nlohmann::json& s = sem["surfaces"][sem["values"][0][face].get<std::size_t>()];
      if (s["type"] != "RoofSurface") continue;
      ASSERT_TRUE(s.contains("b3_hellingshoek")) << b.id;
      if (s["b3_opp"].get<double>() < 10) continue;
      Vec3 c = Vec3::Zero();
      for (std::uint32_t v : b.mesh.faces[face]) c += b.mesh.vertices[v];
      c /= static_cast<double>(b.mesh.faces[face].size());
      double top = -INFINITY;
      Vec3 n_truth = Vec3::Zero();
      for (std::size_t tf = 0; tf < truth.faces.size(); ++tf) {
        const Vec3 n = face_newell(truth, tf);
        if (n.z() <= 0 || !inside_face_plan(truth, tf, c.x(), c.y())) continue;
        const Vec3& p0 = truth.vertices[truth.faces[tf][0]];
        const double z = p0.z() - (n.x() * (c.x() - p0.x()) + n.y() * (c.y() - p0.y())) / n.z();
        if (z > top) top = z, n_truth = n.normalized();
      }
      ASSERT_TRUE(std::isfinite(top)) << b.id << ": no truth roof under a roof surface";
      const double slope = std::acos(n_truth.z()) * 180 / M_PI;
      EXPECT_NEAR(s["b3_hellingshoek"].get<double>(), slope, 1.0) << b.id << " face " << face;
      if (slope > 5) {
        double azimuth = std::atan2(n_truth.x(), n_truth.y()) * 180 / M_PI;
        if (azimuth < 0) azimuth += 360;
        const double d = std::fmod(std::abs(s["b3_azimut"].get<double>() - azimuth) + 180, 360) - 180;
        EXPECT_LE(std::abs(d), 2.0) << b.id << " face " << face;
      }
      ++roofs_checked;
    }
  }
  EXPECT_GE(roofs_checked, 8u);  // the gable's and the hip's slopes among them
}

TEST_F(City, LodChoosesTheGeometriesAndABadLodIsOneLine) {
  const fs::path out = scratch_dir("lod_choice");
  CommandResult r = run_cli("city " + q(data / "tile.las") + " -o " + q(out / "a.city.jsonl") + " --footprints " +
                            q(data / "footprints.geojson") + " --id-field id --lod 1.3,1.2");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const CityBuilding& b : read_cityjson((out / "a.city.jsonl").string()).buildings) {
    ASSERT_EQ(b.lods.size(), 2u) << b.id;
    EXPECT_EQ(b.lods[0].lod, "1.2");
    EXPECT_EQ(b.lods[1].lod, "1.3");
  }
  r = run_cli("city " + q(data / "tile.las") + " -o " + q(out / "b.city.jsonl") + " --lod 2.2");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const CityBuilding& b : read_cityjson((out / "b.city.jsonl").string()).buildings) EXPECT_EQ(b.lods.size(), 1u);
  r = run_cli("city " + q(data / "tile.las") + " -o " + q(out / "c.city.jsonl") + " --lod 1.4");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("hsr: city: --lod: '1.4' is not one of 1.2, 1.3, 2.2"), std::string::npos) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_FALSE(fs::exists(out / "c.city.jsonl"));
  EXPECT_FALSE(fs::exists(out / "c.work"));
}

}  // namespace
