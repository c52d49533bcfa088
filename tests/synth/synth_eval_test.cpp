// Cross-check of the synth truth and scans with the independent eval stage (CGAL PMP validity checks and
// point-to-mesh distances). Separate binary so synth_test does not depend on hsr_eval.
#include "eval/eval.h"
#include "synth/synth.h"

#include <gtest/gtest.h>

namespace hsr {
namespace {

class SynthEval : public ::testing::TestWithParam<std::string> {};

TEST_P(SynthEval, TruthIsValidAndNoiseFreePointsLieOnIt) {
  SynthParams p;
  p.noise = 0;
  p.target_points = 8000;
  const SynthScan s = run_synth(GetParam(), p);
  const Validity v = check_validity(s.truth, /*check_self_intersections=*/true);
  EXPECT_TRUE(v.valid()) << GetParam() << ": " << v.summary();
  EXPECT_GT(v.volume, 0.0);

  EvalParams ep;
  ep.mesh_samples = 20000;
  const EvalResult r = run_eval(s.cloud, s.truth, &s.truth, ep);
  EXPECT_LE(r.accuracy.p2m_max, 1e-6) << GetParam();
  // Truth against itself: zero distance both ways (checks eval sees the same surface we wrote).
  EXPECT_LE(r.accuracy.hausdorff, 1e-9) << GetParam();
}

INSTANTIATE_TEST_SUITE_P(AllModels, SynthEval, ::testing::ValuesIn(synth_model_names()));

}  // namespace
}  // namespace hsr
