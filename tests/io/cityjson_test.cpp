// Tests of the CityJSON 2.0 / CityJSONSeq writer and reader (io/cityjson.h): every rule of the spec the
// writer relies on, written as a checker that is itself shown to catch each violation; semantics from the
// face classes (by normal, or the stage's own); the transform keeping georeferenced coordinates; rounding
// that merges vertices, flattens or pinches faces (repaired, or refused with InvalidOutput and no file);
// round trips through the reader, write_mesh / read_mesh dispatch and the sequence format.
#include "io/cityjson.h"

#include "core/error.h"
#include "core/face_class.h"
#include "eval/eval.h"
#include "io/io.h"
#include "synth/synth.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

namespace fs = std::filesystem;
using namespace hsr;
using nlohmann::json;

namespace {

// ------------------------------------------------------------------------------------------ the spec's rules

/// One violated rule per string, each naming the rule (CityJSON 2.0.1: §1 CityJSON Object, §3 Geometry
/// Objects, §3.1 vertices, §3.2 boundaries, §3.3 semantics, §4 transform, §5.6 referenceSystem, §7.2
/// CityJSONFeature; rings as val3dity checks them: 101 too few points, 102 consecutive points the same).
struct RuleChecker {
  std::vector<std::string> violations;
  void fail(const std::string& rule) { violations.push_back(rule); }

  void check_transform(const json& doc) {
    if (!doc.contains("transform") || !doc["transform"].contains("scale") || !doc["transform"].contains("translate"))
      return fail("transform: mandatory, with scale and translate");
    for (const char* k : {"scale", "translate"}) {
      const json& a = doc["transform"][k];
      if (!a.is_array() || a.size() != 3 || !a[0].is_number() || !a[1].is_number() || !a[2].is_number())
        fail(std::string("transform: ") + k + " is an array of 3 numbers");
    }
  }

  void check_vertices(const json& vertices) {
    if (!vertices.is_array()) return fail("vertices: an array");
    for (const json& v : vertices)
      if (!v.is_array() || v.size() != 3 || !v[0].is_number_integer() || !v[1].is_number_integer() ||
          !v[2].is_number_integer())
        return fail("vertices: each exactly 3 integers");
  }

  void check_ring(const json& ring, std::size_t num_vertices) {
    if (!ring.is_array()) return fail("boundaries: a ring is an array of indices");
    std::set<std::int64_t> distinct;
    for (std::size_t i = 0; i < ring.size(); ++i) {
      if (!ring[i].is_number_integer() || ring[i].get<std::int64_t>() < 0 ||
          ring[i].get<std::uint64_t>() >= num_vertices)
        return fail("boundaries: indices are 0-based and index \"vertices\"");
      if (ring[i] == ring[(i + 1) % ring.size()]) fail("ring: no repeated consecutive vertex (val3dity 102)");
      distinct.insert(ring[i].get<std::int64_t>());
    }
    if (distinct.size() < 3) fail("ring: at least 3 distinct vertices (val3dity 101)");
  }

  void check_semantics(const json& g) {
    if (!g.contains("semantics")) return;
    const json& sem = g["semantics"];
    if (!sem.contains("surfaces") || !sem.contains("values")) return fail("semantics: surfaces and values both present");
    const json& shells = g["boundaries"];
    const json& values = sem["values"];
    if (!values.is_array() || values.size() != shells.size()) return fail("semantics: values depth = boundaries depth - 2");
    for (std::size_t s = 0; s < shells.size(); ++s) {
      if (!values[s].is_array() || values[s].size() != shells[s].size())
        return fail("semantics: one value per surface");
      for (const json& v : values[s])
        if (!v.is_null() && (!v.is_number_integer() || v.get<std::int64_t>() < 0 || v.get<std::uint64_t>() >= sem["surfaces"].size()))
          return fail("semantics: a value is null or indexes \"surfaces\"");
    }
    static const std::set<std::string> building_types{"RoofSurface", "GroundSurface", "WallSurface", "ClosureSurface",
                                                      "OuterCeilingSurface", "OuterFloorSurface", "Window", "Door",
                                                      "InteriorWallSurface", "CeilingSurface", "FloorSurface"};
    for (const json& s : sem["surfaces"])
      if (!s.contains("type") || !building_types.count(s["type"].get<std::string>()))
        fail("semantics: a Semantic Object has a type allowed for a Building");
  }

