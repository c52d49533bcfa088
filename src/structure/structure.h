// Stage 1: scene structure analysis (paper §3.1; DESIGN.md §1 stage 1 and its notes "Scale", "Normals",
// "Plane detection", "Boundaries and segments", "Adjacency").
//
// From a point cloud: per-point normals, planar primitives (region growing by default, efficient RANSAC as
// an option, each refit by least squares), per plane a regularized alpha-shape boundary with 2D outward
// normals and 2D boundary segments lifted back to 3D, the adjacency graph of the planes (mutual k-nearest
// neighbours of inliers), its second order, and the intersection lines of adjacent / second-order-adjacent
// non-parallel planes.
//
// Every distance parameter is relative to r, the average point spacing (core/spacing.h); the resolved
// absolute values are logged and returned in SceneStructure::params.
// Deterministic: the same cloud and parameters give the same result, bit for bit.
// Errors: hsr::Error with stage "structure": Status::BadInput for fewer than 3 points, all points identical
// or all points on one line; Status::NoPlanes when no plane reaches the minimum size.
#pragma once

#include "core/types.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace hsr {

enum class PlaneDetector { RegionGrowing, Ransac };

struct StructureParams {
  // --- scale
  double spacing = 0.0;             ///< r, absolute; 0: computed by average_spacing() (mean 6-NN distance)

  // --- normals (used only when the cloud has none)
  int normal_k = 12;                ///< neighbours for the PCA normal of each point
  /// Scanner positions (local coordinates). When non-empty, each estimated normal is oriented towards the
  /// nearest one; otherwise by minimum-spanning-tree propagation.
  std::vector<Vec3> scanners;

  // --- plane detection
  PlaneDetector detector = PlaneDetector::RegionGrowing;
  int region_k = 12;                ///< region growing: neighbours of a point (kNN graph)
  double max_distance = 2.0;        ///< point-to-plane distance of an inlier, in r
  /// Angle between an inlier's normal and its plane's normal, degrees (unsigned unless signed_normals).
  double max_angle_deg = 25.0;
  /// Region growing also requires an inlier's normal to face the same way as its seed's. Keeps the two faces
  /// of a wall thinner than max_distance apart, but needs consistently oriented normals (scanner-oriented
  /// input normals; MST orientation can flip patches), hence off by default: then such a wall is one plane.
  bool signed_normals = false;
  /// The smallest plane: at least max(min_region_points, min_region_fraction x the number of points)
  /// inliers, and min_region_width r across (below). Issue 25 proposes an absolute floor (20 points, no
  /// share, 3 r wide: a desk's side, 0.6 x 0.7 m, has about 25 points at 60 points/m²); it is available
  /// through these fields but not the default (DECISIONS.md #58). A room is detected with no share and
  /// region_k + 1 points (RoomParams::min_region_points, DECISIONS.md #69).
  int min_region_points = 30;
  /// Floor relative to the scene: also at least this share of all points (0: none). In a large hall this
  /// hides every piece of furniture (issue 25).
  double min_region_fraction = 0.003;
  /// Rounds of leftover assignment after detection: an unassigned point joins the plane of one of its
  /// region_k neighbours when within max_distance of it and its normal within leftover_max_angle_deg of
  /// the plane's (nearest plane wins). Brings the inliers up to the edges, where PCA normals blend two
  /// faces (about 45 degrees off on a right-angle edge). The plane equation stays the region's fit. 0 disables.
  int leftover_rounds = 3;
  double leftover_max_angle_deg = 50.0;  ///< degrees
  double ransac_probability = 0.01; ///< RANSAC: probability of missing the largest candidate
  double ransac_cluster_epsilon = 3.0;  ///< RANSAC: connectivity distance of a shape's inliers, in r
  std::uint64_t seed = 1;           ///< RANSAC sampling seed (region growing is not random)
  /// Plane regularisation: normals within `regularize_angle_deg` of parallel are snapped to their common
  /// (inlier-weighted) direction, and parallel planes facing the same way (by their inliers' normals) whose
  /// offsets differ by less than max_distance are merged into one plane, even when far apart.
  bool regularize = false;
  double regularize_angle_deg = 3.0;  ///< degrees

