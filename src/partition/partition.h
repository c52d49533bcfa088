// Stage 5: the space partition (paper §3.5, DESIGN.md §2). Convex polygons in, an exact CellComplex out.
//
// Partitioners (all fill the same CellComplex, see cell_complex.h):
//   exhaustive  every support plane cuts every cell it crosses: the full plane arrangement inside the box
//               (the paper's "EP"; cubic in the number of planes, the test oracle on small inputs).
//   bsp         polygons inserted one by one in decreasing area order; a polygon's plane splits exactly the
//               cells whose interior its (exact) fragment crosses with positive area; polygons coplanar with
//               an earlier one do not re-split (their plane already bounds the cells). COMPOD-style peer.
//   kinetic     every polygon grows at one speed inside the box (face-based, kinetic_growth.h); a polygon
//               stops at its k-th collision. The paper's "KP" / KSR. Domains holding more than
//               max_polygons_per_domain polygons are first split in two (recursively) by the support plane
//               of one of their polygons, the one that splits the others most evenly, as a bsp step (that
//               polygon is then done); the other polygons are clipped to the sub-domains (keeping their
//               time function) and cannot grow past the wall.
//               (Not DESIGN.md's artificial axis-aligned walls: the output surface used them where they cut
//               a polygon's growth short, i.e. facets on no data plane; docs/DECISIONS.md #13.)
//   hierarchical levels 1 -> 2 -> 3 as nested domains (the paper's method, §3.5): level 1 grows in the box,
//               level L once per cell of level L-1 with that cell's facets as walls (events A); per-polygon
//               speed; a same-level adjacent polygon stops (events C), a non-adjacent one is crossed
//               (events B) while the polygon is inside the bounds set by its adjacent planes' lines, up to
//               max_crossings planes (kinetic_growth.h). Cells of one level grow in parallel.
//   For both: the grown regions split the domain (a cell is split by a plane where the plane's region meets
//   its interior), then cells separated by a facet outside every region are merged back, so the cells are
//   exactly the connected components of the domain minus the regions (convex, see kinetic_growth.h).
//   All domains are cells of one conforming complex, split in place (complex_builder.h): a vertex created on
//   a wall is inserted in the neighbouring cells' facets at once, so walls shared by two domains need no
//   overlay afterwards. Growth (the expensive part) runs in parallel over the domains of a level; the splits
//   are applied in domain order (each domain as soon as it has grown, beside the growth of the later ones), so
//   the output does not depend on the number of threads.
//
// Exactness: every decision is a sign of a rational expression (GMP), decided by a double filter with a
// proven error bound or an interval when it can, and otherwise exactly on integers over positive common
// denominators (no gcd); vertices are built by Cramer's rule on the planes' integer coefficients, each
// coordinate canonicalised once (exact_geometry.h, docs/DECISIONS.md #51). The filters change no decision:
// partition_internal::set_filters(false) gives the same complexes (tests/partition/test_partition_filters.cpp).
// Input planes are read exactly from
// their doubles and normalised so that coplanar planes (either orientation) share one SupportPlane, which
// lists every input plane id on it. An input polygon is projected exactly onto its plane along the
// plane's dominant normal axis and replaced by the 2D convex hull of the projection. SupportPlane::exact /
// approx are canonical (first non-zero of a, b, c is +1), so their normal may be opposite to the input
// plane's normal.
#pragma once

#include "partition/cell_complex.h"

#include <nlohmann/json_fwd.hpp>

#include <string>
#include <utility>
#include <vector>

