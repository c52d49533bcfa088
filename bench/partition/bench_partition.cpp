// Partition benchmark: seconds, peak memory and complex sizes of the exhaustive, bsp, kinetic and
// hierarchical partitioners on random rectangle sets in the unit box (DESIGN.md §2).
//
// usage: bench_partition [--sizes 50,100,200] [--methods bsp,exhaustive,kinetic,hierarchical]
//                        [--exhaustive-max 50] [--seed 1] [--axis-fraction 0] [--max-per-domain 20]
//                        [--threads 0] [--max-crossings 8] [--exact-volumes]
//                        [--half-sizes 0.05,0.3] [--validate] [--verbose] [--adjacency bbox|touch|none]
//                        [--levels 0] [--set key=value,...] [--input FILE,...] [--repeat N]
// Cells get no exact volume unless --exact-volumes (as in the pipeline: PartitionParams::exact_volumes).
// Prints one row per (size, method) and, per method, the fitted exponent e of cpu seconds ~ polygons^e.
// The real scans: bench/partition/real_files.sh.
// Hierarchical input: each rectangle gets a random level (1-3, uniform) and speed (uniform in [0.5, 1]);
// two rectangles of one level are "adjacent" when their bounding boxes overlap (--adjacency bbox, a stand-in
// for the structure stage's adjacency graph), when they intersect (touch: the structure stage's adjacency,
// inliers of both planes near each other, seen on polygons) or never (none); --levels 0 puts every rectangle
// on level 1. Kinetic ignores levels and speeds. --set: PartitionParams overrides (partition_options.h).
// Rectangles: centre uniform in [0,1]^3, half sizes uniform in [0.05, 0.3] (--half-sizes min,max), normal
// uniform on the sphere, or axis-aligned with probability --axis-fraction (CAD-like scenes). Peak memory is the process's VmHWM
// after the run (monotone: runs go from small to large). cpu_s is process CPU time (std::clock), steadier
// than wall time on a shared machine. Progress lines go to stderr.
// --input: instead of random rectangles, partition saved inputs (partition_input.json of `hsr reconstruct --dump`,
// in the order given; the exponent is then fitted over their polygon counts); --repeat N: N runs each, the row
// is the one with the least CPU time. "peak_MB" is then the growth of the process's peak (VmHWM) during the
// partition (the first run), besides the loaded inputs.
#include "core/error.h"
#include "core/log.h"
#include "partition/partition.h"
#include "partition_options.h"

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>

using namespace hsr;

namespace {

double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * (static_cast<double>(rng() >> 11) * 0x1.0p-53);
}

std::vector<ConvexPolygon> random_rectangles(std::uint64_t seed, int count, double axis_fraction, double min_half,
                                             double max_half) {
  std::mt19937_64 rng(seed);
  std::vector<ConvexPolygon> out;
  for (int i = 0; i < count; ++i) {
    Vec3 n;
    if (uniform(rng, 0, 1) < axis_fraction) {
      n = Vec3::Zero();
      n[static_cast<int>(rng() % 3)] = 1;
    } else {
      do n = Vec3(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
      while (n.norm() < 1e-2 || n.norm() > 1);
      n.normalize();
    }
    const Vec3 c(uniform(rng, 0, 1), uniform(rng, 0, 1), uniform(rng, 0, 1));
    const Vec3 u = n.unitOrthogonal(), v = n.cross(u);
    const double hu = uniform(rng, min_half, max_half), hv = uniform(rng, min_half, max_half);
    ConvexPolygon p;
    p.plane_id = i;
    p.level = 1 + static_cast<int>(rng() % 3);
    p.speed = uniform(rng, 0.5, 1.0);
    p.plane.normal = n;
    p.plane.offset = -n.dot(c);
    p.vertices = {c - hu * u - hv * v, c + hu * u - hv * v, c + hu * u + hv * v, c - hu * u + hv * v};
    out.push_back(p);
  }
  return out;
}

// Segment of convex polygon `p` on the plane of `q` as an interval of the parameter along `dir` (empty: lo > hi).
std::pair<double, double> cut_interval(const ConvexPolygon& p, const ConvexPolygon& q, const Vec3& dir) {
  double lo = 1e300, hi = -1e300;
  const std::size_t n = p.vertices.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& a = p.vertices[i];
    const Vec3& b = p.vertices[(i + 1) % n];
    const double sa = q.plane.normal.dot(a) + q.plane.offset, sb = q.plane.normal.dot(b) + q.plane.offset;
    if ((sa < 0) == (sb < 0)) continue;
    const Vec3 x = a + (sa / (sa - sb)) * (b - a);
    lo = std::min(lo, x.dot(dir));
    hi = std::max(hi, x.dot(dir));
  }
  return {lo, hi};
}

