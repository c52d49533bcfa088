// `hsr synth city --size`: a survey written tile by tile (synth/city_synth.h SynthSurvey; issue 40 item 2). The
// tiles of a survey are exactly the survey scanned as one tile, cut by position, to the bit (each ray draws
// its own numbers); buildings cut by a tile edge keep all their points; the files of a 2 x 2 survey hold the
// same footprints, truth and points as the one-tile survey; bad options are refused with one line.
#include "core/error.h"
#include "io/io.h"
#include "synth/city_synth.h"
#include "test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace fs = std::filesystem;
using namespace hsr;
using namespace hsr::test;

namespace {

/// A 160 m survey: 2 x 2 plots of 55 m (centres at 27.5 and 82.5 m), so a tile edge at 80 m cuts the second
/// row and column of buildings.
SynthCityParams small_survey(double tile_size) {
  SynthCityParams p;
  p.survey_size = 160.0;
  p.tile_size = tile_size;
  p.density = 6.0;
  p.seed = 3;
  p.terraced = 1;
  return p;
}

std::string file_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST(SynthSurvey, TwoByTwoTilesAreTheOneTileCut) {
  const SynthSurvey whole = plan_synth_survey(small_survey(160.0));
  const SynthSurvey cut = plan_synth_survey(small_survey(80.0));
  ASSERT_EQ(whole.tiles_per_side, 1);
  ASSERT_EQ(cut.tiles_per_side, 2);
  ASSERT_EQ(whole.buildings.size(), 5u);  // 4 plots and a terraced block
  ASSERT_EQ(cut.buildings.size(), whole.buildings.size());
  const SynthCity one = scan_survey_tile(whole, 0, 0);
  ASSERT_GT(one.cloud.size(), 100000u);
  std::size_t matched = 0;
  std::vector<std::set<int>> tiles_of_building(whole.buildings.size());
  for (int row = 0; row < 2; ++row)
    for (int col = 0; col < 2; ++col) {
      const SynthCity part = scan_survey_tile(cut, row, col);
      std::vector<std::size_t> expected;  // the one tile's points on this tile, in their order
      for (std::size_t i = 0; i < one.cloud.size(); ++i) {
        const Vec3& q = one.cloud.points[i];
        const bool east = q.x() >= 80.0, north = q.y() >= 80.0;
        if (east == (col == 1) && north == (row == 1)) expected.push_back(i);
      }
      ASSERT_EQ(part.cloud.size(), expected.size()) << "tile r" << row << "c" << col;
      for (std::size_t k = 0; k < expected.size(); ++k) {
        const std::size_t i = expected[k];
        ASSERT_EQ(part.cloud.points[k], one.cloud.points[i]) << "point " << k << " of tile r" << row << "c" << col;
        ASSERT_EQ(part.cloud.attributes.classification[k], one.cloud.attributes.classification[i]);
        ASSERT_EQ(part.cloud.attributes.return_number[k], one.cloud.attributes.return_number[i]);
        ASSERT_EQ(part.cloud.attributes.number_of_returns[k], one.cloud.attributes.number_of_returns[i]);
        ASSERT_EQ(part.point_building[k], one.point_building[i]);
        if (part.point_building[k] >= 0) tiles_of_building[static_cast<std::size_t>(part.point_building[k])].insert(row * 2 + col);
      }
      matched += expected.size();
    }
  EXPECT_EQ(matched, one.cloud.size());
  std::size_t split = 0;
  for (const auto& t : tiles_of_building) split += t.size() > 1;
  EXPECT_GE(split, 1u) << "no building cut by the tile edges: the test does not test the cut";
  // Every class is there: ground, building, tree.
  std::set<int> classes(one.cloud.attributes.classification.begin(), one.cloud.attributes.classification.end());
  EXPECT_EQ(classes, (std::set<int>{2, 5, 6}));
}

TEST(SynthSurvey, TheFilesOfTwoByTwoTilesHoldTheOneTilesFootprintsTruthAndPoints) {
  const fs::path dir = fs::path(HSR_TEST_TMP_DIR) / "files";
  fs::remove_all(dir);
  SynthSurvey whole = plan_synth_survey(small_survey(160.0));
  SynthSurvey cut = plan_synth_survey(small_survey(80.0));
  const std::size_t one = write_synth_survey(whole, (dir / "whole").string());
  const std::size_t four = write_synth_survey(cut, (dir / "cut").string());
  EXPECT_EQ(four, one);
  EXPECT_EQ(file_bytes(dir / "cut" / "footprints.geojson"), file_bytes(dir / "whole" / "footprints.geojson"));
  for (const SynthCityBuilding& b : whole.buildings)
    EXPECT_EQ(file_bytes(dir / "cut" / "truth" / (b.id + ".obj")), file_bytes(dir / "whole" / "truth" / (b.id + ".obj")));
  auto truth = [&](const char* which) {
    std::ifstream in(dir / which / "truth.json");
    return nlohmann::json::parse(in);
  };
  const nlohmann::json a = truth("whole"), b = truth("cut");
  EXPECT_EQ(a["building"], b["building"]);  // ids, footprints, ground, and each building's points over its tiles
  ASSERT_EQ(b["survey"]["tiles"].size(), 4u);
  std::size_t read = 0;
  for (const auto& t : b["survey"]["tiles"]) {
    const PointCloud c = read_points((dir / "cut" / t["file"].get<std::string>()).string());
    EXPECT_EQ(c.size(), t["points"].get<std::size_t>());
    read += c.size();
    const auto& e = t["extent"];
    BBox box;
    for (const Vec3& q : c.points) box.extend(q + c.origin);
    // A point lies on its tile, or within the scan's reach past the survey's side (the nearest tile).
    const double slack = (t["row"] == 1 || t["col"] == 1) ? SynthSurvey::kScanMargin : 0.0;
    EXPECT_GE(box.min.x(), e[0].get<double>() - 1e-3);
    EXPECT_GE(box.min.y(), e[1].get<double>() - 1e-3);
    EXPECT_LE(box.max.x(), e[2].get<double>() + slack + 1e-3);
    EXPECT_LE(box.max.y(), e[3].get<double>() + slack + 1e-3);
  }
  EXPECT_EQ(read, one);
  EXPECT_EQ(a["points"], b["points"]);
}

TEST(SynthSurvey, BadOptionsAreOneLine) {
  const fs::path out = fs::path(HSR_TEST_TMP_DIR) / "bad";
  for (const std::string args : {"--size 0", "--size -2", "--size 0.01", "--size 1 --tile-size 0", "--size 2 --tile-size 10",
                                 "--size 1 --buildings 20", "--size 1 --tiles 3", "--tile-size 500", "--unclassified",
                                 "--size 1 --terraced -1"}) {
    fs::remove_all(out);
    const CommandResult r = run_cli("synth city " + args + " -o '" + out.string() + "'");
    EXPECT_NE(r.exit_code, 0) << args;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << args << ": " << r.output;
    EXPECT_FALSE(fs::exists(out / "tiles")) << args;
  }
}