  void check_solid(const json& g, std::size_t num_vertices) {
    if (g.value("type", "") != "Solid") return fail("geometry: a Building's geometry here is a Solid");
    static const std::set<std::string> lods{"0", "1", "2", "3", "0.0", "0.1", "0.2", "0.3", "1.0", "1.1", "1.2", "1.3",
                                            "2.0", "2.1", "2.2", "2.3", "3.0", "3.1", "3.2", "3.3"};
    if (!g.contains("lod") || !g["lod"].is_string() || !lods.count(g["lod"].get<std::string>()))
      fail("geometry: lod is a string of the allowed LoDs");
    if (!g.contains("boundaries") || !g["boundaries"].is_array() || g["boundaries"].empty())
      return fail("boundaries: a Solid is an array of shells");
    for (const json& shell : g["boundaries"]) {
      if (!shell.is_array() || shell.empty()) return fail("boundaries: a shell is an array of surfaces");
      for (const json& surface : shell) {
        if (!surface.is_array() || surface.empty()) return fail("boundaries: a surface is an array of rings");
        for (const json& ring : surface) check_ring(ring, num_vertices);
      }
    }
    check_semantics(g);
  }

  void check_city_objects(const json& objects, std::size_t num_vertices) {
    if (!objects.is_object()) return fail("CityObjects: an object keyed by id");
    for (const auto& [id, co] : objects.items()) {
      if (!co.contains("type")) fail("City Object: has a type");
      if (co.contains("geographicalExtent") && co["geographicalExtent"].size() != 6)
        fail("City Object: geographicalExtent has 6 numbers");
      if (co.contains("attributes") && !co["attributes"].is_object()) fail("City Object: attributes is an object");
      if (co.contains("geometry"))
        for (const json& g : co["geometry"]) check_solid(g, num_vertices);
    }
  }

  void check_document(const json& doc) {
    if (doc.value("type", "") != "CityJSON") fail("CityJSON: type is \"CityJSON\"");
    if (doc.value("version", "") != "2.0") fail("CityJSON: version is \"2.0\"");
    check_transform(doc);
    if (!doc.contains("CityObjects")) fail("CityJSON: has CityObjects");
    if (!doc.contains("vertices")) return fail("CityJSON: has vertices");
    check_vertices(doc["vertices"]);
    if (doc.contains("metadata") && doc["metadata"].contains("referenceSystem") &&
        doc["metadata"]["referenceSystem"].get<std::string>().rfind("https://www.opengis.net/def/crs/", 0) != 0)
      fail("metadata: referenceSystem is an OGC CRS URL");
    if (doc.contains("CityObjects")) check_city_objects(doc["CityObjects"], doc["vertices"].size());
  }

  void check_feature(const json& f) {
    if (f.value("type", "") != "CityJSONFeature") fail("CityJSONFeature: type is \"CityJSONFeature\"");
    if (!f.contains("id") || !f["id"].is_string()) return fail("CityJSONFeature: id is a string");
    if (!f.contains("CityObjects") || !f["CityObjects"].contains(f["id"].get<std::string>()))
      fail("CityJSONFeature: id names one of its CityObjects");
    for (const char* k : {"transform", "version", "metadata"})
      if (f.contains(k)) fail(std::string("CityJSONFeature: no ") + k + " member");
    if (!f.contains("vertices")) return fail("CityJSONFeature: has vertices");
    check_vertices(f["vertices"]);
    if (f.contains("CityObjects")) check_city_objects(f["CityObjects"], f["vertices"].size());
  }