// Two rectangles of one level are adjacent when they intersect (their cuts on the common line overlap): the
// structure stage's adjacency (inliers of both planes are neighbours) seen on polygons.
std::vector<std::pair<int, int>> touch_adjacency(const std::vector<ConvexPolygon>& polys) {
  std::vector<std::pair<int, int>> out;
  for (std::size_t i = 0; i < polys.size(); ++i)
    for (std::size_t j = i + 1; j < polys.size(); ++j) {
      if (polys[i].level != polys[j].level) continue;
      const Vec3 dir = polys[i].plane.normal.cross(polys[j].plane.normal);
      if (dir.norm() < 1e-9) continue;
      const auto a = cut_interval(polys[i], polys[j], dir), b = cut_interval(polys[j], polys[i], dir);
      if (a.first <= a.second && b.first <= b.second && a.first <= b.second && b.first <= a.second)
        out.emplace_back(polys[i].plane_id, polys[j].plane_id);
    }
  return out;
}

std::vector<std::pair<int, int>> bbox_adjacency(const std::vector<ConvexPolygon>& polys) {
  std::vector<BBox> boxes;
  for (const auto& p : polys) {
    BBox b;
    for (const Vec3& v : p.vertices) b.extend(v);
    boxes.push_back(b);
  }
  std::vector<std::pair<int, int>> out;
  for (std::size_t i = 0; i < polys.size(); ++i)
    for (std::size_t j = i + 1; j < polys.size(); ++j)
      if (polys[i].level == polys[j].level && !((boxes[i].min.array() > boxes[j].max.array()).any() ||
                                                 (boxes[j].min.array() > boxes[i].max.array()).any()))
        out.emplace_back(polys[i].plane_id, polys[j].plane_id);
  return out;
}

// Least-squares slope of log(cpu seconds) against log(polygons), per method.
void print_exponents(const std::map<Partitioner, std::vector<std::pair<double, double>>>& timings) {
  for (const auto& [m, pts] : timings) {
    if (pts.size() < 2) continue;
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const auto& [n, t] : pts) {
      const double x = std::log(n), y = std::log(std::max(t, 1e-6));
      sx += x; sy += y; sxx += x * x; sxy += x * y;
    }
    const double k = static_cast<double>(pts.size());
    std::printf("fitted exponent %-11s %.2f  (cpu seconds ~ polygons^e over %zu sizes)\n", partitioner_name(m),
                (k * sxy - sx * sy) / (k * sxx - sx * sx), pts.size());
  }
}

