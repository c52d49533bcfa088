// Random convex polygon sets for partition stress (tests/reliability and bench/stress): seeded, header-only.
// A set mixes the configurations that break partitions: random planes, axis-aligned planes, exact duplicates
// (coplanar polygons), nearly parallel planes, planes through a common point, polygons on or beyond the box.
#pragma once

#include "partition/partition.h"

#include <cmath>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

namespace hsr::stress {

inline double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }
inline double uniform(std::mt19937_64& rng, double a, double b) { return a + (b - a) * uniform01(rng); }

/// One random partition input with `count` polygons in the unit box; deterministic for a seed.
inline PartitionInput random_polygon_set(std::uint64_t seed, int count) {
  std::mt19937_64 rng(seed);
  PartitionInput in;
  in.points_bbox.min = Vec3::Zero();
  in.points_bbox.max = Vec3::Ones();
  const Vec3 common(uniform01(rng), uniform01(rng), uniform01(rng));
  for (int i = 0; i < count; ++i) {
    ConvexPolygon p;
    p.plane_id = i;
    Vec3 centre(uniform01(rng), uniform01(rng), uniform01(rng));
    Vec3 n;
    const int kind = static_cast<int>(rng() % 6);
    if (kind == 0) {
      n = Vec3::Unit(static_cast<int>(rng() % 3));                        // axis-aligned
    } else if (kind == 1 && i > 0) {
      const ConvexPolygon& q = in.polygons[rng() % in.polygons.size()];   // nearly parallel to an earlier one
      n = (q.plane.normal + 1e-4 * Vec3(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1))).normalized();
    } else if (kind == 2 && i > 0) {
      const ConvexPolygon& q = in.polygons[rng() % in.polygons.size()];   // exactly coplanar with an earlier one
      n = q.plane.normal;
      centre = q.vertices.front() + 0.2 * (q.vertices.back() - q.vertices.front());
    } else {
      n = Vec3(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
      if (n.norm() < 1e-3) n = Vec3::UnitZ();
      n.normalize();
      if (kind == 3) centre = common;                                      // many planes through one point
    }
    p.plane.normal = n;
    p.plane.offset = -n.dot(centre);
    const Vec3 u = n.unitOrthogonal(), v = n.cross(u);
    const double radius = uniform(rng, 0.05, 0.8);  // large ones cross the box sides
    const int corners = 3 + static_cast<int>(rng() % 6);
    const double phase = uniform(rng, 0, 2 * M_PI);
    for (int k = 0; k < corners; ++k) {
      const double a = phase + 2 * M_PI * k / corners;
      p.vertices.push_back(centre + radius * (std::cos(a) * u + std::sin(a) * v));
    }
    p.level = 1 + static_cast<int>(rng() % 3);
    p.speed = uniform(rng, 0.5, 1.0);
    in.polygons.push_back(std::move(p));
  }
  for (int i = 0; i < count; ++i)
    for (int j = i + 1; j < count; ++j)
      if (rng() % 3 == 0) in.adjacent_planes.emplace_back(i, j);
  return in;
}

inline const std::vector<Partitioner>& all_partitioners() {
  static const std::vector<Partitioner> all = {Partitioner::Exhaustive, Partitioner::Bsp, Partitioner::Kinetic,
                                               Partitioner::Hierarchical};
  return all;
}

}  // namespace hsr::stress