  /// CityJSONSeq: one object per line (no newline inside), the first a CityJSON object with the transform
  /// and empty CityObjects and vertices, then CityJSONFeature objects.
  void check_sequence(const std::string& text) {
    std::istringstream in(text);
    std::string line;
    std::size_t n = 0;
    while (std::getline(in, line)) {
      const json obj = json::parse(line);
      if (n++ == 0) {
        check_document(obj);
        if (!obj["CityObjects"].empty() || !obj["vertices"].empty())
          fail("CityJSONSeq: the first line has empty CityObjects and vertices");
      } else {
        check_feature(obj);
      }
    }
    if (text.empty() || text.back() != '\n') fail("CityJSONSeq: each object is followed by a newline");
  }
};

std::vector<std::string> violations_of(const json& doc) {
  RuleChecker c;
  c.check_document(doc);
  return c.violations;
}

// ------------------------------------------------------------------------------------------ meshes

/// Axis-aligned box [0,sx]x[0,sy]x[0,sz], faces counter-clockwise seen from outside.
PolygonMesh box(double sx = 2, double sy = 1.5, double sz = 1) {
  PolygonMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.emplace_back(i & 1 ? sx : 0, i & 2 ? sy : 0, i & 4 ? sz : 0);
  m.faces = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  return m;
}

/// The unit box whose top is split into a strip of width `strip` along x = 0 and the rest; the front and
/// back faces carry the strip's corner as a collinear vertex. At 1 mm a 0.3 mm strip collapses.
PolygonMesh box_with_strip(double strip) {
  PolygonMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1},
                {strip, 0, 1}, {strip, 1, 1}};
  m.faces = {{0, 3, 2, 1},        // bottom
             {0, 1, 5, 8, 4},     // front y = 0
             {2, 3, 7, 9, 6},     // back y = 1
             {0, 4, 7, 3},        // left x = 0
             {1, 2, 6, 5},        // right x = 1
             {4, 8, 9, 7},        // top strip
             {8, 5, 6, 9}};       // top rest
  return m;
}

/// The unit box with a sliver triangle on top along the front edge: its apex B = (0.5, width, 1); the
/// rest of the top carries B. At 1 mm a 0.2 mm sliver flattens onto the edge, which then needs B.
PolygonMesh box_with_sliver(double width) {
  PolygonMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, {0.5, width, 1}};
  m.faces = {{0, 3, 2, 1},        // bottom
             {0, 1, 5, 4},        // front y = 0, top edge 5 -> 4
             {2, 3, 7, 6},        // back
             {0, 4, 7, 3},        // left
             {1, 2, 6, 5},        // right
             {4, 5, 8},           // sliver
             {4, 8, 5, 6, 7}};    // rest of the top
  return m;
}

/// A prism over a hexagon with a waist of width `waist` at x = 1: at 1 mm a 0.2 mm waist pinches the top
/// and bottom rings and the solid becomes two prisms sharing an edge (not a 2-manifold).
PolygonMesh waisted_prism(double waist) {
  const double w = waist / 2;
  const std::vector<Vec2> p{{0, 0}, {1, 0.5 - w}, {2, 0}, {2, 1}, {1, 0.5 + w}, {0, 1}};
  PolygonMesh m;
  for (double z : {0.0, 1.0})
    for (const Vec2& q : p) m.vertices.emplace_back(q.x(), q.y(), z);
  const std::uint32_t n = 6;
  m.faces.push_back({5, 4, 3, 2, 1, 0});            // bottom, facing down
  m.faces.push_back({6, 7, 8, 9, 10, 11});          // top
  for (std::uint32_t i = 0; i < n; ++i) m.faces.push_back({i, (i + 1) % n, (i + 1) % n + n, i + n});
  return m;
}

/// A file in this suite's scratch folder (created once, not emptied: a test may write several files).
std::string tmp(const std::string& name) {
  const fs::path dir = fs::path(HSR_TEST_TMP_DIR) / "cityjson";
  fs::create_directories(dir);
  fs::remove(dir / name);
  return (dir / name).string();
}

