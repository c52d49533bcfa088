// Evaluation (DESIGN.md §3, paper §4): accuracy of a mesh against the input points and, when known, the
// true surface; and the validity checks (closed, 2-manifold, oriented, self-intersection free, bounds a
// volume) that reconstruct also runs before it writes anything.
//
// How the checks are made (CGAL 5.5, inside eval.cpp): the polygon faces are read as a polygon soup;
// a soup that CGAL accepts as a polygon mesh is consistently oriented and manifold; one that only needs
// re-orienting (no vertex duplication) is manifold but not oriented; one that needs vertices duplicated
// is non-manifold, and then "closed" is reported false as well (a non-manifold mesh has no well-defined
// inside). The faces are triangulated (triangulate_polygon below: ear clipping with exact predicates,
// correct for non-convex faces; the added diagonals are shared edges, so coplanar pieces of one face never
// count as intersecting) for the self-intersection test, the volume and the distances. A face whose
// projection is not a simple polygon of positive area makes the mesh self-intersecting (not valid).
#pragma once

#include "core/types.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace hsr {

struct EvalParams {
  /// Number of area-uniform samples taken on a mesh (mesh-to-points, Chamfer, Hausdorff).
  std::size_t mesh_samples = 200000;
  std::uint64_t seed = 1;  ///< seed of the sampling (std::mt19937_64); same seed, same result
  /// Self-intersection test (CGAL PMP) is the slowest check; can be turned off for huge meshes.
  bool check_self_intersections = true;
  /// Points -> mesh distances (p2m) are taken over at most this many input points: above it, over a
  /// uniform random subset of exactly this size (seeded by `seed`); 0: always all. The mean's standard
  /// error on 500,000 points is below 0.2 % of the standard deviation; p2m_max is the subset's maximum.
  std::size_t max_points = 500000;
  /// The run's self-check (no truth given): the samples on the mesh scale with the input, this many per input
  /// point, at least min_mesh_samples and at most mesh_samples; the report gives the number (mesh_samples) and
  /// the standard error of the m2p mean it leaves (accuracy.m2p_mean_stderr). One sample per point: the mesh
  /// sampled as densely as the scan sampled the scene; a building of 2,000 points is checked on 2,000 samples
  /// (the mean to about 2 %), not 200,000 (issue 43; DECISIONS #80, #102). 0: always mesh_samples (`hsr eval`
  /// and runs with a truth take all of them: the benchmarks' Chamfer figures).
  std::size_t samples_per_point = 1;
  std::size_t min_mesh_samples = 2000;
  /// A run's points the model must explain (scene.h points_to_explain) that lie farther than this from the model
  /// are unexplained (the report's counts.points_unexplained, issue 42), in r, the point spacing the pipeline
  /// uses: 3 r, beyond the inlier distance (1 r) and the noise of a roof, so a point on a modelled surface is
  /// explained and a roof part left out, a tree or a neighbour's wall is not.
  double unexplained_distance = 3.0;
  /// The run warns when more than this share of the points to explain is unexplained (a part of the building
  /// may be left out; measured on the 112 shared buildings: median 0.27 %, docs/results/buildings.md).
  double unexplained_warn_share = 0.05;
};

/// The samples run_eval draws on a mesh evaluated against `points` input points (EvalParams: mesh_samples,
/// or with samples_per_point the self-check's number; with a truth, mesh_samples).
std::size_t mesh_sample_count(const EvalParams& params, std::size_t points, bool has_truth);

/// Every field of EvalParams as JSON and back (eval_report.cpp; core/params_json.h): the run report's
/// parameters and `hsr reconstruct --config`. from_json keeps fields the object lacks, and throws
/// Error(BadInput, "config") on a key it does not know or a value of the wrong type.
void to_json(nlohmann::json& j, const EvalParams& p);
void from_json(const nlohmann::json& j, EvalParams& p);

