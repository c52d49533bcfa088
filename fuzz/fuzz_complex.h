// The byte format and the contract of fuzz_extraction: extraction -> writers -> eval on random exact cell
// complexes (built by the real partitioners from random polygons decoded from the bytes) and random
// labelings (issue 15). Shared with tests/reliability (its findings replayed as regression tests).
//   byte 0  bits 0-1 partitioner (exhaustive, bsp, kinetic, hierarchical); bit 2 merge_coplanar off;
//           bits 3-4 lambda (0, 0.05, 0.5, 1); bits 5-6 output format (obj, ply, off, obj)
//   byte 1  number of polygons: 1 + (b mod kMaxFuzzPolygons)
//   then 8 bytes per polygon: normal (3 bytes, each -3..3), centre (3 bytes, each on a 1/16 grid of
//           [0, 1]), radius (0.05 .. 0.8), corners (3 .. 8) and level (1..3) / phase; small integer
//           normals and grid centres make coplanar, parallel and concurrent planes frequent
//   then the labels: bit k of the remaining bytes (cycled; all inside when none) is the target label of
//           cell k. Each facet between a target-inside and a target-outside cell gets one inlier voting
//           for that (its centroid, normal from inside to outside), so the min-cut returns the target
//           labelling or one close to it, non-manifold ones included (the repair's input).
// Contract (check_extraction_case): run_extraction returns a mesh or throws Error(DegenerateInput);
// every face is simple (run_extraction proves it); a mesh without non-manifold edges or vertices is
// valid (closed, manifold, oriented, self-intersection free) unless rounding made a face touch itself,
// and its volume is the inside cells' exact volume; each writer's file reads back to the same mesh; eval
// runs on the written mesh and agrees with the validity of the original.
#pragma once

#include "extraction/extraction.h"
#include "partition/partition.h"

#include <cstddef>
#include <cstdint>
#include <string>

namespace hsr::fuzz {

inline constexpr std::size_t kMaxFuzzPolygons = 8;

struct ComplexCase {
  PartitionInput partition_input;
  PartitionParams partition;
  ExtractionParams extraction;
  std::string format = "obj";          ///< mesh writer: obj, ply or off
  std::vector<std::uint8_t> labels;    ///< label bytes (bit k: cell k inside), may be empty
};

ComplexCase decode_complex_case(const std::uint8_t* data, std::size_t size);

/// Runs the case and checks the contract above; returns "" or what broke it. `scratch_dir` receives the
/// written meshes (one file per format, overwritten).
std::string check_extraction_case(const ComplexCase& c, const std::string& scratch_dir);

}  // namespace hsr::fuzz
