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
  Plane plane;                ///< normal = outward normal of the truth faces on it
  double area = 0.0;          ///< total area of the truth faces on this plane
  std::size_t points = 0;     ///< number of scan points sampled on it (0: the plane is missing in the scan)
};

/// The models. Outdoor models (box, house, dormer_house, courtyard) stand on z = 0 and the bracket lies on
/// z = 0; their bottom faces are in the truth but no scanner sees them (no points: realistic, intended).
/// Convention everywhere: truth faces are oriented with normals pointing out of the truth solid. For the
/// room, the truth solid is the room's interior *air* (room box minus table minus pillar), scanned from
/// inside, so its face normals point into the walls, the furniture and the pillar.
/// Truth faces are convex planar polygons (possibly with collinear vertices where a neighbouring face has a
/// corner), vertex 0 a strict corner, so fan triangulation is valid.
/// Scanner: Fibonacci ray directions, randomly rotated per scanner (seeded), first hit along the ray
/// (occlusion), hits at grazing incidence (|cos| < 0.02) dropped, range noise N(0, noise * diagonal).
struct SynthScan {
  std::string model;
  std::uint64_t seed = 1;           ///< the parameters it was made with (written to planes.json)
  double noise = 0.0;
  std::size_t target_points = 0;
  PointCloud cloud;                 ///< points with unit normals oriented towards the scanner that saw them
  std::vector<int> point_plane;     ///< index into `planes` of the face each point was sampled on
  PolygonMesh truth;                ///< closed, 2-manifold, outward oriented model
  std::vector<SynthPlane> planes;   ///< distinct planes of the model (coplanar faces share one)
  std::vector<Vec3> scanners;       ///< positions actually used
  std::vector<int> point_scanner;   ///< index into `scanners` of the scanner that saw each point
  std::vector<int> face_plane;      ///< index into `planes` of each truth face
  /// True for indoor models (the room): the scanners are inside the truth solid, which is the interior
  /// air volume, so truth normals point away from the scanners and point normals are opposite to them.
  /// False: the truth is the building/part volume and point normals agree with the truth normals.
  bool indoor = false;
};

/// Model names, in a fixed order: box, house, dormer_house, bracket, room, courtyard.
std::vector<std::string> synth_model_names();

/// Builds the model and scans it. Deterministic for given params. Throws hsr::Error(BadInput) for an unknown
/// model name (the message lists the valid ones).
SynthScan run_synth(const std::string& model, const SynthParams& params = {});

/// Writes DIR/points.ply (binary, with normals), DIR/truth.obj and DIR/planes.json; creates DIR.
void write_synth(const SynthScan& scan, const std::string& dir);

}  // namespace hsr
