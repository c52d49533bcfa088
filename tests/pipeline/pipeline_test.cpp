// End to end (issue "End-to-end reconstruction"): every synth model reconstructs to a valid mesh close to
// its truth; a box gives exactly 6 faces and 8 vertices; degenerate inputs fail with a clear status.
#include "core/error.h"
#include "io/io.h"
#include "pipeline.h"
#include "synth/synth.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace hsr;

namespace {

PipelineResult reconstruct_synth(const std::string& model, double noise, Partitioner method,
                                 SynthScan* scan_out = nullptr) {
  SynthParams sp;
  sp.noise = noise;
  sp.seed = 7;
  SynthScan scan = run_synth(model, sp);
  PipelineParams pp;
  pp.partition.method = method;
  pp.truth = &scan.truth;
  pp.eval.mesh_samples = 50000;
  PipelineResult r = run_pipeline(scan.cloud, pp);
  if (scan_out) *scan_out = std::move(scan);
  return r;
}

}  // namespace

TEST(Pipeline, BoxGivesSixFacesEightVertices) {
  for (Partitioner m : {Partitioner::Exhaustive, Partitioner::Bsp}) {
    const PipelineResult r = reconstruct_synth("box", 0.0, m);
    EXPECT_EQ(r.mesh.num_faces(), 6u) << partitioner_name(m);
    EXPECT_EQ(r.mesh.num_vertices(), 8u) << partitioner_name(m);
    EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  }
}

// Outdoor models: the scanners are outside, so the reconstruction is the solid. (The room is scanned from
// inside; its truth is the room's air volume — handled with the visibility stage, see the room test.)
class SynthModels : public ::testing::TestWithParam<std::string> {};

TEST_P(SynthModels, ValidAndCloseToTruthWithoutNoise) {
  const PipelineResult r = reconstruct_synth(GetParam(), 0.0, Partitioner::Bsp);
  EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  ASSERT_TRUE(r.eval.accuracy.has_truth);
  EXPECT_LT(r.eval.accuracy.chamfer, 0.005) << GetParam();
  EXPECT_LT(r.eval.accuracy.p2m_mean, 0.005) << GetParam();
}

TEST_P(SynthModels, ValidAndCloseToTruthWithDefaultNoise) {
  const PipelineResult r = reconstruct_synth(GetParam(), SynthParams{}.noise, Partitioner::Bsp);
  EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_LT(r.eval.accuracy.chamfer, 0.01) << GetParam();
}

INSTANTIATE_TEST_SUITE_P(Outdoor, SynthModels,
                         ::testing::Values("box", "house", "dormer_house", "bracket", "courtyard"));

TEST(Pipeline, BspNeverMoreCellsThanExhaustiveAndSameSurface) {
  for (const char* model : {"house", "bracket"}) {
    const PipelineResult ex = reconstruct_synth(model, 0.0, Partitioner::Exhaustive);
    const PipelineResult bsp = reconstruct_synth(model, 0.0, Partitioner::Bsp);
    EXPECT_LE(bsp.report["counts"]["cells"].get<int>(), ex.report["counts"]["cells"].get<int>()) << model;
    EXPECT_LE(bsp.eval.accuracy.chamfer, ex.eval.accuracy.chamfer * 1.05 + 1e-6) << model;
  }
}

TEST(Pipeline, ReportHasEverySection) {
  const PipelineResult r = reconstruct_synth("box", 0.0, Partitioner::Bsp);
  for (const char* key : {"parameters", "seconds", "counts", "validity", "accuracy", "peak_memory_mb"})
    EXPECT_TRUE(r.report.contains(key)) << key;
  for (const char* stage : {"structure", "hulls", "partition", "extraction", "eval", "total"})
    EXPECT_TRUE(r.report["seconds"].contains(stage)) << stage;
  EXPECT_EQ(r.report["counts"]["output_faces"].get<std::size_t>(), r.mesh.num_faces());
  EXPECT_GT(r.report["counts"]["cells"].get<int>(), 1);
}

