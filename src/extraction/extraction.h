// Stage 6: surface extraction (paper §3.6; DESIGN.md §1 stage 6 "Extraction").
//
// Labels every cell of the exact CellComplex inside/outside by minimising U = P + λ M with one s-t
// max-flow, then outputs the facets between inside and outside cells, oriented outward, with adjacent
// coplanar facets merged into polygons (no keyholes), T-junctions resolved and vertices shared.
//
// Energy (per facet f of support plane with unit normal N, cells c+ = cells[0] on the positive side and
// c- = cells[1] on the negative side; "outside the box" is a fixed node labelled outside):
//   * Point term P (paper eq. 3). Every inlier point of an input plane is assigned to at most one facet of
//     the support plane carrying it (the first facet, by index, whose polygon contains the point's
//     projection). A point with normal n votes for "the side n points to is outside": if n·N > 0 it wants
//     c+ outside and c- inside, if n·N < 0 the reverse (n·N == 0: no vote). Paper eq. 3 sums over both
//     end cells of the facet, which makes it purely *unary*: each point pays 1 for each of the two cells
//     whose label disagrees with its vote. Per facet, with a = #(n·N>0) and b = #(n·N<0):
//         (c+ out, c- in) costs 2b,  (c+ in, c- out) costs 2a,  equal labels cost a + b.
//     (We use the plane normal N where the paper uses the centroid-to-centroid vector u_ij: since c+ lies on
//     the positive side, sign(n·u) = sign(n·N) up to the paper's robustness argument, and N is exact.)
//     Every point is weighted π r² / A (r = spacing, A = total area of all facets of the complex).
//   * Area term M (paper eq. 4). A facet on the surface (labels differ) costs
//         max(0, area_f − π r² |I_f|) / A,
//     clamped at zero (DESIGN.md): a negative cut weight would make the energy non-submodular, and the point
//     term already rewards well-supported facets.
//   U = P + λ M is a binary submodular energy (unary + non-negative Potts pairwise terms), minimised exactly
// by one s-t minimum cut (Boost's boykov_kolmogorov_max_flow, deterministic). Ties go to "outside".
//   Normalisation follows the paper (both terms in units of A); note that P is not divided by the number of
// points, so denser sampling (smaller r at equal coverage) keeps the balance: a point stands for π r².
//
// Surface: facets with one inside and one outside cell, loops reversed where needed so normals point out.
// Every surface vertex lying inside another surface facet's edge is inserted into that loop (exact
// collinearity on the exact vertices), so neighbouring polygons share all vertices on common edges. Facets of
// one support plane and orientation sharing edges are merged into their union when it is a disk (one simple
// boundary loop); a region with a hole or a pinch is covered by several disks grown greedily (never keyholes,
// never triangulated). A vertex is dropped only when it is a straight (180°) vertex of every output polygon
// through it. Non-manifold labellings are repaired by flipping cells (ExtractionParams::repair_non_manifold);
// then the label clean-up (label_cleanup.h, ExtractionParams::face_price) flips cells whose faces cost more
// faces than surface displacement (docs/DECISIONS.md #26).
#pragma once

#include "core/types.h"
#include "partition/cell_complex.h"

#include <nlohmann/json_fwd.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace hsr {

