// Internal to stage city: the footprints' GDAL side, built into the module libhsr_gdal.so (core/module.h,
// DECISIONS #188) and called through it by footprints.cpp. What crosses is plain data: rings as OGR gives them
// (the closing repeat included), the same doubles; footprints.cpp turns them into polygons for every source.
#pragma once

#include "city/footprints.h"
#include "core/module.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace hsr::city_gdal {

/// One feature as read: its id (the id field's value or the FID), fields, and each polygon's rings (outer
/// first), corners as stored, curved polygons linearised, reprojected into the points' CRS when asked.
struct RawFeature {
  std::string id;
  nlohmann::json attributes = nlohmann::json::object();
  std::vector<std::vector<std::vector<Vec2>>> polygons;
};

/// A layer as read: its features in layer order and footprints.h's CRS figures (FootprintSet's crs, crs_note,
/// crs_compared).
struct RawLayer {
  std::vector<RawFeature> features;
  std::string crs, crs_note;
  bool crs_compared = false;
};

}  // namespace hsr::city_gdal

// The module's entry points (module_function<...>("gdal", "<name>")); each throws hsr::Error as footprints.h says.
/// The layer of `path` (an existing file) that `params` names, brought into `params.points_crs`.
using HsrGdalReadFootprints = hsr::city_gdal::RawLayer(const std::string& path, const hsr::FootprintReadParams& params);
HSR_MODULE_ENTRY HsrGdalReadFootprints hsr_gdal_read_footprints;
/// write_footprints (footprints.h).
using HsrGdalWriteFootprints = void(const std::string& path, const std::vector<hsr::FootprintFeature>& features,
                                    const std::string& crs, const std::string& layer);
HSR_MODULE_ENTRY HsrGdalWriteFootprints hsr_gdal_write_footprints;
/// crs_epsg_code (footprints.h).
using HsrGdalCrsEpsgCode = std::string(const std::string& crs);
HSR_MODULE_ENTRY HsrGdalCrsEpsgCode hsr_gdal_crs_epsg_code;
/// crs_metres_per_unit (footprints.h).
using HsrGdalCrsMetresPerUnit = double(const std::string& crs, bool* projected, std::string* unit);
HSR_MODULE_ENTRY HsrGdalCrsMetresPerUnit hsr_gdal_crs_metres_per_unit;
