#include "fuzz_cloud.h"

#include <algorithm>
#include <cmath>

namespace hsr::fuzz {

FuzzCase decode_fuzz_case(const std::uint8_t* data, std::size_t size) {
  FuzzCase c;
  if (size < kFuzzHeaderBytes) return c;
  const std::uint8_t flags = data[0], scale_byte = data[1], min_byte = data[2];
  static const Partitioner methods[4] = {Partitioner::Exhaustive, Partitioner::Bsp, Partitioner::Kinetic,
                                         Partitioner::Hierarchical};
  c.params.partition.method = methods[flags & 3];
  c.params.partition.threads = 1;  // libFuzzer wants one thread; results do not depend on it
  c.params.hulls.recovered_planes = (flags & 4) == 0;
  c.params.structure.detector = (flags & 8) ? PlaneDetector::Ransac : PlaneDetector::RegionGrowing;
  c.params.structure.min_region_points = 6 + min_byte % 40;
  c.params.eval.mesh_samples = 2000;  // keeps one run fast; validity checks do not depend on it
  const double scale = std::pow(10.0, static_cast<int>(scale_byte & 15) % 10 - 4);
  const double offset = (scale_byte & 16) ? 1e6 : 0.0;
  const std::size_t n = std::min(kMaxFuzzPoints, (size - kFuzzHeaderBytes) / 6);
  c.cloud.points.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* p = data + kFuzzHeaderBytes + 6 * i;
    Vec3 v;
    for (int k = 0; k < 3; ++k) v[k] = (p[2 * k] | (p[2 * k + 1] << 8)) * (10.0 / 65536.0) * scale + offset;
    c.cloud.points.push_back(v);
  }
  return c;
}

std::string encode_fuzz_case(const PointCloud& cloud, std::uint8_t flags, std::uint8_t min_points_byte) {
  std::string out;
  out.push_back(static_cast<char>(flags));
  out.push_back(static_cast<char>(4));
  out.push_back(static_cast<char>(min_points_byte));
  const std::size_t n = std::min(kMaxFuzzPoints, cloud.points.size());
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      const double q = std::clamp(std::round(cloud.points[i][k] * 6553.6), 0.0, 65535.0);
      const auto u = static_cast<std::uint16_t>(q);
      out.push_back(static_cast<char>(u & 0xFF));
      out.push_back(static_cast<char>(u >> 8));
    }
  return out;
}

}  // namespace hsr::fuzz
