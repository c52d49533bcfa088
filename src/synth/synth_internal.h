// Internal interfaces of the synth stage (not part of the public API): the model builder (exact CSG in
// models.cpp) and the ray caster (AABB tree in scan.cpp), kept apart so CGAL stays out of synth.cpp.
#pragma once

#include "core/types.h"
#include "synth/synth.h"

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <utility>
#include <string>
#include <vector>

namespace hsr::synth_detail {

// Seeded draws, written once for every generator: from the generator's top 53 bits, so the same seed gives
// the same scene on every platform (std's distributions are not specified bit for bit).

/// Uniform in (0, 1].
inline double uniform01(std::mt19937_64& rng) { return (static_cast<double>(rng() >> 11) + 1.0) * 0x1.0p-53; }

/// Standard normal (Box-Muller on two uniform01 draws).
inline double gaussian(std::mt19937_64& rng) {
  const double u1 = uniform01(rng), u2 = uniform01(rng);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

/// Uniform in [lo, hi).
inline double draw(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * (static_cast<double>(rng() >> 11) * 0x1.0p-53);
}

/// The airborne scanner's share of the rays crossing a tree crown that return from it (the aerial models'
/// scanner and the city tile's alike).
inline constexpr double kCrownEchoShare = 0.7;

/// A procedural model: its truth mesh (closed, 2-manifold, convex planar faces, outward oriented) and
/// its default scanner positions.
struct Model {
  PolygonMesh mesh;
  std::vector<Vec3> scanners;
  bool indoor = false;  ///< scanners are inside the solid (the room: the solid is the interior air)
  bool aerial = false;  ///< an aerial building (metres, on z = 0): scanned by the airborne scanner
  double density = 0.0;  ///< default scan density, points per m² of the truth (0: target_points decides)
  double noise_length = 0.0;  ///< SynthParams::noise is a fraction of this length (metres); 0: the diagonal
  std::vector<SynthBlock> blocks;  ///< indoor models: the furniture
};

/// Builds a model by name; returns std::nullopt for an unknown name. The seed draws the dimensions of the
/// aerial and indoor models (the other models are fixed); the indoor ones also read blocks and planes.
std::optional<Model> build_model(const std::string& name, const SynthParams& params);

/// One planar region of a model's surface: its directed boundary edges (indices into a vertex list), the
/// region on their left seen from where `normal` points (outer loop counter-clockwise, holes clockwise),
/// and the unit normal pointing out of the solid.
struct PlanarRegion {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> boundary;
  Vec3 normal = Vec3::UnitZ();
};

/// The truth mesh of a solid given by its planar regions (models.cpp): vertices in a canonical
/// (lexicographic) order, each region split into convex faces exactly as the CSG models' faces are (a
/// convex single loop kept, anything else triangulated exactly and merged back into convex pieces). The
/// vertices must be distinct and the regions' boundaries must close the solid.
PolygonMesh mesh_of_regions(const std::vector<Vec3>& vertices, std::vector<PlanarRegion> regions);

/// The indoor models (indoor.cpp, see synth_indoor_model_names()); std::nullopt for another name.
std::optional<Model> build_indoor_model(const std::string& name, const SynthParams& params);

/// A tree crown seen from the air: an ellipsoid that returns an echo from inside it for a share of the
/// rays crossing it (the others pass through gaps in the foliage).
struct Crown {
  Vec3 centre;
  double radius = 3.0, height = 2.4;  ///< horizontal and vertical semi-axes, metres
  /// Entry and exit parameters of the ray o + t d (|d| = 1) through the crown, if it crosses it.
  std::optional<std::pair<double, double>> crossing(const Vec3& o, const Vec3& d) const {
    const Vec3 scale(1.0 / radius, 1.0 / radius, 1.0 / height);
    const Vec3 oo = (o - centre).cwiseProduct(scale), dd = d.cwiseProduct(scale);
    const double a = dd.squaredNorm(), b = oo.dot(dd), c = oo.squaredNorm() - 1.0;
    const double disc = b * b - a * c;
    if (disc <= 0) return std::nullopt;
    const double root = std::sqrt(disc);
    return std::make_pair((-b - root) / a, (-b + root) / a);
  }
};

/// First-hit ray casting against the faces of a mesh.
class RayCaster {
 public:
  /// `face_planes[f]` is the plane of mesh face f (used to put hit points exactly on the face's plane).
  RayCaster(const PolygonMesh& mesh, const std::vector<Plane>& face_planes);
  ~RayCaster();
  RayCaster(const RayCaster&) = delete;
  RayCaster& operator=(const RayCaster&) = delete;

  struct Hit {
    int face = -1;
    double t = 0.0;  ///< distance along the (unit) direction
  };
  /// First face hit by the ray origin + t * dir (t > 0, |dir| = 1), if any.
  std::optional<Hit> first_hit(const Vec3& origin, const Vec3& dir) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hsr::synth_detail
