// Internal to stage io: the raw geometry each format reader returns (global coordinates, not yet
// validated or shifted), and small helpers shared by the readers and writers. Not a public header.
#pragma once

#include "core/error.h"
#include "core/types.h"
#include "io/e57.h"

#include <array>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace hsr::io_detail {

/// What a format reader hands back: coordinates exactly as stored in the file (global), normals if the
/// file has them (one per point, not yet checked), faces if the file has a face element.
struct RawGeometry {
  std::vector<Vec3> points;
  std::vector<Vec3> normals;
  std::vector<std::vector<std::uint32_t>> faces;
  bool always_shift = false;  ///< LAS: georeferenced by construction, always shifted to a local origin
  PointAttributes attributes;  ///< LAS: per-point fields (PointCloud::attributes)
  std::string crs;             ///< LAS: PointCloud::crs
  std::vector<Vec3> scanners;  ///< E57: each scan's scanner position (its pose translation), file coordinates
};

/// Throws hsr::Error(status, "io", "'<path>': <what>"). (Inline: the modules' readers use it too, core/module.h.)
[[noreturn]] inline void fail(Status status, const std::string& path, const std::string& what) {
  throw Error(status, "io", "'" + path + "': " + what);
}

/// Whole file as bytes; FileNotFound if missing, not a regular file or unreadable.
std::string read_whole_file(const std::string& path);

/// Parses a double (optional leading '+'; "nan"/"inf" accepted, rejected later by validation). (Inline: the
/// modules' readers use it too, core/module.h.)
inline bool parse_double(std::string_view tok, double& value) {
  if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
  if (tok.empty()) return false;
  const auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), value);
  return ec == std::errc() && ptr == tok.data() + tok.size();
}

/// Appends v formatted like printf("%.17g") (exact round trip).
void append_double(std::string& out, double v);

// Little-/big-endian scalar encoding independent of the host byte order.
bool host_is_little_endian();
inline void swap_bytes(unsigned char* p, std::size_t n) {
  for (std::size_t i = 0; i < n / 2; ++i) std::swap(p[i], p[n - 1 - i]);
}
template <class T>
T load_scalar(const unsigned char* p, bool little_endian) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (little_endian != host_is_little_endian()) swap_bytes(b, sizeof(T));
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}
template <class T>
void store_scalar(std::string& out, T v, bool little_endian) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (little_endian != host_is_little_endian()) swap_bytes(b, sizeof(T));
  out.append(reinterpret_cast<const char*>(b), sizeof(T));
}

RawGeometry read_ply(const std::string& path);
RawGeometry read_las(const std::string& path);
RawGeometry read_e57(const std::string& path, const E57Limits& limits);

/// PLY body + header for a point set or mesh in global coordinates (vertices + origin). `normals` and
/// `colors` may be empty; `faces` null for a point set. Throws BadInput (naming `path`) on bad face indices.
std::string format_ply(const std::string& path, const std::vector<Vec3>& vertices, const Vec3& origin,
                       const std::vector<Vec3>& normals, const std::vector<std::array<std::uint8_t, 3>>& colors,
                       const std::vector<std::vector<std::uint32_t>>* faces, bool binary);

}  // namespace hsr::io_detail
