// LAZ decode speed of hsr (bench/laz/run.sh runs it beside laz-perf): for each file, the best of R runs of
// (a) decoding every point record (io_detail::read_las_point_records: the LAZ decoder alone, records as
// the LAS file would hold them) and (b) read_points (decoder + record parser + cloud). Prints points per
// second and an FNV-1a hash of all records, which laz-perf's run prints too (same bytes decoded). Threads:
// HSR_THREADS (the decoder's chunks run in parallel).
#include "core/error.h"
#include "core/log.h"
#include "io/io.h"
#include "io/las_internal.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

std::uint64_t fnv1a(const std::vector<unsigned char>& bytes) {
  std::uint64_t h = 14695981039346656037ull;  // FNV-1a 64 offset basis
  for (unsigned char b : bytes) h = (h ^ b) * 1099511628211ull;
  return h;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: laz_decode_bench REPEATS FILE...\n");
    return 2;
  }
  hsr::log::set_level(hsr::log::Level::Quiet);
  const int repeats = std::atoi(argv[1]);
  const char* threads = std::getenv("HSR_THREADS");
  try {
    for (int f = 2; f < argc; ++f) {
      const std::string path = argv[f];
      std::vector<unsigned char> records;
      double best_decode = 1e300, best_read = 1e300;
      std::uint64_t count = 0;
      for (int r = 0; r < repeats; ++r) {
        auto t = std::chrono::steady_clock::now();
        count = hsr::io_detail::read_las_point_records(path, records).count;
        best_decode = std::min(best_decode, seconds_since(t));
        t = std::chrono::steady_clock::now();
        const hsr::PointCloud cloud = hsr::read_points(path);
        best_read = std::min(best_read, seconds_since(t));
        if (cloud.size() != count) throw std::runtime_error("count mismatch");
      }
      std::printf("hsr\t%s\tthreads=%s\tpoints=%llu\tdecode_s=%.4f\tdecode_pts_per_s=%.0f\tread_points_s=%.4f\tread_pts_per_s=%.0f\tfnv1a=%016llx\n",
                  path.c_str(), threads ? threads : "all", static_cast<unsigned long long>(count), best_decode,
                  count / best_decode, best_read, count / best_read, static_cast<unsigned long long>(fnv1a(records)));
    }
  } catch (const hsr::Error& e) {
    std::fprintf(stderr, "hsr: %s\n", e.one_line().c_str());
    return 1;
  }
  return 0;
}
