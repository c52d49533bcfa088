// Stage 2: visible plane categorization (paper §3.2, supplement §1.1; DESIGN.md §1 stage 2).
//
// Each plane's alpha shape is a luminous object: from farthest-point keypoints on its inliers, rays in
// Fibonacci directions are shot against the alpha shapes of all planes (a ray ignores its own plane): a
// bounding volume hierarchy over one box per plane's shape picks the shapes a ray can meet, and each is
// tested by crossing parity against its boundary edges (DECISIONS.md #33; the paper's AABB tree over the
// alpha triangles gives the same first hits). A ray is *visible* when it escapes (hits nothing) or when the first plane it hits
// is already labelled highly visible and the ray arrives from that plane's visible side. The labels are
// iterated until the highly visible set stops growing (supplement, Algorithm 1), then smoothed by a binary
// MRF on the adjacency graph solved exactly by one s-t max-flow.
//
// Decisions (documented deviations, see also DESIGN.md):
// - One-sided ratio. A plane is the boundary of a solid and is seen from one side only, so its ratio is the
//   fraction of visible rays among the rays emitted into its *outward* half-space (the side with the larger
//   visible fraction). The paper's whole-sphere fraction puts every face of a closed convex enclosure at
//   ~0.5 (one half escapes, the other half hits the enclosure from inside), which makes the 0.5 rule a coin
//   toss for the room scanned from inside and for boxes; the one-sided ratio gives the enclosing planes ~1
//   and furniture ~0. The whole-sphere fraction is kept in `ratio_sphere` for reference.
// - Labels are updated after each full pass (Jacobi), so the result does not depend on the plane order.
// - Outward normal: highly visible planes take their visible side (vote). A barely visible plane takes the
//   side with more visible rays only when the counts differ beyond their noise (rays_tell_sides_apart), and
//   never when the scene was scanned from inside (its rays meet the room on one side and its own piece on
//   the other: the few that escape through gaps in the enclosure tell nothing; issue 25, DECISIONS.md #64);
//   otherwise it keeps the side of the majority of its inliers' normals, flipped when the highly visible
//   planes' outward normals mostly disagree with their inliers' normals (scanner inside: indoor scenes), so
//   barely visible planes are oriented consistently with the enclosing ones.
// - MRF: cost(x=1) = 1 − v, cost(x=0) = v (DESIGN.md: the paper's data term switches at 0.25), smoothness
//   w_ij·|x_i − x_j| per adjacency edge with w_ij = w / max(deg_i, deg_j) by default, so the smoothness a
//   plane pays in total is at most w: a plane's label can differ from its own threshold label (v > 0.5)
//   only when its evidence |1 − 2v| is under w (for w = 0.5: ratios within 0.25–0.75), however many
//   neighbours it has. The chain behaviour stays (a weakly supported label between two confident
//   neighbours follows them). With the literal w_ij = w = 0.5, any plane touching two highly visible planes
//   is labelled highly visible whatever its ratio (2 · 0.5 ≥ |1 − 2v|): the room's pillar (v ≈ 0.1,
//   touching floor and ceiling) became level 1; and a plane with many neighbours is overruled by them: the
//   floor of a furnished hall (ratio 1.00, 191 barely visible pieces on it) became level 2. The earlier
//   normalisation w / sqrt(deg_i deg_j) kept the pillar but still let the hall's floor and ceiling go (their
//   total pull grows as sqrt(deg)); issue 25, DECISIONS.md #4. `normalize_smoothness = false` gives the
//   literal form. Ties of the exact minimum go to "barely visible" (minimal source set of the cut).
// - Scanned from inside (a room; issue 25): the one-sided rule needs nothing else indoors. A room's walls,
//   floor and ceiling are its periphery, exactly as a building's envelope is from outside: their rays
//   escape behind them (ratio 1.00 in the synth hall), while the furniture's rays meet the room on one side
//   and the piece's own faces on the other. So the enclosure is level 1 and the furniture level 2 — the
//   paper's own indoor reading (suppl. "Weighting Parameter": structural planes highly visible, tables and
//   chairs barely visible). `scanned_from_inside` records which case it was (for the pictures).
// - A room is closed (`close_room`, DECISIONS.md #68): the furniture's rays would otherwise escape through its
//   own shadows (the floor under a desk is a hole in the floor's alpha shape, not an opening) and make desk
//   and crate tops level 1; in a room, an escaping ray that crosses an enclosing plane's convex hull meets it.
// Deterministic: keypoints start at the first inlier, directions are a fixed Fibonacci set.
#pragma once