struct ExtractionParams {
  double lambda = 0.5;          ///< λ: weight of the area term M relative to the point term P (paper eq. 2, in [0,1])
  bool merge_coplanar = true;   ///< merge adjacent coplanar surface facets of equal orientation into polygons
  /// Make the surface a 2-manifold when the optimal labels let inside cells touch only along an edge or at a
  /// vertex: per defect, flip the adjacent cell whose flip raises U least (each cell once); if that gets
  /// stuck, only turn outside cells inside until no defect is left (terminates: at worst the whole box).
  bool repair_non_manifold = true;
  /// Building mode (DESIGN.md §4, scene.h): the solid is what lies under the roofs, down to the ground (the
  /// partition box's bottom, which the pipeline puts at the ground height):
  ///   * across every non-vertical facet the cell above may be inside only if the cell below is (no
  ///     floating slab, no overhang: an LoD2 building), a hard directed term of the cut (still submodular);
  ///   * facets on the ground cost no area, facets on walls (vertical data planes, detected or recovered)
  ///     wall_area_weight times the area term: walls are often not scanned, and a roof part must not be lost
  ///     for want of them; the box's sides (closing the solid where no wall was found) cost the full term;
  ///   * when the optimum labels nothing inside, the cell whose points want it most is kept with what lies
  ///     under it (ExtractionResult::forced_cells), so a roof-only scan gives an extruded model;
  ///   * the non-manifold repair flips a cell together with the cells the orders tie to it.
  bool building = false;
  double wall_area_weight = 0.25;  ///< building mode: weight of the area term on wall facets (0..1)
  /// Weight of the area term on the facets of planes a recovery rule vouches for (ExtractionInput::vouched: a
  /// room's pieces' box faces, posts and board slabs), 0..1. Such a face stands where the rule's evidence puts an
  /// unseen surface (a box side behind its seen face, a board's underside): its few supporting points are all the
  /// scan can hold of it, and the area term, paid in full, made the slab or box behind them air. 1: as any facet.
  double vouched_area_weight = 1.0;
  /// Weight of the area term on a level facet inside a slab a room's rule vouches solid (ExtractionInput::
  /// solid_slabs: a raised top's thickness down to the underside its rim measured; extraction.cpp slab_facets). Air
  /// under such a facet leaves the top a sliver over the slab's measured underside: the facet then stands for that
  /// underside and its own surface both, twice its area. Why: another top's plane at the same height (millimetres
  /// off by its fit) runs through the slab, and the cells under it, holding no point, cost as much solid (their
  /// bottom, their sides) as air (the facet): the min-cut left half the offices' tables a sliver (DECISIONS #229's
  /// Left). Measured (#230): 2 and 3 gave the same models; one label for the whole column (a tie above every other
  /// term) lost a table and 3 chairs whose columns' sides outweighed their tops' votes. 1: as any facet.
  double slab_facet_weight = 2.0;
  /// Label clean-up after the min-cut (label_cleanup.h): the largest mean displacement of the surface, as a
  /// fraction of the box diagonal, paid to remove one output face. Cells are flipped greedily, cheapest
  /// displacement per removed face first, while that price is at most face_price, the face count never
  /// rises and the surface stays a 2-manifold. 0: the min-cut's labels as they are (the paper). Default
  /// 3e-5, Detail::Medium (apply_detail): on the shared scans 39 % fewer faces and slivers 32 % -> 1.8 % of
  /// the faces, median p2m 0.48 % -> 0.57 % (bench/results/faces.md).
  double face_price = 3e-5;
  /// Clean-up: a face whose region is under this share of the surface area is small (0.1 %, the report's
  /// small faces)...
  double small_face_share = 0.001;
  /// ...and removing it counts as this many faces in the price: a sliver may cost that much more
  /// displacement than an ordinary face (dimensionless).
  double small_face_weight = 10.0;
  /// Clean-up: skipped (with a warning, ExtractionResult::cleanup_skipped) on a complex of more cells than
  /// this, a safety bound: its greedy search still grows faster than linearly in the cells (measured
  /// 2026-12-01, the whole extraction stage: cgal_urban with bsp, 3,552 cells, 1.5 s; exhaustive, 19,705
  /// cells, 6 s; the bunny with exhaustive, 54,090 cells, 24 s), while hierarchical gives a few hundred
  /// cells on real scans.
  /// 0: no limit. A cell count, so the outcome stays the same on every machine and thread count.
  std::size_t cleanup_max_cells = 100000;
  /// Clean-up: the points' displacement (LabelCleanupParams::point_tolerance, label_cleanup.h) ignores moves
  /// under this many point spacings r: within about the scan's noise a point is as close to either side of a
  /// sliver. Measured on the 10 shared scans at `--detail medium` (2026-12-01): 1 r gives 459 faces, 9 under
  /// 0.1 % of the area, median p2m 0.521 %; 0.5 r 464 / 11; without the points' term 452 / 8 / 0.572 %, and
  /// a low roof annex the points support can go (DECISIONS #38).
  double point_tolerance_spacings = 1.0;
  /// Clean-up: a flip that would move at least support_points of the points on the facets leaving the
  /// surface farther than support_distance_spacings r from the surface is never made: the part they support
  /// stays, whatever its share of the scene (LabelCleanupParams::support_points). The face price is a mean
  /// over the whole surface, so in a hall of furniture each piece is a small share and was cleaned away
  /// (issue 25). 20 points: a plane's worth (StructureParams::min_region_points); 2 r: a plane's inlier
  /// distance (StructureParams::max_distance), within which a point is as well explained by the surface it
  /// moves to. 0 points (default): no such bound (DECISIONS.md).
  std::size_t support_points = 0;
  double support_distance_spacings = 2.0;
};

