// Visual report (src/report): the page's content (every stage view, offline, subsampled data), errors, and the CLI flags. The browser end-to-end
// test is browser_test.py (needs Chromium).
#include "core/error.h"
#include "eval/eval.h"
#include "io/io.h"
#include "pipeline/pipeline.h"
#include "report/report.h"
#include "test_meshes.h"
#include "synth/synth.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

using namespace hsr;

namespace {

/// The JSON block of a page.
nlohmann::json page_data(const std::string& page) {
  const std::string open = "<script id=\"hsr-data\" type=\"application/json\">";
  const std::size_t a = page.find(open);
  EXPECT_NE(a, std::string::npos);
  const std::size_t b = page.find("</script>", a);
  return nlohmann::json::parse(page.substr(a + open.size(), b - a - open.size()));
}

std::size_t base64_bytes(const std::string& s) {
  std::size_t pad = 0;
  if (!s.empty() && s.back() == '=') ++pad;
  if (s.size() > 1 && s[s.size() - 2] == '=') ++pad;
  return s.size() / 4 * 3 - pad;
}

}  // namespace

class ReportPage : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    SynthParams sp;
    sp.seed = 7;
    scan_ = new SynthScan(run_synth("house", sp));
    PipelineParams pp;
    pp.artifacts = &artifacts_;
    pp.eval.mesh_samples = 20000;
    result_ = new PipelineResult(run_pipeline(scan_->cloud, pp));
  }
  static void TearDownTestSuite() {
    delete result_;
    delete scan_;
  }
  static SynthScan* scan_;
  static PipelineArtifacts artifacts_;
  static PipelineResult* result_;
};
SynthScan* ReportPage::scan_ = nullptr;
PipelineArtifacts ReportPage::artifacts_;
PipelineResult* ReportPage::result_ = nullptr;

TEST_F(ReportPage, ArtifactsAreTheRunsStages) {
  EXPECT_EQ(artifacts_.structure.planes.size(), result_->report["counts"]["planes"].get<std::size_t>());
  EXPECT_EQ(artifacts_.complex.cells.size(), result_->report["counts"]["cells"].get<std::size_t>());
  EXPECT_EQ(artifacts_.inside.size(), artifacts_.complex.cells.size());
  EXPECT_EQ(artifacts_.polygons.size(), result_->report["counts"]["polygons"].get<std::size_t>());
  EXPECT_EQ(artifacts_.visibility.ratio.size(), artifacts_.structure.planes.size());
  ASSERT_EQ(artifacts_.cloud.size(), scan_->cloud.size());
  // The artifact cloud carries the extraction's normals: every inlier's on its plane's outward side.
  for (std::size_t k = 0; k < artifacts_.structure.planes.size(); ++k)
    for (int i : artifacts_.structure.planes[k].inliers)
      ASSERT_GE(artifacts_.cloud.normals[static_cast<std::size_t>(i)].dot(artifacts_.visibility.outward_normal[k]), 0);
}

TEST_F(ReportPage, HasEveryStageViewAndIsSelfContained) {
  ReportParams params;
  params.max_points = 1000;
  const std::string page = html_report(artifacts_, result_->mesh, result_->report, params);
  const nlohmann::json data = page_data(page);
  std::vector<std::string> ids;
  for (const auto& v : data["views"]) ids.push_back(v["id"]);
  EXPECT_EQ(ids, (std::vector<std::string>{"input", "planes", "visibility", "levels", "polygons", "partition", "mesh"}));
  // Subsampled to max_points, float32 xyz each; every shared-points layer has one RGB per point.
  EXPECT_EQ(base64_bytes(data["points"]), 1000u * 12u);
  for (const auto& v : data["views"])
    for (const auto& layer : v["layers"]) {
      if (layer["type"] == "points" && layer.value("shared", false)) EXPECT_EQ(base64_bytes(layer["col"]), 3000u);
      if (layer["type"] == "mesh") EXPECT_EQ(base64_bytes(layer["pos"]) / 12, base64_bytes(layer["col"]) / 3);
    }
  // The output mesh view holds the output mesh: 3 corners per triangle of its faces.
  const auto& mesh_layer = data["views"][6]["layers"][0];
  EXPECT_EQ(base64_bytes(mesh_layer["pos"]), triangulate_faces(result_->mesh).size() * 3 * 12);
  EXPECT_EQ(data["report"]["counts"], result_->report["counts"]);
  // three.js and its controls are inlined; nothing is fetched from elsewhere; no placeholder left.
  EXPECT_NE(page.find("REVISION"), std::string::npos);
  EXPECT_NE(page.find("OrbitControls"), std::string::npos);
  for (const char* bad : {"src=\"http", "href=\"http", "<link", "@import", "{{DATA_JSON}}", "/*{{THREE_JS}}*/"})
    EXPECT_EQ(page.find(bad), std::string::npos) << bad;
  // A page of a few MB at most, even with the default 50k points.
  EXPECT_LT(html_report(artifacts_, result_->mesh, result_->report).size(), 8u << 20);
}

