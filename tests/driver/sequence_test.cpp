// The drivers' CityJSONSeq (src/driver/driver.h write_cityjson_sequence): features prepared ahead, as hsr city's
// FeatureMaker makes them while its workers run, give the same bytes as features prepared by the writer.
#include "driver/driver.h"
#include "io/cityjson.h"
#include "test_meshes.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>

namespace fs = std::filesystem;
using namespace hsr;
using namespace hsr::test;

namespace {

/// Three buildings (unit cubes, the second missing its file) whose LoDs add a box beside the cube and count
/// the calls.
struct Tile {
  fs::path dir;
  std::vector<driver::SequenceEntry> entries;
  std::atomic<int> lods_made{0};
  explicit Tile(const std::string& name) : dir(fs::path(HSR_TEST_TMP_DIR) / name) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    for (int i = 0; i < 3; ++i) {
      PolygonMesh cube = unit_cube();
      cube.origin = Vec3(100.0 + 3 * i, 200.0, 5.0);
      const std::string file = (dir / ("b" + std::to_string(i) + ".city.json")).string();
      if (i != 1) write_cityjson(file, cube, CityJsonParams{});
      driver::SequenceEntry e;
      e.input = "b" + std::to_string(i);
      e.cityjson = file;
      e.id = "B" + std::to_string(i);
      e.before = {{"rank", i}};
      e.lods = [this](const CityBuilding& b, const nlohmann::json& attributes, double) {
        ++lods_made;
        driver::FeatureLods out;
        PolygonMesh taller = b.mesh;
        for (Vec3& v : taller.vertices) v.z() *= 2.0;
        out.solids.push_back({"1.2", taller});
        out.attributes["rank_seen"] = attributes.value("rank", -1);
        return out;
      };
      entries.push_back(std::move(e));
    }
  }
};

}  // namespace

TEST(DriverSequence, FeaturesMadeAheadGiveTheSameBytesAsFeaturesMadeByTheWriter) {
  Tile tile("ahead");
  const std::string by_writer = (tile.dir / "writer.city.jsonl").string(), ahead = (tile.dir / "ahead.city.jsonl").string();
  ASSERT_EQ(driver::write_cityjson_sequence(by_writer, 0.001, "", tile.entries), 2u);  // b1 has no file
  EXPECT_EQ(tile.lods_made, 2);

  std::vector<std::optional<driver::PreparedFeature>> prepared;
  {
    driver::FeatureMaker maker(tile.entries);
    maker.add(2);  // in the order their runs end, not the sequence's
    maker.add(1);
    prepared = maker.take();
  }
  ASSERT_EQ(prepared.size(), 3u);
  EXPECT_FALSE(prepared[0].has_value());  // not given: the writer prepares it
  ASSERT_TRUE(prepared[1].has_value());
  EXPECT_FALSE(prepared[1]->model.has_value());
  EXPECT_NE(prepared[1]->read_warning.find("b1 left out"), std::string::npos) << prepared[1]->read_warning;
  ASSERT_TRUE(prepared[2].has_value() && prepared[2]->model.has_value());
  EXPECT_EQ(prepared[2]->solids.size(), 2u);  // the child's solid, then the LoD's
  EXPECT_EQ(prepared[2]->attributes.value("rank_seen", -1), 2);
  EXPECT_EQ(tile.lods_made, 3);  // b2's, once

  ASSERT_EQ(driver::write_cityjson_sequence(ahead, 0.001, "", tile.entries, std::move(prepared)), 2u);
  EXPECT_EQ(tile.lods_made, 4);  // b0's by the writer; b2's not again
  EXPECT_EQ(read_file(ahead), read_file(by_writer));
}

TEST(DriverSequence, AMakerLeftWithWorkGivenEndsCleanly) {
  Tile tile("left");
  driver::FeatureMaker maker(tile.entries);
  for (std::size_t i = 0; i < 3; ++i) maker.add(i);
  maker.add(7);  // no such entry: ignored
}
