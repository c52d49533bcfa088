// Height rasters (core/raster.h, io/raster.h): bilinear sampling between cell centres, no-data, and reading a
// GeoTIFF written here with GDAL (the file a user passes as --ground DTM.tif).
#include "core/error.h"
#include "core/raster.h"
#include "io/raster.h"
#include "test_util.h"

#include <gdal_priv.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace hsr {
namespace {

/// 3 x 2 cells of 2 m, north-up, upper-left corner at (100, 50): z = x / 10 + y / 100 at each cell centre.
Raster small_raster() {
  Raster r;
  r.x0 = 100;
  r.y0 = 50;
  r.dx = 2;
  r.dy = -2;
  r.width = 3;
  r.height = 2;
  for (int row = 0; row < 2; ++row)
    for (int col = 0; col < 3; ++col) {
      const double x = 101 + 2 * col, y = 49 - 2 * row;
      r.z.push_back(static_cast<float>(x / 10 + y / 100));
    }
  return r;
}

TEST(Raster, SamplesBilinearlyBetweenCellCentres) {
  const Raster r = small_raster();
  double z = 0;
  // A plane is reproduced exactly (to float precision) anywhere between the centres...
  for (const auto& [x, y] : {std::pair{101.0, 49.0}, {102.0, 48.0}, {104.5, 47.5}, {103.0, 47.0}}) {
    ASSERT_TRUE(r.sample(x, y, z)) << x << " " << y;
    EXPECT_NEAR(z, x / 10 + y / 100, 1e-5);
  }
  // ...and held at the nearest centre in the outer half cell; outside the grid there is nothing.
  ASSERT_TRUE(r.sample(100.2, 49.8, z));
  EXPECT_NEAR(z, 101.0 / 10 + 49.0 / 100, 1e-5);
  EXPECT_FALSE(r.sample(99.9, 49.0, z));
  EXPECT_FALSE(r.sample(101.0, 50.1, z));
  EXPECT_FALSE(r.sample(101.0, 45.9, z));
  // A cell without data is needed only where it has weight.
  Raster hole = r;
  hole.z[1] = std::nanf("");
  EXPECT_FALSE(hole.sample(102.0, 48.0, z));
  ASSERT_TRUE(hole.sample(101.0, 47.0, z));
  EXPECT_NEAR(z, 101.0 / 10 + 47.0 / 100, 1e-5);
}

TEST(Raster, ReadsAGeoTiffWithItsGeotransformAndNoData) {
  GDALAllRegister();
  const std::string dir = test::scratch_dir("geotiff").string();
  const std::string path = dir + "/dtm.tif";
  {
    GDALDriver* drv = GetGDALDriverManager()->GetDriverByName("GTiff");
    ASSERT_NE(drv, nullptr);
    GDALDataset* ds = drv->Create(path.c_str(), 3, 2, 1, GDT_Float32, nullptr);
    double gt[6] = {100, 2, 0, 50, 0, -2};
    ds->SetGeoTransform(gt);
    const Raster src = small_raster();
    std::vector<float> cells = src.z;
    cells[4] = -9999;
    GDALRasterBand* band = ds->GetRasterBand(1);
    band->SetNoDataValue(-9999);
    ASSERT_EQ(band->RasterIO(GF_Write, 0, 0, 3, 2, cells.data(), 3, 2, GDT_Float32, 0, 0), CE_None);
    GDALClose(ds);
  }
  const Raster r = read_raster(path);
  EXPECT_EQ(r.width, 3);
  EXPECT_EQ(r.height, 2);
  EXPECT_EQ(r.x0, 100);
  EXPECT_EQ(r.dy, -2);
  EXPECT_TRUE(std::isnan(r.z[4]));
  EXPECT_FLOAT_EQ(r.z[0], small_raster().z[0]);
  double z = 0;
  ASSERT_TRUE(r.sample(102.0, 49.0, z));
  EXPECT_NEAR(z, 10.2 + 0.49, 1e-5);
  // Not a raster, and no file: one line, the right status.
  const std::string text = dir + "/not_a_raster.tif";
  std::ofstream(text) << "hello";
  EXPECT_EQ(test::status_of([&] { read_raster(text); }), Status::BadFormat);
  EXPECT_EQ(test::status_of([&] { read_raster(dir + "/missing.tif"); }), Status::FileNotFound);
}

}  // namespace
}  // namespace hsr
