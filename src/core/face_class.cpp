#include "core/face_class.h"

#include <cmath>

namespace hsr {

const char* face_class_name(FaceClass c) {
  switch (c) {
    case FaceClass::Roof: return "roof";
    case FaceClass::Wall: return "wall";
    case FaceClass::Ground: return "ground";
    case FaceClass::Closure: return "closure";
    case FaceClass::Unknown: break;
  }
  return "unknown";
}

bool parse_face_class(const std::string& name, FaceClass& out) {
  for (FaceClass c : {FaceClass::Unknown, FaceClass::Roof, FaceClass::Wall, FaceClass::Ground, FaceClass::Closure})
    if (name == face_class_name(c)) {
      out = c;
      return true;
    }
  return false;
}

Vec3 newell_vector(const std::vector<Vec3>& vertices, const std::vector<std::uint32_t>& loop) {
  Vec3 n = Vec3::Zero();
  const std::size_t k = loop.size();
  for (std::size_t i = 0; i < k; ++i) n += vertices[loop[i]].cross(vertices[loop[(i + 1) % k]]);
  return n;
}

std::vector<FaceClass> classify_faces_by_normal(const PolygonMesh& mesh) {
  std::vector<FaceClass> out(mesh.faces.size(), FaceClass::Unknown);
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const Vec3 n = newell_vector(mesh.vertices, mesh.faces[f]);
    const double len = n.stableNorm();
    if (!(len > 0) || !std::isfinite(len)) continue;
    const double nz = n.z() / len;
    out[f] = std::abs(nz) < kVerticalFaceNz ? FaceClass::Wall : nz > 0 ? FaceClass::Roof : FaceClass::Ground;
  }
  return out;
}

std::vector<FaceClass> face_classes_or_by_normal(const PolygonMesh& mesh) {
  std::vector<FaceClass> out = classify_faces_by_normal(mesh);
  if (mesh.face_class.size() == mesh.faces.size())
    for (std::size_t f = 0; f < out.size(); ++f)
      if (mesh.face_class[f] != FaceClass::Unknown) out[f] = mesh.face_class[f];
  return out;
}

}  // namespace hsr
