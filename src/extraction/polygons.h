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

}  // namespace hsr
