// As few faces as the shape needs (issue 14): the label clean-up removes the slivers the min-cut leaves, the
// --detail levels are monotone in the face count, and every level keeps the output valid and on the truth.
#include "core/error.h"
#include "eval/eval.h"
#include "extraction/extraction.h"
#include "io/io.h"
#include "pipeline/pipeline.h"
#include "synth/synth.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <utility>

using namespace hsr;

namespace {

struct Outcome {
  std::size_t faces = 0, small = 0;
  bool valid = false;
  double chamfer = 0.0;
};

Outcome reconstruct(const std::string& model, Detail detail, double noise = SynthParams{}.noise) {
  SynthParams sp;  // `hsr synth MODEL --noise N`: default seed
  sp.noise = noise;
  const SynthScan scan = run_synth(model, sp);
  PipelineParams pp;
  apply_detail(detail, pp.extraction);
  pp.truth = &scan.truth;
  pp.eval.mesh_samples = 30000;
  const PipelineResult r = run_pipeline(scan.cloud, pp);
  return {r.mesh.num_faces(), r.eval.face_sizes.small_faces, r.eval.validity.valid(), r.eval.accuracy.chamfer};
}

}  // namespace

// The synth courtyard (two buildings around a courtyard) scanned with 20 times the default range noise
// (`hsr synth courtyard --noise 0.02`): the min-cut's labels alone give 46 faces, 11 of them under 0.1 % of the
// area (cells that follow the noise along the walls and roofs). The default level removes every one and
// keeps the model on its truth (34 faces; Chamfer 1.06 % -> 1.08 % of the diagonal).
TEST(Faces, TheNoisyCourtyardsSliversAreGone) {
  const Outcome full = reconstruct("courtyard", Detail::Full, 0.02);
  ASSERT_GE(full.small, 5u) << "the min-cut alone no longer leaves slivers here: pick another case";
  const Outcome medium = reconstruct("courtyard", Detail::Medium, 0.02);
  EXPECT_TRUE(medium.valid);
  EXPECT_EQ(medium.small, 0u);
  EXPECT_LT(medium.faces, full.faces);
  EXPECT_GE(medium.faces, 14u);  // not a box (6) nor one block: two buildings, gables and the courtyard
  EXPECT_LT(medium.chamfer, 0.015);
  EXPECT_LT(medium.chamfer, 1.1 * full.chamfer + 1e-4);
}

// Two shared scans whose last slivers at the default level no single cell flip removed (each flip opened a
// new face), but a flip of two neighbouring cells does (label_cleanup.cpp add_pairs; bench/results/faces.md
// "The small faces one by one"): cgal_cube's strip of 6e-7 of the area and city3d_bldg94's two.
TEST(Faces, TheSharedScansSliversThatNeedTwoCellsAreGone) {
  for (const char* f : {"cgal_cube.ply", "city3d_bldg94.ply"}) {
    const std::string path = test::shared_data(f);
    if (path.empty()) GTEST_SKIP() << "../shared/data not found";
    PipelineParams pp;
    apply_detail(Detail::Medium, pp.extraction);
    // #54's wall placement: with the walls through the outermost outline points (#167) city3d_bldg94 keeps two
    // faces under 0.1 % of its area at this detail (a cost #167 lists, not yet cleaned up)
    pp.recovery.wall_edge_quantile = 0.9;
    const PipelineResult r = run_pipeline(read_points(path), pp);
    EXPECT_TRUE(r.eval.validity.valid()) << f;
    EXPECT_EQ(r.eval.face_sizes.small_faces, 0u) << f;
    EXPECT_GE(r.mesh.num_faces(), 20u) << f;  // 30 and 36 faces today; not a box (6)
  }
}

