// Plain data shared by every stage: points, meshes, planes.
// Kept free of CGAL so any stage header can include it cheaply.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross(); declared in Core, defined here

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace hsr {

using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;

/// Per-point attributes of survey formats (LAS, LAZ, COPC), as the file stores them.
/// Invariant: every vector is empty (the file has no such field) or has one entry per point of its cloud.
struct PointAttributes {
  std::vector<std::uint8_t> classification;     ///< ASPRS class (2 ground, 6 building, 1 unclassified, ...)
  std::vector<std::uint8_t> return_number;      ///< 1-based return number of the pulse
  std::vector<std::uint8_t> number_of_returns;  ///< returns of that pulse
  std::vector<std::uint16_t> intensity;
  std::vector<double> gps_time;
  std::vector<std::array<std::uint16_t, 3>> rgb;  ///< 16-bit red, green, blue
  bool empty() const {
    return classification.empty() && return_number.empty() && number_of_returns.empty() && intensity.empty() &&
           gps_time.empty() && rgb.empty();
  }
};

/// A point cloud in *local* coordinates.
/// Invariants: `normals` is empty or has `points.size()` entries of unit length; each of `attributes`'
/// vectors is empty or has `points.size()` entries;
/// global coordinates are `points[i] + origin` (the origin is chosen on load so that local coordinates
/// stay small; every writer adds it back).
struct PointCloud {
  std::vector<Vec3> points;
  std::vector<Vec3> normals;       ///< empty when the source had none
  Vec3 origin = Vec3::Zero();      ///< local-to-global shift
  std::string source;              ///< file it came from (for messages); may be empty
  PointAttributes attributes;      ///< LAS/LAZ per-point fields; empty for other formats
  /// The file's coordinate reference system: OGC WKT (LAS WKT VLR) or "EPSG:N" (GeoTIFF keys VLR); empty
  /// when the file does not say.
  std::string crs;

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool has_normals() const { return !normals.empty() && normals.size() == points.size(); }
  /// The mean of the points indexed by `idx` (zero when `idx` is empty).
  Vec3 mean_of(const std::vector<int>& idx) const {
    Vec3 c = Vec3::Zero();
    for (int i : idx) c += points[static_cast<std::size_t>(i)];
    return idx.empty() ? c : Vec3(c / static_cast<double>(idx.size()));
  }
};

/// What an output face is (DESIGN.md §4; CityJSON's RoofSurface / WallSurface / GroundSurface /
/// ClosureSurface). Set by the stage that knows it (building mode: from the plane each face lies on);
/// Unknown where nobody said (then core/face_class.h classifies by the face's normal).
enum class FaceClass : std::uint8_t {
  Unknown = 0,
  Roof,     ///< on a roof plane (or, by normal: facing up)
  Wall,     ///< on a vertical wall plane, scanned or recovered (by normal: vertical)
  Ground,   ///< the bottom of the solid, on the ground (by normal: facing down)
  Closure,  ///< closes a side without data (a face on the partition box's side walls)
};

/// A polygon mesh in local coordinates.
/// Invariants: every face has >= 3 distinct vertex indices < vertices.size(); faces are ordered
/// counter-clockwise seen from outside (normal points out of the enclosed volume) when the mesh is closed;
/// face_class is empty or has one entry per face.
struct PolygonMesh {
  std::vector<Vec3> vertices;
  std::vector<std::vector<std::uint32_t>> faces;
  Vec3 origin = Vec3::Zero();      ///< local-to-global shift, as in PointCloud
  std::vector<FaceClass> face_class;  ///< per face, or empty (unknown)

  std::size_t num_vertices() const { return vertices.size(); }
  std::size_t num_faces() const { return faces.size(); }
};

/// Plane n·x + d = 0 with |n| = 1, in local coordinates.
struct Plane {
  Vec3 normal = Vec3::UnitZ();
  double offset = 0.0;
  double signed_distance(const Vec3& p) const { return normal.dot(p) + offset; }
};

/// Axis-aligned box.
struct BBox {
  Vec3 min = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 max = Vec3::Constant(-std::numeric_limits<double>::infinity());
  void extend(const Vec3& p) { min = min.cwiseMin(p); max = max.cwiseMax(p); }
  bool valid() const { return (min.array() <= max.array()).all(); }
  Vec3 size() const { return max - min; }
  double diagonal() const { return valid() ? size().norm() : 0.0; }
  Vec3 center() const { return 0.5 * (min + max); }
};

BBox bounding_box(const std::vector<Vec3>& points);

/// The points of `cloud` at `ids` (in that order) with their normals and attributes; origin, CRS and source
/// kept (core/point_cloud.cpp).
PointCloud select_points(const PointCloud& cloud, const std::vector<std::size_t>& ids);

}  // namespace hsr