TEST_F(ReportPage, StillPageHasOneViewAndEmptyInputIsAnError) {
  const nlohmann::json data = page_data(html_still(&result_->mesh, &scan_->cloud));
  ASSERT_EQ(data["views"].size(), 1u);
  EXPECT_EQ(data["mode"], "still");
  EXPECT_EQ(data["views"][0]["layers"].size(), 2u);
  EXPECT_EQ(test::status_of([&] { html_still(nullptr, nullptr); }), Status::BadInput);
}

// Issue 25, the indoor view: a room scanned from inside is shown cut away (automatically), a house from
// outside; the cut lies under the top (the ceiling goes) and above the floor; the mesh, closed and oriented
// outward, may be drawn from its inner side; the option overrides the choice either way.
TEST_F(ReportPage, ARoomScannedFromInsideIsCutAwayAHouseIsNot) {
  EXPECT_FALSE(artifacts_.visibility.scanned_from_inside);
  EXPECT_FALSE(page_data(html_report(artifacts_, result_->mesh, result_->report)).contains("cutaway"));
  EXPECT_FALSE(normals_face_inward(scan_->cloud));

  SynthParams sp;
  sp.seed = 3;
  const SynthScan room = run_synth("room", sp);
  EXPECT_TRUE(normals_face_inward(room.cloud));
  PipelineArtifacts a;
  PipelineParams pp;
  pp.artifacts = &a;
  pp.eval.mesh_samples = 20000;
  const PipelineResult r = run_pipeline(room.cloud, pp);
  EXPECT_TRUE(a.visibility.scanned_from_inside);
  EXPECT_TRUE(r.report["visibility"]["scanned_from_inside"].get<bool>());
  const nlohmann::json data = page_data(html_report(a, r.mesh, r.report));
  ASSERT_TRUE(data.contains("cutaway"));
  // Page coordinates are relative to the scene centre: the room is 3 high, the cut 0.3 under its top.
  const BBox box = bounding_box(room.cloud.points);
  const double top = box.max.z() - data["centre"][2].get<double>();
  const double bottom = box.min.z() - data["centre"][2].get<double>();
  EXPECT_NEAR(data["cutaway"]["z"].get<double>(), top - 0.1 * (top - bottom), 0.05);
  EXPECT_GT(data["cutaway"]["z"].get<double>(), bottom + 0.5 * (top - bottom));
  // The exploded partition is not cut; the output mesh view may show the mesh's inner side.
  for (const auto& v : data["views"]) EXPECT_EQ(v.value("cut", true), v["id"] != "partition") << v["id"];
  EXPECT_TRUE(data["views"][6]["layers"][0]["inner"].get<bool>());

  ReportParams outside;
  outside.view = ModelView::Outside;
  EXPECT_FALSE(page_data(html_report(a, r.mesh, r.report, outside)).contains("cutaway"));
  ReportParams cut;
  cut.view = ModelView::Cutaway;
  EXPECT_TRUE(page_data(html_still(&result_->mesh, &scan_->cloud, cut)).contains("cutaway"));
  EXPECT_FALSE(page_data(html_still(&result_->mesh, &scan_->cloud)).contains("cutaway"));
  cut.view = ModelView::Auto;
  cut.scanned_from_inside = true;
  EXPECT_TRUE(page_data(html_still(&r.mesh, nullptr, cut)).contains("cutaway"));
  EXPECT_EQ(parse_model_view("cutaway"), ModelView::Cutaway);
  EXPECT_EQ(test::status_of([] { parse_model_view("ceiling"); }), Status::BadInput);

  // Without normals there is no scanner side to read.
  PointCloud bare = room.cloud;
  bare.normals.clear();
  EXPECT_FALSE(normals_face_inward(bare));
}

