// The CLI on a LAZ file and on its LAS twin (../shared/laz): `hsr info` prints the same figures and
// `hsr reconstruct` writes the same bytes; a broken LAZ gives one line `hsr: io: ...`, a non-zero exit and no
// output file.
#include "test_util.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace hsr {
namespace {

std::string laz_file(const std::string& name) {
  const std::filesystem::path p = std::filesystem::path(HSR_SHARED_LAZ_DIR) / name;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

/// The output without its "file" line (the only one naming the input).
std::string without_file_line(const std::string& out) {
  std::string kept;
  std::size_t at = 0;
  while (at < out.size()) {
    const std::size_t nl = out.find('\n', at);
    const std::string line = out.substr(at, nl == std::string::npos ? std::string::npos : nl + 1 - at);
    if (line.rfind("file ", 0) != 0) kept += line;
    at = nl == std::string::npos ? out.size() : nl + 1;
  }
  return kept;
}

TEST(LazCli, InfoPrintsTheFiguresOfTheLasTwin) {
  const std::string laz = laz_file("autzen_trim.laz"), las = laz_file("autzen_trim.las");
  if (laz.empty() || las.empty()) GTEST_SKIP() << "../shared/laz/autzen_trim.{laz,las} not found";
  const auto a = test::run_cli("info " + laz), b = test::run_cli("info " + las);
  ASSERT_EQ(a.exit_code, 0) << a.output;
  ASSERT_EQ(b.exit_code, 0) << b.output;
  EXPECT_EQ(without_file_line(a.output), without_file_line(b.output));
  EXPECT_NE(a.output.find("points    110000"), std::string::npos) << a.output;
  EXPECT_NE(a.output.find("returns   1: 99257, 2: 9021, 3: 1623, 4: 99"), std::string::npos) << a.output;  // the header's counts
  EXPECT_NE(a.output.find("crs       NAD_1983_HARN_Lambert_Conformal_Conic  (OGC WKT"), std::string::npos) << a.output;
}

TEST(LazCli, ReconstructWritesTheBytesOfTheLasTwin) {
  const std::string laz = laz_file("autzen_trim.laz"), las = laz_file("autzen_trim.las");
  if (laz.empty() || las.empty()) GTEST_SKIP() << "../shared/laz/autzen_trim.{laz,las} not found";
  const auto dir = test::scratch_dir("reconstruct");
  const auto a = test::run_cli("-q reconstruct " + laz + " -o " + (dir / "laz.obj").string());
  const auto b = test::run_cli("-q reconstruct " + las + " -o " + (dir / "las.obj").string());
  ASSERT_EQ(a.exit_code, 0) << a.output;
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const std::string mesh = test::read_file(dir / "laz.obj");
  EXPECT_GT(mesh.size(), 1000u);
  EXPECT_TRUE(mesh == test::read_file(dir / "las.obj")) << "the meshes differ";
}

TEST(LazCli, BrokenLazIsOneLineAndNoOutput) {
  const std::string laz = laz_file("autzen_trim.laz");
  if (laz.empty()) GTEST_SKIP() << "../shared/laz/autzen_trim.laz not found";
  const auto dir = test::scratch_dir("broken");
  const std::string f = test::read_file(laz);
  const auto cut = dir / "cut.laz";
  test::write_file(cut, f.substr(0, f.size() - 100000));  // the last chunk and the chunk table lost
  const auto r = test::run_cli("reconstruct " + cut.string() + " -o " + (dir / "out.obj").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(r.output.rfind("hsr: io: '" + cut.string() + "': LAZ file is truncated", 0), 0u) << r.output;
  EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << "one line: " << r.output;
  EXPECT_EQ(test::count_entries(dir), 1u) << "no output file";
  const auto info = test::run_cli("info " + cut.string());
  EXPECT_NE(info.exit_code, 0);
}

}  // namespace
}  // namespace hsr
