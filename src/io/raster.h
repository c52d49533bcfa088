// Stage 0: reading a height raster (a terrain model: GeoTIFF or any raster GDAL reads) into core/raster.h's
// plain Raster. GDAL (Debian's libgdal-dev) stays inside raster_gdal.cpp, in the module libhsr_gdal.so.
#pragma once

#include "core/raster.h"

#include <string>

namespace hsr {

/// Reads band 1 of a raster file as heights. North-up files only (no rotation terms in the geotransform);
/// the band's no-data value becomes NaN. Errors: hsr::Error, stage "io", one line naming the file —
/// FileNotFound (missing or unreadable), BadFormat (not a raster GDAL reads, no band, a rotated or
/// degenerate geotransform, no cell with data).
Raster read_raster(const std::string& path);

}  // namespace hsr