  // --- boundaries and segments (per plane, in its 2D frame)
  double alpha_radius = 3.0;        ///< alpha-shape disk radius, in r (CGAL alpha = squared radius)
  int boundary_normal_k = 6;        ///< boundary neighbours for the PCA of a boundary point's 2D normal
  double segment_max_distance = 1.0;  ///< boundary point to its segment's line, in r
  double segment_max_angle_deg = 25.0;  ///< boundary point normal to its segment's normal, degrees
  int min_segment_points = 6;       ///< boundary points supporting a segment, at least
  bool regularize_segments = true;  ///< snap near-parallel / near-orthogonal / near-collinear segments
  double segment_angle_tolerance_deg = 5.0;  ///< degrees, for parallel and orthogonal snapping
  double segment_collinear_tolerance = 1.0;  ///< offset difference of collinear segments, in r

  // --- adjacency and intersection lines
  int adjacency_k = 10;             ///< kNN graph of all points used for plane adjacency
  int min_adjacent_pairs = 2;       ///< mutual kNN pairs (one inlier of each plane) for adjacency
  double min_line_angle_deg = 5.0;  ///< planes closer than this to parallel get no intersection line

  // --- cost bound of region growing (appended last: aggregate order of the fields above unchanged)
  /// A point that has been in this many grown regions smaller than the minimum seeds no further region
  /// (it can still join one); 0: no limit, every unassigned point seeds (CGAL's behaviour). Bounds the cost
  /// of planes smaller than the minimum, which would otherwise be regrown from each of their points
  /// (region_growing.cpp; max 255).
  int max_seed_failures = 64;
  /// The smallest plane's width: its inliers' extent across the plane's narrow direction
  /// (structure_internal.h projected_width: a uniformly filled rectangle's shorter side), in r. A band
  /// narrower than 3 r is about one neighbourhood wide: along an edge where the estimated normals turn, or
  /// along a scan's ragged border, not a face. 0 (default): no width test.
  double min_region_width = 0.0;
  /// The smallest plane counts its inliers at distinct positions (a duplicated point, as merged scans have,
  /// counts once; region_growing.cpp is_large_enough). Part of issue 25's absolute floor, off by default:
  /// on the shared scans it changes two airborne buildings' planes (DECISIONS.md).
  bool min_region_distinct = false;
  /// Planes whose fits coincide up to rounding (normals within ~1e-6 rad, offsets within 1e-9 of the
  /// diagonal) get the larger one's exact equation, so the exact partition does not see two planes 1e-15
  /// apart (issue 25 item 9: fit4cad_PC3's output was not valid). On by default: such planes are one plane
  /// up to the fits' rounding; of the shared scans it changes only cgal_cube's partition (fewer cells, the
  /// same faces) and cgal_fandisk's (29 -> 27 faces, p2m 0.248 -> 0.267 %; DECISIONS.md #60).
  bool share_coincident_planes = true;
};

/// Every field of StructureParams as JSON and back (structure_params.cpp; core/params_json.h): the run report's
/// parameters and `hsr reconstruct --config`. from_json keeps fields the object lacks, and throws
/// Error(BadInput, "config") on a key it does not know or a value of the wrong type.
void to_json(nlohmann::json& j, const StructureParams& p);
void from_json(const nlohmann::json& j, StructureParams& p);

/// A 2D segment of a plane's boundary, lifted to 3D.
/// Invariants: a, b on the plane (up to rounding); `normal` unit, in the plane, orthogonal to b − a and
/// pointing away from the plane's inliers; `support` indices of input points (boundary points of `plane`).
struct BoundarySegment {
  Vec3 a = Vec3::Zero(), b = Vec3::Zero();
  Vec3 normal = Vec3::Zero();
  std::vector<int> support;
  int plane = -1;
  double length() const { return (b - a).norm(); }
};

/// A detected planar primitive.
/// Invariants: `inliers` sorted, non-empty, each inlier belongs to exactly one plane; `plane` is the
/// least-squares plane of the inliers (|normal| = 1), or, when that coincides up to rounding with a larger
/// plane's (normals within 1e-6 rad, offsets within 1e-9 of the diagonal), exactly that plane's equation; frame_u, frame_v, plane.normal are orthonormal and
/// right-handed; `frame_origin` lies on the plane; boundary, boundary_points and boundary_normals have the
/// same length (boundary points are inlier indices, their projections on the plane, and their 2D unit
/// outward normals in the (u, v) frame); boundary_edges index those arrays and form closed loops.
struct DetectedPlane {
  Plane plane;
  std::vector<int> inliers;
  Vec3 centroid = Vec3::Zero();     ///< mean of the inliers
  double area = 0.0;                ///< area of the regularized alpha shape of the projected inliers
  Vec3 frame_origin = Vec3::Zero(), frame_u = Vec3::UnitX(), frame_v = Vec3::UnitY();
  std::vector<int> boundary;
  std::vector<Vec3> boundary_points;
  std::vector<Vec2> boundary_normals;
  /// The alpha shape's boundary edges as pairs of boundary slots (indices into `boundary`), each oriented
  /// with the shape on its left in the (u, v) frame (counter-clockwise around the shape, clockwise around
  /// its holes); sorted by (smaller slot, larger slot).
  std::vector<std::array<int, 2>> boundary_edges;
  std::vector<BoundarySegment> segments;