struct Validity {
  bool closed = false;                  ///< manifold and no border edges
  /// at most two faces per edge, orientable, no non-manifold vertex (border edges allowed: see closed)
  bool manifold = false;
  /// closed, consistently oriented as given, outermost component outward and positive volume
  /// (the orientation of nested components is part of bounds_volume)
  bool oriented = false;
  bool self_intersection_free = false;  ///< no two faces intersect except at shared edges/vertices
  bool bounds_volume = false;           ///< CGAL does_bound_a_volume (false if self-intersecting)
  /// false when the self-intersection test was skipped; self_intersection_free is then assumed true.
  bool self_intersections_checked = false;
  double volume = 0.0;                  ///< signed volume (0 unless closed)
  bool valid() const { return closed && manifold && oriented && self_intersection_free && bounds_volume; }
  std::string summary() const;          ///< "valid" or the list of failed checks
};

/// All distances are fractions of the *input points'* bbox diagonal.
struct Accuracy {
  double p2m_mean = 0, p2m_rms = 0, p2m_max = 0;  ///< input points -> mesh
  double m2p_mean = 0, m2p_max = 0;               ///< mesh samples -> input points
  /// The standard error of m2p_mean from its samples (their standard deviation / sqrt(samples)).
  double m2p_mean_stderr = 0;
  bool has_truth = false;
  double chamfer = 0;    ///< symmetric: 0.5 (mean d(mesh samples, truth) + mean d(truth samples, mesh))
  double hausdorff = 0;  ///< symmetric: max of both directed maxima
  /// The two directions of the Chamfer distance: truth -> mesh sees a missing wall or roof part (truth
  /// surface far from the model), mesh -> truth a floating slab or a wing (model surface far from truth).
  double truth_to_mesh_mean = 0, mesh_to_truth_mean = 0;
  double truth_to_mesh_max = 0, mesh_to_truth_max = 0;
};

/// Share of the surface area a face must reach not to count as small (0.1 %; issue 14: slivers).
constexpr double kSmallFaceShare = 0.001;

/// The mesh's faces against its whole surface area (polygon areas from core/face_class.h's newell_vector).
struct FaceSizes {
  double smallest_share = 0.0;   ///< area of the smallest face / area of all faces (0 for an empty mesh)
  std::size_t small_faces = 0;   ///< faces whose area is under small_share of the total
  double small_share = kSmallFaceShare;  ///< the threshold used (fraction of the total area)
};

/// Face sizes of `mesh`, small faces counted under `small_share` (a fraction of the total area).
FaceSizes face_sizes(const PolygonMesh& mesh, double small_share = kSmallFaceShare);

struct EvalResult {
  std::size_t vertices = 0, faces = 0, points = 0;
  /// The faces counted as surface regions (core/face_class.h surface_regions: per connected region of coplanar
  /// faces, one plus one per hole), as a synth truth's polygon_faces are: comparable whatever the polygon split.
  std::size_t regions = 0;
  FaceSizes face_sizes;          ///< smallest face's share of the area, faces under 0.1 % of it
  std::size_t mesh_samples = 0;  ///< samples drawn on each mesh (EvalParams::mesh_samples)
  std::size_t points_evaluated = 0;  ///< input points the p2m figures are over (EvalParams::max_points)
  double mesh_area = 0;          ///< absolute surface area of the mesh (in the points' units squared)
  double diagonal = 0;  ///< absolute length the fractions refer to
  Validity validity;
  Accuracy accuracy;
  /// Each input point's distance to the mesh (the points' units), in input order, when p2m was taken over every
  /// point (points_evaluated == points); empty otherwise. What the run's count of the points the model leaves
  /// unexplained reads instead of measuring the same distances again (issue 43 item 1); run_pipeline empties it
  /// after that count.
  std::vector<double> point_distance;
  /// The m2p figures (accuracy.m2p_*) and mesh_area are not measured yet: run_eval was asked for them later
  /// (MeshToPoints::Later) and add_mesh_to_points has not run. They read 0 until it does.
  bool m2p_later = false;
};