// Normals that point into a building do not make it a room: AHN3_08314's file normals disagree with its
// roofs' and walls' visible sides (parity -0.92 of the enclosing inliers), but an aerial scan in building
// mode is seen from above; and a file with normals either way (cgal_cube, -0.002) is not a room either.
TEST(ReportScenes, AirborneBuildingsAndInconsistentNormalsAreNotCutAway) {
  const std::string ahn = test::shared_airborne("AHN3_08314.ply"), cube = test::shared_data("cgal_cube.ply");
  if (ahn.empty() || cube.empty()) GTEST_SKIP() << "../shared/airborne or ../shared/data not found";
  PipelineParams pp;
  pp.eval.mesh_samples = 5000;
  const PipelineResult building = run_pipeline(read_points(ahn), pp);
  EXPECT_EQ(building.report["scene"]["mode"], "building");
  EXPECT_FALSE(building.report["visibility"]["scanned_from_inside"].get<bool>());
  const PipelineResult object = run_pipeline(read_points(cube), pp);
  EXPECT_FALSE(object.report["visibility"]["scanned_from_inside"].get<bool>());
  // hsr render decides from the files alone: the same two, and AHN3_08831 (its few wall points at the
  // box's sides point inward too), are not rooms; the synth meeting room is.
  for (const char* f : {"AHN3_08314.ply", "AHN3_08831.ply"})
    EXPECT_FALSE(normals_face_inward(read_points(test::shared_airborne(f)))) << f;
  EXPECT_FALSE(normals_face_inward(read_points(cube)));
  SynthParams sp;
  EXPECT_TRUE(normals_face_inward(run_synth("meeting_room", sp).cloud));
}

TEST(Render, MissingChromiumIsAClearError) {
  RenderParams rp;
  rp.chromium = "/nonexistent/chromium";
  EXPECT_EQ(find_chromium(rp), "");
  try {
    render_png("page.html", "out.png", rp);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.status(), Status::NotImplemented);
    EXPECT_NE(std::string(e.what()).find("chromium"), std::string::npos);
  }
}

TEST(ReportCli, HtmlFlagWritesThePageAndRenderWithoutBrowserFails) {
  const auto dir = test::scratch_dir("cli");
  ASSERT_EQ(test::run_cli("-q synth box -o " + dir.string()).exit_code, 0);
  const auto page = dir / "report.html";
  const auto r = test::run_cli("-q reconstruct " + (dir / "points.ply").string() + " -o " + (dir / "box.obj").string() +
                               " --html " + page.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string html = test::read_file(page);
  EXPECT_EQ(page_data(html)["views"].size(), 7u);
  EXPECT_EQ(page_data(html)["report"]["counts"]["output_faces"], 6);
  // With no browser: one-line error naming the package, no PNG left behind.
  const std::string env = "HSR_CHROMIUM=/nonexistent/chromium ";
  FILE* pipe = ::popen((env + HSR_CLI_PATH + " render " + (dir / "box.obj").string() + " -o " +
                        (dir / "nobrowser.png").string() + " 2>&1").c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string out;
  char buf[512];
  while (std::fgets(buf, sizeof buf, pipe)) out += buf;
  const int status = ::pclose(pipe);
  EXPECT_NE(WEXITSTATUS(status), 0);
  EXPECT_NE(out.find("hsr: render: Chromium not found"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir / "nobrowser.png"));
}
