// The run budget's defaults (core/budget.h) and the CLI over its memory budget (issue 25): the default is a
// share of the physical memory, reported in the run report; a run over the budget stops with one line
// naming the budget and leaves no file behind.
#include "core/budget.h"
#include "io/io.h"
#include "synth/synth.h"
#include "test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace hsr {
namespace {

namespace fs = std::filesystem;

TEST(Budget, DefaultMemoryBudgetIsAShareOfThePhysicalMemory) {
  const double physical = physical_memory_mb();
  ASSERT_GT(physical, 100.0);
  EXPECT_NEAR(default_memory_budget_mb(), kDefaultMemoryShare * physical, 1.0);
  EXPECT_LT(default_memory_budget_mb(), physical);
  EXPECT_GT(resident_memory_mb(), 0.0);
}

TEST(BudgetCli, TheDefaultMemoryBudgetIsInTheReport) {
  const fs::path dir = test::scratch_dir("default_budget");
  SynthParams sp;
  sp.target_points = 5000;
  write_points((dir / "box.ply").string(), run_synth("box", sp).cloud);
  const test::CommandResult r = test::run_cli("-q reconstruct " + (dir / "box.ply").string() + " -o " +
                                              (dir / "box.obj").string() + " --report " + (dir / "r.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(dir / "r.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_NEAR(report["budget"]["max_memory_mb"].get<double>(), default_memory_budget_mb(), 1e-9);
  EXPECT_NEAR(report["budget"]["physical_memory_mb"].get<double>(), physical_memory_mb(), 1e-9);
}

TEST(BudgetCli, ARunOverTheMemoryBudgetStopsWithOneLineAndLeavesNoFile) {
  const fs::path dir = test::scratch_dir("memory_budget");
  SynthParams sp;
  sp.target_points = 300000;
  write_points((dir / "house.ply").string(), run_synth("house", sp).cloud);
  const fs::path out = dir / "out";
  fs::create_directories(out);
  // The run needs well over 60 MB (the points alone are 14 MB, their kNN graph 14 more, the partition
  // and extraction more); the process starts at about 15 MB.
  const test::CommandResult r =
      test::run_cli("-q reconstruct " + (dir / "house.ply").string() + " -o " + (out / "house.obj").string() +
                    " --report " + (out / "report.json").string() + " --max-memory 60");
  EXPECT_EQ(r.exit_code, exit_code(Status::BudgetExceeded)) << r.output;
  EXPECT_EQ(r.output.rfind("hsr: ", 0), 0u) << r.output;
  EXPECT_NE(r.output.find("memory budget of 60 MB exceeded"), std::string::npos) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_EQ(test::count_entries(out), 0u) << "a file was left behind";
}

}  // namespace
}  // namespace hsr
