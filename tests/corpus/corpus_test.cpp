// Degenerate-geometry corpus (issue "Reliability"): every case of degenerate_corpus() gives its expected
// outcome through run_pipeline, with every partitioner for the cases that must give a mesh; failures go
// through the CLI with the right exit code, the failing stage in the message and no file left behind; the
// resource budget stops a run cleanly.
#include "core/budget.h"
#include "degenerate_corpus.h"
#include "io/io.h"
#include "pipeline/pipeline.h"
#include "synth/synth.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>

using namespace hsr;
namespace fs = std::filesystem;

namespace {

const std::vector<corpus::CorpusCase>& all_cases() {
  static const std::vector<corpus::CorpusCase> cases = corpus::degenerate_corpus();
  return cases;
}

const corpus::CorpusCase& find_case(const std::string& name) {
  for (const auto& c : all_cases())
    if (c.name == name) return c;
  throw std::runtime_error("no corpus case " + name);
}

std::vector<std::string> case_names() {
  std::vector<std::string> names;
  for (const auto& c : all_cases()) names.push_back(c.name);
  return names;
}

std::string gtest_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string s = info.param;
  for (char& ch : s)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return s;
}

/// Status of one run (Ok when a mesh came back); the error's stage in `stage`.
Status run(const PointCloud& cloud, Partitioner method, PipelineResult* result, std::string* stage) {
  PipelineParams pp;
  pp.partition.method = method;
  pp.eval.mesh_samples = 5000;
  try {
    *result = run_pipeline(cloud, pp);
    return Status::Ok;
  } catch (const Error& e) {
    *stage = e.stage();
    return e.status();
  }
}

}  // namespace

class Corpus : public ::testing::TestWithParam<std::string> {};

TEST_P(Corpus, GivesItsExpectedOutcome) {
  const corpus::CorpusCase& c = find_case(GetParam());
  SCOPED_TRACE(c.name + ": " + c.why);
  // Failures happen before the partition; meshes must come out of every partitioner.
  const std::vector<Partitioner> methods =
      c.expected == Status::Ok ? std::vector<Partitioner>{Partitioner::Exhaustive, Partitioner::Bsp,
                                                          Partitioner::Kinetic, Partitioner::Hierarchical}
                               : std::vector<Partitioner>{Partitioner::Bsp};
  for (Partitioner m : methods) {
    SCOPED_TRACE(partitioner_name(m));
    PipelineResult r;
    std::string stage;
    const Status s = run(c.cloud, m, &r, &stage);
    ASSERT_EQ(s, c.expected) << "got " << status_name(s) << " from stage '" << stage << "'";
    if (s != Status::Ok) {
      EXPECT_FALSE(stage.empty());
      continue;
    }
    EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
    if (c.exact) {
      EXPECT_EQ(r.mesh.num_faces(), c.faces);
      EXPECT_EQ(r.mesh.num_vertices(), c.vertices);
    } else {
      EXPECT_GE(r.mesh.num_faces(), c.faces);
    }
    // Close to the points (noise-free samples): mean point-to-mesh distance below 0.5% of the diagonal.
    EXPECT_LT(r.eval.accuracy.p2m_mean, 0.005);
    // The mesh lies where the points are: every vertex inside the points' bbox grown by 1% of its diagonal.
    const BBox b = bounding_box(c.cloud.points);
    const double tol = 0.01 * b.diagonal();
    for (const Vec3& v : r.mesh.vertices)
      for (int k = 0; k < 3; ++k) {
        EXPECT_GE(v[k], b.min[k] - tol);
        EXPECT_LE(v[k], b.max[k] + tol);
      }
  }
}

INSTANTIATE_TEST_SUITE_P(Degenerate, Corpus, ::testing::ValuesIn(case_names()), gtest_name);

TEST(CorpusList, CoversTheIssueCases) {
  // The issue's list: each kind of degeneracy has at least one case.
  for (const char* name : {"duplicate_points", "collinear_points", "single_plane", "two_parallel_planes",
                           "nearly_coplanar_0.01deg", "pyramid_four_planes_one_point", "bowtie_four_planes_one_line",
                           "box_faces_on_bbox", "offset_1e6", "size_1e-3", "ten_points"})
    EXPECT_NO_THROW(find_case(name)) << name;
}

