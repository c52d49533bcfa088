// Height rasters through GDAL (raster.h), built into the module libhsr_gdal.so (core/module.h).
#include "io/raster_gdal.h"

#include "io/io_internal.h"

#include <gdal_priv.h>

#include <cmath>
#include <memory>
#include <mutex>

using namespace hsr;

Raster hsr_gdal_read_raster(const std::string& path) {
  using io_detail::fail;
  static std::once_flag registered;
  std::call_once(registered, [] { GDALAllRegister(); });
  CPLPushErrorHandler(CPLQuietErrorHandler);  // GDAL's own messages would print; ours is the one line
  std::unique_ptr<GDALDataset> ds(static_cast<GDALDataset*>(GDALOpen(path.c_str(), GA_ReadOnly)));
  CPLPopErrorHandler();
  if (!ds) fail(Status::BadFormat, path, "not a raster GDAL can read");
  if (ds->GetRasterCount() < 1) fail(Status::BadFormat, path, "raster has no band");
  double gt[6];
  if (ds->GetGeoTransform(gt) != CE_None) fail(Status::BadFormat, path, "raster has no georeferencing (geotransform)");
  if (gt[2] != 0 || gt[4] != 0 || !(gt[1] > 0) || gt[5] == 0 || !std::isfinite(gt[0]) || !std::isfinite(gt[3]))
    fail(Status::BadFormat, path, "raster is rotated or its cell size is degenerate (north-up rasters only)");
  Raster r;
  r.source = path;
  r.x0 = gt[0];
  r.dx = gt[1];
  r.y0 = gt[3];
  r.dy = gt[5];
  r.width = ds->GetRasterXSize();
  r.height = ds->GetRasterYSize();
  if (r.width <= 0 || r.height <= 0) fail(Status::BadFormat, path, "raster is empty");
  if (const char* wkt = ds->GetProjectionRef()) r.crs = wkt;
  GDALRasterBand* band = ds->GetRasterBand(1);
  r.z.resize(static_cast<std::size_t>(r.width) * static_cast<std::size_t>(r.height));
  if (band->RasterIO(GF_Read, 0, 0, r.width, r.height, r.z.data(), r.width, r.height, GDT_Float32, 0, 0) != CE_None)
    fail(Status::BadFormat, path, "cannot read the raster's cells");
  int has_nodata = 0;
  const double nodata = band->GetNoDataValue(&has_nodata);
  std::size_t with_data = 0;
  for (float& v : r.z) {
    if ((has_nodata && (static_cast<double>(v) == nodata || (std::isnan(nodata) && std::isnan(v)))) || !std::isfinite(v))
      v = std::nanf("");
    else
      ++with_data;
  }
  if (with_data == 0) fail(Status::BadFormat, path, "raster has no cell with data");
  return r;
}
