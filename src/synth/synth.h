// Synthetic scans with ground truth (DESIGN.md §3): procedural CAD- and building-like models, scanned by a
// simulated terrestrial/aerial LiDAR (ray casting, range noise, occlusion), so tests can assert accuracy
// against truth and the missing-plane protocol can be measured.
#pragma once

#include "core/types.h"

#include <cstdint>
#include <string>
#include <vector>

namespace hsr {

struct SynthParams {
  std::uint64_t seed = 1;       ///< all randomness (noise, ray jitter) derives from it
  /// Range noise: standard deviation along the ray, as a fraction of the model's bbox diagonal.
  /// Default 0.001 ("the default noise" of the tests); 0 gives exact points on the model.
  double noise = 0.001;
  /// Scanner positions (model coordinates). Empty: the model's own default positions.
  std::vector<Vec3> scanners;
  /// Approximate total number of points over all scanners.
  std::size_t target_points = 40000;
};

/// A true plane of the model: equation and the area of the model's surface lying on it.
struct SynthPlane {
  Plane plane;
  double area = 0.0;
};

struct SynthScan {
  std::string model;
  PointCloud cloud;                 ///< points with unit normals oriented towards the scanner that saw them
  std::vector<int> point_plane;     ///< index into `planes` of the face each point was sampled on
  PolygonMesh truth;                ///< closed, 2-manifold, outward oriented model
  std::vector<SynthPlane> planes;   ///< distinct planes of the model (coplanar faces share one)
  std::vector<Vec3> scanners;       ///< positions actually used
};

/// Model names, in a fixed order: box, house, dormer_house, bracket, room, courtyard.
std::vector<std::string> synth_model_names();

/// Builds the model and scans it. Deterministic for given params. Throws hsr::Error(BadInput) for an unknown
/// model name (the message lists the valid ones).
SynthScan run_synth(const std::string& model, const SynthParams& params = {});

/// Writes DIR/points.ply (binary, with normals), DIR/truth.obj and DIR/planes.json; creates DIR.
void write_synth(const SynthScan& scan, const std::string& dir);

}  // namespace hsr
