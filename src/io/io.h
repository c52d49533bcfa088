// Stage 0: reading point clouds and meshes, writing meshes and point sets (DESIGN.md §1, stage 0).
//
// Formats (chosen by file extension, case-insensitive; LAS and LAZ by content: a file starting with the LAS
// signature "LASF" is read as LAS whatever its name, and the point format's compression bit says LAZ):
//   points: .ply (ascii, binary_little_endian, binary_big_endian; any scalar type char/uchar/short/ushort/
//           int/uint/float/double or int8/uint8/.../float64; properties in any order; extra properties,
//           list properties and extra elements skipped; nx/ny/nz optional), .xyz / .xyzn / .pwn / .txt / .pts
//           (3 or 6 numbers per line, decided by the first data line, extra columns ignored, '#' lines and a
//           leading single-number count line skipped, commas allowed as separators), .off ([ST][C][N]OFF;
//           faces ignored unless sampling), .obj (vertices, or faces when sampling), .las / .laz (LAS 1.0–1.4,
//           point formats 0–10, scale and offset applied; uncompressed or LASzip-compressed, COPC included:
//           laz.cpp; keeps PointCloud::attributes and ::crs), .e57 (ASTM E2807: every scan turned by its pose
//           into one cloud, invalid points dropped, intensity and colour kept in PointCloud::attributes; each
//           scan's pose translation is a scanner position: io/e57.h, docs/guide/formats.md).
//   meshes: .obj (v, f with v / v/vt / v/vt/vn / v//vn and negative indices), .off, .ply with a face element
//           (vertex_indices or vertex_index list), .city.json / .city.jsonl holding one Building (io/cityjson.h).
//           Consecutive repeated indices are merged; faces left with
//           fewer than 3 distinct vertices are dropped with a warning. Sampling fan-triangulates polygons.
// Georeferenced input: if the bbox centre is far from the origin (|c| > ReadParams::local_origin_threshold
// in any axis, or always for LAS), points are shifted to a local origin; PointCloud::origin keeps the shift
// and every writer adds it back. The origin is the bbox centre rounded to an integer, per axis, and an axis
// is shifted only when that shift is exact for every coordinate (all values within a factor 2 of the
// origin: Sterbenz), or when its centre is itself beyond the threshold. So local + origin gives the file's
// values back bit for bit in every usual case (UTM tiles, small scenes far from 0).
// Writers: PLY vertices and normals as double (a binary round trip is exact), ascii numbers with 17
// significant digits; all writes are atomic (core/atomic_file.h) and input is validated before anything
// is written (bad face index, non-finite coordinate: BadInput, no file created).
// Errors: hsr::Error with stage "io" and a one-line message naming the file (Status::FileNotFound,
// BadFormat for unknown/corrupt/truncated files or counts not matching the data, BadInput for zero points,
// NaN/inf coordinates or normals, all points identical). A zero-length normal drops all normals (warning).
#pragma once

