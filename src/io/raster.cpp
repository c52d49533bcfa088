// Height rasters (raster.h): read by GDAL in the module libhsr_gdal.so (raster_gdal.cpp), loaded on first use.
#include "io/raster.h"

#include "io/io_internal.h"
#include "io/raster_gdal.h"

#include <filesystem>

namespace hsr {

Raster read_raster(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    io_detail::fail(Status::FileNotFound, path, "file not found or not a regular file");
  return module_function<HsrGdalReadRaster>("gdal", "hsr_gdal_read_raster")(path);
}

}  // namespace hsr
