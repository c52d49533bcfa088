// A small LAS writer (stage 0, io): LAS 1.2, point data format 1 (coordinates, intensity, return number and
// count, classification, GPS time; ASPRS LAS 1.2 specification), for `hsr synth city` and tests. Coordinates
// are stored as integers X with X * scale + offset = the global coordinate (local + cloud.origin), rounded
// to the nearest step; the point attributes of PointCloud::attributes are written where present (else 0;
// return number and count 1). The CRS (PointCloud::crs or LasWriteParams::crs) is written as a GeoTIFF key
// directory record (LASF_Projection 34735) for "EPSG:N" (ProjectedCSTypeGeoKey, or GeographicTypeGeoKey for
// codes 4000-4999), or as an OGC WKT record (2112) otherwise; what io's reader (las.cpp) reads back.
#pragma once

#include "core/types.h"

#include <string>

namespace hsr {

struct LasWriteParams {
  double scale = 0.001;  ///< size of one integer step on x, y and z, in the file's units (1 mm)
  /// Offset of the integers, per axis; NaN (default): the cloud's origin (integer-valued for georeferenced data).
  Vec3 offset = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  std::string crs;       ///< "": the cloud's own (PointCloud::crs); else WKT or "EPSG:N"
};

/// Writes `cloud` to `path` atomically (core/atomic_file.h); same cloud and parameters, same bytes. Throws
/// Error(BadInput, "io") for an empty cloud, a scale <= 0, a coordinate out of the int32 range at that scale,
/// a classification above 31 or a return number or count above 7 (format 1 stores 5 and 3 bits).
void write_las(const std::string& path, const PointCloud& cloud, const LasWriteParams& params = {});

}  // namespace hsr