/// The detail / size trade-off (`hsr reconstruct --detail`, README "Detail"): each level sets
/// ExtractionParams::face_price and λ (apply_detail). full: the min-cut's labels as they are (the paper).
enum class Detail { Full, High, Medium, Low };
/// "full" | "high" | "medium" | "low"; throws hsr::Error(BadInput) otherwise.
Detail parse_detail(const std::string& name);
const char* detail_name(Detail d);
/// Sets params.face_price and params.lambda to the level's values (table in extraction.cpp).
void apply_detail(Detail d, ExtractionParams& params);

/// Every field of ExtractionParams as JSON and back (extraction_params.cpp; core/params_json.h): the run report's
/// parameters and `hsr reconstruct --config`. from_json keeps fields the object lacks, and throws
/// Error(BadInput, "config") on a key it does not know or a value of the wrong type.
void to_json(nlohmann::json& j, const ExtractionParams& p);
void from_json(const nlohmann::json& j, ExtractionParams& p);

struct ExtractionInput {
  const CellComplex* complex = nullptr;        ///< the partition (required)
  const PointCloud* cloud = nullptr;           ///< points and normals, local coordinates (normals required,
                                               ///< pointing outward: only their side of each plane matters)
  /// The points' normals when not cloud's own (the pipeline passes the input's points with the normals
  /// turned to their planes' outward sides, without copying the points); one per point.
  const std::vector<Vec3>* normals = nullptr;
  const std::vector<int>* point_plane = nullptr;  ///< per point: input plane id it is an inlier of, -1 none
                                                  ///< (ids as in SupportPlane::input_planes)
  double spacing = 0.0;                        ///< r, average point spacing (absolute length, > 0)
  /// Per input plane id (as point_plane's), nonzero where a recovery rule vouches for the plane's surface: the
  /// facets of a support plane whose input planes are all vouched for pay ExtractionParams::vouched_area_weight
  /// of the area term. Null or shorter: none.
  const std::vector<char>* vouched = nullptr;
  /// Regions a recovery rule vouches solid (RecoveryResult::solid_slabs: a raised top's slab down to the underside
  /// its rim measured), each as the half-spaces bounding it (Plane::signed_distance < 0 inside): a facet on a plane
  /// that is not upright whose two cells both lie in one of them pays ExtractionParams::slab_facet_weight of its
  /// area term. Null: none.
  const std::vector<std::vector<Plane>>* solid_slabs = nullptr;
};

