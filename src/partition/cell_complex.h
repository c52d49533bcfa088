// The exact cell complex every partitioner fills (DESIGN.md §2), and its validator.
// Paper §3.5 (the partition) / §3.6 (what extraction reads from it).
//
// Plain index arrays. Coordinates are exact rationals (GMP mpq_class, thread-safe as values); a double
// copy of each vertex is kept for output and for inexact consumers (extraction's point term, dumps).
#pragma once

#include "core/types.h"

#include <gmpxx.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace hsr {

using Rational = mpq_class;

struct ExactPoint {
  Rational x, y, z;
  bool operator==(const ExactPoint& o) const { return x == o.x && y == o.y && z == o.z; }
};

/// a x + b y + c z + d = 0, exact. Built exactly from the double plane (every double is a rational).
struct ExactPlane {
  Rational a, b, c, d;
  /// The normal's coefficient on `axis` (0 = x: a, 1 = y: b, 2 = z: c).
  const Rational& coef(int axis) const { return axis == 0 ? a : axis == 1 ? b : c; }
};

/// A support plane of the complex: an input plane (possibly shared by several coplanar input polygons) or
/// a side of the bounding box.
struct SupportPlane {
  enum class Kind { Input, BoxSide };
  Kind kind = Kind::Input;
  ExactPlane exact;
  Plane approx;                   ///< unit normal double version of `exact`
  /// ids (ConvexPolygon::plane_id) of the input planes lying on it: Input, or BoxSide when an input plane
  /// coincides exactly with a side of the box (the side keeps kind BoxSide and lists it here).
  std::vector<int> input_planes;
  int box_side = -1;              ///< 0..5 = -x,+x,-y,+y,-z,+z for BoxSide
};

/// A convex planar facet.
/// Invariants: `vertices` is a simple convex loop of >= 3 distinct vertices, not all collinear, lying exactly on
/// `planes[plane]`, ordered counter-clockwise seen from the positive side of that plane (the side its
/// normal (a,b,c) points to). The complex is edge-conforming: a vertex lying on an edge of a facet is a
/// vertex of that facet's loop, so a loop may contain "flat" vertices (180° interior angle, in order along
/// the edge) where a neighbouring facet has a corner; every facet edge is an edge of the other facets
/// containing it (no T-junctions). cells[0] is the cell on the positive side, cells[1] the one on the negative
/// side; -1 means "outside the box" (only for BoxSide facets, which have exactly one -1).
struct Facet {
  std::vector<std::uint32_t> vertices;
  int plane = -1;
  std::array<int, 2> cells = {-1, -1};
  int level = 0;  ///< partition level that created it (0 = box, 1..3 = hierarchical levels)
};

/// A closed convex polyhedron bounded by its facets.
struct Cell {
  std::vector<std::uint32_t> facets;
  Rational volume;         ///< exact when CellComplex::exact_volumes, else 0
  double volume_approx = 0;  ///< approximate (the centroid's tetrahedra, in doubles); always set
  Vec3 centroid = Vec3::Zero();  ///< approximate (volume-weighted, computed in doubles)
};

/// Invariants (checked by validate()): every cell is a closed convex polyhedron (each edge of its facets,
/// oriented outward, is used exactly once in each direction); every facet separates
/// exactly two cells, or one cell and the outside for box-side facets; cell volumes sum exactly to the box
/// volume; facets of one support plane do not overlap; vertices are unique (keyed by exact value); the
/// complex is edge-conforming (no facet edge holds another vertex of the complex's edges in its interior).
struct CellComplex {
  std::vector<ExactPoint> vertices;
  std::vector<Vec3> vertices_approx;  ///< same size as `vertices`
  std::vector<SupportPlane> planes;
  std::vector<Facet> facets;
  std::vector<Cell> cells;
  ExactPoint box_min, box_max;        ///< the (enlarged) bounding box, exact
  BBox box;                           ///< same box in doubles
  /// Cell::volume holds the exact volume (PartitionParams::exact_volumes). validate() recomputes the exact
  /// volumes either way and checks their sum; it compares them with Cell::volume only when this is set.
  bool exact_volumes = true;
};

/// A convex polygon to insert: its plane id (index of the detected/recovered plane it comes from), the
/// plane, and its vertices (3D, approximately on the plane; partitioners project them exactly onto it).
struct ConvexPolygon {
  int plane_id = -1;
  Plane plane;
  std::vector<Vec3> vertices;
  int level = 1;       ///< 1 highly visible, 2 barely visible, 3 recovered (hierarchical partition)
  double speed = 1.0;  ///< growth speed (kinetic / hierarchical)
};

struct ValidationReport {
  bool ok = true;
  std::vector<std::string> problems;  ///< one line each, empty when ok
};

/// Checks every invariant above exactly. If `inputs` is given, also checks that each input polygon
/// (projected onto its support plane as the partitioners do) is covered by facets of that plane, exactly:
/// the areas of the facets' intersections with the polygon sum to the area of the polygon inside the box
/// (facets of a plane do not overlap, so this is the area of the union). Meant for tests and debugging:
/// cost grows like the complex size times the facet size, with rational arithmetic.
ValidationReport validate(const CellComplex& complex, const std::vector<ConvexPolygon>* inputs = nullptr);

/// Exact volume of the box of `complex`.
Rational box_volume(const CellComplex& complex);

}  // namespace hsr