// Through the CLI: a failing case exits with its status's code, names the stage, and writes nothing.
TEST(CorpusCli, FailureNamesTheStageAndLeavesNoFile) {
  const fs::path dir = test::scratch_dir("cli_failure");
  for (const char* name : {"single_plane", "two_parallel_planes", "ten_points"}) {
    const corpus::CorpusCase& c = find_case(name);
    const fs::path in = dir / (std::string(name) + ".ply");
    write_points(in.string(), c.cloud);
    const fs::path out_dir = dir / (std::string(name) + "_out");
    fs::create_directories(out_dir);
    const test::CommandResult r =
        test::run_cli("reconstruct " + in.string() + " -o " + (out_dir / "mesh.obj").string() + " --report " +
                      (out_dir / "report.json").string());
    EXPECT_EQ(r.exit_code, exit_code(c.expected)) << name << ": " << r.output;
    EXPECT_NE(r.output.find("hsr: structure: "), std::string::npos) << name << ": " << r.output;
    EXPECT_EQ(test::count_entries(out_dir), 0u) << name << ": a file was left behind";
  }
}

TEST(CorpusCli, MeshCaseWritesTheMesh) {
  const fs::path dir = test::scratch_dir("cli_ok");
  const fs::path in = dir / "octahedron.ply";
  write_points(in.string(), find_case("octahedron_four_planes_per_vertex").cloud);
  const test::CommandResult r = test::run_cli("reconstruct " + in.string() + " -o " + (dir / "mesh.obj").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const PolygonMesh mesh = read_mesh((dir / "mesh.obj").string());
  EXPECT_GE(mesh.num_faces(), 8u);  // eight true faces (plus tiny ones where fitted planes miss a vertex)
}

// Resource guards.
TEST(Budget, TimeBudgetStopsTheFirstStageInProcess) {
  PipelineParams pp;
  pp.budget.max_seconds = 1e-9;
  try {
    run_pipeline(find_case("box_faces_on_bbox").cloud, pp);
    FAIL() << "no BudgetExceeded";
  } catch (const Error& e) {
    EXPECT_EQ(e.status(), Status::BudgetExceeded) << e.one_line();
    EXPECT_EQ(e.stage(), "structure") << e.one_line();
    EXPECT_NE(std::string(e.what()).find("time budget"), std::string::npos) << e.one_line();
  }
}

TEST(Budget, MemoryBudgetBelowTheProcessSizeStops) {
  PipelineParams pp;
  pp.budget.max_memory_mb = 1.0;  // the test process alone is larger
  try {
    run_pipeline(find_case("box_faces_on_bbox").cloud, pp);
    FAIL() << "no BudgetExceeded";
  } catch (const Error& e) {
    EXPECT_EQ(e.status(), Status::BudgetExceeded) << e.one_line();
    EXPECT_NE(std::string(e.what()).find("memory budget"), std::string::npos) << e.one_line();
  }
}

TEST(Budget, GenerousBudgetChangesNothing) {
  PipelineParams pp;
  pp.budget.max_seconds = 3600;
  pp.budget.max_memory_mb = 1e6;
  const PipelineResult r = run_pipeline(find_case("box_faces_on_bbox").cloud, pp);
  EXPECT_EQ(r.mesh.num_faces(), 6u);
}

TEST(Budget, CheckOutsideARunDoesNothing) {
  EXPECT_NO_THROW(check_budget("anything"));
  {
    Budget b;
    b.max_seconds = 1e-9;
    BudgetScope scope(b);
    EXPECT_THROW(check_budget("x"), Error);
  }
  EXPECT_NO_THROW(check_budget("anything"));
}

// The CLI on a big cloud with a tiny time budget: stops quickly with BudgetExceeded, no output file.
TEST(BudgetCli, TinyMaxSecondsOnABigCloudStopsCleanly) {
  const fs::path dir = test::scratch_dir("budget_cli");
  SynthParams sp;
  sp.target_points = 400000;
  write_points((dir / "big.ply").string(), run_synth("house", sp).cloud);
  const fs::path out_dir = dir / "out";
  fs::create_directories(out_dir);
  const auto t0 = std::chrono::steady_clock::now();
  const test::CommandResult r = test::run_cli("reconstruct " + (dir / "big.ply").string() + " -o " +
                                              (out_dir / "mesh.ply").string() + " --max-seconds 0.3");
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.exit_code, exit_code(Status::BudgetExceeded)) << r.output;
  EXPECT_NE(r.output.find("budget of 0.3 s exceeded"), std::string::npos) << r.output;
  EXPECT_EQ(test::count_entries(out_dir), 0u);
  // Stopped at the budget (plus the watchdog's grace and process start-up), not at the end of the run.
  EXPECT_LT(secs, 0.3 + Budget{}.hard_stop_grace + 8.0) << r.output;
}