// --input: the saved partition inputs, each with every method.
int run_inputs(const std::vector<std::string>& files, const std::vector<Partitioner>& methods,
               const PartitionParams& overrides, int threads, bool exact_volumes, bool check, int repeat) {
  std::map<Partitioner, std::vector<std::pair<double, double>>> timings;
  std::printf("%-11s %6s %9s %9s %8s %9s %9s %9s %7s  %s\n", "method", "polys", "wall_s", "cpu_s", "peak_MB", "cells",
              "facets", "vertices", "valid", "input");
  for (const std::string& file : files) {
    PartitionInput in;
    try {
      std::ifstream f(file);
      if (!f) throw Error(Status::BadInput, "bench", "cannot read " + file);
      from_json(nlohmann::json::parse(f), in);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench_partition: %s: %s\n", file.c_str(), e.what());
      return 2;
    }
    for (Partitioner m : methods) {
      PartitionParams params = overrides;
      params.method = m;
      params.threads = threads;
      params.exact_volumes = exact_volumes;
      double best_wall = 0, best_cpu = -1, peak_growth = 0;
      CellComplex cx;
      for (int r = 0; r < repeat; ++r) {
        const double peak_before = log::peak_memory_mb();
        const double t0 = log::now_seconds();
        const std::clock_t c0 = std::clock();
        cx = run_partition(in, params);
        const double wall = log::now_seconds() - t0;
        const double cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
        if (r == 0) peak_growth = log::peak_memory_mb() - peak_before;
        if (best_cpu < 0 || cpu < best_cpu) { best_cpu = cpu; best_wall = wall; }
      }
      std::string valid = "-";
      if (check) valid = validate(cx, &in.polygons).ok ? "ok" : "FAILED";
      std::printf("%-11s %6zu %9.3f %9.3f %8.1f %9zu %9zu %9zu %7s  %s\n", partitioner_name(m), in.polygons.size(),
                  best_wall, best_cpu, peak_growth, cx.cells.size(), cx.facets.size(), cx.vertices.size(), valid.c_str(),
                  file.c_str());
      std::fflush(stdout);
      timings[m].emplace_back(static_cast<double>(in.polygons.size()), best_cpu);
    }
  }
  print_exponents(timings);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> sizes = {50, 100, 200};
  int exhaustive_max = 50;
  std::uint64_t seed = 1;
  double axis_fraction = 0;
  double min_half = 0.05, max_half = 0.3;
  bool check = false;
  bool exact_volumes = false;
  int threads = 0;
  std::vector<Partitioner> methods = {Partitioner::Bsp, Partitioner::Exhaustive};
  std::string adjacency_kind = "bbox";
  std::vector<std::string> inputs;
  int repeat = 1;
  PartitionParams overrides;
  bool levels = true;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) { std::fprintf(stderr, "missing value for %s\n", a.c_str()); std::exit(2); }
      return argv[++i];
    };
    if (a == "--sizes") {
      sizes.clear();
      std::stringstream ss(next());
      std::string item;
      while (std::getline(ss, item, ',')) sizes.push_back(std::stoi(item));
    } else if (a == "--exhaustive-max") exhaustive_max = std::stoi(next());
    else if (a == "--seed") seed = std::stoull(next());
    else if (a == "--axis-fraction") axis_fraction = std::stod(next());
    else if (a == "--validate") check = true;
    else if (a == "--exact-volumes") exact_volumes = true;
    else if (a == "--half-sizes") {
      const std::string v = next();
      const auto comma = v.find(',');
      min_half = std::stod(v.substr(0, comma));
      max_half = std::stod(v.substr(comma + 1));
    }
    else if (a == "--verbose") log::set_level(log::Level::Verbose);
    else if (a == "--adjacency") adjacency_kind = next();
    else if (a == "--set") {
      std::stringstream ss(next());
      std::string item;
      while (std::getline(ss, item, ',')) {
        const auto eq = item.find('=');
        if (eq == std::string::npos || !bench::apply_partition_option(overrides, item.substr(0, eq), std::stoi(item.substr(eq + 1)))) {
          std::fprintf(stderr, "bad --set item %s\n", item.c_str());
          return 2;
        }
      }
    }
    else if (a == "--levels") levels = std::stoi(next()) != 0;
    else if (a == "--input") {
      std::stringstream ss(next());
      std::string item;
      while (std::getline(ss, item, ',')) inputs.push_back(item);
    }
    else if (a == "--repeat") repeat = std::max(1, std::stoi(next()));
    else if (a == "--max-per-domain") overrides.max_polygons_per_domain = std::stoi(next());
    else if (a == "--threads") threads = std::stoi(next());
    else if (a == "--max-crossings") overrides.max_crossings = std::stoi(next());
    else if (a == "--methods") {
      methods.clear();
      std::stringstream ss(next());
      std::string item;
      while (std::getline(ss, item, ',')) methods.push_back(parse_partitioner(item));
    }
    else { std::fprintf(stderr, "unknown option %s\n", a.c_str()); return 2; }
  }
  if (!inputs.empty()) return run_inputs(inputs, methods, overrides, threads, exact_volumes, check, repeat);
  BBox box;
  box.extend(Vec3(0, 0, 0));
  box.extend(Vec3(1, 1, 1));
  std::map<Partitioner, std::vector<std::pair<double, double>>> timings;  // method -> (polygons, cpu seconds)
  std::printf("%-11s %6s %9s %9s %8s %9s %9s %9s %7s\n", "method", "polys", "wall_s", "cpu_s", "peak_MB", "cells",
              "facets", "vertices", "valid");
  for (int n : sizes) {
    auto polys = random_rectangles(seed * 7919 + n, n, axis_fraction, min_half, max_half);
    if (!levels)
      for (ConvexPolygon& p : polys) p.level = 1;
    const auto adjacency = adjacency_kind == "bbox"    ? bbox_adjacency(polys)
                           : adjacency_kind == "touch" ? touch_adjacency(polys)
                                                       : std::vector<std::pair<int, int>>{};
    for (Partitioner m : methods) {
      if (m == Partitioner::Exhaustive && n > exhaustive_max) continue;
      PartitionParams params = overrides;
      params.method = m;
      params.threads = threads;
      params.exact_volumes = exact_volumes;
      const double t0 = log::now_seconds();
      const std::clock_t c0 = std::clock();
      CellComplex cx = run_partition({polys, box, adjacency}, params);
      const double seconds = log::now_seconds() - t0;
      const double cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
      std::string valid = "-";
      if (check) valid = validate(cx, &polys).ok ? "ok" : "FAILED";
      std::printf("%-11s %6d %9.3f %9.3f %8.1f %9zu %9zu %9zu %7s\n", partitioner_name(m), n, seconds, cpu,
                  log::peak_memory_mb(), cx.cells.size(), cx.facets.size(), cx.vertices.size(), valid.c_str());
      std::fflush(stdout);
      timings[m].emplace_back(n, cpu);
    }
  }
  print_exponents(timings);
  return 0;
}
