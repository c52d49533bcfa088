// bench_structure [--detector rg|ransac] [--repeat N] [--verbose] [files...]
// Times run_structure (stage 1) on each file (default: the real scans of the shared data folder) and prints
// one table row per file: points, spacing, planes, assigned points, segments, adjacent pairs, lines, the
// best wall time over the repeats and the peak memory. Files that are absent are skipped.
#include "structure/structure.h"

#include "core/error.h"
#include "core/log.h"
#include "io/io.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  hsr::StructureParams params;
  int repeat = 1;
  bool verbose = false;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--detector" && i + 1 < argc) {
      params.detector = std::string(argv[++i]) == "ransac" ? hsr::PlaneDetector::Ransac : hsr::PlaneDetector::RegionGrowing;
    } else if (a == "--verbose") {
      verbose = true;
    } else if (a == "--repeat" && i + 1 < argc) {
      repeat = std::max(1, std::atoi(argv[++i]));
    } else {
      files.push_back(a);
    }
  }
  if (files.empty()) {
    const std::string dir = HSR_SHARED_DATA_DIR;
    for (const char* f : {"manhattan_example1.ply", "cgal_building.ply", "cgal_cube.ply", "cgal_b9.ply", "cgal_urban.las",
                          "city3d_bldg94.ply", "planefinder_officeCorner.ply", "abc_00470.xyz", "cgal_fandisk.off"})
      files.push_back(dir + "/" + f);
  }
  hsr::log::set_level(verbose ? hsr::log::Level::Verbose : hsr::log::Level::Quiet);
  std::printf("%-30s %8s %9s %6s %8s %6s %6s %6s %9s %8s\n", "file", "points", "spacing", "planes", "assigned",
              "segs", "adj", "lines", "time_s", "peak_MB");
  for (const auto& path : files) {
    const std::string name = std::filesystem::path(path).filename().string();
    if (!std::filesystem::exists(path)) {
      std::printf("%-30s skipped (absent)\n", name.c_str());
      continue;
    }
    try {
      const hsr::PointCloud cloud = hsr::read_points(path);
      double best = 1e300;
      hsr::SceneStructure s;
      for (int r = 0; r < repeat; ++r) {
        const double t0 = hsr::log::now_seconds();
        s = hsr::run_structure(cloud, params);
        best = std::min(best, hsr::log::now_seconds() - t0);
      }
      std::size_t assigned = 0, segs = 0, adj = 0;
      for (const auto& p : s.planes) { assigned += p.inliers.size(); segs += p.segments.size(); }
      for (const auto& a : s.adjacency) adj += a.size();
      std::printf("%-30s %8zu %9.4g %6zu %7.1f%% %6zu %6zu %6zu %9.3f %8.0f\n", name.c_str(), cloud.size(), s.spacing,
                  s.planes.size(), 100.0 * assigned / cloud.size(), segs, adj / 2, s.lines.size(), best,
                  hsr::log::peak_memory_mb());
    } catch (const hsr::Error& e) {
      std::printf("%-30s error: %s\n", name.c_str(), e.one_line().c_str());
    }
    std::fflush(stdout);
  }
  return 0;
}
