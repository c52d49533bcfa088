// bench_structure [--detector rg|ransac] [--repeat N] [--verbose] [--params JSON] [--dump DIR] [files...]
// Times run_structure (stage 1) on each file (default: the real scans of the shared data folder) and prints
// one table row per file: points, spacing, planes, assigned points, segments, adjacent pairs, lines, the
// best wall time over the repeats and the peak memory. Files that are absent are skipped. --params: a JSON
// object of StructureParams fields ('{"min_region_points": 12}'); --dump: write_structure_dump per file
// into DIR/<file name>.
#include "structure/structure.h"

#include "core/error.h"
#include "core/log.h"
#include "io/io.h"

#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  hsr::StructureParams params;
  int repeat = 1;
  bool verbose = false;
  std::string dump;
  std::FILE* planes_csv = nullptr;  // --planes-csv FILE: one row per plane (size, area, flatness)
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--detector" && i + 1 < argc) {
      params.detector = std::string(argv[++i]) == "ransac" ? hsr::PlaneDetector::Ransac : hsr::PlaneDetector::RegionGrowing;
    } else if (a == "--verbose") {
      verbose = true;
    } else if (a == "--params" && i + 1 < argc) {
      hsr::from_json(nlohmann::json::parse(argv[++i]), params);
    } else if (a == "--planes-csv" && i + 1 < argc) {
      planes_csv = std::fopen(argv[++i], "w");
      if (planes_csv) std::fprintf(planes_csv, "file,plane,inliers,area_r2,rms_r,normal_dev_deg,width_r,length_r\n");
    } else if (a == "--dump" && i + 1 < argc) {
      dump = argv[++i];
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
      if (!dump.empty()) hsr::write_structure_dump(cloud, s, dump + "/" + name);
      if (planes_csv)
        for (std::size_t k = 0; k < s.planes.size(); ++k) {
          const hsr::DetectedPlane& p = s.planes[k];
          double sq = 0, dev = 0;
          for (int i : p.inliers) {
            sq += std::pow(p.plane.signed_distance(cloud.points[i]), 2);
            dev += std::acos(std::min(1.0, std::abs(s.normals[i].normalized().dot(p.plane.normal)))) * 180 / M_PI;
          }
          const double n = static_cast<double>(p.inliers.size());
          // Extent in the plane: sqrt(12 x the 2D covariance's eigenvalues) (a uniform rectangle's sides).
          Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
          Eigen::Vector2d mean = Eigen::Vector2d::Zero();
          for (int i : p.inliers) mean += p.to_2d(cloud.points[i]);
          mean /= n;
          for (int i : p.inliers) {
            const Eigen::Vector2d d = p.to_2d(cloud.points[i]) - mean;
            cov += d * d.transpose() / n;
          }
          Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov);
          std::fprintf(planes_csv, "%s,%zu,%zu,%.2f,%.4f,%.3f,%.2f,%.2f\n", name.c_str(), k, p.inliers.size(),
                       p.area / (s.spacing * s.spacing), std::sqrt(sq / n) / s.spacing, dev / n,
                       std::sqrt(12 * std::max(0.0, es.eigenvalues()(0))) / s.spacing,
                       std::sqrt(12 * std::max(0.0, es.eigenvalues()(1))) / s.spacing);
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
  if (planes_csv) std::fclose(planes_csv);
  return 0;
}
