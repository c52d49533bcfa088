// End to end (issue "End-to-end reconstruction"): every synth model reconstructs to a valid mesh close to
// its truth; a box gives exactly 6 faces and 8 vertices; degenerate inputs fail with a clear status.
#include "core/error.h"
#include "eval/eval.h"
#include "io/io.h"
#include "pipeline/pipeline.h"
#include "synth/synth.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <random>
#include <tuple>

using namespace hsr;

namespace {

/// Turns a scan, its normals and its truth by `degrees` about the vertical axis through the origin. The
/// synth models are axis-aligned with corners on the partition box's grid, so their bounding box is close
/// to (the box: equal to) their truth; turned 45 degrees it is far from every model's truth, and a test of a
/// shape then fails if the pipeline returns the bounding box.
void turn_about_z(SynthScan& scan, double degrees) {
  const Eigen::Matrix3d r = Eigen::AngleAxisd(degrees * M_PI / 180.0, Vec3::UnitZ()).toRotationMatrix();
  for (Vec3& p : scan.cloud.points) p = r * p;
  for (Vec3& n : scan.cloud.normals) n = r * n;
  for (Vec3& v : scan.truth.vertices) v = r * v;
}

PipelineResult reconstruct_synth(const std::string& model, double noise, Partitioner method,
                                 SynthScan* scan_out = nullptr, double turn_degrees = 0.0) {
  SynthParams sp;
  sp.noise = noise;
  sp.seed = 7;
  SynthScan scan = run_synth(model, sp);
  if (turn_degrees != 0.0) turn_about_z(scan, turn_degrees);
  PipelineParams pp;
  pp.partition.method = method;
  pp.truth = &scan.truth;
  pp.eval.mesh_samples = 50000;
  PipelineResult r = run_pipeline(scan.cloud, pp);
  if (scan_out) *scan_out = std::move(scan);
  return r;
}

const Partitioner kAccuracyMethods[] = {Partitioner::Bsp, Partitioner::Hierarchical};

}  // namespace

TEST(Pipeline, BoxGivesSixFacesEightVertices) {
  // Turned 45 degrees: every output corner must be a corner of the true box (noise-free scan: the fitted
  // planes meet within 1e-9 of them), which the bounding box's corners are not.
  for (Partitioner m : {Partitioner::Exhaustive, Partitioner::Bsp, Partitioner::Kinetic, Partitioner::Hierarchical}) {
    SynthScan scan;
    const PipelineResult r = reconstruct_synth("box", 0.0, m, &scan, 45.0);
    EXPECT_EQ(r.mesh.num_faces(), 6u) << partitioner_name(m);
    EXPECT_EQ(r.mesh.num_vertices(), 8u) << partitioner_name(m);
    EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
    const double tol = 1e-6 * bounding_box(scan.truth.vertices).diagonal();
    for (const Vec3& v : r.mesh.vertices) {
      double nearest = INFINITY;
      for (const Vec3& c : scan.truth.vertices) nearest = std::min(nearest, (v + r.mesh.origin - c).norm());
      EXPECT_LT(nearest, tol) << partitioner_name(m) << ": vertex " << v.transpose() << " is no corner of the box";
    }
  }
}

// Outdoor models: the scanners are outside, so the reconstruction is the solid. (The room is scanned from
// inside; its truth is the room's air volume — handled with the visibility stage, see the room test.)
// Each model turned 45 degrees (turn_about_z), with the paper's partition and bsp.
class SynthModels : public ::testing::TestWithParam<std::tuple<std::string, Partitioner>> {};

TEST_P(SynthModels, ValidAndCloseToTruthWithoutNoise) {
  const auto& [model, method] = GetParam();
  const PipelineResult r = reconstruct_synth(model, 0.0, method, nullptr, 45.0);
  EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  ASSERT_TRUE(r.eval.accuracy.has_truth);
  EXPECT_LT(r.eval.accuracy.chamfer, 0.002) << model;
  EXPECT_LT(r.eval.accuracy.p2m_mean, 0.002) << model;
}

TEST_P(SynthModels, ValidAndCloseToTruthWithDefaultNoise) {
  const auto& [model, method] = GetParam();
  const PipelineResult r = reconstruct_synth(model, SynthParams{}.noise, method, nullptr, 45.0);
  EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_LT(r.eval.accuracy.chamfer, 0.003) << model;
}

INSTANTIATE_TEST_SUITE_P(Outdoor, SynthModels,
                         ::testing::Combine(::testing::Values("box", "house", "dormer_house", "bracket", "courtyard"),
                                            ::testing::ValuesIn(kAccuracyMethods)),
                         [](const ::testing::TestParamInfo<SynthModels::ParamType>& info) {
                           return std::get<0>(info.param) + "_" + partitioner_name(std::get<1>(info.param));
                         });