#include "core/types.h"
#include "io/e57.h"

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace hsr {

struct ReadParams {
  /// If > 0 and the file holds a mesh with faces: sample this many points uniformly by area on the faces,
  /// each with its face normal (deterministic, seeded by `seed`). 0: use the vertices as points.
  std::size_t sample_count = 0;
  std::uint64_t seed = 1;
  /// Shift to a local origin when the bbox centre is farther than this from 0 in any axis (units of the
  /// file). LAS files are always shifted.
  double local_origin_threshold = 1e4;
  /// What an E57 file may hold before it is refused with one line (io/e57.h).
  E57Limits e57;
};

/// Reads a point cloud. Normals are normalised to unit length; zero normals make the cloud normal-less.
PointCloud read_points(const std::string& path, const ReadParams& params = {});

/// read_points() that also returns the scanner positions the file records, in file coordinates (add nothing,
/// subtract the cloud's origin for local ones): one per E57 scan (its pose translation), in scan order;
/// empty for the other formats.
PointCloud read_points(const std::string& path, const ReadParams& params, std::vector<Vec3>& scanners);

/// A run of consecutive points of a file, as read_point_chunks hands them on.
struct PointChunk {
  std::uint64_t first = 0;      ///< the index in the file of the run's first point
  std::vector<Vec3> points;     ///< file coordinates (LAS: X * scale + offset), not shifted to a local origin
  PointAttributes attributes;   ///< as read_points keeps them (LAS/LAZ); empty for other formats
};

/// Points in a chunk of read_point_chunks unless told otherwise.
constexpr std::size_t kPointChunk = std::size_t{1} << 16;

/// Streams the points of a file in file order, in runs of at most `chunk_points` (>= 1): the points and
/// attributes read_points gives, in file coordinates (read_points' point i + its origin). LAS and LAZ (COPC
/// included) are decoded run by run through the one LAS/LAZ decoder: memory is one run and, for LAZ, one
/// batch of decoded chunks, whatever the file's size. Other formats are read whole (read_points; their
/// points are its local points + origin). Returns the file's CRS (PointCloud::crs). Throws as read_points
/// does (non-finite coordinates: before the run holding them is handed on; zero points or all points
/// identical: after the last run), so a caller keeps nothing of a file that throws.
std::string read_point_chunks(const std::string& path, const std::function<void(const PointChunk&)>& sink,
                              std::size_t chunk_points = kPointChunk);

/// A run of consecutive points of a file that can be read without the others (read_point_parts).
struct PointPart {
  std::uint64_t first = 0;  ///< the index in the file of its first point
  std::uint64_t count = 0;  ///< its points
};

/// Points of a part of an uncompressed LAS file: what one seek skips or one read takes (LAZ: its chunks, as
/// the writer cut them, commonly 50,000 points).
constexpr std::uint64_t kLasPartPoints = std::uint64_t{1} << 16;

/// The parts of a point file, in file order, covering every point once: a LAZ file's chunks (COPC: its
/// octree's nodes; one part for a pointwise stream without chunks), an uncompressed LAS file's runs of
/// kLasPartPoints records, any other format one part (it is read whole). Reads the header and, for LAZ, the
/// chunk table; no point. Throws as read_points does for a malformed header or chunk table.
std::vector<PointPart> point_parts(const std::string& path);

/// read_point_chunks of the parts `wanted` names only (`wanted[i]` for point_parts(path)[i]; its size must be
/// theirs): a LAZ chunk not wanted is neither read nor decoded, an uncompressed part is seeked over, another
/// format is read whole when any part is wanted. Runs never span two parts; chunk.first is the file index of a
/// run's first point. Throws as read_point_chunks does, except that a file of zero points or of identical
/// points is refused only when every part is wanted (a caller reading some parts has read the whole once).
std::string read_point_parts(const std::string& path, const std::vector<char>& wanted, const std::function<void(const PointChunk&)>& sink,
                             std::size_t chunk_points = kPointChunk);

/// The plan and height extent of a point file in file coordinates, for indexing tiles: a LAS/LAZ/COPC file's
/// header bounds (nothing else is read; a header whose bounds are not finite or not min <= max, or that
/// declares no point, is read whole), any other format's points read whole. Throws as read_points does.
BBox read_extent(const std::string& path);

/// The local origin of points read from a file or given in memory (the Python module), as the file comment
/// says: the bbox centre rounded per axis, where that shift is exact for every coordinate (all values within a
/// factor 2 of the origin, same sign: Sterbenz) or the centre lies beyond `threshold`; zero when no axis' centre
/// lies beyond `threshold` and `always` is false (LAS: always).
Vec3 local_origin(const std::vector<Vec3>& points, bool always = false,
                  double threshold = ReadParams{}.local_origin_threshold);
/// The same from the points' bounding box (what the rule reads of them), for points seen as a stream.
Vec3 local_origin(const BBox& box, bool always = false, double threshold = ReadParams{}.local_origin_threshold);

/// Reads a polygon mesh (OBJ, OFF, PLY with a face element).
PolygonMesh read_mesh(const std::string& path);

enum class FileEncoding { Ascii, Binary };

/// Writes a polygon mesh (format from the extension: .obj, .ply, .off, or .city.json: CityJSON with the
/// defaults of io/cityjson.h: 1 mm grid, rings and edge pairing of the rounded solid checked), adding
/// mesh.origin back.
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
