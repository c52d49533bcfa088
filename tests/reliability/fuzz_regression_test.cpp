// Regression tests for the readers' fuzz findings (fuzz/, `make fuzz`): every input saved in
// tests/reliability/fuzz_regressions/<ext>/ must keep the reader contract (fuzz/reader_contract.h). Each
// file's name says what it found. Links stage io only (part of the CI's sanitizer subset).
#include "core/log.h"
#include "reader_contract.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

using namespace hsr;
namespace fs = std::filesystem;

namespace {

const fs::path kRegressions = fs::path(HSR_FUZZ_REGRESSIONS_DIR);

std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> out;
  if (fs::is_directory(dir))
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file()) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST(FuzzRegressions, ReadersKeepTheirContract) {
  log::set_level(log::Level::Quiet);
  const fs::path scratch = test::scratch_dir("readers");
  int checked = 0;
  for (const char* ext : {"ply", "xyz", "off", "las", "laz"}) {
    for (const fs::path& f : files_in(kRegressions / ext)) {
      const fs::path copy = scratch / (f.stem().string() + "." + ext);
      fs::copy_file(f, copy, fs::copy_options::overwrite_existing);
      try {
        fuzz::check_reader_contract(copy.string(), (scratch / "roundtrip.ply").string());
      } catch (const fuzz::ReaderContractViolation& v) {
        ADD_FAILURE() << f << ": " << v.what();
      }
      ++checked;
    }
  }
  log::set_level(log::Level::Info);
  EXPECT_GT(checked, 0) << "no regression input found in " << kRegressions;
}
