// 3D Tiles out (src/tiles3d): the glb's layout by the glTF 2.0 specification, the tileset's structure by 3D Tiles
// 1.1, a building placed on the earth where its CRS says (known answer: the RD New origin near Amersfoort), its
// height and plan kept, bad input refused.
#include "core/error.h"
#include "io/cityjson.h"
#include "test_util.h"
#include "tiles3d/glb.h"
#include "tiles3d/tiles3d.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>

namespace fs = std::filesystem;
using namespace hsr;
using namespace hsr::test;

namespace {

std::uint32_t u32(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(b[at + k]);
  return v;
}

/// The glb's JSON chunk, after checking the header and the chunks' layout; `bin` receives the BIN chunk.
nlohmann::json parse_glb(const std::string& b, std::string& bin) {
  EXPECT_EQ(u32(b, 0), 0x46546C67u);  // "glTF"
  EXPECT_EQ(u32(b, 4), 2u);
  EXPECT_EQ(u32(b, 8), b.size());
  const std::uint32_t json_length = u32(b, 12);
  EXPECT_EQ(u32(b, 16), 0x4E4F534Au);
  EXPECT_EQ(json_length % 4, 0u);
  const std::size_t bin_at = 20 + json_length;
  EXPECT_EQ(u32(b, bin_at + 4), 0x004E4942u);
  bin = b.substr(bin_at + 8, u32(b, bin_at));
  EXPECT_EQ(bin.size() % 4, 0u);
  EXPECT_EQ(bin_at + 8 + bin.size(), b.size());
  return nlohmann::json::parse(b.substr(20, json_length));
}

/// A box of w x d x h metres with its south-west bottom corner at (x, y, z), its faces outward.
PolygonMesh box(double x, double y, double z, double w, double d, double h) {
  PolygonMesh m;
  for (int k = 0; k < 8; ++k) m.vertices.emplace_back(x + (k & 1 ? w : 0), y + (k & 2 ? d : 0), z + (k & 4 ? h : 0));
  m.faces = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  return m;
}

TEST(Glb, LayoutAccessorsAndBoundsFollowTheSpecification) {
  GlbMesh m;
  m.name = "tri";
  m.extras = {{"height", 3.5}};
  m.positions = {{0, 0, 0}, {2, 0, 0}, {0, 1, -3}};
  m.normals = {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}};
  m.colors = {{1, 0, 0}, {1, 0, 0}, {1, 0, 0}};
  m.indices = {0, 1, 2};
  std::string bin;
  const nlohmann::json g = parse_glb(glb_bytes({m, m}), bin);
  EXPECT_EQ(g["asset"]["version"], "2.0");
  ASSERT_EQ(g["nodes"].size(), 2u);
  EXPECT_EQ(g["nodes"][0]["name"], "tri");
  EXPECT_EQ(g["nodes"][0]["extras"]["height"], 3.5);
  EXPECT_EQ(g["buffers"][0]["byteLength"], bin.size());
  const nlohmann::json& prim = g["meshes"][1]["primitives"][0];
  const nlohmann::json& pos = g["accessors"][prim["attributes"]["POSITION"].get<int>()];
  EXPECT_EQ(pos["count"], 3);
  EXPECT_EQ(pos["min"], nlohmann::json({0.0, 0.0, -3.0}));
  EXPECT_EQ(pos["max"], nlohmann::json({2.0, 1.0, 0.0}));
  for (const auto& view : g["bufferViews"]) {
    EXPECT_EQ(view["byteOffset"].get<std::size_t>() % 4, 0u);
    EXPECT_LE(view["byteOffset"].get<std::size_t>() + view["byteLength"].get<std::size_t>(), bin.size());
  }
  // The second mesh's indices read back from the BIN chunk.
  const nlohmann::json& idx = g["accessors"][prim["indices"].get<int>()];
  const nlohmann::json& view = g["bufferViews"][idx["bufferView"].get<int>()];
  std::uint32_t read[3];
  std::memcpy(read, bin.data() + view["byteOffset"].get<std::size_t>(), sizeof read);
  EXPECT_EQ(read[0], 0u);
  EXPECT_EQ(read[2], 2u);
  m.indices = {0, 1, 3};  // past the vertices
  EXPECT_EQ(status_of([&] { glb_bytes({m}); }), Status::Internal);
}