  Vec2 to_2d(const Vec3& p) const { return {(p - frame_origin).dot(frame_u), (p - frame_origin).dot(frame_v)}; }
  Vec3 to_3d(const Vec2& q) const { return frame_origin + q.x() * frame_u + q.y() * frame_v; }
  /// Distance from c to the nearest of boundary_points (in xy only when `xy`); infinity when there is none:
  /// where the plane reaches (recovery's partners and walls, hulls' expansion).
  double boundary_distance(const Vec3& c, bool xy = false) const;
};

/// Line where two planes cross. Invariants: plane_a < plane_b; |direction| = 1, orthogonal to both normals;
/// `point` on both planes, the point of the line nearest to the midpoint of the two centroids.
struct IntersectionLine {
  int plane_a = -1, plane_b = -1;
  Vec3 point = Vec3::Zero(), direction = Vec3::UnitX();
  bool adjacent = false;            ///< true: first-order adjacent pair; false: second-order only
};

struct SceneStructure {
  double spacing = 0.0;             ///< r used (absolute)
  /// Alpha-shape radius the plane boundaries were computed with (absolute: StructureParams::alpha_radius x r);
  /// 0 in a structure not made by run_structure. Visibility's occluders use the same radius by default.
  double alpha_radius = 0.0;
  BBox bbox;
  std::vector<Vec3> normals;        ///< per point, unit: the input's if present, else estimated and oriented
  std::vector<int> point_plane;     ///< per point, plane index or -1
  std::vector<DetectedPlane> planes;  ///< sorted by decreasing inlier count (ties: smallest first inlier)
  /// First-order adjacency: i and j are adjacent when at least min_adjacent_pairs pairs of their inliers are
  /// mutual adjacency_k-nearest neighbours (a pair with a leftover inlier counts only if both points lie
  /// within max_distance of both planes). adjacency[i] sorted, symmetric, without i. second_order[i]: planes
  /// sharing an adjacent plane with i that are neither i nor adjacent to i (sorted, symmetric).
  std::vector<std::vector<int>> adjacency, second_order;
  std::vector<IntersectionLine> lines;  ///< sorted by (plane_a, plane_b)
  nlohmann::json params;            ///< resolved parameter values (absolute distances) for the run report

  bool adjacent(int i, int j) const;
};

/// Boundary of the regularized alpha shape of 2D points: the union of the Delaunay triangles whose squared
/// circumradius (CGAL's Compute_squared_radius_2) is at most radius^2, i.e. CGAL's Alpha_shape_2 in
/// REGULARIZED mode with alpha = radius^2. Computed exactly from the points near the outline only
/// (boundary.cpp explains why that is enough), so its cost follows the outline, not the point count.
struct AlphaShapeBoundary {
  int dimension = -1;                     ///< of the Delaunay triangulation used; < 2: collinear input, no shape
  std::vector<std::array<int, 2>> edges;  ///< point indices, shape on the left; sorted by (min, max) index
  std::vector<int> inner;                 ///< per edge: the third vertex of its interior triangle
  double area = 0.0;                      ///< signed area enclosed by the edges (holes subtracted)
};
AlphaShapeBoundary alpha_shape_boundary(const std::vector<Vec2>& points, double radius);

namespace structure_detail {
struct KnnGraph;
}

/// A k-nearest-neighbour graph kept from one call to the next on the same points (DECISIONS #145, #150):
/// run_structure and add_small_planes take it from here when it fits (the same points, the same k) or build it and
/// leave it, so that a building's runs of the chain (the first, steps 0, 5 and 6) build it once, not once per stage
/// and run. Held by the caller (the pipeline's DetectionMemo); n x k ints (k = max(normal_k, region_k,
/// adjacency_k): 48 bytes a point by default).
struct KnnGraphCache {
  std::shared_ptr<const structure_detail::KnnGraph> graph;
  /// The points it was built over: their data pointer, count, first and last point (a graph is reused only on
  /// the same points).
  const Vec3* data = nullptr;
  std::size_t size = 0;
  Vec3 first = Vec3::Zero(), last = Vec3::Zero();
  /// The points' average spacing (core/spacing.h average_spacing with its defaults) in their units, measured by
  /// the run_structure that built the graph; 0 when the graph was built without it (add_small_planes, or a given
  /// StructureParams::spacing). run_structure takes a kept graph only with a spacing it can use.
  double spacing = 0.0;
  /// The points' normals as run_structure estimated and oriented them over this graph (none when the cloud gave
  /// its own), with the normal_k and scanners they were made with: a later run asking the same takes them
  /// instead of estimating them again (step 6's tighter planes ask another detection, not other normals; #200).
  std::vector<Vec3> normals;
  int normals_k = 0;
  std::vector<Vec3> normals_scanners;
};