// Found while turning the models (issue 15): the noise-free house turned 30 degrees has its corner at the
// origin on the partition box's side, where the two fitted walls cross that side 1e-14 apart: a sliver
// facet of the exact complex ends up on the surface, simple exactly but degenerate once rounded to doubles
// (extraction warns), so the written mesh cannot be valid. The run must end with InvalidOutput naming the
// failed checks (it used to hand that face to CGAL's triangulation, which asserts or crashes on such faces).
TEST(Pipeline, SubPrecisionSliverEndsWithInvalidOutputNotACrash) {
  for (Partitioner m : kAccuracyMethods) {
    try {
      const PipelineResult r = reconstruct_synth("house", 0.0, m, nullptr, 30.0);
      EXPECT_TRUE(r.eval.validity.valid()) << "a valid mesh is fine too (the partition no longer makes the sliver)";
    } catch (const Error& e) {
      EXPECT_EQ(e.status(), Status::InvalidOutput) << e.one_line();
      EXPECT_NE(std::string(e.what()).find("self-intersecting"), std::string::npos) << e.one_line();
    }
  }
}

TEST(Pipeline, BspNeverMoreCellsThanExhaustiveAndSameSurface) {
  for (const char* model : {"house", "bracket"}) {
    const PipelineResult ex = reconstruct_synth(model, 0.0, Partitioner::Exhaustive, nullptr, 45.0);
    const PipelineResult bsp = reconstruct_synth(model, 0.0, Partitioner::Bsp, nullptr, 45.0);
    EXPECT_LE(bsp.report["counts"]["cells"].get<int>(), ex.report["counts"]["cells"].get<int>()) << model;
    EXPECT_LE(bsp.eval.accuracy.chamfer, ex.eval.accuracy.chamfer * 1.05 + 1e-6) << model;
    EXPECT_LT(ex.eval.accuracy.chamfer, 0.002) << model << ": the same surface, and the true one";
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

// One upright plane: no roof to stand a building on (a level one is a flat roof: BuildingRoofs tests its prism).
TEST(Pipeline, PointsOnOnePlaneAreRejected) {
  PointCloud cloud;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 2000; ++i) {
    cloud.points.emplace_back(u(rng), 0.0, u(rng));
    cloud.normals.emplace_back(0, 1, 0);
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

/// Winding number of the closed mesh about q (1 inside, 0 outside), summed over eval's triangles.
double winding_number(const PolygonMesh& mesh, const Vec3& q) {
  double total = 0;
  for (const auto& t : triangulate_faces(mesh)) {
    const Vec3 a = mesh.vertices[t[0]] - q, b = mesh.vertices[t[1]] - q, c = mesh.vertices[t[2]] - q;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    total += 2 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
  }
  return total / (4 * M_PI);
}

// The room is scanned from inside: its enclosing planes are the most visible, their outward side faces
// away from the scanners, and the reconstruction is the room's free space (as the synth truth is).
// What comes back, and why (the truth has 50 faces: room, pillar, table top, edges and legs):
//  * the 8 x 6 x 3 room and its 0.5 x 0.5 floor-to-ceiling pillar, carved out of the free space: the
//    pillar's faces have 280, 117, 92 and 15 points, under the default smallest plane (0.3 % of 40,000 =
//    120 points), so the test allows planes down to 30 points; the face with 15 points is recovered from
//    its neighbours' boundary segments (paper §3.3). With the defaults the room comes back as its box.
//  * the table's top (2.4 x 1.5 m, 239 points), not its legs: its 6 cm edges and 8 cm legs are about one point
//    spacing (r = 6.8 cm) wide, so no plane bounds the space under it; the top's box hangs from it as thick as
//    its edge's points say (RecoveryParams::rim_underside, DECISIONS #229; before it, one spacing, and the
//    min-cut made the table air: the volume was the truth's plus the table's, 0.234 m^3). The volume is the
//    truth's within 0.05 %.
TEST(Pipeline, RoomScannedFromInsideGivesItsFreeSpaceWithThePillar) {
  SynthParams sp;
  sp.seed = 7;
  sp.noise = 0.0;
  const SynthScan scan = run_synth("room", sp);
  const double true_volume = std::abs(check_validity(scan.truth).volume);
  const double table_volume = 2.4 * 1.5 * 0.06 + 4 * 0.08 * 0.08 * 0.72;
  ASSERT_NEAR(true_volume, 8 * 6 * 3 - 0.5 * 0.5 * 3 - table_volume, 1e-9);
  for (Partitioner m : kAccuracyMethods) {
    SCOPED_TRACE(partitioner_name(m));
    PipelineParams pp;
    pp.partition.method = m;
    pp.structure.min_region_fraction = 0;  // see above: min_region_points (30) is the only bound
    pp.truth = &scan.truth;
    pp.eval.mesh_samples = 50000;
    const PipelineResult r = run_pipeline(scan.cloud, pp);
    EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
    // Within 0.05 % of the room (the box would be 0.5 % off: 144 instead of 143.25).
    EXPECT_NEAR(r.eval.validity.volume, true_volume, 0.0005 * 144);
    EXPECT_NEAR(winding_number(r.mesh, Vec3(5.75, 3.75, 1.5)), 0.0, 1e-6) << "inside the pillar: not free space";
    EXPECT_NEAR(winding_number(r.mesh, Vec3(1.0, 1.0, 1.5)), 1.0, 1e-6) << "the room's air";
    EXPECT_NEAR(winding_number(r.mesh, Vec3(3.2, 2.25, 0.4)), 1.0, 1e-6) << "under the table: air, as said above";
    EXPECT_NEAR(winding_number(r.mesh, Vec3(3.2, 2.25, 0.75)), 0.0, 1e-6) << "in the table's top: solid (#229)";
    EXPECT_LT(r.eval.accuracy.chamfer, 0.002);
  }
}