// ------------------------------------------------------------------------------------------ tests

TEST(CityJsonRules, CheckerCatchesEachViolation) {
  // The checker must fail on each broken rule, or the tests below prove nothing.
  const json good = cityjson_document(box(), {});
  ASSERT_TRUE(violations_of(good).empty());
  const std::string id = good["CityObjects"].begin().key();
  auto shell = [&](json& d) -> json& { return d["CityObjects"][id]["geometry"][0]["boundaries"][0]; };
  auto values = [&](json& d) -> json& { return d["CityObjects"][id]["geometry"][0]["semantics"]["values"]; };
  std::vector<std::pair<std::string, std::function<void(json&)>>> breaks{
      {"index out of range", [&](json& d) { shell(d)[0][0][0] = 99; }},
      {"two vertices", [&](json& d) { shell(d)[0][0] = {0, 1}; }},
      {"consecutive repeat", [&](json& d) { shell(d)[0][0] = {0, 0, 1, 2}; }},
      {"values count", [&](json& d) { values(d)[0].erase(0); }},
      {"value beyond surfaces", [&](json& d) { values(d)[0][0] = 7; }},
      {"float vertex", [&](json& d) { d["vertices"][0][0] = 0.5; }},
      {"no transform", [&](json& d) { d.erase("transform"); }},
      {"lod number", [&](json& d) { d["CityObjects"][id]["geometry"][0]["lod"] = 2; }},
      {"crs not a URL", [&](json& d) { d["metadata"]["referenceSystem"] = "EPSG:7415"; }},
  };
  for (auto& [what, mutate] : breaks) {
    json bad = good;
    mutate(bad);
    EXPECT_FALSE(violations_of(bad).empty()) << what;
  }
}

TEST(CityJsonRules, WriterOutputObeysEveryRuleOnSynthModels) {
  SynthParams sp;
  sp.target_points = 500;
  for (const std::string& model : synth_model_names()) {
    const SynthScan scan = run_synth(model, sp);
    CityJsonParams p;
    p.id = model;
    p.crs = "EPSG:7415";
    const json doc = cityjson_document(scan.truth, p);
    EXPECT_EQ(violations_of(doc), std::vector<std::string>{}) << model;
    EXPECT_EQ(doc["CityObjects"][model]["geometry"][0]["boundaries"][0].size(), scan.truth.faces.size()) << model;
    EXPECT_EQ(doc["metadata"]["referenceSystem"], "https://www.opengis.net/def/crs/EPSG/0/7415");
  }
}

TEST(CityJson, SemanticsByNormalForAnUnclassifiedBox) {
  const json doc = cityjson_document(box(), {});
  const json& g = doc["CityObjects"]["building"]["geometry"][0];
  EXPECT_EQ(g["type"], "Solid");
  EXPECT_EQ(g["lod"], "2.2");
  const json& sem = g["semantics"];
  // Surfaces in the order roof, wall, ground; faces: bottom, top, 4 sides.
  ASSERT_EQ(sem["surfaces"].size(), 3u);
  EXPECT_EQ(sem["surfaces"][0]["type"], "RoofSurface");
  EXPECT_EQ(sem["surfaces"][1]["type"], "WallSurface");
  EXPECT_EQ(sem["surfaces"][2]["type"], "GroundSurface");
  EXPECT_EQ(sem["values"], json::parse("[[2, 0, 1, 1, 1, 1]]"));
}

