// The CLI as a user meets it: help, version, bad input → one clear line and a non-zero exit, and never a
// half-written output file.
#include "test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>
#include <vector>

using namespace hsr::test;

namespace {

std::size_t count_lines(const std::string& s) { return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n')); }

/// Runs reconstruct on a bad input and checks the contract: non-zero exit, one line naming the file,
/// no output file left behind (not even a temporary).
void expect_clean_failure(const std::filesystem::path& dir, const std::string& input, const std::string& needle) {
  const auto before = count_entries(dir);
  const auto out = dir / "out.obj";
  const CommandResult r = run_cli("reconstruct '" + input + "' -o '" + out.string() + "'");
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_EQ(count_lines(r.output), 1u) << r.output;
  EXPECT_NE(r.output.find("hsr: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(needle), std::string::npos) << "expected '" << needle << "' in: " << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_EQ(count_entries(dir), before) << "a failed run left a file behind";
}

/// run_cli with the dynamic loader listing every object it loads (LD_DEBUG=files: "file=libX.so ...").
CommandResult run_cli_listing_loads(const std::string& args) {
  ::setenv("LD_DEBUG", "files", 1);
  CommandResult r = run_cli(args);
  ::unsetenv("LD_DEBUG");
  return r;
}

}  // namespace

TEST(Cli, VersionAndHelp) {
  CommandResult r = run_cli("--version");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.output.find("hsr "), std::string::npos);
  for (const char* sub : {"reconstruct", "synth", "eval", "info"}) {
    r = run_cli(std::string(sub) + " --help");
    EXPECT_EQ(r.exit_code, 0) << sub;
    EXPECT_NE(r.output.find("Usage"), std::string::npos) << sub << ": " << r.output;
  }
}

// DECISIONS #188: GDAL and Xerces-C are in modules loaded on first use, so a run that reads no footprint, raster
// or E57 file maps neither (they cost every run 30 MB and about 0.1 s of CPU before main()); one that does loads them.
TEST(Cli, ARunThatNeedsNoFootprintLoadsNeitherGdalNorXerces) {
  const auto dir = scratch_dir("modules");
  CommandResult r = run_cli_listing_loads("synth box -o '" + dir.string() + "' --seed 2 --points 3000");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_cli_listing_loads("-q reconstruct '" + (dir / "points.ply").string() + "' -o '" + (dir / "box.obj").string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_NE(r.output.find("file=libc.so"), std::string::npos) << "LD_DEBUG listed nothing";
  for (const char* lib : {"libgdal", "libxerces", "libhsr_gdal", "libhsr_xml", "libproj"})
    EXPECT_EQ(r.output.find(lib), std::string::npos) << lib << " was loaded by a reconstruction";
  // Writing footprints (synth city) needs GDAL: the module and GDAL come in then.
  r = run_cli_listing_loads("synth city --buildings 2 -o '" + (dir / "city").string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("libhsr_gdal.so"), std::string::npos);
  EXPECT_NE(r.output.find("libgdal"), std::string::npos);
  EXPECT_EQ(r.output.find("libhsr_xml"), std::string::npos) << "the E57 module was loaded for footprints";
}

TEST(Cli, NoSubcommandIsAnError) {
  const CommandResult r = run_cli("");
  EXPECT_NE(r.exit_code, 0);
}

TEST(Cli, SynthListNamesSixModels) {
  const CommandResult r = run_cli("synth --list");
  ASSERT_EQ(r.exit_code, 0);
  EXPECT_GE(count_lines(r.output), 6u);
  for (const char* m : {"box", "house", "dormer_house", "bracket", "room", "courtyard"})
    EXPECT_NE(r.output.find(m), std::string::npos) << m;
}

TEST(Cli, BadInputsFailCleanly) {
  const auto dir = scratch_dir("bad_inputs");
  expect_clean_failure(dir, (dir / "missing.ply").string(), "missing.ply");

  write_file(dir / "points.unknownext", "1 2 3\n");
  expect_clean_failure(dir, (dir / "points.unknownext").string(), "points.unknownext");

  write_file(dir / "empty.xyz", "");
  expect_clean_failure(dir, (dir / "empty.xyz").string(), "empty.xyz");

  write_file(dir / "nan.xyz", "0 0 0\n1 nan 0\n0 1 0\n");
  expect_clean_failure(dir, (dir / "nan.xyz").string(), "nan.xyz");

  write_file(dir / "same.xyz", "1 1 1\n1 1 1\n1 1 1\n1 1 1\n");
  expect_clean_failure(dir, (dir / "same.xyz").string(), "same.xyz");

  // A binary PLY that promises 100 vertices but holds 3.
  std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex 100\nproperty float x\n"
                    "property float y\nproperty float z\nend_header\n";
  ply.append(3 * 3 * sizeof(float), '\0');
  write_file(dir / "truncated.ply", ply);
  expect_clean_failure(dir, (dir / "truncated.ply").string(), "truncated.ply");
}

TEST(Cli, InfoOnSyntheticScan) {
  const auto dir = scratch_dir("info");
  CommandResult r = run_cli("synth box -o '" + dir.string() + "' --seed 3");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_cli("info '" + (dir / "points.ply").string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("normals   yes"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("spacing"), std::string::npos) << r.output;
}

TEST(Cli, InfoOnEverySharedFile) {
  const std::string data = HSR_SHARED_DATA_DIR;
  if (!std::filesystem::exists(data)) GTEST_SKIP() << "shared data folder absent: " << data;
  for (const auto& e : std::filesystem::directory_iterator(data)) {
    if (e.path().extension() == ".tsv") continue;
    const CommandResult r = run_cli("info -q '" + e.path().string() + "'");
    EXPECT_EQ(r.exit_code, 0) << e.path() << ": " << r.output;
    EXPECT_NE(r.output.find("points"), std::string::npos) << r.output;
  }
}

TEST(Cli, EvalOfTruthAgainstItsOwnNoiselessScanIsExact) {
  const auto dir = scratch_dir("eval_truth");
  CommandResult r = run_cli("synth house -o '" + dir.string() + "' --noise 0 --points 5000");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_cli("eval -q --json '" + (dir / "points.ply").string() + "' '" + (dir / "truth.obj").string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_TRUE(j["validity"]["valid"].get<bool>()) << r.output;
  EXPECT_LT(j["accuracy"]["p2m_mean"].get<double>(), 1e-6) << r.output;
  EXPECT_GT(j["points"].get<int>(), 1000);
}

// Issue 15: `--config REPORT.json` replays a run from its report, byte for byte, with the flags given
// beside it overriding the report; the paper's sensitivity parameters are flags.
TEST(Cli, ConfigReplaysARunFromItsReportByteForByte) {
  const auto dir = scratch_dir("replay");
  const std::string pts = (dir / "points.ply").string();
  ASSERT_EQ(run_cli("synth dormer_house -q -o '" + dir.string() + "' --seed 4 --points 20000").exit_code, 0);
  const std::string flags =
      " --partition kinetic --k 2 --lambda 0.6 --smoothness 0.3 --recovery-angle 12 --recovery-distance 4"
      " --alpha-radius 2.5 --max-distance 1.5 --scanner '50,-40,30' --no-recovery";
  CommandResult r = run_cli("reconstruct -q '" + pts + "' -o '" + (dir / "a.obj").string() + "' --report '" +
                            (dir / "a.json").string() + "'" + flags);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_cli("reconstruct -q '" + pts + "' -o '" + (dir / "b.obj").string() + "' --config '" +
              (dir / "a.json").string() + "' --report '" + (dir / "b.json").string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string a = read_file(dir / "a.obj");
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, read_file(dir / "b.obj")) << "the replay gave other bytes";
  const auto ja = nlohmann::json::parse(read_file(dir / "a.json")), jb = nlohmann::json::parse(read_file(dir / "b.json"));
  EXPECT_EQ(ja["parameters"], jb["parameters"]);
  EXPECT_EQ(ja["parameters"]["visibility"]["smoothness"], 0.3);
  EXPECT_EQ(ja["parameters"]["recovery"]["distance"], 4.0);
  EXPECT_EQ(ja["parameters"]["hulls"]["recovered_planes"], false);
  EXPECT_EQ(ja["parameters"]["structure"]["scanners"].size(), 1u);

  // Without the report the same command gives another mesh (the parameters matter)...
  r = run_cli("reconstruct -q '" + pts + "' -o '" + (dir / "c.obj").string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(a, read_file(dir / "c.obj"));
  // ...and a flag beside --config wins over the report.
  r = run_cli("reconstruct -q '" + pts + "' -o '" + (dir / "d.obj").string() + "' --config '" +
              (dir / "a.json").string() + "' --lambda 0.4 --report '" + (dir / "d.json").string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto jd = nlohmann::json::parse(read_file(dir / "d.json"));
  EXPECT_EQ(jd["parameters"]["extraction"]["lambda"], 0.4);
  EXPECT_EQ(jd["parameters"]["partition"]["kinetic_k"], 2);
}

// The same for a building-mode run (aerial synth scans): the scene stage's parameters and the building-mode
// settings of recovery, hulls and extraction replay too, chosen by `auto` or given.
TEST(Cli, ConfigReplaysABuildingRunByteForByte) {
  const auto dir = scratch_dir("replay_aerial");
  for (const char* model : {"aerial_gable", "aerial_dormer"}) {
    const std::filesystem::path sub = dir / model;
    const std::string pts = (sub / "points.ply").string();
    ASSERT_EQ(run_cli("synth " + std::string(model) + " -q -o '" + sub.string() + "' --seed 5").exit_code, 0);
    for (const std::string flags : {std::string(""), std::string(" --scene building --ground-z -0.75 --wall-weight 0.4 "
                                                                  "--partition bsp --recovery-distance 4")}) {
      CommandResult r = run_cli("reconstruct -q '" + pts + "' -o '" + (sub / "a.obj").string() + "' --report '" +
                                (sub / "a.json").string() + "'" + flags);
      ASSERT_EQ(r.exit_code, 0) << model << flags << ": " << r.output;
      r = run_cli("reconstruct -q '" + pts + "' -o '" + (sub / "b.obj").string() + "' --config '" +
                  (sub / "a.json").string() + "' --report '" + (sub / "b.json").string() + "'");
      ASSERT_EQ(r.exit_code, 0) << model << flags << ": " << r.output;
      const std::string a = read_file(sub / "a.obj");
      EXPECT_FALSE(a.empty());
      EXPECT_EQ(a, read_file(sub / "b.obj")) << model << flags << ": the replay gave other bytes";
      const auto ja = nlohmann::json::parse(read_file(sub / "a.json"));
      const auto jb = nlohmann::json::parse(read_file(sub / "b.json"));
      EXPECT_EQ(ja["parameters"], jb["parameters"]) << model << flags;
      EXPECT_EQ(ja["resolved"], jb["resolved"]) << model << flags;
      EXPECT_EQ(ja["scene"]["mode"], "building") << model << flags;
      EXPECT_EQ(ja["resolved"]["recovery"]["vertical"], true) << model << flags;
      EXPECT_EQ(ja["scene"], jb["scene"]) << model << flags;
      if (!flags.empty()) {
        EXPECT_EQ(ja["parameters"]["scene"]["mode"], "building");
        EXPECT_EQ(ja["parameters"]["extraction"]["wall_area_weight"], 0.4);
        EXPECT_EQ(ja["parameters"]["scene"]["building"]["ground_z"], -0.75) << "synth coordinates need no shift";
      } else {
        EXPECT_EQ(ja["parameters"]["scene"]["mode"], "auto");
        EXPECT_TRUE(ja["parameters"]["scene"]["building"]["ground_z"].is_null()) << "none given";
      }
    }
  }
}

TEST(Cli, BadConfigFailsCleanly) {
  const auto dir = scratch_dir("bad_config");
  const std::string pts = (dir / "points.ply").string();
  ASSERT_EQ(run_cli("synth box -q -o '" + dir.string() + "' --points 5000").exit_code, 0);
  write_file(dir / "typo.json", R"({"parameters": {"extraction": {"lamda": 0.3}}})");
  write_file(dir / "garbage.json", "not json");
  for (const char* cfg : {"typo.json", "garbage.json"}) {
    const CommandResult r = run_cli("reconstruct '" + pts + "' -o '" + (dir / "out.obj").string() + "' --config '" +
                                    (dir / cfg).string() + "'");
    EXPECT_NE(r.exit_code, 0) << cfg;
    EXPECT_EQ(count_lines(r.output), 1u) << r.output;
    EXPECT_NE(r.output.find("hsr: config: "), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir / "out.obj"));
  }
}

#ifdef HSR_HOT_TEXT
// DECISIONS #243: the functions a usual run executes (apps/hsr/hot_text.txt, scripts/hot_text.sh) lie side by side in
// the program, so that the code a one-room office maps (64 KiB around each page it touches) is about what it runs:
// spread among the synth, city and tiles code they kept 4.5-4.7 MB of the program's pages resident, side by side
// 3.0-3.4 MB. The list must also still name most of the program's functions (else rerun scripts/hot_text.sh).
TEST(Cli, TheFunctionsAUsualRunExecutesLieSideBySide) {
  /// The longest stretch of code the listed functions may span, as a multiple of their summed sizes (the rest is
  /// alignment padding: functions start on 16 bytes).
  constexpr double kMaxSpanOverSize = 1.1;
  /// The share of the listed functions the program must still hold (below it the list is stale: rerun
  /// scripts/hot_text.sh).
  constexpr double kMinShareFound = 0.8;
  std::vector<std::string> listed;
  std::ifstream list(HSR_HOT_TEXT);
  ASSERT_TRUE(list) << HSR_HOT_TEXT;
  for (std::string line; std::getline(list, line);)
    if (line.rfind(".text.", 0) == 0 && line.rfind(".text.unlikely.", 0) != 0 && line.rfind(".text.startup.", 0) != 0)
      listed.push_back(line.substr(6));  // a function's own section: .text.SYMBOL
  ASSERT_GT(listed.size(), 100u);
  std::map<std::string, std::pair<unsigned long, unsigned long>> where;  // symbol -> (address, size)
  FILE* nm = ::popen(("nm --defined-only -S '" + std::string(HSR_CLI_PATH) + "'").c_str(), "r");
  ASSERT_NE(nm, nullptr);
  char buf[8192];
  while (std::fgets(buf, sizeof buf, nm)) {
    std::istringstream in(buf);
    std::string address, size, kind, symbol;
    if (in >> address >> size >> kind >> symbol) where[symbol] = {std::stoul(address, nullptr, 16), std::stoul(size, nullptr, 16)};
  }
  ::pclose(nm);
  unsigned long lo = ~0ul, hi = 0, total = 0;
  std::size_t found = 0;
  for (const std::string& symbol : listed) {
    const auto it = where.find(symbol);
    if (it == where.end()) continue;
    ++found;
    lo = std::min(lo, it->second.first);
    hi = std::max(hi, it->second.first + it->second.second);
    total += it->second.second;
  }
  EXPECT_GE(static_cast<double>(found), kMinShareFound * static_cast<double>(listed.size()))
      << found << " of " << listed.size() << " listed functions in the program: rerun scripts/hot_text.sh";
  ASSERT_GT(total, 0u);
  EXPECT_LE(static_cast<double>(hi - lo), kMaxSpanOverSize * static_cast<double>(total))
      << "the listed functions (" << total << " bytes) span " << (hi - lo) << " bytes of code";
}
#endif
