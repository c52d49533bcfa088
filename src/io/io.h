// Stage 0: reading point clouds and meshes, writing meshes and point sets (DESIGN.md §1, stage 0).
//
// Formats (chosen by file extension, case-insensitive):
//   points: .ply (ascii, binary_little_endian, binary_big_endian; float/double; properties in any order;
//           extra properties ignored; nx/ny/nz optional), .xyz / .xyzn / .pwn / .txt (3 or 6 numbers per
//           line), .off (point set: faces ignored unless sampling), .las (1.2–1.4, uncompressed, point
//           formats 0–3 and 6–8, scale and offset applied).
//   meshes: .obj, .off, .ply with faces (polygons, triangulated by fan for sampling).
// Georeferenced input: if the bbox centre is far from the origin (|c| > 1e4 in any axis, or always for
// LAS), points are shifted so the bbox centre becomes the local origin; PointCloud::origin keeps the
// shift and every writer adds it back.
// Errors: hsr::Error with stage "io" and a one-line message naming the file (Status::FileNotFound,
// BadFormat for unknown/corrupt/truncated files, BadInput for zero points, NaN/inf, all points identical).
#pragma once

#include "core/types.h"

#include <array>
#include <cstdint>
#include <string>

namespace hsr {

struct ReadParams {
  /// If > 0 and the file holds a mesh with faces: sample this many points uniformly by area on the faces,
  /// each with its face normal (deterministic, seeded by `seed`). 0: use the vertices as points.
  std::size_t sample_count = 0;
  std::uint64_t seed = 1;
  /// Shift to a local origin when the bbox centre is farther than this from 0 in any axis (units of the
  /// file). LAS files are always shifted.
  double local_origin_threshold = 1e4;
};

/// Reads a point cloud. Normals are normalised to unit length; zero normals make the cloud normal-less.
PointCloud read_points(const std::string& path, const ReadParams& params = {});

/// Reads a polygon mesh (OBJ, OFF, PLY with a face element).
PolygonMesh read_mesh(const std::string& path);

enum class FileEncoding { Ascii, Binary };

/// Writes a polygon mesh (format from the extension: .obj, .ply, .off), adding mesh.origin back.
/// Atomic: written to a temporary file, then renamed. Doubles are written with 17 significant digits
/// (ascii) so a round trip is exact.
void write_mesh(const std::string& path, const PolygonMesh& mesh, FileEncoding encoding = FileEncoding::Ascii);

/// Writes a point set (.ply ascii/binary, .xyz / .xyzn text), with normals when present, and optional
/// per-point RGB colours (empty or one per point; PLY only). Atomic, origin added back.
void write_points(const std::string& path, const PointCloud& cloud, FileEncoding encoding = FileEncoding::Binary,
                  const std::vector<std::array<std::uint8_t, 3>>& colors = {});

/// Lower-case extension without the dot ("ply"), or "" if none.
std::string file_extension(const std::string& path);

}  // namespace hsr
