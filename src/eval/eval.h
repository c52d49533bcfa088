// Evaluation (DESIGN.md §3, paper §4): accuracy of a mesh against the input points and, when known, the
// true surface; and the validity checks (closed, 2-manifold, oriented, self-intersection free, bounds a
// volume) that reconstruct also runs before it writes anything.
#pragma once

#include "core/types.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>

namespace hsr {

struct EvalParams {
  /// Number of area-uniform samples taken on a mesh (mesh-to-points, Chamfer, Hausdorff).
  std::size_t mesh_samples = 200000;
  std::uint64_t seed = 1;
  /// Self-intersection test (CGAL PMP) is the slowest check; can be turned off for huge meshes.
  bool check_self_intersections = true;
};

struct Validity {
  bool closed = false;                  ///< no border edges
  bool manifold = false;                ///< every edge has two faces, no non-manifold vertex
  bool oriented = false;                ///< consistent orientation, outward (positive volume)
  bool self_intersection_free = false;  ///< no two faces intersect except at shared edges/vertices
  bool bounds_volume = false;           ///< CGAL does_bound_a_volume
  double volume = 0.0;                  ///< signed volume (0 unless closed)
  bool valid() const { return closed && manifold && oriented && self_intersection_free && bounds_volume; }
  std::string summary() const;          ///< "valid" or the list of failed checks
};

/// All distances are fractions of the *input points'* bbox diagonal.
struct Accuracy {
  double p2m_mean = 0, p2m_rms = 0, p2m_max = 0;  ///< input points -> mesh
  double m2p_mean = 0, m2p_max = 0;               ///< mesh samples -> input points
  bool has_truth = false;
  double chamfer = 0;    ///< symmetric: 0.5 (mean d(mesh samples, truth) + mean d(truth samples, mesh))
  double hausdorff = 0;  ///< symmetric: max of both directed maxima
};

struct EvalResult {
  std::size_t vertices = 0, faces = 0, points = 0;
  double diagonal = 0;  ///< absolute length the fractions refer to
  Validity validity;
  Accuracy accuracy;
};

/// Validity only (fast path used by reconstruct before writing).
Validity check_validity(const PolygonMesh& mesh, bool check_self_intersections = true);

/// Accuracy and validity. `truth` may be null. Throws hsr::Error(BadInput) when points or mesh are empty.
EvalResult run_eval(const PointCloud& points, const PolygonMesh& mesh, const PolygonMesh* truth,
                    const EvalParams& params = {});

nlohmann::json to_json(const EvalResult& result);
/// A few human-readable lines.
std::string summary(const EvalResult& result);

}  // namespace hsr
