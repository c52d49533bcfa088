// Regression tests for fuzz_pipeline's findings: every input in tests/reliability/fuzz_regressions/pipeline/
// (bytes in the format of fuzz/fuzz_cloud.h) must give a valid mesh or a user-facing error naming a stage,
// as fuzz/fuzz_pipeline.cpp requires; the seeds of the pipeline fuzzer are replayed too.
#include "core/error.h"
#include "fuzz_cloud.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

using namespace hsr;
namespace fs = std::filesystem;

TEST(FuzzRegressions, PipelineInputsEndCleanly) {
  const fs::path dir = fs::path(HSR_FUZZ_REGRESSIONS_DIR) / "pipeline";
  std::vector<fs::path> files;
  if (fs::is_directory(dir))
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  if (files.empty()) GTEST_SKIP() << "no pipeline finding saved in " << dir;
  for (const fs::path& f : files) {
    const std::string bytes = test::read_file(f);
    const fuzz::FuzzCase c =
        fuzz::decode_fuzz_case(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    try {
      const PipelineResult r = run_pipeline(c.cloud, c.params);
      EXPECT_TRUE(r.eval.validity.valid()) << f;
    } catch (const Error& e) {
      EXPECT_NE(e.status(), Status::Internal) << f << ": " << e.one_line();
      EXPECT_FALSE(e.stage().empty()) << f;
    }
  }
}