TEST(CityJson, SemanticsFromTheStagesClassesWinOverTheNormal) {
  PolygonMesh m = box();
  m.face_class = {FaceClass::Ground, FaceClass::Roof, FaceClass::Closure, FaceClass::Unknown,
                  FaceClass::Wall, FaceClass::Wall};
  m.face_class[3] = FaceClass::Unknown;  // falls back to the normal: a wall
  const json sem = cityjson_document(m, {})["CityObjects"]["building"]["geometry"][0]["semantics"];
  ASSERT_EQ(sem["surfaces"].size(), 4u);
  EXPECT_EQ(sem["surfaces"][3]["type"], "ClosureSurface");
  EXPECT_EQ(sem["values"], json::parse("[[2, 0, 3, 1, 1, 1]]"));
}

TEST(CityJson, TransformKeepsGeoreferencedCoordinates) {
  PolygonMesh m = box(12.3456789, 8.7654321, 6.5);
  m.origin = Vec3(85123, 447456, -2);  // as io.h chooses it for RD / UTM data: integers
  CityJsonParams p;
  p.scale = 0.001;
  const json doc = cityjson_document(m, p);
  EXPECT_EQ(doc["transform"]["scale"], json::parse("[0.001, 0.001, 0.001]"));
  EXPECT_EQ(doc["transform"]["translate"], json::parse("[85123.0, 447456.0, -2.0]"));
  for (std::size_t i = 0; i < m.vertices.size(); ++i) {
    const json& q = doc["vertices"][i];
    for (int k = 0; k < 3; ++k) {
      const double decoded = q[k].get<std::int64_t>() * 0.001 + doc["transform"]["translate"][k].get<double>();
      EXPECT_LE(std::abs(decoded - (m.vertices[i][k] + m.origin[k])), 0.0005 + 1e-9);
    }
  }
  const json& ext = doc["CityObjects"]["building"]["geographicalExtent"];
  EXPECT_NEAR(ext[0].get<double>(), 85123, 1e-9);
  EXPECT_NEAR(ext[4].get<double>(), 447456 + 8.765, 1e-6);  // 8.7654321 rounded to the millimetre
}

TEST(CityJson, RoundTripThroughTheReaderIsExactOnTheGrid) {
  SynthParams sp;
  sp.target_points = 500;
  const SynthScan scan = run_synth("dormer_house", sp);
  PolygonMesh truth = scan.truth;
  truth.origin = Vec3(1000, -2000, 0);
  CityJsonParams p;
  p.id = "dormer";
  p.attributes = {{"hsr_facets", truth.faces.size()}};
  const std::string path = tmp("dormer.city.json");
  write_cityjson(path, truth, p);
  const CityModel model = read_cityjson(path);
  ASSERT_EQ(model.buildings.size(), 1u);
  const CityBuilding& b = model.buildings[0];
  EXPECT_EQ(b.id, "dormer");
  EXPECT_EQ(b.attributes["hsr_facets"], truth.faces.size());
  EXPECT_EQ(model.translate, truth.origin);
  // Same faces, vertices within half a step of the original, classes those of the writer.
  EXPECT_EQ(b.mesh.faces, truth.faces);
  ASSERT_EQ(b.mesh.vertices.size(), truth.vertices.size());
  for (std::size_t i = 0; i < truth.vertices.size(); ++i)
    EXPECT_LE((b.mesh.vertices[i] + b.mesh.origin - truth.vertices[i] - truth.origin).cwiseAbs().maxCoeff(), 0.0005 + 1e-9);
  EXPECT_EQ(b.mesh.face_class, face_classes_or_by_normal(truth));
  EXPECT_TRUE(check_validity(b.mesh).valid());
  // Writing the decoded mesh again gives the same bytes: the grid is a fixed point.
  const std::string again = tmp("again.city.json");
  write_cityjson(again, b.mesh, p);
  EXPECT_EQ(test::read_file(path), test::read_file(again));
}

TEST(CityJson, WriteMeshAndReadMeshDispatchOnTheExtension) {
  const std::string path = tmp("box.CITY.JSON");
  write_mesh(path, box());
  const json doc = json::parse(test::read_file(path));
  EXPECT_EQ(doc["type"], "CityJSON");
  const PolygonMesh back = read_mesh(path);
  EXPECT_EQ(back.faces, box().faces);
  ASSERT_EQ(back.vertices.size(), 8u);
  for (std::size_t i = 0; i < 8; ++i) EXPECT_LE((back.vertices[i] - box().vertices[i]).norm(), 1e-12);
}

