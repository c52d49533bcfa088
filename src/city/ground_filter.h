// The ground filter of `hsr city` for tiles without classification (README "City scale"): the Simple
// Morphological Filter, SMRF (T. J. Pingel, K. C. Clarke, W. A. McBride, "An improved simple morphological
// filter for the terrain classification of airborne LIDAR data", ISPRS J. Photogramm. Remote Sens. 77, 2013,
// pp. 21-30), the method PDAL's filters.smrf implements, with PDAL's defaults.
//
// Steps (the paper's section 2, one function each in ground_filter.cpp):
//   1. the minimum surface: a grid of `cell` metres holding the lowest point of each cell; empty cells
//      filled by inpainting (below);
//   2. a progressive morphological opening of that surface with windows of radius 1, 2, ... cells up to
//      max_window metres: a cell whose height drops by more than slope x radius x cell from one window to
//      the next stands on an object (a building or a tree wider than the previous window) and is flagged;
//   3. the provisional ground model: the minimum surface with the flagged cells removed and inpainted;
//   4. every point is ground when it lies within elevation_threshold + elevation_scalar x (the model's local
//      slope) of the model (bilinear), above or below.
// Differences from the paper, documented in docs/DECISIONS.md: the opening uses a square window (separable
// running minima and maxima, linear in the cells) where the paper uses a disk; the inpainting is a
// harmonic (Laplace) fill by Gauss-Seidel sweeps from a nearest-neighbour start, where the paper uses
// D'Errico's inpaint_nans (springs); the paper's low-outlier net is not applied (a low point lowers its cell
// of the minimum surface only, which the opening then treats as ground).
#pragma once

#include "core/types.h"

#include <vector>

namespace hsr {

struct SmrfParams {
  double cell = 1.0;                 ///< grid cell size, in the tile's units (metres): PDAL's default
  double slope = 0.15;               ///< slope threshold, rise over run (dimensionless): PDAL's default
  double max_window = 18.0;          ///< radius of the largest opening window, metres: PDAL's default
  double elevation_threshold = 0.5;  ///< metres: PDAL's default
  double elevation_scalar = 1.25;    ///< times the ground model's slope (rise over run), added to the threshold
  int inpaint_sweeps = 200;          ///< Gauss-Seidel sweeps of the harmonic fill
};

/// A regular grid of heights over the tile (x, y local, as the cloud's points): cell (i, j) covers
/// [x0 + i c, x0 + (i + 1) c) x [y0 + j c, y0 + (j + 1) c).
struct HeightGrid {
  double x0 = 0, y0 = 0, cell = 1;
  int nx = 0, ny = 0;
  std::vector<double> z;  ///< nx * ny, row-major by j (index i + nx * j)
  double at(int i, int j) const { return z[static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * j]; }
  /// Bilinear value at (x, y) between the cell centres (clamped at the grid's border).
  double sample(double x, double y) const;
  /// Slope (rise over run, central differences) of the cell holding (x, y).
  double slope(double x, double y) const;
};

struct GroundFilterResult {
  std::vector<char> ground;  ///< per point: 1 ground
  HeightGrid model;          ///< the ground model of step 3 (heights above it decide building points)
  std::size_t object_cells = 0;  ///< cells flagged by the opening
};

/// The ground model of known ground points (e.g. LAS class 2): step 1's minimum surface of them with the
/// empty cells inpainted (step 3 without the opening). Throws Error(BadInput, "city") for no point.
HeightGrid ground_model_of(const std::vector<Vec3>& ground, const SmrfParams& params = {});

/// SMRF on `points` (local coordinates, z up). Throws Error(BadInput, "city") for parameters out of range
/// or no point. Deterministic.
GroundFilterResult run_ground_filter(const std::vector<Vec3>& points, const SmrfParams& params = {});

}  // namespace hsr
