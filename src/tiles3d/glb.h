// glTF 2.0 binary (.glb) of triangle meshes, as 3D Tiles 1.1 content (tiles3d.h). Plain data in, bytes out.
// Khronos glTF 2.0 specification: a 12-byte header, a JSON chunk and a BIN chunk, each 4-byte aligned.
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace hsr {

/// One mesh of a glb: flat-shaded triangles, vertex by vertex. Invariants: normals and colors hold one entry
/// per position (or colors is empty); every index < positions.size(); indices.size() is a multiple of 3.
struct GlbMesh {
  std::string name;                              ///< the node's name (a building id)
  nlohmann::json extras = nlohmann::json::object();  ///< the node's extras (its attributes)
  std::vector<std::array<float, 3>> positions;   ///< in the content's frame (glTF: y up), metres
  std::vector<std::array<float, 3>> normals;     ///< unit length
  std::vector<std::array<float, 3>> colors;      ///< linear RGB in [0, 1], or empty
  std::vector<std::uint32_t> indices;            ///< triangles
};

/// The .glb bytes of `meshes`, one node and one mesh (one primitive, one shared material) each, in order.
/// Throws Error(Internal, "tiles3d") when a mesh breaks its invariants.
std::string glb_bytes(const std::vector<GlbMesh>& meshes, const std::string& generator = "hsr");

}  // namespace hsr
