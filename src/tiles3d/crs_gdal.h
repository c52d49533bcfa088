// Internal to stage tiles3d: earth-centred coordinates through GDAL/PROJ (crs_gdal.cpp), built into the module
// libhsr_gdal.so (core/module.h, DECISIONS #188) and called by tiles3d.cpp.
#pragma once

#include "core/module.h"
#include "core/types.h"

#include <functional>
#include <string>

namespace hsr::tiles3d_gdal {

/// A CRS's way to the earth-centred frame (EPSG:4978) at one place.
struct EarthPlace {
  Vec3 ecef = Vec3::Zero();  ///< the place in ECEF, metres
  double lon = 0, lat = 0;   ///< its longitude and latitude (WGS 84), degrees
  /// Takes a point of the CRS to ECEF in place; false when it cannot.
  std::function<bool(double& x, double& y, double& z)> to_ecef;
};

}  // namespace hsr::tiles3d_gdal

/// The place `centre` of CRS `crs` (WKT or "EPSG:N") in ECEF. Throws Error(BadInput, "tiles3d") for an unknown
/// CRS or one that cannot be brought to ECEF.
using HsrGdalEarthPlace = hsr::tiles3d_gdal::EarthPlace(const hsr::Vec3& centre, const std::string& crs);
HSR_MODULE_ENTRY HsrGdalEarthPlace hsr_gdal_earth_place;
