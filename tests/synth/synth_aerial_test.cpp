// The aerial synth models and the airborne scanner (issue 13): every model is a valid closed building
// standing on z = 0; the scan sees roofs at the survey density, walls little or not at all, never a bottom;
// ground and tree points are in the scan but not in the truth (point_plane -1); all of it seeded.
#include "core/error.h"
#include "eval/eval.h"
#include "synth/synth.h"
#include "test_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace hsr {
namespace {

using test::aerial_scan;
SynthScan aerial(const std::string& model, std::uint64_t seed, int ground, int trees, double noise = 0.03) {
  return aerial_scan(model, seed, ground, trees, noise);
}

double footprint_area(const SynthScan& s) {  // area of the truth's faces facing straight down (its bottom)
  double a = 0;
  for (std::size_t f = 0; f < s.truth.faces.size(); ++f) {
    const Plane& pl = s.planes[static_cast<std::size_t>(s.face_plane[f])].plane;
    if (pl.normal.z() < -1 + 1e-9) a += s.planes[static_cast<std::size_t>(s.face_plane[f])].area;
  }
  return a;
}

class AerialModel : public ::testing::TestWithParam<std::string> {};

TEST_P(AerialModel, TruthIsAValidClosedBuildingOnTheGround) {
  for (std::uint64_t seed : {1, 2, 3}) {
    const SynthScan s = aerial(GetParam(), seed, 0, 0);
    EXPECT_TRUE(s.aerial);
    const Validity v = check_validity(s.truth);
    EXPECT_TRUE(v.valid()) << GetParam() << " seed " << seed << ": " << v.summary();
    const BBox box = bounding_box(s.truth.vertices);
    EXPECT_NEAR(box.min.z(), 0.0, 1e-9);
    EXPECT_GT(box.max.z(), 2.5);
    EXPECT_GT(v.volume, 0.0);
    // Several roof planes (more than a box's one) and a bottom the size of the footprint.
    std::size_t roofs = 0;
    for (const SynthPlane& p : s.planes) roofs += p.plane.normal.z() > 0.1;
    EXPECT_GE(roofs, 2u) << GetParam();
    EXPECT_GT(footprint_area(s), 40.0);
  }
}

TEST_P(AerialModel, RoofsAtTheSurveyDensityWallsSparseBottomUnseen) {
  const SynthScan s = aerial(GetParam(), 1, 0, 0, 0.0);
  double roof_area = 0, wall_area = 0;
  std::size_t roof_points = 0, wall_points = 0, bottom_points = 0;
  for (std::size_t k = 0; k < s.planes.size(); ++k) {
    const SynthPlane& p = s.planes[k];
    if (p.plane.normal.z() < -0.5) bottom_points += p.points;
    else if (std::abs(p.plane.normal.z()) < 0.1) wall_area += p.area, wall_points += p.points;
    else roof_area += p.area * std::abs(p.plane.normal.z()), roof_points += p.points;  // in plan: survey density
  }
  EXPECT_EQ(bottom_points, 0u);
  const double roof_density = static_cast<double>(roof_points) / roof_area;
  EXPECT_GT(roof_density, 0.7 * SynthParams{}.aerial_density) << GetParam();
  EXPECT_LT(roof_density, 1.5 * SynthParams{}.aerial_density) << GetParam();
  EXPECT_LT(static_cast<double>(wall_points) / wall_area, 0.3 * roof_density) << "walls are seen from above only";
}

TEST_P(AerialModel, NoiseFreePointsLieOnTheirTruthPlane) {
  const SynthScan s = aerial(GetParam(), 2, 0, 0, 0.0);
  ASSERT_EQ(s.point_plane.size(), s.cloud.size());
  const double diag = bounding_box(s.truth.vertices).diagonal();
  for (std::size_t i = 0; i < s.cloud.size(); ++i) {
    ASSERT_GE(s.point_plane[i], 0) << "no ground or trees were asked for";
    EXPECT_LE(std::abs(s.planes[static_cast<std::size_t>(s.point_plane[i])].plane.signed_distance(s.cloud.points[i])),
              1e-6 * diag);
  }
}

INSTANTIATE_TEST_SUITE_P(All, AerialModel, ::testing::ValuesIn(synth_aerial_model_names()));

TEST(AerialSynth, GroundAndTreesAreInTheScanNotInTheTruth) {
  const SynthScan s = aerial("aerial_gable", 3, 1, 2, 0.0);
  std::size_t ground = 0, trees = 0;
  const BBox truth = bounding_box(s.truth.vertices);
  for (std::size_t i = 0; i < s.cloud.size(); ++i) {
    if (s.point_plane[i] >= 0) continue;
    const Vec3& p = s.cloud.points[i];
    if (std::abs(p.z()) < 1e-6) ++ground;  // on the ground plane z = 0
    else ++trees;                          // in a crown, above the ground
  }
  EXPECT_GT(ground, 1000u);
  EXPECT_GT(trees, 20u);
  // The ground reaches beyond the building on every side.
  BBox all = bounding_box(s.cloud.points);
  EXPECT_LT(all.min.x(), truth.min.x() - 3.0);
  EXPECT_GT(all.max.y(), truth.max.y() + 3.0);
  // Without them: nothing off the truth.
  const SynthScan bare = aerial("aerial_gable", 3, 0, 0, 0.0);
  EXPECT_EQ(std::count(bare.point_plane.begin(), bare.point_plane.end(), -1), 0);
}

TEST(AerialSynth, DeterministicForASeedAndDifferentAcrossSeeds) {
  const SynthScan a = aerial("aerial_mixed", 5, -1, -1), b = aerial("aerial_mixed", 5, -1, -1);
  EXPECT_EQ(a.cloud.points, b.cloud.points);
  EXPECT_EQ(a.truth.vertices, b.truth.vertices);
  const SynthScan c = aerial("aerial_mixed", 6, -1, -1);
  EXPECT_NE(a.truth.vertices, c.truth.vertices) << "the seed draws the building";
}

TEST(AerialSynth, BadDensityIsBadInput) {
  SynthParams p;
  p.aerial_density = 0;
  EXPECT_THROW(run_synth("aerial_flat", p), Error);
}

}  // namespace
}  // namespace hsr
