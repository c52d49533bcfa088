// Internal to stage io: the entry point of the rasters' GDAL side (raster_gdal.cpp), built into the module
// libhsr_gdal.so (core/module.h, DECISIONS #188) and called by raster.cpp.
#pragma once

#include "core/module.h"
#include "core/raster.h"

#include <string>

/// read_raster (raster.h) of an existing regular file.
using HsrGdalReadRaster = hsr::Raster(const std::string& path);
HSR_MODULE_ENTRY HsrGdalReadRaster hsr_gdal_read_raster;