TEST(CityJsonRounding, CollapsedStripIsDroppedAndMergedVerticesDeduplicated) {
  const CityJsonSolid s = quantize_solid(box_with_strip(0.0003), 0.001, Vec3::Zero());
  EXPECT_EQ(s.merged_vertices, 2u);  // the strip's inner corners land on the box's corners
  EXPECT_EQ(s.dropped_faces, 1u);    // the strip
  EXPECT_EQ(s.vertices.size(), 8u);
  ASSERT_EQ(s.faces.size(), 6u);
  for (const auto& f : s.faces) EXPECT_EQ(f.size(), 4u);  // the collinear corner merged away
  EXPECT_TRUE(check_validity(decode_solid(s)).valid());
  // At 0.1 mm the strip survives: 7 faces, nothing merged.
  const CityJsonSolid fine = quantize_solid(box_with_strip(0.0003), 0.0001, Vec3::Zero());
  EXPECT_EQ(fine.merged_vertices, 0u);
  EXPECT_EQ(fine.faces.size(), 7u);
}

TEST(CityJsonRounding, FlattenedSliverLeavesNoTJunction) {
  const PolygonMesh m = box_with_sliver(0.0002);
  ASSERT_TRUE(check_validity(m).valid());
  const CityJsonSolid s = quantize_solid(m, 0.001, Vec3::Zero());
  EXPECT_EQ(s.merged_vertices, 0u);
  EXPECT_EQ(s.dropped_faces, 1u);
  EXPECT_EQ(s.inserted_vertices, 1u);  // B into the front face's top edge
  EXPECT_EQ(s.faces.size(), 6u);
  EXPECT_EQ(s.faces[1].size(), 5u);
  EXPECT_TRUE(check_validity(decode_solid(s)).valid());
}

TEST(CityJsonRounding, PinchedSolidIsRefusedAndNothingIsWritten) {
  const PolygonMesh m = waisted_prism(0.0002);
  ASSERT_TRUE(check_validity(m).valid());
  const std::string path = tmp("pinched.city.json");
  CityJsonParams exact;
  exact.finer_steps = 0;
  try {
    write_cityjson(path, m, exact);
    FAIL() << "expected InvalidOutput";
  } catch (const Error& e) {
    EXPECT_EQ(e.status(), Status::InvalidOutput);
    EXPECT_EQ(e.stage(), "io");
    EXPECT_NE(std::string(e.what()).find("--cityjson-scale"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(path));
  // Unchecked (a --force run): the pinched top and bottom are split into rings that obey the rules.
  const CityJsonSolid s = quantize_solid(m, 0.001, Vec3::Zero(), false);
  EXPECT_EQ(s.split_faces, 2u);
  EXPECT_EQ(s.faces.size(), 2u * 2 + 6);
  CityJsonParams p;
  p.require_valid = false;
  EXPECT_TRUE(violations_of(cityjson_document(m, p)).empty());
  // A finer grid keeps the waist: valid; by default the document falls back to it, and says so.
  EXPECT_TRUE(check_validity(decode_solid(quantize_solid(m, 0.0001, Vec3::Zero()))).valid());
  write_cityjson(path, m, {});
  EXPECT_EQ(json::parse(test::read_file(path))["transform"]["scale"][0], 0.0001);
}

TEST(CityJsonRounding, AFlattenedSolidPassesTheEdgesButNotTheGeometricCheck) {
  // A flat tetrahedron whose apex is 0.4 mm above its base: at 1 mm every face lies in z = 0. The edges
  // still pair up; only the geometric check (eval's, through `validate`) sees that no volume is left.
  PolygonMesh tet;
  tet.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.25, 0.25, 0.0004}};
  tet.faces = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
  ASSERT_TRUE(check_validity(tet).valid());
  const auto geometric = [](const PolygonMesh& m) {
    const Validity v = check_validity(m);
    return v.valid() ? std::string() : v.summary();
  };
  EXPECT_EQ(quantize_solid(tet, 0.001, Vec3::Zero()).faces.size(), 4u);
  EXPECT_EQ(test::status_of([&] { quantize_solid(tet, 0.001, Vec3::Zero(), true, geometric); }), Status::InvalidOutput);
  CityJsonParams p;
  p.validate = geometric;
  p.finer_steps = 0;
  EXPECT_EQ(test::status_of([&] { cityjson_document(tet, p); }), Status::InvalidOutput);
  p.finer_steps = 3;  // 0.1 mm keeps the apex 4 steps above the base
  EXPECT_EQ(cityjson_document(tet, p)["transform"]["scale"][0], 0.0001);
  p.scale = 0.01;     // 1 cm, 1 mm, 0.1 mm: the third step passes
  EXPECT_EQ(cityjson_document(tet, p)["transform"]["scale"][0].get<double>(), 0.01 / 10 / 10);
  p.finer_steps = 1;
  EXPECT_EQ(test::status_of([&] { cityjson_document(tet, p); }), Status::InvalidOutput);
}

