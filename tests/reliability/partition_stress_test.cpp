// Short seeded partition stress (issue "Reliability"; the long run is bench/stress/partition_stress): random
// polygon sets (random, axis-aligned, coplanar, nearly parallel, concurrent planes; polygons crossing the box)
// through every partitioner, each complex checked exactly by validate() including the coverage of the inputs.
// Every partitioner is built: any error (NotImplemented included) fails the test.
#include "core/error.h"
#include "random_polygons.h"

#include <gtest/gtest.h>

using namespace hsr;

class PartitionStress : public ::testing::TestWithParam<Partitioner> {};

TEST_P(PartitionStress, RandomSetsGiveValidComplexes) {
  const Partitioner method = GetParam();
  PartitionParams params;
  params.method = method;
  params.threads = 1;
  int checked = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const int count = 2 + static_cast<int>(seed % 9);  // 2..10 polygons
    const PartitionInput in = stress::random_polygon_set(seed, count);
    CellComplex complex;
    try {
      complex = run_partition(in, params);
    } catch (const Error& e) {
      FAIL() << partitioner_name(method) << " seed " << seed << ": " << e.one_line();
    }
    const ValidationReport report = validate(complex, &in.polygons);
    ASSERT_TRUE(report.ok) << partitioner_name(method) << " seed " << seed << " (" << count
                           << " polygons): " << (report.problems.empty() ? "" : report.problems.front());
    ASSERT_GE(complex.cells.size(), 1u);
    ++checked;
  }
  EXPECT_EQ(checked, 40);
}

INSTANTIATE_TEST_SUITE_P(All, PartitionStress, ::testing::ValuesIn(stress::all_partitioners()),
                         [](const ::testing::TestParamInfo<Partitioner>& info) {
                           return std::string(partitioner_name(info.param));
                         });
