// The 10-million-point case (issue "Reliability"; deliberately not in the tests): a hip-roof house sampled
// with N points (default 10,000,000, tests/corpus/degenerate_corpus.h), through the whole pipeline. Prints
// per-stage seconds, peak memory, output size and validity as JSON; exit code 0 only for a valid mesh.
// Usage: ten_million [--points N] [--partition bsp|exhaustive|kinetic|hierarchical] [--max-seconds S]
#include "core/error.h"
#include "core/log.h"
#include "degenerate_corpus.h"
#include "pipeline/pipeline.h"

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>

using namespace hsr;

int main(int argc, char** argv) {
  double points = 1e7;
  std::string method = "bsp";
  double max_seconds = 0;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--points") points = std::atof(argv[i + 1]);
    else if (a == "--partition") method = argv[i + 1];
    else if (a == "--max-seconds") max_seconds = std::atof(argv[i + 1]);
  }
  log::set_level(log::Level::Verbose);
  const std::vector<corpus::Polygon3> polys = corpus::hip_roof_house();  // total area about 64.9
  const double area = corpus::total_area(polys);
  const double t0 = log::now_seconds();
  PointCloud cloud = corpus::sample_polygons(polys, points / area, 2024);
  cloud.normals.clear();  // as a raw scan: the structure stage estimates them
  std::fprintf(stderr, "ten_million: %zu points sampled in %.1f s\n", cloud.size(), log::now_seconds() - t0);
  PipelineParams pp;
  pp.partition.method = parse_partitioner(method);
  pp.budget.max_seconds = max_seconds;
  try {
    const PipelineResult r = run_pipeline(cloud, pp);
    std::cout << r.report.dump(2) << '\n';
    return r.eval.validity.valid() ? 0 : 1;
  } catch (const Error& e) {
    std::cerr << "ten_million: " << e.one_line() << '\n';
    return exit_code(e.status());
  }
}
