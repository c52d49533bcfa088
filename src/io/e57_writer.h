// A small E57 (ASTM E2807) writer, for the tests and the fuzz seeds: several scans with their poses,
// cartesian or spherical coordinates (8-byte floats, or bit-packed scaled integers), structured scans
// (rowIndex / columnIndex and an invalid state per point), intensity (4-byte floats with intensityLimits 0-1)
// and colour (bit-packed 8-bit integers). Pages, checksums, sections and packets as io/e57.h's reader reads
// them. Not a general E57 writer: no images, no other nodes than those.
#pragma once

#include "core/types.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace hsr {

struct E57WriteScan {
  std::string name = "scan";
  std::array<double, 4> rotation{1, 0, 0, 0};  ///< pose quaternion w, x, y, z
  Vec3 translation = Vec3::Zero();              ///< pose translation (the scanner's position)
  /// Per point, in the scan's own frame: x, y, z, or (spherical) range, azimuth, elevation (radians).
  std::vector<Vec3> points;
  bool spherical = false;
  /// > 0: coordinates as ScaledInteger of this scale (units per step, bit-packed); 0: Float, 8 bytes.
  double scaled_integer_scale = 0;
  /// Empty, or per point the invalid state (0 valid, 1 direction only, 2 invalid) and, for a structured scan,
  /// rowIndex / columnIndex (both empty or both per point).
  std::vector<std::uint8_t> invalid_state;
  std::vector<std::uint32_t> row, column;
  std::vector<float> intensity;                          ///< empty, or per point in [0, 1]
  std::vector<std::array<std::uint8_t, 3>> color;        ///< empty, or per point
};

struct E57WriteOptions {
  /// Largest chunk of one bytestream per data packet (bytes); small values spread a scan over many packets.
  std::size_t max_chunk_bytes = 8192;
};

/// The bytes of an E57 file holding `scans` (in /data3D order). Throws hsr::Error (stage "io", BadInput) on
/// vectors whose sizes disagree with the points.
std::string e57_file_bytes(const std::vector<E57WriteScan>& scans, const E57WriteOptions& options = {});

/// Writes e57_file_bytes() to `path` (atomic).
void write_e57(const std::string& path, const std::vector<E57WriteScan>& scans, const E57WriteOptions& options = {});

}  // namespace hsr
