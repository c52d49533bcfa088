// Stage 6, internal to src/extraction: the output polygons of a labelling's surface (polygons.cpp), which
// run_extraction (extraction.cpp) calls after the labelling.
#pragma once

#include "extraction/extraction.h"
#include "extraction/surface.h"

#include "core/face_class.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace hsr {

/// Merges the loops of one (support plane, orientation) group. Loops sharing an edge (in opposite
/// directions) form components; a component whose union is a disk becomes one polygon. A component with a
/// hole (or a pinch vertex) is never turned into a keyhole polygon: it is covered greedily by disks instead
/// (grow a region facet by facet, breadth first from its lowest-index facet, accepting a neighbour only when
/// the union stays bounded by one simple loop; repeat from the next unused facet).
std::vector<Loop> merge_group(const std::vector<Loop>& loops, std::size_t* holed_components);

/// What an output face is, from its support plane and orientation (sign +1: the face's outward normal is
/// the plane's normal): the box's bottom is the ground, its other sides close the solid where the data
/// ends; a data plane (or a box side that is one) by its outward normal: up roof, vertical wall, down ground.
FaceClass face_class_of(const CellComplex& cx, int plane, int sign);

/// The output mesh of the polygons (complex vertex loops): vertices shared, numbered in order of first use,
/// a vertex dropped only where no polygon needs it (it is a straight, non-corner vertex of every polygon
/// using it; after T-junction insertion every polygon geometrically passing through a surface vertex lists
/// it, so the mesh stays watertight). `plane_of[k]` is polygon k's support plane. `mesh_index` gets each
/// complex vertex's mesh vertex (-1: not used).
PolygonMesh assemble_mesh(const CellComplex& cx, const std::vector<Loop>& polygons, const std::vector<int>& plane_of,
                          std::vector<std::int64_t>& mesh_index);

/// Whether every edge of `faces` has exactly one face on each side (each directed edge used once, its reverse
/// once) and no face repeats a corner.
bool closed_two_sided(const std::vector<std::vector<std::uint32_t>>& faces);

/// Two rounded corners closer than this many units in the last place of their largest coordinate (at least 1) are
/// one point in the output's doubles: an edge between them cannot be drawn (DECISIONS #158).
constexpr double kSubPrecisionUlps = 16.0;

/// The edges of `mesh` whose two corners are closer than kSubPrecisionUlps, collapsed: their corners become one
/// (the lower index's position), a face left with fewer than 3 corners goes (with its face_class), unused vertices
/// go. Why: sub-precision cells of the exact complex (two nearly parallel planes of a turned piece meeting) leave
/// faces whose corners round to one point, a face of zero area that the validity check rightly calls
/// self-intersecting; in doubles the collapse is the only drawable surface. Applied only when every edge of the
/// result has exactly one face on each side, as in the mesh given, and no face repeats a corner (else the mesh
/// is left as it is, and prove_simple_polygons's warning stands). Returns the number of edges collapsed.
std::size_t collapse_sub_precision_edges(PolygonMesh& mesh);

/// Zips the necks of the faces whose rounded corners are not a simple polygon (`not_simple_once_rounded`, per
/// face, from prove_simple_polygons): a corner c of face f within kSubPrecisionUlps of one of f's own edges a -> b
/// (and farther than that from a and from b: a short edge is collapse_sub_precision_edges' matter) is inserted into
/// that edge, in f and in the face across it (b -> a); f is then split at its repeated corners, and a piece of two
/// corners (a neck of no width in doubles: its two edges are each other's reverse) goes. The pieces keep f's class
/// and stand where f stood. Why: the exact complex can hold a face with a neck narrower than the doubles'
/// precision (a turned piece's nearly parallel planes: a chair's face whose two halves are joined by a strip
/// 1e-15 m wide); exact and simple, it touches or crosses itself once rounded, and the validity check rightly
/// calls the mesh self-intersecting. Zipped, the mesh is the rounded surface with the neck's zero width made
/// exact (DECISIONS #161). A face's zip is kept only when the whole mesh still has every edge with exactly one
/// face on each side and no face repeating a corner, and every face it changed is simple once rounded (exact, on
/// the doubles, in the projection of its exact plane, the proof's) and turns as its exact polygon does; else that
/// face is left as it was. `mesh_index` maps complex vertices to mesh vertices (as for prove_simple_polygons);
/// call it before the mesh is changed otherwise. Returns the number of corners inserted into edges. (In
/// simple_polygons.cpp, beside the proof whose projections it uses.)
std::size_t zip_sub_precision_necks(const CellComplex& complex, PolygonMesh& mesh,
                                    const std::vector<std::int64_t>& mesh_index,
                                    const std::vector<char>& not_simple_once_rounded);

}  // namespace hsr
