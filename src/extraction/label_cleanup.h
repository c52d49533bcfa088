// Stage 6, after the min-cut: the label clean-up that removes faces nobody needs (issue 14; see
// ExtractionParams::face_price in extraction.h). Internal to src/extraction (extraction.cpp calls it).
//
// The min-cut's point term counts votes, not distances: a sliver cell along a well-supported face is kept
// because the points on its facet want exactly that facet on the surface, although the surface would move
// by a hair without it. The clean-up therefore judges a change of labels by how far it moves the surface
// (the volume of the flipped cells over the surface area: the mean displacement, in units of the box
// diagonal, like p2m; or, when larger, the mean displacement of the points: each point on a facet that
// leaves the surface moves to the facets that enter it, so a part the data supports costs its height, a
// sliver its thickness) against how many output faces it removes. Greedy, cheapest first: each step takes, among
// the candidate flips that remove faces, the one with the lowest displacement per face removed, as long as
// that price is at most the face price and the surface stays a closed 2-manifold. The candidates around a
// face: all its inside cells, all its outside cells, each of its cells alone, and around a small face also
// each of its cells with one same-label neighbour (a sliver often needs two cells to go without opening
// another face). With --verbose it logs, for each small face left, why no candidate removed it. A face under small_share
// of the area counts small_weight faces in the price (slivers are worth more displacement), and no flip
// raises the face count. The path does not depend on the price (only where it stops does), so a higher
// price never gives more faces.
//
// Labels only: the surface is still made of the exact complex's facets, so it stays closed, oriented and
// free of self-intersections whatever cells are flipped; a defect count (surface.h) guards the manifoldness.
// A flip that would move the points of a part they support (LabelCleanupParams::support_points) is never
// made, whatever its price.
//
// Cost (issue 25): a flip's face count change is computed from the facets it changes and the regions
// index (the regions it splits are explored from the cut, all pieces at once, until one is left), so it
// costs the flip's neighbourhood, not the regions it touches (the floor of a hall: thousands of facets);
// candidates are kept with a price key (a lower bound, then the price) in one ordered queue, and only the
// candidates on the planes a flip changed are looked at again.
#pragma once

#include "partition/cell_complex.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace hsr {

struct LabelCleanupParams {
  /// Largest displacement (fraction of the box diagonal, mean over the surface) paid to remove one output
  /// face. 0: no clean-up.
  double face_price = 0.0;
  /// A face is small when its region's area is under this share of the surface area (0.1 %, as the
  /// report's small faces; eval.h kSmallFaceShare).
  double small_share = 0.001;
  /// A small face removed counts as this many faces in the price (slivers are worth more displacement).
  double small_weight = 10.0;
  /// Points moving less than this (absolute length; the pipeline passes ExtractionParams::
  /// point_tolerance_spacings times the point spacing) move for free in the points' displacement (cost()).
  double point_tolerance = 0.0;
  /// A flip that moves at least `support_points` of the points (on the facets leaving the surface) farther
  /// than `support_distance` (absolute length) from the surface is never made: the part they support
  /// stays, however small its share of the whole surface. 0: no such bound.
  std::size_t support_points = 0;
  double support_distance = 0.0;
  std::size_t max_moves = 100000;  ///< safety bound on accepted moves
};

struct LabelCleanupResult {
  std::size_t moves = 0;          ///< accepted flips (each of one or more cells)
  std::size_t cells_flipped = 0;  ///< cells whose label the clean-up changed (counted per flip)
  std::size_t rejected = 0;       ///< cheapest candidates refused because the surface would not be manifold
  std::size_t supported = 0;      ///< candidates never made because they would move supported points
  std::size_t faces_before = 0, faces_after = 0;  ///< output faces as the clean-up counts them (see .cpp)
  std::size_t small_before = 0, small_after = 0;  ///< of which small (LabelCleanupParams::small_share)
  double displacement = 0.0;      ///< sum of the accepted flips' displacements (fraction of the diagonal)
};

/// The cells that must flip with cell c (c first; building mode adds the cells its orders tie to c). An empty
/// FlipSet: every cell flips alone. `read` (may be null) gets every cell whose label the answer depends on
/// (with repeats), so that the clean-up knows when a set it listed may have changed.
using FlipSet = std::function<std::vector<int>(const std::vector<bool>& inside, int c, std::vector<int>* read)>;

/// Flips cells of `inside` as described above. Never leaves no cell inside; never raises the number of
/// places where the surface is not a 2-manifold (surface.h, DefectCounter).
/// `facet_points`: per facet of `cx`, the input points assigned to it (the min-cut's votes; empty: none known,
/// the price is the surface's displacement only).
LabelCleanupResult clean_up_labels(const CellComplex& cx, std::vector<bool>& inside, const LabelCleanupParams& params,
                                   const FlipSet& flip_set, const std::vector<std::size_t>& facet_points);

/// For tests: clean_up_labels computing every candidate listing and every key again after each flip (the
/// search before DECISIONS #144); clean_up_labels must give the same labels.
LabelCleanupResult clean_up_labels_without_reuse_for_tests(const CellComplex& cx, std::vector<bool>& inside,
                                                           const LabelCleanupParams& params, const FlipSet& flip_set,
                                                           const std::vector<std::size_t>& facet_points);

/// For tests: the change of the output faces and small faces (under small_share of the surface) if `cells`
/// flipped, as the clean-up computes it (from the region index and the change's neighbourhood) and by
/// counting every region of the touched planes before and after. `inside` is left as it was.
struct FaceDeltas {
  int faces = 0, small = 0;                  ///< the clean-up's
  int counted_faces = 0, counted_small = 0;  ///< counting every region
};
FaceDeltas face_deltas_for_tests(const CellComplex& cx, std::vector<bool>& inside, const std::vector<int>& cells,
                                 double small_share);

}  // namespace hsr