/// Invariants: inside.size() == complex->cells.size() and at least one cell is inside; mesh faces are
/// simple polygons (no repeated vertex, never keyholes), oriented counter-clockwise seen from outside
/// (normal from inside to outside); every mesh vertex is a complex vertex (coordinates = vertices_approx)
/// used by at least one face; no mesh vertex lies in the interior of an edge of another face (T-junctions
/// resolved). For a valid complex the mesh is closed (each undirected edge used by exactly two faces, in
/// opposite directions) and 2-manifold, unless the repair is off or fails (then non_manifold_edges or
/// non_manifold_vertices > 0, and a warning is logged).
struct ExtractionResult {
  std::vector<bool> inside;        ///< per cell: labelled inside
  PolygonMesh mesh;                ///< output surface, local coordinates; origin copied from the cloud; its
                                   ///< face_class set for every face (see face_class_of in polygons.cpp:
                                   ///< box bottom ground, other box sides closure, data planes by normal)
  double energy = 0.0;             ///< U = P + λ M of the returned labelling (normalised as above); the
                                   ///< exact minimum unless repaired_cells > 0 or cleanup_moves > 0
  std::size_t repaired_cells = 0;  ///< cells flipped by the non-manifold repair
  std::size_t forced_cells = 0;    ///< building mode: cells forced inside because the optimum had none
  std::size_t cleanup_moves = 0;   ///< flips the label clean-up made (ExtractionParams::face_price)
  std::size_t cleanup_cells = 0;   ///< cells those flips changed
  bool cleanup_skipped = false;    ///< the complex had more than ExtractionParams::cleanup_max_cells cells
  double cleanup_displacement = 0.0;  ///< their summed displacement, fraction of the box diagonal
  std::size_t surface_facets = 0;  ///< complex facets between an inside and an outside cell (before merging)
  std::size_t output_faces = 0;    ///< == mesh.faces.size()
  /// Edges shorter than the doubles' precision collapsed in the output (collapse_sub_precision_edges, #158).
  std::size_t sub_precision_edges = 0;
  /// Corners closer to their own face's edge than the doubles' precision, zipped into it (zip_sub_precision_necks,
  /// DECISIONS #161): the mesh's faces are then no longer the complex's exact polygons.
  std::size_t sub_precision_necks = 0;
  std::size_t voting_points = 0;   ///< inlier points assigned to a facet (they enter the point term)
  std::size_t non_manifold_edges = 0;  ///< mesh edges not used exactly twice in opposite directions (0 = closed, manifold edges)
  std::size_t non_manifold_vertices = 0;  ///< surface vertices where the surface pinches (several fans) after repair
};

/// Labels the cells and extracts the surface. Throws hsr::Error(BadInput) on missing/mismatched inputs and
/// hsr::Error(DegenerateInput) when the optimum labels no cell inside. All cells inside is valid (the box;
/// a warning is logged).
ExtractionResult run_extraction(const ExtractionInput& input, const ExtractionParams& params);

/// Proves every face of `mesh` a simple polygon, exactly, on the complex's exact vertices: at least 3
/// corners, not all on one line, all on the plane of the first three that are not, and, projected along
/// that plane's dominant normal axis, no two edges meeting except consecutive ones at their shared corner (no repeated point,
/// spike, touching or crossing). `mesh_index[v]` is the mesh vertex of complex vertex v, or -1 (mesh
/// vertices are complex vertices, as run_extraction writes them; it calls this before returning). Throws
/// hsr::Error(Internal, "extraction") naming the first face that is not simple. Returns (and logs a
/// warning with, unless `not_simple_once_rounded` is given: the caller then mends them and says what is left) the
/// number of faces at risk once rounded to the doubles of mesh.vertices: not simple in
/// the same projection, or with a corner (or edge) within 16 ulps of the largest coordinate from another
/// corner or edge it does not share. Such sub-precision features of the exact complex can make the
/// written mesh touch or cross itself, which eval then reports (simple_polygons.cpp). With
/// `not_simple_once_rounded`, it gets one flag per face: 1 where the rounded corners are not simple in that projection.
std::size_t prove_simple_polygons(const CellComplex& complex, const PolygonMesh& mesh,
                                  const std::vector<std::int64_t>& mesh_index,
                                  std::vector<char>* not_simple_once_rounded = nullptr);

/// Energy U = P + λ M (as defined above) of an arbitrary labelling; what run_extraction minimises.
double extraction_energy(const ExtractionInput& input, const ExtractionParams& params,
                         const std::vector<bool>& inside);

/// Debug dump (ASCII PLY with per-face colours): every cell drawn shrunk towards its centroid (factor 0.85),
/// inside cells red, outside cells light blue; face properties also carry the cell id and its label.
/// Written atomically (core/atomic_file.h). Coordinates are local (no origin shift).
void write_labels_dump(const CellComplex& complex, const std::vector<bool>& inside, const std::string& path_ply);

}  // namespace hsr