#include "core/types.h"
#include "structure/structure.h"

#include <vector>

namespace hsr {

struct VisibilityParams {
  int keypoints = 16;            ///< farthest-point keypoints per plane (fewer when the plane has fewer inliers)
  int directions = 50;           ///< ray directions, Fibonacci sphere (both half-spaces)
  double smoothness = 0.5;       ///< w, MRF smoothness weight per adjacency edge (data costs are in [0, 1])
  int max_iterations = 100;      ///< cap on the passes of the iterative labelling
  /// Alpha-shape disk radius in r; 0: the structure stage's (SceneStructure::alpha_radius, else
  /// StructureParams::alpha_radius), so both stages use one radius unless this is set.
  double alpha_radius = 0.0;
  double threshold = 0.5;        ///< a plane is "originally" highly visible when its ratio exceeds this
  bool one_sided = true;         ///< ratio over the outward half-space (true) or the whole sphere (paper, false)
  /// Edge weight w / max(deg_i, deg_j) (true) or w (false, DESIGN.md literal). See the file comment.
  bool normalize_smoothness = true;
  /// A room is closed: a ray that escapes through the convex hull of a plane the first labelling found highly
  /// visible (the floor under a desk, the wall behind a shelf: the shadows the furniture casts, not openings)
  /// meets that plane, and the labelling runs again (close_room). A room: scanned from inside (by the
  /// parity, VisibilityResult::scanned_from_inside), or `room` (the pipeline's room rule said so: without
  /// file normals the parity cannot tell).
  bool close_room = true;
  bool room = false;
};

/// Every field of VisibilityParams as JSON and back (visibility_params.cpp; core/params_json.h): the run report's
/// parameters and `hsr reconstruct --config`. from_json keeps fields the object lacks, and throws
/// Error(BadInput, "config") on a key it does not know or a value of the wrong type.
void to_json(nlohmann::json& j, const VisibilityParams& p);
void from_json(const nlohmann::json& j, VisibilityParams& p);

/// Per-plane result. Invariants: all vectors have structure.planes.size() entries; ratio in [0, 1];
/// outward_normal unit and parallel to the plane normal (±).
struct VisibilityResult {
  std::vector<double> ratio;          ///< fraction of visible rays (outward half-space when one_sided)
  std::vector<double> ratio_sphere;   ///< fraction of visible rays over the whole sphere (the paper's)
  std::vector<Vec3> outward_normal;   ///< unit, the visible side (vote), see file comment for ties
  std::vector<bool> initially_highly; ///< the iterative labels before the MRF (ratio > threshold)
  std::vector<bool> highly;           ///< final MRF label: true highly visible (level 1), false barely (level 2)
  /// The scene was scanned from inside (a room): scanned_from_inside() of the highly visible planes (their
  /// visible sides against their inliers' normals, which point at the scanner: file normals, or normals
  /// oriented towards --scanner; MST-estimated normals carry no scanner side). The report and the pictures
  /// show such a model cut away (src/report); the pipeline leaves it false in building mode (aerial scans).
  bool scanned_from_inside = false;
  int iterations = 0;                 ///< passes of the iterative labelling (both labellings in a closed room)
  std::size_t closed_rays = 0;        ///< escaping rays close_room turned into hits (scanned from inside)
  std::size_t rays = 0;               ///< rays cast (once; hits are cached across passes)
};

VisibilityResult run_visibility(const PointCloud& cloud, const SceneStructure& structure,
                                const VisibilityParams& params = {});

/// The per-plane results of the planes `from` (indices into v's planes, in their new order); the run's
/// figures (scanned_from_inside, iterations, rays, closed_rays) as they were.
VisibilityResult subset_visibility(const VisibilityResult& v, const std::vector<int>& from);

/// Flips every plane inlier's normal in `normals` (one per point) to its plane's outward side
/// (`visibility.outward_normal`), so later stages do not depend on how the normals were oriented. Returns
/// the number flipped.
std::size_t orient_inlier_normals(const SceneStructure& structure, const VisibilityResult& visibility,
                                  std::vector<Vec3>& normals);

/// The scan was taken from inside the enclosure: `parity` sums, over the highly visible planes, their inlier
/// count signed + when their visible side agrees with the majority of their inliers' normals and − when not;
/// true when the disagreeing inliers outweigh the agreeing ones by more than half of `enclosing_inliers`
/// (their total). A file whose normals are inconsistent (cgal_cube: −0.002 of the total) is not a room; the
/// synth room and hall are −1.00. Exposed for tests.
bool scanned_from_inside(double parity, double enclosing_inliers);

/// A barely visible plane's rays tell its outward side when its visible counts on the two sides differ by more
/// than twice their noise (two standard deviations of the difference of two Poisson counts of equal rate:
/// |a − b| > 2 sqrt(a + b)); one or two escaping rays against none are chance (a gap in another plane's
/// alpha shape), and the inliers' normals decide. Exposed for tests.
bool rays_tell_sides_apart(int visible_one_side, int visible_other_side);

/// Exact minimiser of E(x) = Σ_i [x_i (1 − v_i) + (1 − x_i) v_i] + Σ_{(i,j)} w_ij |x_i − x_j| over binary x
/// (x = 1: highly visible), by one max-flow; w_ij = w / max(deg_i, deg_j) when `normalize`, else w.
/// `edges` lists each undirected pair once or twice (duplicates and self loops are dropped before degrees
/// are counted). Ties go to 0. Exposed for tests.
std::vector<bool> label_mrf(const std::vector<double>& v, const std::vector<std::pair<int, int>>& edges,
                            double w, bool normalize = false);

/// The edge weights label_mrf uses: the deduplicated edges (a < b, sorted) and their w_ij.
std::vector<std::pair<std::pair<int, int>, double>> mrf_edge_weights(
    int n, const std::vector<std::pair<int, int>>& edges, double w, bool normalize);

/// The first plane each ray meets (-1: none), per plane: keypoint after keypoint (farthest_point_samples of
/// its inliers), within each the directions of fibonacci_directions(params.directions). A ray starts on its
/// plane (the keypoint projected onto it) and ignores that plane; it meets another plane when it crosses
/// that plane's alpha shape (the union of its alpha triangles: radius params.alpha_radius, by default the
/// structure's); the nearest crossing wins, ties to the smaller plane index. Exposed for tests.
std::vector<std::vector<int>> first_hits(const PointCloud& cloud, const SceneStructure& structure,
                                         const VisibilityParams& params = {});
/// The same from the lights light_origins gave (run_visibility computes them once for both casts).
std::vector<std::vector<int>> first_hits(const PointCloud& cloud, const SceneStructure& structure,
                                         const VisibilityParams& params, const std::vector<std::vector<Vec3>>& lights);

/// The lights of each plane, in the order first_hits casts their rays: its inliers' farthest_point_samples
/// (params.keypoints), each projected onto the plane.
std::vector<std::vector<Vec3>> light_origins(const PointCloud& cloud, const SceneStructure& structure,
                                             const VisibilityParams& params = {});

/// VisibilityParams::close_room: every ray of `hits` (first_hits' layout) that escapes (-1) and crosses the
/// convex hull of an `enclosure` plane (its inliers', in its plane) becomes a hit on the nearest such plane,
/// except a plane the ray's light lies on (within the structure's max_distance). Returns how many rays it closed.
/// `lights`: light_origins' of the same structure and params.
std::size_t close_room(const PointCloud& cloud, const SceneStructure& structure, const VisibilityParams& params,
                       const std::vector<std::vector<Vec3>>& lights, const std::vector<bool>& enclosure,
                       std::vector<std::vector<int>>& hits);

/// `n` unit directions of a Fibonacci sphere (deterministic).
std::vector<Vec3> fibonacci_directions(int n);

/// Indices (into `points`) of `count` farthest-point samples starting at index 0; all when fewer points.
std::vector<int> farthest_point_samples(const std::vector<Vec3>& points, int count);

}  // namespace hsr
