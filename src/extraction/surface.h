// Stage 6 (paper §3.6), internal to src/extraction: the surface of a labelling (the facets between inside
// and outside cells, with T-junction vertices inserted), where it fails to be a 2-manifold, and a count of
// those places kept up to date flip by flip for the label clean-up (label_cleanup.h).
#pragma once

#include "partition/cell_complex.h"

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace hsr {

using Loop = std::vector<std::uint32_t>;
using DirectedEdge = std::pair<std::uint32_t, std::uint32_t>;

/// w lies strictly inside segment (a, b) (exact).
bool on_open_segment(const ExactPoint& a, const ExactPoint& b, const ExactPoint& w);
/// prev -> v -> next go straight on (v is not a corner of the loop), exact; all three lie on `plane`.
bool is_straight(const ExactPoint& prev, const ExactPoint& v, const ExactPoint& next, const ExactPlane& plane);

/// Inserts into every loop edge the vertices of `loops` lying strictly inside it (exact test), so that
/// polygons meeting along an edge share all vertices on it.
void insert_t_junctions(const CellComplex& cx, std::vector<Loop>& loops);

/// The facets between inside and outside cells, oriented outward, with T-junction vertices inserted.
struct Surface {
  std::vector<Loop> loops;
  std::vector<int> facet;                  ///< complex facet of each loop
  std::vector<std::pair<int, int>> group;  ///< (support plane, +1 loop normal = plane normal / -1 reversed)
};
Surface surface_of(const CellComplex& cx, const std::vector<bool>& inside);

/// Places where the surface is not a 2-manifold, each with the cells whose flip could repair it.
struct Defects {
  std::size_t edges = 0;     ///< edges used by more than two surface facets
  std::size_t vertices = 0;  ///< vertices whose incident facets form several fans
  struct Defect {
    std::vector<int> preferred;  ///< cells most likely to repair it by one flip (may be empty)
    std::vector<int> all;        ///< every cell bounding a surface facet at the defect
  };
  std::vector<Defect> list;  ///< the edges (by vertex pair), then the vertices (by id)
};
Defects find_defects(const CellComplex& cx, const Surface& s);

/// Number of fans the surface loops at a vertex form: loop i reaches the vertex from `around[i].first`
/// and leaves it to `around[i].second`; loops sharing one of those edges are in one fan. More than one
/// fan: the vertex is a pinch.
std::size_t fans_at(const std::vector<std::pair<std::uint32_t, std::uint32_t>>& around);

/// find_defects(cx, surface_of(cx, inside)).list.size(), kept up to date under flips of cells: a flip changes
/// the surface only at the vertices of the flipped cells' facets and along the edges through them, so the
/// defects are recounted there only. Every facet's loop is stored once with every vertex that lies inside
/// one of its edges; a vertex is on the surface loops exactly when a surface facet has it as a corner.
class DefectCounter {
 public:
  DefectCounter(const CellComplex& cx, const std::vector<bool>& inside);
  /// The defects of the current labels.
  std::size_t count() const { return count_; }
  /// The defects if the cells `flipped` changed label; `inside` holds the labels with them changed.
  std::size_t count_with(const std::vector<bool>& inside, const std::vector<int>& flipped);
  /// Makes `inside` (the current labels with `flipped` changed) the current labels.
  void commit(const std::vector<bool>& inside, const std::vector<int>& flipped);

 private:
  bool on_surface(const std::vector<bool>& inside, int facet) const;
  /// Moves the corner counts from labels `from` to labels `to` (which differ at most at `flipped`).
  void move_corners(const std::vector<bool>& from, const std::vector<bool>& to, const std::vector<int>& flipped);
  /// The vertices whose defects a flip of `flipped` can change (sorted).
  std::vector<std::uint32_t> around(const std::vector<int>& flipped) const;
  /// Defects at the vertices `where` (pinches) and on the edges with an end there, under `inside` and the
  /// current corner counts.
  std::size_t defects_at(const std::vector<std::uint32_t>& where, const std::vector<bool>& inside) const;

  const CellComplex& cx_;
  std::vector<Loop> loops_;                            ///< per facet: its loop with every inner edge vertex
  std::vector<std::vector<char>> corner_;              ///< per facet and loop position: a corner of the facet
  std::vector<std::vector<std::pair<int, int>>> at_;   ///< per vertex: (facet, position in its loop)
  std::vector<int> corners_on_surface_;                ///< per vertex: surface facets with it as a corner
  std::vector<bool> inside_;                           ///< the current labels
  std::size_t count_ = 0;
};

}  // namespace hsr
