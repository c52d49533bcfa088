// A height raster (a terrain model, DTM) as plain data: read by io/raster (GDAL), sampled by the scene stage
// for the ground under a building (DESIGN.md §4, `--ground DTM.tif`).
#pragma once

#include <string>
#include <vector>

namespace hsr {

/// North-up grid of heights in the file's global coordinates. Cell (col, row) covers
/// [x0 + col·dx, x0 + (col+1)·dx] × [y0 + (row+1)·dy, y0 + row·dy] (dy < 0 for north-up files: row 0 is the
/// top) and its height z[row · width + col] holds at the cell's centre.
/// Invariants: width, height > 0; z.size() == width · height; dx > 0; dy != 0; NaN marks "no data".
struct Raster {
  double x0 = 0, y0 = 0;   ///< the outer corner of cell (0, 0): GDAL's geotransform[0], [3]
  double dx = 1, dy = -1;  ///< cell size in x and y (geotransform[1], [5])
  int width = 0, height = 0;
  std::vector<float> z;
  std::string crs;         ///< OGC WKT of the file's reference system, or empty
  std::string source;      ///< file it came from (for messages)

  /// Bilinear height at (x, y), global coordinates, between the centres of the four cells around it (nearest
  /// cell within half a cell of the grid's edge). False where the point is outside the grid or a cell it needs
  /// has no data.
  bool sample(double x, double y, double& out) const;
};

}  // namespace hsr