TEST(CityJsonSeq, HeaderThenOneFeaturePerLineSharingOneTransform) {
  PolygonMesh a = box(), b = box(3, 2, 5);
  a.origin = Vec3(85000, 447000, 0);
  b.origin = Vec3(85100, 446900, 1);
  CityJsonParams p;
  p.crs = "EPSG:7415";
  const Vec3 T = a.origin;
  std::vector<json> features;
  p.id = "a";
  features.push_back(cityjson_feature(a, p, T));
  p.id = "b";
  features.push_back(cityjson_feature(b, p, T));
  const std::string path = tmp("two.city.jsonl");
  write_cityjsonseq(path, cityjson_seq_header(p, T), features);
  const std::string text = test::read_file(path);
  RuleChecker c;
  c.check_sequence(text);
  EXPECT_EQ(c.violations, std::vector<std::string>{});
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 3);
  const CityModel model = read_cityjson(path);
  EXPECT_EQ(model.reference_system, "https://www.opengis.net/def/crs/EPSG/0/7415");
  ASSERT_EQ(model.buildings.size(), 2u);
  EXPECT_EQ(model.buildings[1].id, "b");
  // b's integers are relative to a's origin: exactly its own document's integers shifted by the whole
  // number of steps between the origins; decoded, they are b's coordinates.
  const json own = cityjson_document(b, p);
  const json& fv = features[1]["vertices"];
  ASSERT_EQ(fv.size(), own["vertices"].size());
  const std::int64_t shift[3] = {100000, -100000, 1000};
  for (std::size_t i = 0; i < fv.size(); ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(fv[i][k].get<std::int64_t>(), own["vertices"][i][k].get<std::int64_t>() + shift[k]);
  const PolygonMesh& rb = model.buildings[1].mesh;
  for (std::size_t i = 0; i < b.vertices.size(); ++i)
    EXPECT_LE((rb.vertices[i] + rb.origin - b.vertices[i] - b.origin).norm(), 1e-9);
}

