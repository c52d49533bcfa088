// The byte format of fuzz_pipeline: a tiny point cloud and a few pipeline parameters decoded from fuzzer
// bytes, and its inverse (the seed generator encodes synth scans with it).
//   byte 0  bits 0-1 partitioner (exhaustive, bsp, kinetic, hierarchical), bit 2 no recovery, bit 3 RANSAC
//   byte 1  low nibble: scale 10^((n mod 10) - 4); bit 4: coordinates offset by 1e6 (georeferenced-like)
//   byte 2  minimum plane size: 6 + (b mod 40) points
//   then 6 bytes per point (at most kMaxFuzzPoints): x, y, z as little-endian uint16, mapped to
//   [0, 10) * scale (+ offset). Missing trailing bytes are ignored.
#pragma once

#include "pipeline/pipeline.h"

#include <cstddef>
#include <cstdint>
#include <string>

namespace hsr::fuzz {

inline constexpr std::size_t kMaxFuzzPoints = 200;
inline constexpr std::size_t kFuzzHeaderBytes = 3;

struct FuzzCase {
  PointCloud cloud;
  PipelineParams params;
};

FuzzCase decode_fuzz_case(const std::uint8_t* data, std::size_t size);

/// Bytes that decode to (a quantised copy of) `cloud`, whose coordinates must lie in [0, 10) (clamped), with
/// header bytes `flags`, scale nibble 4 (scale 1) and minimum plane size byte `min_points_byte`.
std::string encode_fuzz_case(const PointCloud& cloud, std::uint8_t flags, std::uint8_t min_points_byte);

}  // namespace hsr::fuzz