// The clean-up weighs the points it would move (DECISIONS #38): on city3d_bldg94 with the partition's
// wait + trim rules (issue 17) the min-cut keeps a low roof annex that a price over the surface's
// displacement alone removed at the default level (p2m max 2.5 % -> 7.1 % of the diagonal: its points left
// floating). With the points' displacement it stays, and the sliver clean-up still works (few small faces).
TEST(Faces, APartThePointsSupportIsNotCleanedAway) {
  const std::string path = test::shared_data("city3d_bldg94.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/data not found";
  const PointCloud cloud = read_points(path);
  PipelineParams pp;
  pp.partition.wait_at_bounds = true;
  pp.partition.trim = true;
  apply_detail(Detail::Full, pp.extraction);
  const PipelineResult full = run_pipeline(cloud, pp);
  ASSERT_LT(full.eval.accuracy.p2m_max, 0.03) << "the min-cut itself no longer keeps the annex: pick another case";
  apply_detail(Detail::Medium, pp.extraction);
  const PipelineResult medium = run_pipeline(cloud, pp);
  EXPECT_TRUE(medium.eval.validity.valid());
  EXPECT_LT(medium.eval.accuracy.p2m_max, 0.03);
  EXPECT_LT(medium.mesh.num_faces(), full.mesh.num_faces());
  EXPECT_LE(medium.eval.face_sizes.small_faces, 2u);
  // Since the building walls reach their roofs' edges (issue 24) the area-only price keeps this annex too;
  // the price's own effect is seen on manhattan_example1 (object mode): moving its points for free leaves a
  // third more distance from the points to the surface (p2m mean 0.61 % -> 0.81 % of the diagonal).
  const std::string manhattan = test::shared_data("manhattan_example1.ply");
  if (manhattan.empty()) GTEST_SKIP() << "../shared/data not found";
  const PointCloud m = read_points(manhattan);
  PipelineParams mp;
  apply_detail(Detail::Medium, mp.extraction);
  const PipelineResult weighted = run_pipeline(m, mp);
  mp.extraction.point_tolerance_spacings = 1e9;  // every move free: the surface's displacement alone
  const PipelineResult area_only = run_pipeline(m, mp);
  EXPECT_TRUE(area_only.eval.validity.valid());
  EXPECT_GT(area_only.eval.accuracy.p2m_mean, 1.2 * weighted.eval.accuracy.p2m_mean)
      << "the points' price changes nothing here: the test sees nothing";
}

// Above ExtractionParams::cleanup_max_cells the clean-up is skipped, and says so: the labels stay the
// min-cut's (the same faces as --detail full), the report's counts.cleanup_skipped is set.
TEST(Faces, AboveTheCellCapTheCleanUpIsSkipped) {
  SynthParams sp;
  sp.noise = 0.02;
  const SynthScan scan = run_synth("courtyard", sp);
  PipelineParams pp;
  pp.eval.mesh_samples = 30000;
  apply_detail(Detail::Full, pp.extraction);
  const PipelineResult full = run_pipeline(scan.cloud, pp);
  apply_detail(Detail::Medium, pp.extraction);
  const PipelineResult medium = run_pipeline(scan.cloud, pp);
  ASSERT_LT(medium.mesh.num_faces(), full.mesh.num_faces()) << "the clean-up does nothing here: pick another case";
  EXPECT_FALSE(medium.report["counts"]["cleanup_skipped"].get<bool>());
  pp.extraction.cleanup_max_cells = 10;
  const PipelineResult capped = run_pipeline(scan.cloud, pp);
  EXPECT_TRUE(capped.report["counts"]["cleanup_skipped"].get<bool>());
  EXPECT_EQ(capped.mesh.num_faces(), full.mesh.num_faces());
}

TEST(Faces, DetailIsMonotoneInTheFaceCount) {
  for (const auto& [model, noise] : {std::pair<std::string, double>{"dormer_house", SynthParams{}.noise},
                                     std::pair<std::string, double>{"courtyard", 0.02}}) {
    std::size_t previous = 0;
    bool first = true;
    std::map<Detail, Outcome> runs;
    for (Detail d : {Detail::Full, Detail::High, Detail::Medium, Detail::Low}) {
      const Outcome r = reconstruct(model, d, noise);
      EXPECT_TRUE(r.valid) << model << " " << detail_name(d);
      if (!first) EXPECT_LE(r.faces, previous) << model << " " << detail_name(d);
      previous = r.faces;
      first = false;
      runs[d] = r;
    }
    EXPECT_LT(runs[Detail::Low].faces, runs[Detail::Full].faces) << model << ": the control does nothing";
  }
}

TEST(Faces, DetailNamesRoundTripAndBadOnesAreRejected) {
  for (Detail d : {Detail::Full, Detail::High, Detail::Medium, Detail::Low})
    EXPECT_EQ(parse_detail(detail_name(d)), d);
  EXPECT_THROW(parse_detail("ultra"), Error);
  ExtractionParams p;
  apply_detail(Detail::Full, p);
  EXPECT_EQ(p.face_price, 0.0);
  apply_detail(Detail::Low, p);
  EXPECT_GT(p.face_price, 0.0);
}

TEST(Faces, FaceSizesOfAKnownMesh) {
  // A unit cube whose top is split into a 0.9999 x 1 face and a 0.0001 x 1 sliver: 7 faces, area 6.
  PolygonMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1},
                {0.9999, 0, 1}, {0.9999, 1, 1}};
  m.faces = {{0, 3, 2, 1}, {0, 1, 5, 8, 4}, {1, 2, 6, 5}, {2, 3, 7, 9, 6}, {3, 0, 4, 7},
             {4, 8, 9, 7}, {8, 5, 6, 9}};
  const FaceSizes s = face_sizes(m);
  EXPECT_EQ(s.small_faces, 1u);
  EXPECT_NEAR(s.smallest_share, 0.0001 / 6.0, 1e-12);
  EXPECT_EQ(face_sizes(m, 0.17).small_faces, 7u);  // every face is at most 1/6 of the area
  EXPECT_EQ(face_sizes(m, 0.16).small_faces, 1u);
}