TEST(Tiles3d, ABuildingInRdNewStandsOnTheEarthWhereItIs) {
  const fs::path dir = scratch_dir("tiles3d_rd");
  // A 10 x 20 x 6 m block at the RD New origin's false easting/northing (Amersfoort: 52.1552 N, 5.3872 E).
  CityJsonParams p;
  p.crs = "EPSG:28992";
  p.id = "block";
  write_cityjson((dir / "block.city.json").string(), box(155000, 463000, 0, 10, 20, 6), p);
  const Tiles3dSummary s = write_3d_tiles({(dir / "block.city.json").string()}, (dir / "out").string());
  EXPECT_TRUE(s.earth_fixed);
  EXPECT_EQ(s.crs, "EPSG:28992");
  EXPECT_EQ(s.buildings, 1u);
  EXPECT_EQ(s.triangles, 12u);
  const nlohmann::json ts = nlohmann::json::parse(read_file(dir / "out" / "tileset.json"));
  EXPECT_EQ(ts["asset"]["version"], "1.1");
  const nlohmann::json& root = ts["root"];
  EXPECT_EQ(root["refine"], "ADD");
  ASSERT_EQ(root["transform"].size(), 16u);
  ASSERT_EQ(root["children"].size(), 1u);
  EXPECT_EQ(root["children"][0]["content"]["uri"], "block.glb");
  EXPECT_EQ(root["children"][0]["geometricError"], 0);
  // The frame's origin in ECEF: on the ellipsoid's surface at the block's longitude and latitude.
  const Vec3 o(root["transform"][12].get<double>(), root["transform"][13].get<double>(), root["transform"][14].get<double>());
  const double lon = std::atan2(o.y(), o.x()) * 180 / M_PI;
  const double lat = std::atan2(o.z(), std::hypot(o.x(), o.y())) * 180 / M_PI;  // geocentric: below geodetic by ~0.19 deg
  EXPECT_NEAR(lon, 5.3873, 0.002);
  EXPECT_NEAR(lat, 52.1552 - 0.1915, 0.01);
  EXPECT_NEAR(o.norm(), 6.3648e6, 2e3);
  // Its axes: orthonormal, up along the ellipsoid's normal (close to the radius).
  Vec3 axis[3];
  for (int c = 0; c < 3; ++c) axis[c] = Vec3(root["transform"][4 * c].get<double>(), root["transform"][4 * c + 1].get<double>(),
                                             root["transform"][4 * c + 2].get<double>());
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(axis[a].norm(), 1.0, 1e-12);
    for (int b = a + 1; b < 3; ++b) EXPECT_NEAR(axis[a].dot(axis[b]), 0.0, 1e-12);
  }
  EXPECT_GT(axis[2].dot(o.normalized()), 0.99999);
  // The block keeps its height (glTF's y) and its plan (the box's plan diagonal, whatever the grid's turn).
  std::string bin;
  const nlohmann::json g = parse_glb(read_file(dir / "out" / "block.glb"), bin);
  EXPECT_EQ(g["nodes"][0]["name"], "block");
  const nlohmann::json& pos = g["accessors"][g["meshes"][0]["primitives"][0]["attributes"]["POSITION"].get<int>()];
  const double height = pos["max"][1].get<double>() - pos["min"][1].get<double>();
  EXPECT_NEAR(height, 6.0, 0.01);
  EXPECT_EQ(pos["count"], 36);  // 12 triangles, flat shaded
  const nlohmann::json box_volume = root["children"][0]["boundingVolume"]["box"];
  EXPECT_NEAR(2 * box_volume[11].get<double>(), 6.0, 0.01);  // half-axis up
  const double plan = std::hypot(2 * box_volume[3].get<double>(), 2 * box_volume[7].get<double>());
  EXPECT_GT(plan, std::hypot(10.0, 20.0) - 0.02);  // the bounding box of a slightly turned plan is no smaller
  EXPECT_LT(plan, std::hypot(10.0, 20.0) * 1.05);
  EXPECT_NE(read_file(dir / "out" / "index.html").find("GLTFLoader"), std::string::npos);
}

TEST(Tiles3d, WithoutACrsTheSequencesOwnFrameAndBadInputIsRefused) {
  const fs::path dir = scratch_dir("tiles3d_local");
  CityJsonParams p;
  p.id = "a";
  write_cityjson((dir / "a.city.json").string(), box(100, 200, 5, 4, 4, 3), p);
  const Tiles3dSummary s = write_3d_tiles({(dir / "a.city.json").string()}, (dir / "out").string());
  EXPECT_FALSE(s.earth_fixed);
  const nlohmann::json ts = nlohmann::json::parse(read_file(dir / "out" / "tileset.json"));
  EXPECT_EQ(ts["root"]["transform"][12], 102.0);  // the centre: the frame shifted back
  EXPECT_EQ(ts["root"]["transform"][14], 6.5);
  EXPECT_EQ(status_of([&] { write_3d_tiles({}, (dir / "none").string()); }), Status::BadInput);
  EXPECT_EQ(status_of([&] { write_3d_tiles({(dir / "missing.city.jsonl").string()}, (dir / "none").string()); }),
            Status::FileNotFound);
  EXPECT_FALSE(fs::exists(dir / "none" / "tileset.json"));
}

}  // namespace