TEST(Pipeline, Deterministic) {
  const PipelineResult a = reconstruct_synth("dormer_house", SynthParams{}.noise, Partitioner::Bsp);
  const PipelineResult b = reconstruct_synth("dormer_house", SynthParams{}.noise, Partitioner::Bsp);
  ASSERT_EQ(a.mesh.vertices.size(), b.mesh.vertices.size());
  for (std::size_t i = 0; i < a.mesh.vertices.size(); ++i) EXPECT_EQ(a.mesh.vertices[i], b.mesh.vertices[i]);
  EXPECT_EQ(a.mesh.faces, b.mesh.faces);
}

namespace {
Status pipeline_status(const PointCloud& cloud) {
  try {
    run_pipeline(cloud, PipelineParams{});
  } catch (const Error& e) {
    EXPECT_FALSE(std::string(e.what()).empty());
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "message must be one line";
    return e.status();
  }
  return Status::Ok;
}
}  // namespace

TEST(Pipeline, PointsOnOnePlaneAreRejected) {
  PointCloud cloud;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 2000; ++i) {
    cloud.points.emplace_back(u(rng), u(rng), 0.0);
    cloud.normals.emplace_back(0, 0, 1);
  }
  const Status s = pipeline_status(cloud);
  EXPECT_TRUE(s == Status::DegenerateInput || s == Status::BadInput) << status_name(s);
}

TEST(Pipeline, TwoParallelPlanesAreRejected) {
  PointCloud cloud;
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 2000; ++i) {
    const double z = (i % 2) ? 1.0 : 0.0;
    cloud.points.emplace_back(u(rng), u(rng), z);
    cloud.normals.emplace_back(0, 0, z > 0 ? 1 : -1);
  }
  EXPECT_EQ(pipeline_status(cloud), Status::DegenerateInput);
}

TEST(Pipeline, TenPointsFindNoPlane) {
  PointCloud cloud;  // fewer points than the smallest plane may have
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 10; ++i) cloud.points.emplace_back(u(rng), u(rng), u(rng));
  EXPECT_EQ(pipeline_status(cloud), Status::NoPlanes);
}

// Issue "visibility, recovery": the recovered face makes a difference end to end. The synth box's bottom
// is never scanned. With a tight partition box the bottom would be closed by the box side anyway, so the
// test gives the partition a margin: then only the recovered plane can close the box where the truth is.
TEST(Pipeline, RecoveredFaceLowersErrorOnBoxWithMissingFace) {
  SynthParams sp;
  sp.seed = 11;
  const SynthScan scan = run_synth("box", sp);
  PipelineParams pp;
  pp.truth = &scan.truth;
  pp.partition.bbox_margin = 0.05;
  pp.eval.mesh_samples = 50000;
  const PipelineResult with = run_pipeline(scan.cloud, pp);
  pp.hulls.recovered_planes = false;
  const PipelineResult without = run_pipeline(scan.cloud, pp);
  EXPECT_TRUE(with.eval.validity.valid());
  EXPECT_TRUE(without.eval.validity.valid());
  EXPECT_GE(with.report["counts"]["recovered_planes"].get<int>(), 1);
  EXPECT_LT(with.eval.accuracy.chamfer, 0.5 * without.eval.accuracy.chamfer);
  EXPECT_EQ(with.mesh.num_faces(), 6u);
}

// The room is scanned from inside: its enclosing planes are the most visible, their outward side faces
// away from the scanners, and the reconstruction is the room's free space (as the synth truth is).
TEST(Pipeline, RoomScannedFromInsideGivesItsFreeSpace) {
  SynthScan scan;
  const PipelineResult r = reconstruct_synth("room", 0.0, Partitioner::Bsp, &scan);
  EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  const double true_volume = std::abs(check_validity(scan.truth).volume);
  EXPECT_NEAR(r.eval.validity.volume, true_volume, 0.05 * true_volume);
  EXPECT_LT(r.eval.accuracy.chamfer, 0.005);
}
