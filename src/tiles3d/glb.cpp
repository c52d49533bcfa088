// glb_bytes (glb.h).
#include "tiles3d/glb.h"

#include "core/error.h"

#include <cstring>
#include <limits>

namespace hsr {

namespace {

constexpr std::uint32_t kMagic = 0x46546C67;      // "glTF"
constexpr std::uint32_t kJsonChunk = 0x4E4F534A;  // "JSON"
constexpr std::uint32_t kBinChunk = 0x004E4942;   // "BIN\0"
constexpr int kFloat = 5126, kUnsignedInt = 5125;  // accessor component types
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;  // bufferView targets

void put_u32(std::string& out, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) out.push_back(static_cast<char>((v >> (8 * k)) & 0xFF));  // little endian
}

template <class T>
void put_raw(std::string& out, const std::vector<T>& v) {
  const std::size_t n = v.size() * sizeof(T);
  const std::size_t at = out.size();
  out.resize(at + n);
  if (n) std::memcpy(out.data() + at, v.data(), n);
}

/// Appends a bufferView of `data` to the BIN chunk (4-byte aligned) and an accessor of it; returns the
/// accessor's index.
template <class T>
int add_accessor(const std::vector<T>& data, const char* type, int component, int target, nlohmann::json& gltf,
                 std::string& bin, bool bounds) {
  while (bin.size() % 4) bin.push_back('\0');
  const std::size_t offset = bin.size();
  put_raw(bin, data);
  gltf["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bin.size() - offset}, {"target", target}});
  nlohmann::json a = {{"bufferView", gltf["bufferViews"].size() - 1}, {"componentType", component}, {"type", type}};
  if constexpr (std::is_same_v<T, std::array<float, 3>>) {
    a["count"] = data.size();
    if (bounds) {  // POSITION must state its bounds (glTF 2.0, 3.6.2.4)
      std::array<float, 3> lo, hi;
      lo.fill(std::numeric_limits<float>::infinity());
      hi.fill(-std::numeric_limits<float>::infinity());
      for (const auto& p : data)
        for (int k = 0; k < 3; ++k) {
          lo[k] = std::min(lo[k], p[k]);
          hi[k] = std::max(hi[k], p[k]);
        }
      a["min"] = lo;
      a["max"] = hi;
    }
  } else {
    a["count"] = data.size();
  }
  gltf["accessors"].push_back(a);
  return static_cast<int>(gltf["accessors"].size() - 1);
}

void check(const GlbMesh& m) {
  const bool ok = m.normals.size() == m.positions.size() && (m.colors.empty() || m.colors.size() == m.positions.size()) &&
                  m.indices.size() % 3 == 0 && !m.positions.empty() && !m.indices.empty();
  if (!ok) throw Error(Status::Internal, "tiles3d", "glb: mesh '" + m.name + "' breaks its invariants");
  for (std::uint32_t i : m.indices)
    if (i >= m.positions.size()) throw Error(Status::Internal, "tiles3d", "glb: mesh '" + m.name + "' indexes past its vertices");
}

}  // namespace

std::string glb_bytes(const std::vector<GlbMesh>& meshes, const std::string& generator) {
  nlohmann::json gltf = {{"asset", {{"version", "2.0"}, {"generator", generator}}},
                         {"scene", 0},
                         {"scenes", {{{"nodes", nlohmann::json::array()}}}},
                         {"nodes", nlohmann::json::array()},
                         {"meshes", nlohmann::json::array()},
                         {"materials", {{{"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 1}}, {"metallicFactor", 0.0},
                                                                   {"roughnessFactor", 1.0}}}}}},
                         {"accessors", nlohmann::json::array()},
                         {"bufferViews", nlohmann::json::array()}};
  std::string bin;
  for (const GlbMesh& m : meshes) {
    check(m);
    nlohmann::json attributes = {{"POSITION", add_accessor(m.positions, "VEC3", kFloat, kArrayBuffer, gltf, bin, true)},
                                 {"NORMAL", add_accessor(m.normals, "VEC3", kFloat, kArrayBuffer, gltf, bin, false)}};
    if (!m.colors.empty()) attributes["COLOR_0"] = add_accessor(m.colors, "VEC3", kFloat, kArrayBuffer, gltf, bin, false);
    const int indices = add_accessor(m.indices, "SCALAR", kUnsignedInt, kElementArrayBuffer, gltf, bin, false);
    gltf["meshes"].push_back({{"name", m.name}, {"primitives", {{{"attributes", attributes}, {"indices", indices}, {"material", 0}, {"mode", 4}}}}});
    nlohmann::json node = {{"name", m.name}, {"mesh", gltf["meshes"].size() - 1}};
    if (!m.extras.empty()) node["extras"] = m.extras;
    gltf["nodes"].push_back(node);
    gltf["scenes"][0]["nodes"].push_back(gltf["nodes"].size() - 1);
  }
  while (bin.size() % 4) bin.push_back('\0');
  gltf["buffers"] = {{{"byteLength", bin.size()}}};
  std::string json = gltf.dump();
  while (json.size() % 4) json.push_back(' ');
  std::string out;
  put_u32(out, kMagic);
  put_u32(out, 2);
  put_u32(out, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
  put_u32(out, static_cast<std::uint32_t>(json.size()));
  put_u32(out, kJsonChunk);
  out += json;
  put_u32(out, static_cast<std::uint32_t>(bin.size()));
  put_u32(out, kBinChunk);
  out += bin;
  return out;
}

}  // namespace hsr