/// Runs stage 1. See the file comment for errors. `keep` (may be null): the kNN graph and spacing are taken from it
/// when it holds them for these points (KnnGraphCache), else built and left in it. The result does not depend on
/// which.
SceneStructure run_structure(const PointCloud& cloud, const StructureParams& params = {}, KnnGraphCache* keep = nullptr);

/// `detected` (run_structure's result on `cloud`) with every plane's outline segments found again under
/// params' segment fields (segment_max_distance, segment_max_angle_deg, min_segment_points,
/// regularize_segments, segment_angle_tolerance_deg, segment_collinear_tolerance); the rest as it is. Equal to
/// run_structure(cloud, params) when params differ from the detection's in those fields only: the segments are
/// the last thing the detection makes from each plane's boundary and nothing before them reads them. Why: a
/// building's second run with finer segments (BuildingParams::finer_outline_points) need not find its planes,
/// normals and boundaries again (they were most of the second run's time).
SceneStructure resegment_structure(const PointCloud& cloud, const SceneStructure& detected, const StructureParams& params);

/// Whether a and b give the same planes and boundaries: equal in every field but the segment fields that
/// resegment_structure reads.
bool same_detection(const StructureParams& a, const StructureParams& b);

/// `detection` with the segment fields of `segments` (resegment_structure's parameters for a detection made
/// with `detection`).
StructureParams with_segment_fields(StructureParams detection, const StructureParams& segments);

/// The structure restricted to the planes with keep[i] (keep.size() == planes.size()): planes renumbered in
/// order, the dropped planes' inliers unassigned (point_plane -1), adjacency restricted, second order and
/// intersection lines recomputed (lines need planes at least min_line_angle_deg from parallel). Plane
/// equations may have been changed by the caller before (e.g. walls made exactly vertical): the lines follow.
SceneStructure subset_planes(const SceneStructure& s, const std::vector<bool>& keep, double min_line_angle_deg = 5.0);

/// `s` with planes of at least `min_points` inliers and `min_width` (absolute) across found among the points with
/// eligible[i] that lie on no plane of `s` (region growing over them alone, no leftover rounds): s's planes
/// unchanged (inliers, equations, indices, boundaries, adjacency among themselves), the new ones appended,
/// largest first, with their boundaries and their adjacency to every plane (mutual adjacency_k-nearest
/// inliers); second order and lines recomputed. `s` as it is when none is found. `params`: the detection's.
/// `cache` (may be null): the kNN graph of the same points is taken from it, or built and left in it.
SceneStructure add_small_planes(const PointCloud& cloud, const SceneStructure& s, const std::vector<bool>& eligible,
                                const StructureParams& params, std::size_t min_points, double min_width,
                                KnnGraphCache* cache = nullptr);

/// `s` with planes of the given inlier lists appended (each list of points on no plane of `s`, at least 3; shorter
/// lists are dropped): refit to their inliers, largest first, with boundaries and adjacency to every plane, second
/// order and lines recomputed, as add_small_planes appends the planes it finds. `cache`: as add_small_planes'.
SceneStructure add_planes(const PointCloud& cloud, const SceneStructure& s, std::vector<std::vector<int>> inliers,
                          const StructureParams& params, KnnGraphCache* cache = nullptr);

/// Whether the planes with keep[k] (all when keep is empty) are parallel within max_angle_deg (either way), so
/// that they cannot enclose a volume; false when none is kept.
bool all_parallel(const SceneStructure& s, const std::vector<bool>& keep = {}, double max_angle_deg = 5.0);

/// Writes DIR/planes.ply (inliers coloured by plane), DIR/boundaries.obj (segments as `l` lines),
/// DIR/adjacency.json and DIR/structure.json (per plane: equation, inliers, area, segments; params).
/// Creates DIR. Atomic per file.
void write_structure_dump(const PointCloud& cloud, const SceneStructure& s, const std::string& dir);

}  // namespace hsr
