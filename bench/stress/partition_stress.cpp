// Long partition stress (issue "Reliability"): thousands of random polygon sets (tests/reliability/
// random_polygons.h) through every partitioner, each complex checked exactly by validate() with input
// coverage. Prints per partitioner: sets, failures (with their seeds), mean cells, total seconds.
// Usage: partition_stress [--sets N=2000] [--max-polygons M=14] [--first-seed S=1000] [--no-validate-coverage]
// Exit code 1 if any complex is invalid or any partitioner throws (NotImplemented partitioners are skipped).
#include "core/error.h"
#include "random_polygons.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

using namespace hsr;

int main(int argc, char** argv) {
  int sets = 2000, max_polygons = 14;
  std::uint64_t first_seed = 1000;
  bool coverage = true;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--sets" && i + 1 < argc) sets = std::atoi(argv[++i]);
    else if (a == "--max-polygons" && i + 1 < argc) max_polygons = std::atoi(argv[++i]);
    else if (a == "--first-seed" && i + 1 < argc) first_seed = std::strtoull(argv[++i], nullptr, 10);
    else if (a == "--no-validate-coverage") coverage = false;
    else {
      std::fprintf(stderr, "usage: %s [--sets N] [--max-polygons M] [--first-seed S] [--no-validate-coverage]\n", argv[0]);
      return 2;
    }
  }
  int total_failures = 0;
  std::printf("%-13s %6s %8s %10s %10s\n", "partitioner", "sets", "failures", "mean_cells", "seconds");
  for (Partitioner method : stress::all_partitioners()) {
    PartitionParams params;
    params.method = method;
    int done = 0, failures = 0;
    double cells = 0, seconds = 0;
    bool skipped = false;
    for (int s = 0; s < sets && !skipped; ++s) {
      const std::uint64_t seed = first_seed + static_cast<std::uint64_t>(s);
      const int count = 2 + static_cast<int>(seed % static_cast<std::uint64_t>(max_polygons - 1));
      const PartitionInput in = stress::random_polygon_set(seed, count);
      const auto t0 = std::chrono::steady_clock::now();
      try {
        const CellComplex complex = run_partition(in, params);
        seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const ValidationReport r = validate(complex, coverage ? &in.polygons : nullptr);
        if (!r.ok) {
          ++failures;
          std::printf("  FAIL %s seed %llu (%d polygons): %s\n", partitioner_name(method),
                      static_cast<unsigned long long>(seed), count, r.problems.empty() ? "" : r.problems.front().c_str());
        }
        cells += static_cast<double>(complex.cells.size());
        ++done;
      } catch (const Error& e) {
        if (e.status() == Status::NotImplemented) {
          std::printf("  %s: skipped (%s)\n", partitioner_name(method), e.one_line().c_str());
          skipped = true;
          break;
        }
        ++failures;
        ++done;
        std::printf("  FAIL %s seed %llu (%d polygons): %s\n", partitioner_name(method),
                    static_cast<unsigned long long>(seed), count, e.one_line().c_str());
      }
      std::fflush(stdout);
    }
    std::printf("%-13s %6d %8d %10.1f %10.2f\n", partitioner_name(method), done, failures, done ? cells / done : 0.0,
                seconds);
    total_failures += failures;
  }
  return total_failures == 0 ? 0 : 1;
}
