// Small inputs shared by several test suites: a unit cube mesh, an aerial synth scan with chosen extras.
#pragma once

#include "core/types.h"
#include "synth/synth.h"

#include <cstdint>
#include <string>

namespace hsr::test {

/// The unit cube [0,1]^3, faces outward (bottom, top, then the four sides).
inline PolygonMesh unit_cube() {
  PolygonMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  m.faces = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  return m;
}

/// An aerial synth scan (synth.h): ground 1/0/-1 (by the seed), trees N or -1 (by the seed), range noise (m).
inline SynthScan aerial_scan(const std::string& model, std::uint64_t seed, int ground, int trees, double noise = 0.03) {
  SynthParams p;
  p.seed = seed;
  p.aerial_ground = ground;
  p.aerial_trees = trees;
  p.aerial_range_noise = noise;
  return run_synth(model, p);
}

/// Signed volume of a closed mesh (its faces fanned from their first vertex; outward faces: positive).
inline double volume_of(const PolygonMesh& m) {
  double v = 0;
  for (const auto& f : m.faces)
    for (std::size_t i = 1; i + 1 < f.size(); ++i)
      v += m.vertices[f[0]].dot(m.vertices[f[i]].cross(m.vertices[f[i + 1]])) / 6.0;
  return v;
}

}  // namespace hsr::test