namespace hsr {

enum class Partitioner { Exhaustive, Bsp, Kinetic, Hierarchical };

struct PartitionParams {
  Partitioner method = Partitioner::Hierarchical;  ///< which partitioner fills the complex (the paper's method by default)
  /// Margin added on each side of the points' bbox, as a fraction of the bbox diagonal. The enlarged box
  /// is then rounded outward to a dyadic grid of step 2^(floor(log2(diagonal)) - 10) (~diagonal/1000), so
  /// its corners are short rationals. Default 0 (a tight box): an unscanned side of the scene (a building's
  /// floor, a wall hidden from every scanner) is then closed at the extreme points, where the true surface
  /// usually is, instead of a margin away (measured on synth house: Chamfer to truth 0.02% vs 1.2% at 0.05).
  double bbox_margin = 0.0;
  /// bsp: extend each polygon to its bounds before inserting it (the section of the box clipped by the lines
  /// of its adjacent planes that stay out of its inner half, as in hierarchical's events B; unchanged when
  /// it has none), so its plane splits the cells up to its expected true edges. false: the polygon as is.
  bool bsp_extend = true;
  int kinetic_k = 1;  ///< kinetic: a polygon stops at its k-th collision (k >= 1)
  /// kinetic / hierarchical: a domain holding more polygons is split in two by one of its polygons' planes.
  int max_polygons_per_domain = 20;
  /// hierarchical safety budget: a polygon crosses at most this many distinct same-level planes (events B)
  /// and stops at the next one.
  int max_crossings = 8;
  // Ablation switches of issue 17 (bench/results/partition_ablation.md, docs/DECISIONS.md #25 and after):
  // the defaults are the rules above. wait_at_bounds + trim measured fewer cells and a lower p2m on the
  // shared scans, but with the label clean-up they lose a roof annex on city3d_bldg94 (DECISIONS #36): off.
  /// hierarchical: events B crossed while on the way to the bounds. false: every collision with a polygon not
  /// yet crossed stops the growing polygon (kinetic k = 1 with levels and speeds; adjacency changes nothing).
  bool cross_to_bounds = true;
  /// A polygon whose region covers the edge stops (or is crossed by) P only if it reached the point where
  /// P's front first touches the edge no later than P (where the fronts meet). false: coverage of the edge
  /// decides (first arrival on the arrangement edge).
  bool meet_at_point = false;
  /// hierarchical: at an edge on one of its bounds that no other region covers yet, P waits (once) until the
  /// adjacent polygons owning that line could reach the edge; the one arriving last then finds nobody and
  /// crosses, and P stops on it at the shared line. At a T-junction (P's plane crosses the neighbour's inner
  /// half) that neighbour goes on, as it should; at a corner (each plane a bound of the other) the later one
  /// crosses, so the extension beyond the corner starts as late as possible (the paper stops both there,
  /// which convex cells do not allow). false: the first to arrive crosses (docs/DECISIONS.md #11, #25).
  bool wait_at_bounds = false;
  /// hierarchical: after growth, a region face that is neither on the initial polygon nor inside the bounds
  /// is removed when each of its edges inside the region is covered on both sides by another region (the
  /// complex stays valid: the region still ends on another region); repeated until nothing changes. This is
  /// "beyond its bounds a polygon stops at its first collision" whatever the arrival order: a polygon that
  /// passed a plane before that plane's polygon got there loses the part beyond it. false: regions as grown.
  bool trim = false;
  int threads = 0;  ///< kinetic / hierarchical: worker threads for independent domains (0 = all cores)
  /// A building with a footprint (footprint_prism.h walls_standing_for_footprint, issue 43 item 4): a wall
  /// polygon within this many point spacings r of a footprint edge, parallel to it, with no roof part between
  /// them, is the scan's estimate of that edge and is left out of the partition, so the roofs reach the
  /// footprint's own wall and the solid fills the footprint as given. 0: every wall kept. In r (the pipeline
  /// scales it by the point spacing).
  double footprint_wall_offset = 2.0;
  /// ... and parallel to the edge within this angle (degrees).
  double footprint_wall_angle_deg = 10.0;
  /// ... and a point counts as between them beyond this distance from the wall (and above the ground by as
  /// much), in r: about the scan's noise, so a lower roof a metre wide between the wall and the edge counts.
  double footprint_wall_band = 1.0;
  /// Fill Cell::volume with exact volumes (CellComplex::exact_volumes). The pipeline turns it off: the
  /// extraction uses no volume, and validate() recomputes them anyway.
  bool exact_volumes = true;
};

/// Every field of PartitionParams as JSON and back (partition_params.cpp; core/params_json.h): the run report's
/// parameters and `hsr reconstruct --config`. from_json keeps fields the object lacks, and throws
/// Error(BadInput, "config") on a key it does not know or a value of the wrong type.
void to_json(nlohmann::json& j, const PartitionParams& p);
void from_json(const nlohmann::json& j, PartitionParams& p);

struct PartitionInput {
  std::vector<ConvexPolygon> polygons;  ///< one per plane (several per plane allowed: they are merged)
  BBox points_bbox;                     ///< bbox of the input points (before the margin)
  /// hierarchical: pairs of adjacent planes (ConvexPolygon::plane_id values, the structure stage's
  /// adjacency graph). A same-level adjacent polygon stops a growing polygon; order inside a pair is free.
  std::vector<std::pair<int, int>> adjacent_planes;
  /// Inserted after the partitioner, in this order, bsp-style and as given (not extended): each polygon splits
  /// every cell whose interior it crosses with positive area, so afterwards it is covered by facets. The
  /// footprint's walls (footprint_prism.h) come in here; they take no part in the growth. Empty: none.
  std::vector<ConvexPolygon> cuts;
};

/// The whole input as JSON and back (partition_input_json.cpp): bbox, polygons (plane, vertices, level, speed),
/// adjacency; doubles read back exactly. `hsr reconstruct --dump` writes partition_input.json. from_json throws
/// Error(BadInput, "partition") on a missing or mistyped field.
void to_json(nlohmann::json& j, const PartitionInput& in);
void from_json(const nlohmann::json& j, PartitionInput& in);

/// Builds the partition. Throws hsr::Error: BadInput (empty/non-finite bbox, zero normal, negative
/// margin, kinetic_k < 1, speed <= 0 or level outside 1..3 for hierarchical), DegenerateInput (box with
/// zero extent along an axis).
/// Polygons whose projection has zero area still create their support plane (exhaustive cuts with it).
CellComplex run_partition(const PartitionInput& input, const PartitionParams& params);

/// "exhaustive", "bsp", "kinetic", "hierarchical" (the CLI's --partition values).
const char* partitioner_name(Partitioner p);
/// Inverse of partitioner_name(); throws Error(BadInput) naming the unknown value.
Partitioner parse_partitioner(const std::string& name);

/// The box the partition uses for `points_bbox` and `bbox_margin` (exact, dyadic corners).
void partition_box(const BBox& points_bbox, double bbox_margin, ExactPoint& lo, ExactPoint& hi);

/// Writes every facet as a polygon of an ASCII PLY mesh (double coordinates, 17 digits), each face coloured
/// by its support plane (box sides grey). Atomic (core/atomic_file.h). For inspection only.
void write_partition_dump(const CellComplex& complex, const std::string& path_ply);

}  // namespace hsr