TEST(CityJson, CrsUrlAndAttributesFromAReport) {
  EXPECT_EQ(crs_url("EPSG:28992"), "https://www.opengis.net/def/crs/EPSG/0/28992");
  EXPECT_EQ(crs_url("epsg:7415"), "https://www.opengis.net/def/crs/EPSG/0/7415");
  for (const char* bad : {"28992", "EPSG:", "EPSG:28a92", "ESRI:102100"})
    EXPECT_EQ(test::status_of([&] { crs_url(bad); }), Status::BadInput) << bad;
  const json report = json::parse(R"({"validity": {"valid": false, "closed": true, "manifold": true, "oriented": false,
      "self_intersection_free": true, "bounds_volume": false}, "accuracy": {"p2m_mean": 0.003, "p2m_rms": 0.01},
      "counts": {"output_faces": 10}, "seconds": {"total": 0.25}, "version": "0.1.0",
      "quality": {"points_unexplained_share": 0.125, "scene": "building", "scene_choice": "auto", "scene_margin": 0.05,
                  "ground_source": "plane", "removed_points": {"ground_planes": 40}}})");
  const json a = cityjson_attributes(report);
  EXPECT_EQ(a["hsr_valid"], false);
  EXPECT_EQ(a["hsr_validity"], "invalid: not oriented, not bounds_volume");
  EXPECT_EQ(a["hsr_p2m_mean"], 0.003);
  EXPECT_EQ(a["hsr_p2m_rms"], 0.01);
  EXPECT_EQ(a["hsr_facets"], 10);
  EXPECT_EQ(a["hsr_seconds"], 0.25);
  EXPECT_EQ(a["hsr_version"], "0.1.0");
  EXPECT_EQ(a["hsr_points_unexplained_share"], 0.125);
  EXPECT_EQ(a["hsr_scene"], "building");
  EXPECT_EQ(a["hsr_scene_choice"], "auto");
  EXPECT_EQ(a["hsr_scene_margin"], 0.05);
  EXPECT_EQ(a["hsr_ground_source"], "plane");
  EXPECT_EQ(a["hsr_removed_points"]["ground_planes"], 40);
  EXPECT_TRUE(cityjson_attributes(json::object()).empty());
}

TEST(CityJson, BadParametersAndFilesFailWithAStatus) {
  EXPECT_EQ(test::status_of([] { quantize_solid(box(), 0, Vec3::Zero()); }), Status::BadInput);
  EXPECT_EQ(test::status_of([] { quantize_solid(box(), -1, Vec3::Zero()); }), Status::BadInput);
  PolygonMesh far = box();
  far.origin = Vec3(1e13, 0, 0);  // 1e16 steps of 1 mm: beyond 2^53
  EXPECT_EQ(test::status_of([&] { quantize_solid(far, 0.001, Vec3::Zero()); }), Status::BadInput);
  EXPECT_EQ(test::status_of([] { read_cityjson(tmp("missing.city.json")); }), Status::FileNotFound);
  json doc = cityjson_document(box(), {});
  const auto bad_file = [&](const std::string& name, const json& d) {
    const std::string path = tmp(name);
    test::write_file(path, d.dump());
    return test::status_of([&] { read_cityjson(path); });
  };
  json holes = doc;
  holes["CityObjects"]["building"]["geometry"][0]["boundaries"][0][0].push_back({0, 1, 2});
  EXPECT_EQ(bad_file("holes.city.json", holes), Status::BadFormat);
  json floats = doc;
  floats["vertices"][0][0] = 0.5;
  EXPECT_EQ(bad_file("floats.city.json", floats), Status::BadFormat);
  json out_of_range = doc;
  out_of_range["CityObjects"]["building"]["geometry"][0]["boundaries"][0][0][0][0] = 8;
  EXPECT_EQ(bad_file("range.city.json", out_of_range), Status::BadFormat);
  json sem = doc;
  sem["CityObjects"]["building"]["geometry"][0]["semantics"]["values"][0][0] = 3;
  EXPECT_EQ(bad_file("sem.city.json", sem), Status::BadFormat);
  const std::string text_path = tmp("text.city.json");
  test::write_file(text_path, "{not json");
  EXPECT_EQ(test::status_of([&] { read_cityjson(text_path); }), Status::BadFormat);
}

TEST(CityJson, SameMeshSameBytes) {
  SynthParams sp;
  sp.target_points = 500;
  const PolygonMesh truth = run_synth("courtyard", sp).truth;
  EXPECT_EQ(cityjson_document(truth, {}).dump(), cityjson_document(truth, {}).dump());
}

}  // namespace