/// Validity only (fast path used by reconstruct before writing). An empty mesh is invalid (all false).
/// Throws hsr::Error(BadInput, "eval") when a face has fewer than 3 indices or references a missing
/// vertex, or a vertex is NaN/inf.
Validity check_validity(const PolygonMesh& mesh, bool check_self_intersections = true);

/// Accuracy and validity. `truth` may be null. Meshes are moved into the points' local frame through
/// their `origin` fields first. Throws hsr::Error(BadInput, "eval") when points or mesh (or truth) are
/// empty, hold NaN/inf, reference a missing vertex, have zero area, or the points' bbox diagonal is 0.
/// Deterministic for a given seed (sampling uses std::mt19937_64 with its own uniform mapping).
/// Whether run_eval measures the mesh -> points distances now, or leaves them to add_mesh_to_points (a run
/// whose model may be thrown away, issue 43: the pipeline's runs decided by the result). With a truth they are
/// always measured now (the Chamfer figures need the samples).
enum class MeshToPoints { Now, Later };

EvalResult run_eval(const PointCloud& points, const PolygonMesh& mesh, const PolygonMesh* truth,
                    const EvalParams& params = {}, MeshToPoints m2p = MeshToPoints::Now);

/// The m2p figures and mesh_area run_eval left for later (EvalResult::m2p_later), measured as run_eval would
/// have (the same samples, the same figures); nothing when they are there. `points` and `mesh` as given to
/// run_eval.
void add_mesh_to_points(const PointCloud& points, const PolygonMesh& mesh, const EvalParams& params, EvalResult& result);

/// Triangles covering one polygon face: ear clipping in the plane that drops the dominant axis of the
/// loop's Newell normal, every orientation decided exactly on the doubles (CGAL's filtered predicates).
/// Ears clear of every other corner by 1e-10 of the face's size are taken first, so corners that were
/// collinear before rounding do not become sliver triangles poking through a neighbouring face. A face so
/// thin that its normal is rounding is tried in the other projections too: it is simple if one of them is.
/// Returns true when that projection is a simple polygon of positive area: `triangles` then holds
/// loop.size() - 2 triangles of positive area, oriented like the face, as index triples into `loop`, each
/// clipping its middle corner from what was left (so they can be applied as successive face splits).
/// Otherwise (zero area, a face touching or crossing itself) returns false, never crashes, and
/// `triangles` holds what was clipped plus a fan over the rest (empty for zero area): for drawing and
/// distances, not a triangulation.
bool triangulate_polygon(const std::vector<Vec3>& loop, std::vector<std::array<std::uint32_t, 3>>& triangles);

/// Triangles (index triples into mesh.vertices) of every face, by triangulate_polygon.
std::vector<std::array<std::uint32_t, 3>> triangulate_faces(const PolygonMesh& mesh);

/// Unsigned distance from each point to the mesh (its faces as triangulate_faces gives them; AABB tree,
/// in parallel, the queries in the points' kd-tree order, each starting from its neighbour's closest point),
/// in the points' units; points and mesh in the same coordinates (origins ignored).
/// Empty mesh: +inf for every point.
std::vector<double> point_mesh_distances(const std::vector<Vec3>& points, const PolygonMesh& mesh);
/// The same with the points' kd-tree leaf order given (`KdTree(points).leaf_order()`), for several meshes
/// measured against the same points (the LoDs' RMSEs): the same distances, one kd-tree.
std::vector<double> point_mesh_distances(const std::vector<Vec3>& points, const PolygonMesh& mesh,
                                         const std::vector<int>& order);

/// How many of `points` lie farther than `distance` from `mesh` (point_mesh_distances; the same coordinates).
/// Empty mesh: every point.
std::size_t count_farther(const std::vector<Vec3>& points, const PolygonMesh& mesh, double distance);

nlohmann::json to_json(const EvalResult& result);
/// A few human-readable lines.
std::string summary(const EvalResult& result);

}  // namespace hsr
